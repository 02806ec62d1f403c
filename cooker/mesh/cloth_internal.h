// cloth_internal.h — what cloth_build.cpp and cloth_colliders.cpp share; not an API.
#pragma once
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "cooker/mesh/cloth_build.h"
#include "cooker/mesh/mesh_build.h"
#include <ossa/anim/cloth.h>

namespace ossa::cook {

inline constexpr size_t kMaxClothParticlesCooked = kMaxClothParticles;

namespace detail {

/// Each joint's bind-pose model matrix, from the local bind transforms (as the runtime's
/// local_to_model makes them at the bind pose).
std::vector<glm::mat4> bind_model_matrices(const SourceSkeleton& skeleton);

/// A source vertex skinned at the bind pose (model space); the mesh's own position when static.
glm::vec3 bind_position(const SourceMesh& m, size_t v, const std::vector<glm::mat4>& bind_model);

/// A cooked mesh's vertices skinned at the bind pose, decoded from its cooked bytes.
struct DecodedMesh {
  std::vector<glm::vec3> positions, normals;  // model space; normals unit length
};
DecodedMesh decode_bind_pose(const SourceScene& scene, const CookedMesh& mesh);

/// The colliders of a cloth whose particles rest at `rest` (model space, bind pose) with
/// `weight` (0: fixed) and `reach` (each particle's path length to its anchor): the settings'
/// colliders when any are named, else (auto_colliders) capsules fitted to the bones near the cloth.
Result<std::vector<fb::ClothCollider>> cloth_colliders(const SourceScene& scene, const ClothOptions& options,
                                                       const std::vector<glm::vec3>& rest,
                                                       const std::vector<float>& weight,
                                                       const std::vector<float>& reach, const std::string& label,
                                                       std::vector<std::string>* warnings);

}  // namespace detail
}  // namespace ossa::cook
