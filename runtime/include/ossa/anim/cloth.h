// cloth.h — capes, skirts and hair cards simulated on a skinned mesh: XPBD at a fixed substep.
//
// The character-animation seed's cloth (concept eight): mass points joined by springs, a weight per
// vertex (0: the vertex follows the skin), gravity, damping, relaxation and collision with the
// bones. ossa solves it the way current engines do (Macklin et al., "XPBD" 2016 and "Small Steps in
// Physics Simulation" 2019; Kim et al., "Long Range Attachments" 2012):
// - particles are the cloth region's vertices welded by position (cooked, ossa.fbs "Cloth"); each
//   is driven by the skinned position of one mesh vertex, and particles with inverse mass 0 are
//   that position exactly;
// - distance constraints (stretch along the triangles' edges, bending across pairs of triangles)
//   are projected with compliance (seconds^2 per unit mass, 1 / stiffness), so stiffness does not
//   depend on the substep or the iteration count; long-range tethers keep each free particle within
//   its path length of a fixed one, so the cloth cannot stretch however few iterations run; max
//   distance and backstop keep a particle near its skinned position and in front of its skinned
//   surface; spheres and capsules on joints push particles out, last, so no substep ends inside;
// - a fixed internal substep (ClothSettings::substep): update_cloth runs the whole substeps dt
//   covers and banks the rest; the skinned pose, the colliders and the world transform are
//   interpolated across the substeps of one update (quadratically, through the last three
//   updates' inputs: a straight line between frames would jolt the cloth at every frame), and the
//   output is carried the banked time further, so 30, 60, 144 and 240 Hz frames drive the same
//   simulation;
// - simulated in the character's model space: the world transform's change is applied to the
//   particles scaled by linear_inertia and angular_inertia (0: the cloth moves rigidly with the
//   character; 1: it keeps its world-space momentum), and gravity and wind are given in world
//   space. A jump past teleport_distance in one update restarts from the skinned pose, as does
//   reset_cloth. Damping is a rate per second.
//
// Data flow per frame, for a host with or without the graph: skinning gives the particles' skinned
// positions and normals (skin_cloth_particles skins just those vertices, for hosts that skin on
// the GPU; gather_cloth_particles picks them from skin_cpu's output), update_cloth advances the
// simulation from them, the joints' model matrices (colliders), the model-to-world transform and
// dt, and ClothInstance::positions / normals (model space, per particle) are what an engine draws:
// write_cloth_vertices puts them over skin_cpu's streams, or a vertex shader reads them by
// particle. All state is per instance and allocated by make_cloth_instance; nothing in the update
// path allocates, and the same inputs give the same bits.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include <ossa/format/ossa_generated.h>
#include <ossa/format/result.h>
#include <ossa/loader/asset.h>
#include <ossa/loader/cloth_source.h>

namespace ossa {

/// A constraint list (stretch, bend or tethers) laid out for the solver's eight-wide kernels
/// (runtime/anim/cloth_kernels.h), made by make_cloth_instance: each run of the stored order whose
/// constraints share no particle is regrouped (any order within a run gives the same bits) into
/// groups of eight lanes whose ends lie in few contiguous particles, then the run's last few lanes.
struct ClothWideList {
  std::vector<uint32_t> a, b;       // per lane: the ends (an edge may be turned round: same bits)
  std::vector<float> rest, wa, wb;  // per lane: rest length (a tether's length), inverse masses of a and b;
                                    // all 0 in an idle lane (a group's pattern with no constraint there)
  std::vector<uint8_t> kinds;       // per group: how its ends lie (cloth_kernels.h's WideKind)
  std::vector<uint32_t> runs;       // per run, two lane counts: where its groups end, where it ends
};

/// The particles as planes (a structure of arrays, so that the solver's kernels load eight of a
/// coordinate at once): current and previous positions in model space, and inverse masses.
struct ClothParticles {
  std::vector<float> x, y, z;     // now
  std::vector<float> px, py, pz;  // one substep ago, in the same frame
  std::vector<float> w;           // inverse mass (0: the particle is its skinned position)

