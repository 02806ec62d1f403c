// cloth_build.h — a mesh region becomes cloth: paint or settings -> per-vertex weights, carried
// through the mesh stage, then the cooked mesh's particles and constraints (ossa.fbs "Cloth").
//
// Authoring needs no new tool (docs/CLOTH.md):
// - paint: a vertex colour set 1 (glTF COLOR_1, an FBX or Collada mesh's second colour layer)
//   marks cloth. Red is the simulation weight (0: the vertex stays skinned; above 0 it is simulated
//   with inverse mass = red); green and blue scale the settings' max_distance and backstop (white:
//   the settings' values). Assimp 5.2 drops glTF custom attributes such as _CLOTH, so a colour set
//   is the attribute every exporter can write.
// - settings (`<stem>.cook.json` "cloth", cloth_settings.h): regions named by mesh or material,
//   their weights from the distance to the vertices that stay skinned (the rest of the character,
//   or the region's vertices on pin joints), rising from 0 to 1 over `ramp` metres.
//
// Then, per cooked mesh (after welding, reordering and quantization, so indices are final):
// particles are the region's vertices welded by position (seams and UV splits share one); stretch
// edges are the region's triangle edges, bend edges join the far corners of triangles sharing an
// edge, each free particle is tethered to its nearest fixed particle along the edges (Dijkstra,
// the path length in the bind pose), and both edge lists are greedily coloured. Colliders come
// from the settings or are fitted to the limb segments near the cloth: a capsule per bone, its
// radius the body's median distance from the bone (from the vertices that bone moves most), kept
// clear of the cloth's bind pose. Lengths are in the model's units, converted from the settings'
// metres with the scene's metres_per_unit.
#pragma once
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "cooker/model/cloth_options.h"
#include "cooker/model/source_scene.h"
#include <ossa/format/ossa_generated.h>
#include <ossa/format/result.h>

namespace ossa::cook {

/// A cooked mesh's cloth, ready for the writer (fields as ossa.fbs "Cloth").
struct CookedCloth {
  std::vector<uint32_t> particle_vertices;
  std::vector<float> inverse_masses, max_distances, backstops;
  std::vector<uint32_t> vertices;
  std::vector<uint16_t> vertex_particles;
  std::vector<uint8_t> flipped;
  std::vector<uint16_t> triangles;
  std::vector<fb::ClothEdge> stretch, bend;
  std::vector<fb::ClothTether> tethers;
  std::vector<fb::ClothCollider> colliders;
  float thickness = 0.0f, stretch_compliance = 0.0f, bend_compliance = 0.0f, tether_scale = 1.0f;
  float damping = 0.0f, drag = 0.0f, linear_inertia = 1.0f, angular_inertia = 1.0f;
  float teleport_distance = 0.0f, max_speed = 0.0f;
  glm::vec3 gravity{0.0f};
  bool empty() const { return particle_vertices.empty(); }
};

/// Per source mesh, the per-vertex cloth attributes the mesh stage carries (empty: no cloth):
/// (weight = inverse mass, max distance, backstop, 1) in model units (a negative distance: no
/// limit); vertices outside every region are all zero. Errors name the mesh or the setting (a
/// region naming no mesh or material of the scene, paint of the wrong size).
Result<std::vector<std::vector<glm::vec4>>> cloth_attributes(const SourceScene& scene, const ClothOptions& options,
                                                             std::vector<std::string>* warnings);

struct CookedMesh;

/// The cloth of one cooked mesh from its per-vertex attributes (one per cooked vertex). Errors
/// name the mesh (more than 65535 particles, a collider on a joint the skeleton lacks).
Result<CookedCloth> build_cloth(const SourceScene& scene, const ClothOptions& options, const CookedMesh& mesh,
                                const std::vector<glm::vec4>& attributes, std::vector<std::string>* warnings);

}  // namespace ossa::cook
