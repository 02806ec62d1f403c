// pose_error.cpp — the probe-point pose error (pose_error.h).
//
// Written joint by joint in double. The cooker (cooker/clip/clip_error.cpp), ossa-diff and
// ossa-bench-acl all call it, so their figures are one measure.
#include <ossa/anim/pose_error.h>

#include <algorithm>
#include <cstddef>

namespace ossa {

ModelAffine affine_from_trs(const glm::vec3& translation, const glm::quat& rotation, const glm::vec3& scale) {
  glm::dquat q(static_cast<double>(rotation.w), static_cast<double>(rotation.x), static_cast<double>(rotation.y),
               static_cast<double>(rotation.z));
  const double len = glm::length(q);
  q = len > 0.0 ? q / len : glm::dquat(1.0, 0.0, 0.0, 0.0);
  ModelAffine a;
  a.linear = glm::mat3_cast(q);
  a.linear[0] *= static_cast<double>(scale.x);
  a.linear[1] *= static_cast<double>(scale.y);
  a.linear[2] *= static_cast<double>(scale.z);
  a.origin = glm::dvec3(translation.x, translation.y, translation.z);
  return a;
}

void local_to_model_affine(std::span<const int16_t> parents, ConstPoseSpan local, std::span<ModelAffine> out) {
  const size_t n = std::min({static_cast<size_t>(local.joint_count), parents.size(), out.size()});
  for (size_t j = 0; j < n; ++j) {
    const glm::vec3 t(local[kTx][j], local[kTy][j], local[kTz][j]);
    const glm::quat r(local[kRw][j], local[kRx][j], local[kRy][j], local[kRz][j]);
    const glm::vec3 s(local[kSx][j], local[kSy][j], local[kSz][j]);
    const ModelAffine a = affine_from_trs(t, r, s);
    const int parent = parents[j];
    if (parent < 0 || static_cast<size_t>(parent) >= j) {
      out[j] = a;
    } else {
      const ModelAffine& p = out[static_cast<size_t>(parent)];
      out[j].linear = p.linear * a.linear;
      out[j].origin = p.linear * a.origin + p.origin;
    }
  }
}

double probe_error(const ModelAffine& reference, const ModelAffine& test, double probe) {
  const glm::dvec3 d_origin = reference.origin - test.origin;
  double worst = 0.0;
  for (int axis = 0; axis < 3; ++axis) {
    const double length = glm::length(reference.linear[axis]);
    const double local = length > 0.0 ? probe / length : 0.0;  // probe from the joint in model space
    const glm::dvec3 d_axis = (reference.linear[axis] - test.linear[axis]) * local;
    worst = std::max(worst, glm::length(d_origin + d_axis));
    worst = std::max(worst, glm::length(d_origin - d_axis));
  }
  return worst;
}

PoseError model_pose_error(std::span<const ModelAffine> reference, std::span<const ModelAffine> test, double probe) {
  PoseError e;
  const size_t n = std::min(reference.size(), test.size());
  for (size_t j = 0; j < n; ++j) {
    const double err = probe_error(reference[j], test[j], probe);
    if (e.joint < 0 || err > e.max) {
      e.max = err;
      e.joint = static_cast<int>(j);
    }
  }
  return e;
}

PoseError pose_error(std::span<const int16_t> parents, ConstPoseSpan reference, ConstPoseSpan test, double probe,
                     std::span<ModelAffine> scratch) {
  const size_t n = std::min({static_cast<size_t>(reference.joint_count), static_cast<size_t>(test.joint_count),
                             parents.size(), scratch.size() / 2});
  const std::span<ModelAffine> a = scratch.first(n), b = scratch.subspan(n, n);
  local_to_model_affine(parents.first(n), reference, a);
  local_to_model_affine(parents.first(n), test, b);
  return model_pose_error(a, b, probe);
}

}  // namespace ossa
