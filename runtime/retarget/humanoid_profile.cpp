// humanoid_profile.cpp — the profile's table (humanoid.h): names, parents, which bones are
// required, and the structural check of a map against a rig's hierarchy.
#include <ossa/retarget/humanoid.h>

#include "internal/retarget_bones.h"

#include <algorithm>
#include <cctype>

static_assert(ossa::kHumanoidBoneCount == ossa::detail::kRetargetBoneCount,
              "the loader checks retarget nodes against internal/retarget_bones.h: keep it in step");

namespace ossa {
namespace {

using B = HumanoidBone;

struct BoneInfo {
  std::string_view name;
  B parent;
  bool required;
};

constexpr B kNone = B::Count;

constexpr BoneInfo kBones[kHumanoidBoneCount] = {
    {"hips", kNone, true},
    {"spine", B::Hips, true},
    {"chest", B::Spine, false},
    {"upperChest", B::Chest, false},
    {"neck", B::UpperChest, false},
    {"head", B::Neck, true},
    {"leftShoulder", B::UpperChest, false},
    {"leftUpperArm", B::LeftShoulder, true},
    {"leftLowerArm", B::LeftUpperArm, true},
    {"leftHand", B::LeftLowerArm, true},
    {"rightShoulder", B::UpperChest, false},
    {"rightUpperArm", B::RightShoulder, true},
    {"rightLowerArm", B::RightUpperArm, true},
    {"rightHand", B::RightLowerArm, true},
    {"leftUpperLeg", B::Hips, true},
    {"leftLowerLeg", B::LeftUpperLeg, true},
    {"leftFoot", B::LeftLowerLeg, true},
    {"leftToes", B::LeftFoot, false},
    {"rightUpperLeg", B::Hips, true},
    {"rightLowerLeg", B::RightUpperLeg, true},
    {"rightFoot", B::RightLowerLeg, true},
    {"rightToes", B::RightFoot, false},
    {"leftThumbMetacarpal", B::LeftHand, false},
    {"leftThumbProximal", B::LeftThumbMetacarpal, false},
    {"leftThumbDistal", B::LeftThumbProximal, false},
    {"leftIndexProximal", B::LeftHand, false},
    {"leftIndexIntermediate", B::LeftIndexProximal, false},
    {"leftIndexDistal", B::LeftIndexIntermediate, false},
    {"leftMiddleProximal", B::LeftHand, false},
    {"leftMiddleIntermediate", B::LeftMiddleProximal, false},
    {"leftMiddleDistal", B::LeftMiddleIntermediate, false},
    {"leftRingProximal", B::LeftHand, false},
    {"leftRingIntermediate", B::LeftRingProximal, false},
    {"leftRingDistal", B::LeftRingIntermediate, false},
    {"leftLittleProximal", B::LeftHand, false},
    {"leftLittleIntermediate", B::LeftLittleProximal, false},
    {"leftLittleDistal", B::LeftLittleIntermediate, false},
    {"rightThumbMetacarpal", B::RightHand, false},
    {"rightThumbProximal", B::RightThumbMetacarpal, false},
    {"rightThumbDistal", B::RightThumbProximal, false},
    {"rightIndexProximal", B::RightHand, false},
    {"rightIndexIntermediate", B::RightIndexProximal, false},
    {"rightIndexDistal", B::RightIndexIntermediate, false},
    {"rightMiddleProximal", B::RightHand, false},
    {"rightMiddleIntermediate", B::RightMiddleProximal, false},
    {"rightMiddleDistal", B::RightMiddleIntermediate, false},
    {"rightRingProximal", B::RightHand, false},
    {"rightRingIntermediate", B::RightRingProximal, false},
    {"rightRingDistal", B::RightRingIntermediate, false},
    {"rightLittleProximal", B::RightHand, false},
    {"rightLittleIntermediate", B::RightLittleProximal, false},
    {"rightLittleDistal", B::RightLittleIntermediate, false},
};

bool equal_ignoring_case(std::string_view a, std::string_view b) {
  return a.size() == b.size() && std::equal(a.begin(), a.end(), b.begin(), [](char x, char y) {
           return std::tolower(static_cast<unsigned char>(x)) == std::tolower(static_cast<unsigned char>(y));
         });
}

bool is_ancestor(std::span<const int16_t> parents, int ancestor, int joint) {
  for (int j = joint; j >= 0; j = parents[static_cast<size_t>(j)])
    if (j == ancestor) return true;
  return false;
}

bool is_foot(B b) { return b == B::LeftFoot || b == B::RightFoot; }

}  // namespace

std::string_view humanoid_bone_name(HumanoidBone bone) {
  const auto i = static_cast<size_t>(bone);
  return i < kHumanoidBoneCount ? kBones[i].name : std::string_view("?");
}

HumanoidBone find_humanoid_bone(std::string_view name) {
  for (size_t i = 0; i < kHumanoidBoneCount; ++i)
    if (equal_ignoring_case(kBones[i].name, name)) return static_cast<HumanoidBone>(i);
  return HumanoidBone::Count;
}

bool humanoid_bone_required(HumanoidBone bone) {
  const auto i = static_cast<size_t>(bone);
  return i < kHumanoidBoneCount && kBones[i].required;
}

HumanoidBone humanoid_bone_parent(HumanoidBone bone) {
  const auto i = static_cast<size_t>(bone);
  return i < kHumanoidBoneCount ? kBones[i].parent : kNone;
}

std::vector<HumanoidBone> missing_humanoid_bones(const HumanoidMap& map) {
  std::vector<HumanoidBone> missing;
  for (size_t i = 0; i < kHumanoidBoneCount; ++i)
    if (kBones[i].required && map.joints[i] < 0) missing.push_back(static_cast<HumanoidBone>(i));
  return missing;
}

Status check_humanoid(const HumanoidMap& map, std::span<const int16_t> parents, std::string_view rig) {
  const std::string prefix = std::string(rig) + ": ";
  const std::vector<HumanoidBone> missing = missing_humanoid_bones(map);
  if (!missing.empty()) {
    std::string list;
    for (HumanoidBone b : missing) list += (list.empty() ? "" : ", ") + std::string(humanoid_bone_name(b));
    return Error{prefix + "missing humanoid bones: " + list +
                 " (name them in a map file: docs/RETARGET.md; ossa-inspect prints what was found)"};
  }
  for (size_t j = 0; j < parents.size(); ++j)
    if (parents[j] >= static_cast<int>(j) || parents[j] < -1)
      return Error{prefix + "joints are not ordered parents first"};
  std::vector<int> used(parents.size(), -1);
  for (size_t i = 0; i < kHumanoidBoneCount; ++i) {
    const int j = map.joints[i];
    if (j < 0) continue;
    const std::string bone(kBones[i].name);
    if (static_cast<size_t>(j) >= parents.size())
      return Error{prefix + "humanoid bone " + bone + " names joint " + std::to_string(j) + ", past the rig's " +
                   std::to_string(parents.size()) + " joints"};
    if (used[static_cast<size_t>(j)] >= 0)
      return Error{prefix + "humanoid bones " + std::string(kBones[used[static_cast<size_t>(j)]].name) + " and " +
                   bone + " name the same joint"};
    used[static_cast<size_t>(j)] = static_cast<int>(i);
    // The nearest mapped profile ancestor must be a hierarchy ancestor (a foot may hang elsewhere).
    B up = kBones[i].parent;
    while (up != kNone && map[up] < 0) up = kBones[static_cast<size_t>(up)].parent;
    if (up == kNone || is_foot(static_cast<B>(i))) continue;
    if (!is_ancestor(parents, map[up], j) || map[up] == j)
      return Error{prefix + "humanoid bone " + bone + " is not below " + std::string(humanoid_bone_name(up)) +
                   " in the hierarchy"};
  }
  return {};
}

}  // namespace ossa