  size_t size() const { return x.size(); }
  glm::vec3 at(size_t i) const { return {x[i], y[i], z[i]}; }
  glm::vec3 before(size_t i) const { return {px[i], py[i], pz[i]}; }
  void set(size_t i, const glm::vec3& v) {
    x[i] = v.x;
    y[i] = v.y;
    z[i] = v.z;
  }
  void set_before(size_t i, const glm::vec3& v) {
    px[i] = v.x;
    py[i] = v.y;
    pz[i] = v.z;
  }
};

/// One character's cloth: the simulation state, made once; positions() / normals() are the output
/// of the last update. Move-only in spirit (the vectors are its memory); reading any member is
/// fine, writing anything but `settings` is the solver's business.
struct ClothInstance {
  ClothSource source;
  ClothSettings settings;    // starts as source.settings; change freely between updates
  ClothParticles particles;  // the simulation's state
  std::vector<glm::vec3> skinned_before, skinned_normal_before;  // the last update's inputs
  std::vector<glm::vec3> skinned_older;                          // and the one's before it
  std::vector<glm::vec3> out_positions, out_normals;             // the last update's output
  std::vector<glm::vec3> colliders_before;                       // 2 per collider: model-space ends at the last update
  std::vector<glm::vec3> colliders_older, colliders_now;
  std::vector<float> lambda;                    // XPBD multipliers (per wide lane, stretch then bend) if iterations > 1
  std::vector<uint16_t> facing;                 // 3 per particle: a triangle it is a corner of (the wind's normal)
  std::vector<uint32_t> corner_start, corners;  // from corner_start[i]: the triangles particle i is a corner of
  std::vector<glm::vec3> triangle_normals;      // the output's, per triangle (area-weighted)
  ClothWideList wide_stretch, wide_bend, wide_tethers;  // the constraints for the eight-wide kernels
  std::vector<glm::vec4> collider_step;  // 3 per collider, this substep's: ends (w: reach), bounding sphere
  glm::mat4 world_before{1.0f};          // model_to_world at the last update
  glm::mat4 world_state{1.0f};           // model_to_world at the last substep: the particles' frame
  glm::mat4 world_older{1.0f};           // model_to_world at the update before the last
  float dt_before = 0.0f;                // seconds between the older and the last update
  uint32_t history = 0;                  // updates with dt > 0 since the last restart, up to 2
  float banked = 0.0f;                   // seconds not yet simulated (< substep)
  bool started = false;                  // false until the first update, and after reset_cloth
  uint32_t restarts = 0;                 // times the simulation restarted from the skinned pose

  std::span<const glm::vec3> positions() const { return out_positions; }
  std::span<const glm::vec3> normals() const { return out_normals; }
  size_t particle_count() const { return particles.size(); }
};

/// Checks `source` (check_cloth) and allocates all the state an update uses. O(particles +
/// constraints).
Result<ClothInstance> make_cloth_instance(const ClothSource& source, uint32_t vertex_count, size_t joint_count);

/// One update's inputs. skinned_* have one entry per particle, in model space (normals unit
/// length; they may be empty when the cloth has no backstops and no drag). `model` are the
/// skeleton's joint model matrices (colliders; may be empty when it has none). dt >= 0 seconds.
struct ClothInput {
  std::span<const glm::vec3> skinned_positions;
  std::span<const glm::vec3> skinned_normals;
  std::span<const glm::mat4> model;
  glm::mat4 model_to_world{1.0f};
  float dt = 0.0f;
};

/// Advances the simulation by dt (whole substeps, the rest banked, at most 64 substeps: a longer
/// hitch is dropped) and writes positions() and normals(): fixed particles at their skinned
/// positions exactly, the others carried the banked time ahead and kept inside their max
/// distance, in front of their backstop and outside every collider. The first update after
/// creation or reset_cloth, and one whose model_to_world jumped past the teleport settings,
/// restarts from the skinned pose at rest. Errors (input spans too small, non-finite transform or
/// dt, settings out of range) change nothing. Allocation-free. O(substeps * (particles *
/// colliders + constraints * iterations) + triangles).
Status update_cloth(ClothInstance& cloth, const ClothInput& input);

/// The next update restarts from the skinned pose at rest (after a cut or a respawn). O(1).
void reset_cloth(ClothInstance& cloth);

/// `edges` reordered for the solver: greedily coloured, each colour (edges that share no
/// particle, in their given order) stored together, so that make_cloth_instance finds long runs
/// the solver projects eight at a time. Any order is correct; this one is fast. What the cooker
/// stores; for hosts that build cloth themselves. Allocates. O(edges * colours).
std::vector<fb::ClothEdge> colour_cloth_edges(std::span<const fb::ClothEdge> edges, size_t particle_count);

/// The particles' skinned positions and normals (model space): the driving vertices of `mesh`
/// skinned with `palette` (ossa/skinning/skinning.h's skinning_matrices, linear blend), as skin_cpu
/// would skin them. For hosts that skin the rest on the GPU. Allocation-free. O(particles).
Status skin_cloth_particles(const ClothSource& source, const MeshView& mesh, std::span<const glm::mat4> palette,
                            std::span<glm::vec3> positions, std::span<glm::vec3> normals);

/// The same, picked out of skin_cpu's streams (3 floats per vertex of the mesh; normals may be
/// empty, then `normals` is left alone). O(particles).
Status gather_cloth_particles(const ClothSource& source, std::span<const float> skinned_positions,
                              std::span<const float> skinned_normals, std::span<glm::vec3> positions,
                              std::span<glm::vec3> normals);

/// Writes the instance's output over skin_cpu-style streams (3 floats per vertex of the mesh):
/// each of the cloth's vertices gets its particle's position and normal (negated where the
/// cooker flipped it). Either span may be empty. O(cloth vertices).
Status write_cloth_vertices(const ClothInstance& cloth, std::span<float> positions, std::span<float> normals);

}  // namespace ossa
