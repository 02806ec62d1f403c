// cloth_source.h — a cloth's cooked data (ossa.fbs "Cloth", format 9) as spans, its settings, and
// check_cloth, the one list of the cloth solver's preconditions (ossa/anim/cloth.h simulates it).
// In the loader's room because the loader runs check_cloth on every file's cloth, and the loader
// comes before the solver in the runtime's include order (scripts/check-layout.py).
#pragma once
#include <cstdint>
#include <span>

#include <glm/glm.hpp>

#include <ossa/format/ossa_generated.h>
#include <ossa/format/result.h>
#include <ossa/loader/asset.h>

namespace ossa {

/// Particles per cloth: constraints index them with 16 bits.
inline constexpr uint32_t kMaxClothParticles = 65535;

/// What the solver does each substep; the defaults of a cooked cloth come from its file
/// (cloth_source), and a host may change any of them between updates (ClothInstance::settings).
struct ClothSettings {
  float substep = 1.0f / 240.0f;    // seconds per internal step, in [1e-4, 0.05]
  uint32_t iterations = 1;          // constraint passes per substep, 1..16 (small steps need one)
  float thickness = 0.0f;           // particle collision radius, model units
  float stretch_compliance = 0.0f;  // s^2 per unit mass (1 / stiffness): 0 inextensible
  float bend_compliance = 0.0f;
  float tether_scale = 1.0f;       // tether lengths times this, in [1, 2]
  float damping = 0.0f;            // per second: velocity *= exp(-damping * t)
  float drag = 0.0f;               // per second: how fast the cloth takes the air's velocity along its normal
  glm::vec3 gravity{0.0f};         // world space, world units / s^2 (identity transform: model units)
  glm::vec3 wind{0.0f};            // the air's velocity, world space, world units / s
  float linear_inertia = 1.0f;     // [0, 1]: share of the world's translation the cloth feels
  float angular_inertia = 1.0f;    // [0, 1]: share of its rotation
  float teleport_distance = 0.0f;  // world units; > 0: a jump further in one update restarts
  float teleport_angle = 0.0f;     // radians; > 0: a turn further in one update restarts
  float max_speed = 0.0f;          // model units / s; > 0: particle speeds are clamped to it
};

/// A cloth's cooked data as spans (into a loaded file, or the caller's arrays): see ossa.fbs
/// "Cloth" for each field. It must outlive the instances made from it.
struct ClothSource {
  std::span<const uint32_t> particle_vertices;
  std::span<const float> inverse_masses;
  std::span<const float> max_distances;  // empty: none
  std::span<const float> backstops;      // empty: none
  std::span<const uint32_t> vertices;
  std::span<const uint16_t> vertex_particles;
  std::span<const uint8_t> flipped;  // empty: none
  std::span<const uint16_t> triangles;
  std::span<const fb::ClothEdge> stretch;
  std::span<const fb::ClothEdge> bend;
  std::span<const fb::ClothTether> tethers;
  std::span<const fb::ClothCollider> colliders;
  ClothSettings settings;  // the defaults
  size_t particle_count() const { return particle_vertices.size(); }
};

/// The cloth of a mesh of a loaded (hence validated) file, or an empty source (no particles)
/// when the mesh has none.
ClothSource cloth_source(const MeshView& mesh);

/// Every invariant the solver and the helpers below rely on, over a source that may come from
/// anywhere: matching array sizes, 1..kMaxClothParticles particles, indices in range (particle
/// vertices and vertices < vertex_count, vertices strictly increasing, colliders' joints <
/// joint_count), constraints joining two different particles, tether anchors fixed, every number
/// finite and bounded, settings in their ranges. Messages start with "cloth:" and name the field
/// and the entry. The loader runs it on every file's cloths. O(particles + constraints).
Status check_cloth(const ClothSource& source, uint32_t vertex_count, size_t joint_count);
/// The settings alone (a host's changes): ranges as documented on ClothSettings.
Status check_cloth_settings(const ClothSettings& settings);

}  // namespace ossa
