// bounds.h — how big the character is, for framing the camera and sizing the grid.
//
// No vertex is touched: each mesh's cooked bounds box (mesh space) goes through a bind-pose
// palette matrix (model(joint) * inverse_bind: the placement a vertex bound to that slot alone
// gets), and the joints' bind positions are added. When the skin's bind pose and the skeleton's
// agree, every slot has the same matrix and the box is exact. They do not always agree: Pab's
// mesh was skinned with the fingers posed differently from the rig's bind pose, so its finger
// slots carry other matrices, and a union over every slot framed a box 2.4 times too wide. The
// box therefore goes through the matrices of the largest group of slots that agree (corners
// within 1 % of the box diagonal), which is the mesh's actual placement. A mesh's box is also a
// union over what was merged into it: when pab.ossa still held skeleton.fbx's body (Z-up in its
// mesh space) merged with arnaud.fbx's (Y-up), its box covered 1.8 m in every axis. So, with a
// skeleton, an axis on which the mesh box is implausibly larger than the joints' extent (more than
// 1.5x the joints' extent grown by 10 % of the joints' diagonal on each side) is clipped to that
// grown extent. Ordinary meshes (a big-headed CesiumMan, a cylinder around a bone chain) stay
// below the threshold and keep their exact box; this only frames the camera.
#pragma once
#include <limits>
#include <span>

#include <glm/glm.hpp>

#include <ossa/loader/asset.h>

namespace ossa::view {

struct Box {
  glm::vec3 min{std::numeric_limits<float>::max()};
  glm::vec3 max{-std::numeric_limits<float>::max()};

  bool empty() const { return min.x > max.x; }
  void add(glm::vec3 p) {
    min = glm::min(min, p);
    max = glm::max(max, p);
  }
  void add(const Box& b) {
    if (!b.empty()) { add(b.min); add(b.max); }
  }
  glm::vec3 centre() const { return (min + max) * 0.5f; }
  glm::vec3 size() const { return max - min; }
};

/// The character in its bind pose, in model space. `model` holds the bind pose's model matrices
/// (one per skeleton joint; empty for a file without skeleton). O(meshes * slots + joints).
Box bind_pose_bounds(const Asset& asset, std::span<const glm::mat4> model);

/// Box of the joint positions of a posed skeleton (model matrices' translations). O(joints).
Box joint_bounds(std::span<const glm::mat4> model);

}  // namespace ossa::view
