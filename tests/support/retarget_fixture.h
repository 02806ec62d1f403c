// retarget_fixture.h — synthetic humanoid rigs for the retarget tests and bench: any naming
// convention, T-pose or A-pose arms, other proportions, other units, Y-up or Z-up, and joint frames
// turned at random (real rigs' joint axes follow no rule, and a retarget must not depend on them).
//
// A rig is described by slot names (an empty name leaves the slot out) and a shape; positions are
// laid out in a canonical frame (+y up, +z forward, +x the character's left, metres) and then
// turned and scaled as the shape says, so every rig built from one shape stands the same way.
#pragma once
#include <array>
#include <cstdint>
#include <map>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include <ossa/anim/pose.h>
#include <ossa/retarget/humanoid.h>
#include <ossa/retarget/retarget.h>

namespace ossa::test {

struct HumanoidNames {
  std::string convention;
  std::string root, hips;
  std::vector<std::string> spine;           // hips -> chest, at least one
  std::string neck, neck2, head, head_end;  // neck2: a second neck joint (CMU's Neck1, Rigify's spine.005)
  // [side 0 left, 1 right]
  std::array<std::string, 2> shoulder, upper_arm, lower_arm, hand, upper_leg, lower_leg, foot, toes;
  std::array<std::string, 2> hip_joint;  // CMU's LHipJoint: between hips and upper leg; may be empty
  // [side][finger thumb..little][segment]
  std::array<std::array<std::array<std::string, 3>, 5>, 2> fingers;
  /// Helper joints that must not be mapped: {name, the slot name they hang from}.
  std::vector<std::pair<std::string, std::string>> extras;
  /// Profile bone -> the joint name the mapping must find (what the convention means).
  std::vector<std::pair<HumanoidBone, std::string>> expected;
};

HumanoidNames mixamo_names();
HumanoidNames unreal_names();      // UE4 mannequin: pelvis, spine_01..03, clavicle_l, thigh_l, ik_foot_l ...
HumanoidNames unity_names();       // Unity's HumanBodyBones names
HumanoidNames vroid_names();       // VRoid / VRM: J_Bip_C_Hips, J_Bip_L_UpperArm ...
HumanoidNames rigify_names();      // Blender Rigify deform bones: DEF-thigh.L, DEF-upper_arm.L.001 ...
HumanoidNames metarig_names();     // Blender's metarig: spine, spine.001 ... spine.006 (the head)
HumanoidNames cmu_names();         // CMU BVH: Hips, LHipJoint, LeftUpLeg, LThumb ...
HumanoidNames biped_names();       // 3ds Max Biped: Bip01 Pelvis, Bip01 L Thigh, Bip01 L Finger0 ...
HumanoidNames quaternius_names();  // Quaternius: Body, Hips (its lower spine), UpperArm.L, Palm.L, Foot.L (IK)

struct RigShape {
  float arm_down_degrees = 0.0f;  // 0: T-pose, 45: A-pose
  float thigh = 0.43f, shin = 0.42f, upper_arm = 0.28f, forearm = 0.26f;
  float hip_width = 0.09f, shoulder_width = 0.17f;
  glm::quat orientation{1.0f, 0.0f, 0.0f, 0.0f};  // canonical -> model (a Z-up rig, one facing -z)
  float units_per_metre = 1.0f;                   // 100 for a centimetre rig
  uint32_t frame_seed = 0;                        // 0: joint frames aligned with the model; else turned at random
  bool ik_feet = false;                           // feet hang from the root (Quaternius) instead of the shins
};

struct SyntheticRig {
  std::vector<std::string> names;
  std::vector<std::string_view> views;  // into names
  std::vector<int16_t> parents;
  std::vector<Transform> bind;
  std::map<std::string, int> index;
  /// IK feet (RigShape::ik_feet): {foot, shin, the foot's bind position in the shin's frame}; a
  /// motion places such a foot at its shin, as an IK rig's baked clip does.
  std::vector<std::pair<std::pair<int, int>, glm::vec3>> ik_feet;

  int joint(const std::string& name) const;
  /// The rig for make_retarget_map, mapped by name (map_humanoid).
  RetargetRig rig(std::string_view name) const;
};

SyntheticRig make_humanoid(const HumanoidNames& names, const RigShape& shape);

/// The rig's bind pose into `out`.
void bind_pose(const SyntheticRig& rig, PoseSpan out);

/// A deterministic motion on any rig: every joint's local rotation swings about axes of its own
/// (amplitude `degrees`, phase from the joint index), the root travels forward. Frame f of 30 fps.
void synthetic_motion(const SyntheticRig& rig, uint32_t frame, float degrees, PoseSpan out);

}  // namespace ossa::test
