// retarget_internal.h — what the retarget job's files share (retarget.cpp builds the pose, and
// retarget_fixup.cpp corrects it: the mid-plane guard and the contacts). Not a public header.
#pragma once
#include <cstdint>
#include <span>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include <ossa/retarget/retarget.h>

namespace ossa::detail {

inline glm::quat read_rotation(ConstPoseSpan p, uint32_t j) { return {p[kRw][j], p[kRx][j], p[kRy][j], p[kRz][j]}; }

inline glm::vec3 read3(ConstPoseSpan p, PoseComponent first, uint32_t j) {
  return {p[first][j], p[PoseComponent(first + 1)][j], p[PoseComponent(first + 2)][j]};
}

inline void write_rotation(PoseSpan out, uint32_t j, const glm::quat& r) {
  out[kRx][j] = r.x, out[kRy][j] = r.y, out[kRz][j] = r.z, out[kRw][j] = r.w;
}

inline void write(PoseSpan out, uint32_t j, const glm::vec3& t, const glm::quat& r, const glm::vec3& s) {
  out[kTx][j] = t.x, out[kTy][j] = t.y, out[kTz][j] = t.z;
  write_rotation(out, j, r);
  out[kSx][j] = s.x, out[kSy][j] = s.y, out[kSz][j] = s.z;
}

/// A joint whose model rotation a re-evaluation keeps (a foot or hand after IK moved its limb).
struct Kept {
  int16_t joint = -1;
  glm::quat model{1.0f, 0.0f, 0.0f, 0.0f};
};

/// The target's local pose into `out` and its model space into the scratch, from the map's steps
/// and the source's model space (already in the scratch). `pinned`: rotating joints keep the
/// rotations already in `out` (after an IK pass wrote them) except the `kept` ones, which take
/// their kept model rotation back; positions (hips, anchored feet) are placed again, the hips
/// moved by `hips_shift`.
void evaluate(const RetargetMap& map, const RetargetInput& in, RetargetScratch& s, PoseSpan out, bool pinned,
              std::span<const Kept> kept, const glm::vec3& hips_shift);

/// Swings a hand or foot back to its own side of the body's mid-plane where the source's is
/// clearly on its side and the target's crossed (narrower hips or shoulders under the same limb
/// directions), re-evaluating when it moves one. Allocation-free.
void guard_mid_plane(const RetargetMap& map, const RetargetInput& in, RetargetScratch& s, PoseSpan out);

/// The contact fix-up (retarget.h): pelvis shift across the ground, then two-bone IK per planted
/// leg. Allocation-free.
void hold_contacts(const RetargetMap& map, const RetargetInput& in, RetargetScratch& s, PoseSpan out);

}  // namespace ossa::detail
