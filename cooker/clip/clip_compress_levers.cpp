// clip_compress_levers.cpp — step 2 of the clip compressor (the design is in clip_compress.cpp's
// header): the levers that turn a channel's local error into a bound of the model-space
// displacement it causes, from the reference poses.
//
// Why it is a file of its own: it reads only the skeleton and the reference samples
// (clip_reference.h), before any channel is encoded, and clip_compress.cpp calls it once per
// classification round; what the two share is clip_compress_internal.h.
#include <algorithm>
#include <cmath>
#include <vector>

#include "cooker/clip/clip_compress_internal.h"

namespace ossa::cook::compress_detail {
namespace {

/// An upper bound of the largest singular value: sqrt of the largest absolute row sum of A^T A
/// (Gershgorin), exact for a rotation times a uniform scale.
double sigma_max(const glm::dmat3& a) {
  const glm::dmat3 ata = glm::transpose(a) * a;
  double worst = 0.0;
  for (int r = 0; r < 3; ++r) worst = std::max(worst, std::abs(ata[0][r]) + std::abs(ata[1][r]) + std::abs(ata[2][r]));
  return std::sqrt(worst);
}

/// sigma_max(a) * sigma_max(a^-1): how much a non-uniform parent can stretch a local error. 1 for
/// a singular parent (a zero scale flattens everything under it; verification still measures it).
double condition(const glm::dmat3& a) {
  const double det = glm::determinant(a);
  if (!(std::abs(det) > 1e-30)) return 1.0;
  return std::max(1.0, sigma_max(a) * sigma_max(glm::inverse(a)));
}

}  // namespace

/// Levers from the reference poses, maximised over frames. A rotation error of joint j moves its
/// own probe points and its descendants; a descendant k below j whose rotation is compensated
/// (compensates[k]: its keys are fitted to undo its parent's decoded error) stops the swing: k and
/// everything under it then only shift with k's origin, by |o_k - o_j| per unit of error (nothing
/// when k's translation compensates too). `compensated` is j's lever under that assumption,
/// `rotation` the lever without any compensation. O(frames * joints * depth).
std::vector<Lever> compute_levers(const SourceSkeleton& skeleton, const ClipSamples& ref, double probe,
                                  const std::vector<uint8_t>& compensates) {
  const uint32_t joints = ref.joint_count;
  std::vector<Lever> levers(joints);
  std::vector<Affine> model(joints);
  std::vector<double> sigma(joints), reach(joints), reach_compensated(joints);
  for (uint32_t f = 0; f < ref.frame_count; ++f) {
    model_at_frame(skeleton, ref, f, model);
    for (uint32_t j = 0; j < joints; ++j) {
      sigma[j] = sigma_max(model[j].linear);
      reach[j] = reach_compensated[j] = probe;  // probe points sit `probe` from the joint in model space
    }
    // Every joint's probe points, pushed up to each ancestor: O(joints * depth). Walking up from
    // d, `stop` is the compensating joint closest below the current ancestor.
    for (uint32_t d = 0; d < joints; ++d) {
      const double own = probe;
      int stop = (compensates[d] & kCompensatesRotation) ? static_cast<int>(d) : -1;
      for (int a = skeleton.joints[d].parent; a >= 0; a = skeleton.joints[static_cast<size_t>(a)].parent) {
        const auto ai = static_cast<size_t>(a);
        const double full = glm::length(model[d].origin - model[ai].origin) + own;
        reach[ai] = std::max(reach[ai], full);
        double shift = full;
        if (stop >= 0) {
          const auto si = static_cast<size_t>(stop);
          shift = (compensates[si] & kCompensatesTranslation) ? 0.0 : glm::length(model[si].origin - model[ai].origin);
        }
        reach_compensated[ai] = std::max(reach_compensated[ai], shift);
        if (compensates[ai] & kCompensatesRotation) stop = a;
      }
    }
    for (uint32_t j = 0; j < joints; ++j) {
      const int p = skeleton.joints[j].parent;
      const double sp = p < 0 ? 1.0 : sigma[static_cast<size_t>(p)];
      const double kp = p < 0 ? 1.0 : condition(model[static_cast<size_t>(p)].linear);
      levers[j].translation = std::max(levers[j].translation, sp);
      levers[j].rotation = std::max(levers[j].rotation, kp * reach[j]);
      levers[j].compensated = std::max(levers[j].compensated, kp * reach_compensated[j]);
    }
  }
  return levers;
}

}  // namespace ossa::cook::compress_detail
