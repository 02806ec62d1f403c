// cloth_view.h — the character's cooked cloth (ossa/anim/cloth.h) simulated for every instance the
// viewer draws, and its overlay.
//
// One ClothInstance per (crowd instance, mesh with cloth), made when the scene or the crowd changes,
// never per frame. Each frame, after the poses: the cloth particles' skinned positions come from
// skin_cloth_particles with the instance's palette in model space (no crowd offset), and
// update_cloth advances them with the joints' model matrices (colliders) and the crowd placement,
// after the character's own motion through the world (--move / --turn, animation.h Drive), as the
// model-to-world transform. The renderer then draws the particles where they are, `world` and the
// crowd placement applied: on the GPU path its vertex shader reads them for the cloth vertices of
// a mesh it skins (renderer.h), on the CPU path they are written over skin_cpu's streams
// (write_cloth_vertices). A root that jumps further than the cloth's teleport
// distance in one frame (a looping clip with root motion) restarts that cloth from the skinned pose,
// as ClothInstance does for a jump of the world transform.
#pragma once
#include <cstddef>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include <ossa/anim/cloth.h>
#include <ossa/format/result.h>

namespace ossa::view {

struct Scene;
struct Animator;
struct OverlayGeometry;

struct ClothSim {
  size_t instance = 0;  // crowd instance
  size_t mesh = 0;      // character mesh
  ClothInstance state;
  glm::vec3 last_root{0.0f};
};

struct ViewerCloth {
  std::vector<ClothSim> sims;  // instance-major, meshes in order
  bool enabled = true;         // --cloth off / the panel: meshes drawn as skinned
  glm::vec3 wind{0.0f};        // metres per second, world space (the panel, --wind)
  float stiffness = 1.0f;      // scales the cooked compliances down (1: as cooked)
  // The character's motion through the world (animation.h Drive) at the last step: the drawn
  // model matrices hold it; the simulation runs without it in the character's own space and
  // receives it in its model-to-world transform, so a turn swings the cape.
  glm::mat4 world{1.0f};
  std::vector<glm::mat4> palette;    // scratch, sized once
  std::vector<glm::mat4> own_model;  // scratch: the model matrices without `world`, one per joint
  std::vector<glm::vec3> positions, normals;

  bool empty() const { return sims.empty(); }
  /// The simulation of `mesh` of `instance`, or null (no cloth, or cloth off).
  const ClothInstance* find(size_t instance, size_t mesh) const;
};

/// Instances for every mesh of the character that has cloth, `instances` times. Errors name the
/// file (a cloth the solver refuses).
Result<ViewerCloth> make_viewer_cloth(const Scene& scene, size_t instances);

/// Advances every simulation by dt seconds from the animator's current model matrices.
/// `bind` are the renderer's bind matrices per mesh (prepare_bind_matrices), `offsets` the crowd
/// placement. Allocation-free. O(instances * cloth cost).
Status step_viewer_cloth(ViewerCloth& cloth, const Scene& scene, const Animator& animator,
                         std::span<const std::vector<glm::mat4>> bind, std::span<const glm::vec3> offsets, float dt);

/// Every simulation restarts from the skinned pose at its next step (the panel's Reset).
void reset_viewer_cloth(ViewerCloth& cloth);

/// Overlay: the particles (fixed ones red), the stretch edges and the colliders, at the crowd
/// placement. Appends to out.on_top.
void build_cloth_overlay(const ViewerCloth& cloth, const Animator& animator, std::span<const glm::vec3> offsets,
                         OverlayGeometry& out);

}  // namespace ossa::view
