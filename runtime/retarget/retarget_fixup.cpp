// retarget_fixup.cpp — the corrections the retarget job makes after the per-joint transfer
// (retarget.h): limbs kept on their own side of the body, planted feet held.
//
// Both swing limbs with the runtime's two-bone IK (ik.h) from the model space the transfer left
// in the scratch, write the corrected thigh / upper-arm and shin / forearm rotations into the
// pose, and re-evaluate it with the foot's or hand's model rotation kept, so an end effector keeps
// the orientation the transfer gave it.
//
// Mid-plane guard: a hand or foot whose source lies on its own side of the body's mid-plane (the
// plane through the hips, normal to their left axis) by more than kClearSide hips heights, and
// whose target has crossed it, is swung back to kLanding hips heights on its side (never further
// out than the source's). Same limb directions on a rig with narrower hips or shoulders put feet
// and hands across the body; the swing costs the limb a few degrees. A hand reaching across the
// body on the source stays across on the target.
//
// Contacts: each planted ankle's error (from where the contact holds it, or an easing shift) is taken by the pelvis
// first, as the mean over the planted feet, so a single planted foot is held without bending the leg away from the
// source's (the pelvis path strays from the scaled source's by what the target's proportions make of the pose, a few
// percent of the hips height); the IK takes the rest: what two planted feet disagree on.
#include <algorithm>
#include <array>
#include <cmath>

#include <ossa/anim/ik.h>

#include "retarget/retarget_internal.h"

