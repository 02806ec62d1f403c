// describe_humanoid.cpp — ossa-inspect --humanoid (describe_humanoid.h).
#include "tools/inspect/describe_humanoid.h"

#include <cmath>
#include <cstdio>
#include <string_view>
#include <vector>

#include <ossa/anim/pose.h>
#include <ossa/retarget/retarget.h>

namespace ossa::inspect {

Result<std::string> describe_humanoid(const Asset& asset, const tools::HumanoidMapFile* map,
                                      const std::string& map_name) {
  const SkeletonView sk = asset.skeleton();
  if (sk.empty()) return Error{asset.name() + ": holds no skeleton"};
  std::vector<std::string_view> names(sk.joint_count());
  for (size_t j = 0; j < names.size(); ++j) names[j] = sk.joint_name(j);
  const tools::RigMapSpec* spec = nullptr;
  if (map != nullptr) {
    spec = map->rig && tools::rig_map_fits(*map->rig, names) ? &*map->rig
           : map->target                                     ? &*map->target
           : map->source                                     ? &*map->source
                                                             : nullptr;
  }
  auto applied = tools::apply_rig_map(spec, names, sk.parents(), map_name);
  if (!applied) return applied.error();

  std::string out;
  char line[512];
  std::snprintf(line, sizeof line, "humanoid mapping of %s (%zu joints)%s\n", asset.name().c_str(), names.size(),
                spec != nullptr ? (", with " + map_name).c_str() : ", by name");
  out += line;
  size_t found = 0;
  for (size_t b = 0; b < kHumanoidBoneCount; ++b) {
    const auto bone = static_cast<HumanoidBone>(b);
    const int j = applied->humanoid[bone];
    found += j >= 0 ? 1 : 0;
    std::snprintf(line, sizeof line, "  %-24s %s%s\n", std::string(humanoid_bone_name(bone)).c_str(),
                  j >= 0 ? std::string(names[static_cast<size_t>(j)]).c_str() : "-",
                  humanoid_bone_required(bone) ? "" : "  (optional)");
    out += line;
  }
  std::snprintf(line, sizeof line, "%zu of %zu profile bones found\n", found, kHumanoidBoneCount);
  out += line;
  if (Status st = check_humanoid(applied->humanoid, sk.parents(), asset.name()); !st) {
    out += "not retargetable: " + st.message() + "\n";
    return out;
  }
  std::vector<Transform> bind(names.size());
  for (size_t j = 0; j < bind.size(); ++j) {
    const fb::Vec3& t = sk.bind_translations()[j];
    const fb::Quat& r = sk.bind_rotations()[j];
    const fb::Vec3& s = sk.bind_scales()[j];
    bind[j] = Transform{{t.x(), t.y(), t.z()}, glm::quat(r.w(), r.x(), r.y(), r.z()), {s.x(), s.y(), s.z()}};
  }
  RetargetRig rig;
  rig.name = asset.name();
  rig.parents = sk.parents();
  rig.bind = bind;
  rig.names = names;
  rig.humanoid = applied->humanoid;
  rig.rest = RestPose::Bind;
  auto as_bound = make_retarget_pose(rig);
  if (!as_bound) return as_bound.error();
  rig.rest = applied->rest;
  rig.rest_rotations = applied->rest_rotations;
  auto pose = make_retarget_pose(rig);
  if (!pose) return pose.error();
  auto arm_below_horizontal = [&](HumanoidBone upper, HumanoidBone lower) {
    const glm::vec3 d = as_bound->frame * glm::vec3(as_bound->model[static_cast<size_t>(applied->humanoid[lower])][3] -
                                                    as_bound->model[static_cast<size_t>(applied->humanoid[upper])][3]);
    return glm::degrees(std::asin(-d.y / glm::length(d)));
  };
  const glm::vec3 left = glm::inverse(pose->frame) * glm::vec3(1.0f, 0.0f, 0.0f);
  std::snprintf(
      line, sizeof line,
      "retargetable: up (%g, %g, %g), left (%g, %g, %g); arms %.1f / %.1f degrees below horizontal in the bind "
      "pose (%s); retarget pose: %s; hips %g units over the ankles, ankles %g over the floor\n",
      pose->up.x, pose->up.y, pose->up.z, left.x, left.y, left.z,
      arm_below_horizontal(HumanoidBone::LeftUpperArm, HumanoidBone::LeftLowerArm),
      arm_below_horizontal(HumanoidBone::RightUpperArm, HumanoidBone::RightLowerArm),
      std::fabs(arm_below_horizontal(HumanoidBone::LeftUpperArm, HumanoidBone::LeftLowerArm)) < 15.0f
          ? "a T-pose"
          : "an A-pose or lower",
      applied->rest == RestPose::Bind ? "the bind pose as it is" : "limbs straightened onto the body's axes",
      static_cast<double>(pose->hips_height), static_cast<double>(pose->ankle_height));
  out += line;
  return out;
}

}  // namespace ossa::inspect
