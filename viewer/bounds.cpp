// bounds.cpp — see bounds.h.
#include "viewer/bounds.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <ossa/skinning/skinning.h>

namespace ossa::view {

Box joint_bounds(std::span<const glm::mat4> model) {
  Box b;
  for (const glm::mat4& m : model) b.add(glm::vec3(m[3]));
  return b;
}

namespace {

/// Calls f(p) for every finite skinned vertex of the asset in the pose `model`.
template <class F>
void for_each_skinned_vertex(const Asset& asset, std::span<const glm::mat4> model, F&& f) {
  std::vector<glm::mat4> palette;
  std::vector<float> positions;
  for (size_t i = 0; i < asset.mesh_count(); ++i) {
    const MeshView mesh = asset.mesh(i);
    if (mesh.vertex_count() == 0) continue;
    palette.assign(std::max<size_t>(mesh.joints().size(), 1), glm::mat4(1.0f));
    skinning_matrices(mesh, model, palette);
    positions.assign(static_cast<size_t>(mesh.vertex_count()) * 3, 0.0f);
    skin_cpu(mesh, palette, SkinningMethod::Linear, SkinnedStreams{positions, {}, {}});
    for (size_t v = 0; v < positions.size(); v += 3) {
      const glm::vec3 p(positions[v], positions[v + 1], positions[v + 2]);
      if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) f(p);
    }
  }
}

}  // namespace

Box posed_bounds(const Asset& asset, std::span<const glm::mat4> model) {
  Box box = joint_bounds(model);
  for_each_skinned_vertex(asset, model, [&](glm::vec3 p) { box.add(p); });
  return box;
}

const char* axis_name(glm::vec3 f) {
  if (std::fabs(f.x) > std::fabs(f.z)) return f.x > 0.0f ? "+x" : "-x";
  return f.z >= 0.0f ? "+z" : "-z";
}

Facing facing_of(const Asset& asset, std::span<const glm::mat4> model) {
  Box all;
  for_each_skinned_vertex(asset, model, [&](glm::vec3 p) { all.add(p); });
  // A skeleton without a mesh (a BVH capture): its joints, toes ahead of the ankles, tell instead.
  const bool joints = all.empty();
  const auto each_point = [&](auto&& f) {
    if (joints) {
      for (const glm::mat4& m : model) f(glm::vec3(m[3]));
    } else {
      for_each_skinned_vertex(asset, model, f);
    }
  };
  if (joints) all = joint_bounds(model);
  Facing out;
  if (all.empty() || !(all.size().y > 0.0f)) return out;
  const float height = all.size().y, foot_top = all.min.y + 0.10f * height, leg_top = all.min.y + 0.35f * height;
  Box feet, legs;
  each_point([&](glm::vec3 p) {
    if (p.y <= foot_top) feet.add(p);
    else if (p.y <= leg_top) legs.add(p);
  });
  if (feet.empty() || legs.empty()) return out;
  // How far the feet reach past the legs above them, towards each of the four horizontal axes.
  const float reach[4] = {feet.max.z - legs.max.z, legs.min.z - feet.min.z, feet.max.x - legs.max.x,
                          legs.min.x - feet.min.x};
  const glm::vec3 axes[4] = {{0, 0, 1}, {0, 0, -1}, {1, 0, 0}, {-1, 0, 0}};
  // Lopsidedness along an axis: the reach forward minus the reach backward (a heel reaches back a
  // little, toes far forward; sideways both sides reach alike).
  int best = -1;
  float best_score = 0.0f;
  for (int i = 0; i < 4; ++i) {
    const float score = (reach[i] - reach[i ^ 1]) / height;
    if (score > best_score) {
      best = i;
      best_score = score;
    }
  }
  if (best < 0 || best_score < 0.015f) return out;
  out.forward = axes[best];
  out.yaw = std::atan2(out.forward.x, out.forward.z);
  out.evidence = best_score;
  out.from_feet = true;
  return out;
}

}  // namespace ossa::view