namespace ossa::detail {
namespace {

using B = HumanoidBone;

constexpr float kClearSide = 0.05f;  // hips heights: the source is clearly on its side
constexpr float kLanding = 0.02f;    // hips heights: where a crossed target end is put back

struct Limb {
  int16_t upper, lower, end;
};

glm::vec3 at(const std::vector<glm::mat4>& model, int j) { return glm::vec3(model[static_cast<size_t>(j)][3]); }

/// Two-bone IK moving `limb`'s end to `goal`, bending the way it bends (or towards `fallback`).
/// Writes the corrected rotations into `out`; returns false when it could not solve.
bool swing(const RetargetScratch& s, const Limb& limb, const glm::vec3& goal, const glm::vec3& fallback, PoseSpan out) {
  TwoBoneIkInput ik;
  ik.start = s.target_model[static_cast<size_t>(limb.upper)];
  ik.mid = s.target_model[static_cast<size_t>(limb.lower)];
  ik.end = s.target_model[static_cast<size_t>(limb.end)];
  ik.target = goal;
  const glm::vec3 start(ik.start[3]), mid(ik.mid[3]), end(ik.end[3]);
  const glm::vec3 axis = end - start;
  const float len2 = glm::dot(axis, axis);
  glm::vec3 pole = mid - start - (len2 > 0.0f ? glm::dot(mid - start, axis) / len2 : 0.0f) * axis;
  if (glm::dot(pole, pole) < 1e-6f * len2) pole = fallback;
  ik.pole = pole;
  TwoBoneIkOutput result;
  if (!two_bone_ik(ik, &result)) return false;
  const auto upper = static_cast<uint32_t>(limb.upper), lower = static_cast<uint32_t>(limb.lower);
  write_rotation(out, upper, glm::normalize(read_rotation(out, upper) * result.start_correction));
  write_rotation(out, lower, glm::normalize(read_rotation(out, lower) * result.mid_correction));
  return true;
}

/// The target body's forward at this pose (a straight knee bends along it, a straight elbow against it).
glm::vec3 forward(const RetargetMap& map, const RetargetScratch& s) {
  const auto hips = static_cast<size_t>(map.target_humanoid[B::Hips]);
  return s.target_rotation[hips] * (map.target_hips_rest_inverse * map.target_forward);
}

}  // namespace

void guard_mid_plane(const RetargetMap& map, const RetargetInput& in, RetargetScratch& s, PoseSpan out) {
  const HumanoidMap& sh = map.source_humanoid;
  const HumanoidMap& th = map.target_humanoid;
  auto left_axis = [](const RetargetPose& pose, const glm::quat& hips_rotation, const glm::quat& rest_inverse) {
    return hips_rotation * (rest_inverse * (glm::inverse(pose.frame) * glm::vec3(1.0f, 0.0f, 0.0f)));
  };
  const auto s_hips = static_cast<size_t>(sh[B::Hips]), t_hips = static_cast<size_t>(th[B::Hips]);
  const glm::vec3 s_left = left_axis(map.source_pose, s.source_rotation[s_hips], map.source_rest_inverse[s_hips]);
  const glm::vec3 t_left = left_axis(map.target_pose, s.target_rotation[t_hips], map.target_rest_inverse[t_hips]);
  const glm::vec3 s_origin = at(s.source_model, sh[B::Hips]), t_origin = at(s.target_model, th[B::Hips]);
  const float s_height = map.source_pose.hips_height, t_height = map.target_pose.hips_height;

  static constexpr B kLimbs[4][3] = {{B::LeftUpperArm, B::LeftLowerArm, B::LeftHand},
                                     {B::RightUpperArm, B::RightLowerArm, B::RightHand},
                                     {B::LeftUpperLeg, B::LeftLowerLeg, B::LeftFoot},
                                     {B::RightUpperLeg, B::RightLowerLeg, B::RightFoot}};
  std::array<Kept, 4> kept;
  size_t count = 0;
  for (size_t i = 0; i < 4; ++i) {
    const float side = i % 2 == 0 ? 1.0f : -1.0f;
    const float source_side = side * glm::dot(at(s.source_model, sh[kLimbs[i][2]]) - s_origin, s_left) / s_height;
    const glm::vec3 end = at(s.target_model, th[kLimbs[i][2]]);
    const float target_side = side * glm::dot(end - t_origin, t_left) / t_height;
    if (!(source_side > kClearSide) || !(target_side < 0.0f)) continue;
    const float landing = std::min(source_side, kLanding);
    const glm::vec3 goal = end + side * (landing - target_side) * t_height * t_left;
    const Limb limb{th[kLimbs[i][0]], th[kLimbs[i][1]], th[kLimbs[i][2]]};
    const glm::vec3 bend = i < 2 ? -forward(map, s) : forward(map, s);
    const glm::quat end_rotation = s.target_rotation[static_cast<size_t>(limb.end)];
    if (swing(s, limb, goal, bend, out)) {
      kept[count++] = Kept{limb.end, end_rotation};
      s.adjusted |= static_cast<uint8_t>(1u << i);
    }
  }
  if (count > 0) evaluate(map, in, s, out, true, std::span<const Kept>(kept.data(), count), glm::vec3(0.0f));
}

void hold_contacts(const RetargetMap& map, const RetargetInput& in, RetargetScratch& s, PoseSpan out) {
  std::array<glm::vec3, 2> goal{};
  std::array<float, 2> weight{0.0f, 0.0f};
  std::array<bool, 2> held{false, false};
  glm::vec3 shift(0.0f);
  float weights = 0.0f;
  for (size_t leg = 0; leg < 2; ++leg) {
    const FootContact& c = in.contacts[leg];
    const RetargetMap::Leg& l = map.legs[leg];
    if (!(c.weight > 0.0f) || l.upper < 0 || l.lower < 0 || l.foot < 0) continue;
    const glm::vec3 ankle = at(s.target_model, l.foot);
    const glm::vec3 error = c.weight >= 1.0f ? held_ankle(map, s, static_cast<int>(leg), c, in.source_floor) - ankle
                                             : std::min(c.weight, 1.0f) * map.scale * (map.rotation * c.shift);
    if (!std::isfinite(error.x + error.y + error.z)) continue;
    goal[leg] = ankle + error;
    weight[leg] = std::min(c.weight, 1.0f);
    shift += error;
    weights += weight[leg];
    held[leg] = true;
  }
  if (!held[0] && !held[1]) return;
  shift /= std::max(1.0f, weights);
  // A foot easing in or out holds its ground only as much as its weight: the rest of it goes
  // with the pelvis (its IK does not undo the shift a planted foot asked for).
  for (size_t leg = 0; leg < 2; ++leg) goal[leg] += (1.0f - weight[leg]) * shift;
  evaluate(map, in, s, out, true, {}, shift);

  std::array<Kept, 2> kept;
  size_t count = 0;
  for (size_t leg = 0; leg < 2; ++leg) {
    if (!held[leg]) continue;
    const RetargetMap::Leg& l = map.legs[leg];
    const glm::quat foot_rotation = s.target_rotation[static_cast<size_t>(l.foot)];
    if (swing(s, Limb{l.upper, l.lower, l.foot}, goal[leg], forward(map, s), out)) {
      kept[count++] = Kept{l.foot, foot_rotation};
      s.adjusted |= static_cast<uint8_t>(1u << (4 + leg));
    }
  }
  evaluate(map, in, s, out, true, std::span<const Kept>(kept.data(), count), shift);
}

}  // namespace ossa::detail
