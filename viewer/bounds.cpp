// bounds.cpp — see bounds.h.
#include "viewer/bounds.h"

#include <algorithm>
#include <cstring>
#include <vector>

namespace ossa::view {
namespace {

glm::mat4 to_glm(const fb::Mat4& m) {
  glm::mat4 r;
  std::memcpy(&r[0][0], m.m()->data(), sizeof r);
  return r;
}

void add_box(Box& out, const glm::mat4& transform, glm::vec3 lo, glm::vec3 hi) {
  for (int corner = 0; corner < 8; ++corner) {
    const glm::vec3 p((corner & 1) ? hi.x : lo.x, (corner & 2) ? hi.y : lo.y, (corner & 4) ? hi.z : lo.z);
    out.add(glm::vec3(transform * glm::vec4(p, 1.0f)));
  }
}

}  // namespace

Box joint_bounds(std::span<const glm::mat4> model) {
  Box b;
  for (const glm::mat4& m : model) b.add(glm::vec3(m[3]));
  return b;
}

Box bind_pose_bounds(const Asset& asset, std::span<const glm::mat4> model) {
  const Box joints_box = joint_bounds(model);
  Box box;
  for (size_t i = 0; i < asset.mesh_count(); ++i) {
    const MeshView mesh = asset.mesh(i);
    const fb::Vec3* lo = mesh.fb->bounds_min();
    const fb::Vec3* hi = mesh.fb->bounds_max();
    if (lo == nullptr || hi == nullptr) continue;
    const glm::vec3 l(lo->x(), lo->y(), lo->z()), h(hi->x(), hi->y(), hi->z());
    const auto joints = mesh.joints();
    const auto inverse_bind = mesh.inverse_bind();
    if (joints.empty() || model.empty()) {
      add_box(box, glm::mat4(1.0f), l, h);
      continue;
    }
    std::vector<glm::mat4> placement;
    for (size_t s = 0; s < joints.size() && s < inverse_bind.size(); ++s) {
      if (joints[s] < model.size()) placement.push_back(model[joints[s]] * to_glm(inverse_bind[s]));
    }
    // The largest group of slots placing the box alike (O(slots^2), slots <= 65536 but in practice
    // a few dozen, once per load).
    const float tolerance = 0.01f * glm::length(h - l);
    const auto alike = [&](const glm::mat4& a, const glm::mat4& b) {
      for (int corner = 0; corner < 8; ++corner) {
        const glm::vec4 p((corner & 1) ? h.x : l.x, (corner & 2) ? h.y : l.y, (corner & 4) ? h.z : l.z, 1.0f);
        if (glm::length(glm::vec3(a * p - b * p)) > tolerance) return false;
      }
      return true;
    };
    size_t best = 0, best_count = 0;
    for (size_t a = 0; a < placement.size(); ++a) {
      size_t n = 0;
      for (size_t b = 0; b < placement.size(); ++b) n += alike(placement[a], placement[b]) ? 1 : 0;
      if (n > best_count) {
        best = a;
        best_count = n;
      }
    }
    for (size_t b = 0; b < placement.size(); ++b) {
      if (alike(placement[best], placement[b])) add_box(box, placement[b], l, h);
    }
  }
  if (joints_box.empty()) return box;
  const float margin = 0.1f * glm::length(joints_box.size());
  if (!box.empty() && margin > 0.0f) {
    for (int a = 0; a < 3; ++a) {
      const float lo = joints_box.min[a] - margin, hi = joints_box.max[a] + margin;
      if (box.max[a] - box.min[a] <= 1.5f * (hi - lo)) continue;
      box.min[a] = std::max(box.min[a], lo);
      box.max[a] = std::min(box.max[a], hi);
      if (box.min[a] > box.max[a]) box.min[a] = box.max[a] = 0.5f * (lo + hi);
    }
  }
  box.add(joints_box);
  return box;
}

}  // namespace ossa::view
