// retarget_measure.h — how closely a retargeted pose follows its source: the figures ossa-cook's
// --retarget-to report gives and the tests bound.
//
// Read from a RetargetScratch after retarget() (the source's pose and the target's final pose),
// each rig seen in its own body frame (+x left, +y up, +z forward), so a Z-up centimetre rig and a
// Y-up metre rig compare directly:
//   - limb directions: the angle between the source's and the target's upper arm, forearm, thigh
//     and shin (joint towards the next profile joint);
//   - end effectors: the angle between the hands' outward axis (+-x of the retarget pose) and the
//     feet's forward axis as each rig turned them (a foot's axis, not its ankle-to-toe line, whose
//     pitch differs between rigs by their rest poses);
//   - sides: each hand, elbow, foot and knee's signed distance to the body's mid-plane (through
//     the hips, normal to the hips' left axis), in hips heights, on both rigs: a limb crossing the
//     mid-plane on the target where the source's does not shows as a sign change.
#pragma once
#include <array>

#include <glm/glm.hpp>

#include <ossa/retarget/retarget.h>

namespace ossa {

enum RetargetLimb : uint8_t {
  kLeftUpperArm,
  kLeftLowerArm,
  kLeftUpperLeg,
  kLeftLowerLeg,
  kRightUpperArm,
  kRightLowerArm,
  kRightUpperLeg,
  kRightLowerLeg,
  kRetargetLimbCount
};
enum RetargetSidePoint : uint8_t {
  kLeftHandPoint,
  kRightHandPoint,
  kLeftElbowPoint,
  kRightElbowPoint,
  kLeftFootPoint,
  kRightFootPoint,
  kLeftKneePoint,
  kRightKneePoint,
  kRetargetSidePointCount
};

struct RetargetMeasure {
  std::array<float, kRetargetLimbCount> limb_degrees{};
  std::array<float, 2> hand_degrees{}, foot_degrees{};  // left, right
  std::array<float, kRetargetSidePointCount> source_side{}, target_side{};
  std::array<glm::vec3, 2> source_ankle{}, target_ankle{};  // model space of each rig
};

/// Measures the pose left in `scratch` by the last retarget() with `map`. O(1).
void measure_retarget(const RetargetMap& map, const RetargetScratch& scratch, RetargetMeasure* out);

}  // namespace ossa
