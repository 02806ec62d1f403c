// humanoid.h — the humanoid profile retargeting speaks through, and finding it in a rig by name.
//
// Retargeting moves motion between rigs that share no joint names, counts or rest poses. What they
// share is a body: hips, a spine, a head, two arms, two legs. The profile names those parts once,
// with VRM 1.0's humanoid bone names (the 15 bones VRM requires, plus optional chest, upper chest,
// neck, shoulders, toes and 30 finger bones), and a HumanoidMap says which joint of a rig plays
// each part. Everything else a rig has (twist bones, tails, props, IK helpers) is outside the
// profile and keeps its rest pose, or its own clip, when a retarget drives the rig.
//
// map_humanoid finds the parts from joint names and the hierarchy, for the conventions rigs come
// with: Mixamo ("mixamorig:LeftArm"), Unreal's mannequin ("upperarm_l", "thigh_l", "spine_01"),
// Unity / VRM ("LeftUpperArm", "leftUpperArm"), VRoid ("J_Bip_L_UpperArm"), Blender Rigify and its
// metarig ("DEF-upper_arm.L", "thigh.L"), CMU's BVH ("LeftUpLeg", "LThumb"), 3ds Max Biped
// ("Bip01 L Thigh"), Quaternius ("UpperArm.L", "Palm.L"). Names give the limbs; the hierarchy gives
// the rest: the hips are the joint both legs hang from (whatever it is called: Quaternius' "Hips"
// is its lower spine), the spine bones are the joints between the hips and the neck. A rig whose
// names say nothing (CesiumMan's "leg_joint_L_1") is mapped by a map file instead (the tools read
// it; HumanoidMap is plain data a host can also fill itself).
//
// Setup-time code: these functions allocate and are not meant for a frame loop.
#pragma once
#include <array>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <ossa/format/result.h>
#include <ossa/loader/asset.h>

namespace ossa {

/// The profile's bones, VRM 1.0's humanoid bones without eyes and jaw. Order is parents first.
enum class HumanoidBone : uint8_t {
  Hips,
  Spine,
  Chest,
  UpperChest,
  Neck,
  Head,
  LeftShoulder,
  LeftUpperArm,
  LeftLowerArm,
  LeftHand,
  RightShoulder,
  RightUpperArm,
  RightLowerArm,
  RightHand,
  LeftUpperLeg,
  LeftLowerLeg,
  LeftFoot,
  LeftToes,
  RightUpperLeg,
  RightLowerLeg,
  RightFoot,
  RightToes,
  // Fingers, three bones each (the thumb's first is its metacarpal), left then right.
  LeftThumbMetacarpal,
  LeftThumbProximal,
  LeftThumbDistal,
  LeftIndexProximal,
  LeftIndexIntermediate,
  LeftIndexDistal,
  LeftMiddleProximal,
  LeftMiddleIntermediate,
  LeftMiddleDistal,
  LeftRingProximal,
  LeftRingIntermediate,
  LeftRingDistal,
  LeftLittleProximal,
  LeftLittleIntermediate,
  LeftLittleDistal,
  RightThumbMetacarpal,
  RightThumbProximal,
  RightThumbDistal,
  RightIndexProximal,
  RightIndexIntermediate,
  RightIndexDistal,
  RightMiddleProximal,
  RightMiddleIntermediate,
  RightMiddleDistal,
  RightRingProximal,
  RightRingIntermediate,
  RightRingDistal,
  RightLittleProximal,
  RightLittleIntermediate,
  RightLittleDistal,
  Count
};
inline constexpr size_t kHumanoidBoneCount = static_cast<size_t>(HumanoidBone::Count);

/// VRM's name of the bone ("hips", "leftUpperArm", "rightLittleDistal").
std::string_view humanoid_bone_name(HumanoidBone bone);
/// The bone with this VRM name (ASCII case ignored), or HumanoidBone::Count.
HumanoidBone find_humanoid_bone(std::string_view name);
/// One of the 15 bones VRM requires (hips, spine, head, and each arm's and leg's three bones).
bool humanoid_bone_required(HumanoidBone bone);
/// The bone's parent in the profile (the hips' is Count). A bone whose parent a rig lacks hangs
/// from the nearest mapped ancestor in the profile (upper arm from the chest without a shoulder).
HumanoidBone humanoid_bone_parent(HumanoidBone bone);

/// Which joint of one rig plays each profile bone; -1 where the rig has none.
struct HumanoidMap {
  std::array<int16_t, kHumanoidBoneCount> joints;
  HumanoidMap() { joints.fill(-1); }
  int16_t operator[](HumanoidBone bone) const { return joints[static_cast<size_t>(bone)]; }
  int16_t& operator[](HumanoidBone bone) { return joints[static_cast<size_t>(bone)]; }
  bool has(HumanoidBone bone) const { return (*this)[bone] >= 0; }
};

/// The profile found in a rig from its joint names and hierarchy (parents[i] < i, -1 for roots;
/// names.size() == parents.size()). Bones it cannot place are -1; check_humanoid says which of
/// them are required. Deterministic. O(joints * name length).
HumanoidMap map_humanoid(std::span<const std::string_view> names, std::span<const int16_t> parents);
HumanoidMap map_humanoid(const SkeletonView& skeleton);

/// Required bones the map lacks, in profile order.
std::vector<HumanoidBone> missing_humanoid_bones(const HumanoidMap& map);

/// Whether the map can drive a retarget of a rig with these parents: every required bone mapped,
/// joints in range and used once, and each mapped bone below its profile ancestors in the
/// hierarchy (a foot may hang elsewhere: Quaternius' IK feet hang from the root). The error starts
/// with `rig` and names every missing bone ("missing humanoid bones: leftHand, rightHand").
Status check_humanoid(const HumanoidMap& map, std::span<const int16_t> parents, std::string_view rig);

}  // namespace ossa
