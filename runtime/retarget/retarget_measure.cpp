// retarget_measure.cpp — limb directions, end effectors and mid-plane sides of a retargeted pose
// against its source (retarget_measure.h).
#include <ossa/retarget/retarget_measure.h>

#include <algorithm>
#include <cmath>

namespace ossa {
namespace {

using B = HumanoidBone;

float degrees_between(const glm::vec3& a, const glm::vec3& b) {
  const float la = glm::length(a), lb = glm::length(b);
  if (!(la > 0.0f) || !(lb > 0.0f)) return 0.0f;
  return glm::degrees(std::acos(std::clamp(glm::dot(a, b) / (la * lb), -1.0f, 1.0f)));
}

struct Side {
  const std::vector<glm::mat4>& model;
  const std::vector<glm::quat>& rotation;
  const std::vector<glm::quat>& rest_inverse;
  const HumanoidMap& humanoid;
  const RetargetPose& pose;

  glm::vec3 at(B b) const { return glm::vec3(model[static_cast<size_t>(humanoid[b])][3]); }
  /// A rig-space direction in the profile's frame.
  glm::vec3 profile(const glm::vec3& v) const { return pose.frame * v; }
  glm::quat delta(B b) const {
    const auto j = static_cast<size_t>(humanoid[b]);
    return rotation[j] * rest_inverse[j];
  }
  /// A profile-space axis carried by bone b's rotation away from the retarget pose.
  glm::vec3 turned(B b, const glm::vec3& axis) const { return profile(delta(b) * (glm::inverse(pose.frame) * axis)); }
  float side(B b) const {
    const glm::vec3 left = delta(B::Hips) * (glm::inverse(pose.frame) * glm::vec3(1.0f, 0.0f, 0.0f));
    return glm::dot(at(b) - at(B::Hips), left) / pose.hips_height;
  }
};

}  // namespace

void measure_retarget(const RetargetMap& map, const RetargetScratch& s, RetargetMeasure* out) {
  const Side src{s.source_model, s.source_rotation, map.source_rest_inverse, map.source_humanoid, map.source_pose};
  const Side tgt{s.target_model, s.target_rotation, map.target_rest_inverse, map.target_humanoid, map.target_pose};
  static constexpr B kLimbs[kRetargetLimbCount][2] = {
      {B::LeftUpperArm, B::LeftLowerArm},   {B::LeftLowerArm, B::LeftHand},       {B::LeftUpperLeg, B::LeftLowerLeg},
      {B::LeftLowerLeg, B::LeftFoot},       {B::RightUpperArm, B::RightLowerArm}, {B::RightLowerArm, B::RightHand},
      {B::RightUpperLeg, B::RightLowerLeg}, {B::RightLowerLeg, B::RightFoot}};
  for (size_t i = 0; i < kRetargetLimbCount; ++i)
    out->limb_degrees[i] = degrees_between(src.profile(src.at(kLimbs[i][1]) - src.at(kLimbs[i][0])),
                                           tgt.profile(tgt.at(kLimbs[i][1]) - tgt.at(kLimbs[i][0])));
  for (size_t side = 0; side < 2; ++side) {
    const B hand = side == 0 ? B::LeftHand : B::RightHand, foot = side == 0 ? B::LeftFoot : B::RightFoot;
    const glm::vec3 out_axis(side == 0 ? 1.0f : -1.0f, 0.0f, 0.0f), forward(0.0f, 0.0f, 1.0f);
    out->hand_degrees[side] = degrees_between(src.turned(hand, out_axis), tgt.turned(hand, out_axis));
    out->foot_degrees[side] = degrees_between(src.turned(foot, forward), tgt.turned(foot, forward));
    out->source_ankle[side] = src.at(foot);
    out->target_ankle[side] = tgt.at(foot);
  }
  static constexpr B kPoints[kRetargetSidePointCount] = {B::LeftHand, B::RightHand, B::LeftLowerArm, B::RightLowerArm,
                                                         B::LeftFoot, B::RightFoot, B::LeftLowerLeg, B::RightLowerLeg};
  for (size_t i = 0; i < kRetargetSidePointCount; ++i) {
    out->source_side[i] = src.side(kPoints[i]);
    out->target_side[i] = tgt.side(kPoints[i]);
  }
}

}  // namespace ossa
