// map_file.h — the humanoid map file: which joint plays which profile bone when names do not say
// (docs/RETARGET.md), read by ossa-cook (--map), ossa-inspect (--map) and ossa-view.
//
//   {
//     "ossa_humanoid_map": 1,
//     "source": { "bones": { "leftUpperArm": "arm_joint_L__4_", "leftToes": null },
//                 "rest": "straighten" | "bind",
//                 "rest_rotations": { "arm_joint_L__4_": [x, y, z, w] } },
//     "target": { ... },
//     "rig":    { ... }
//   }
//
// "source" and "target" apply to the rig a retarget reads from / writes to; "rig" applies to any
// rig that has every joint it names, so one file describing a character serves it in either role
// (and ossa-inspect). "bones" sets (a joint name) or clears (null) bones over the automatic
// mapping; "rest" picks how the retarget pose is made; "rest_rotations" sets joints' retarget-pose
// local rotations (quaternions, x y z w) after that. Every mistake is an error naming the file and
// the key: unknown keys, duplicate keys (nlohmann keeps the last silently; this reader refuses),
// unknown bone names (with the closest one), joint names the rig lacks.
//
// Tool-side code (nlohmann::json); the runtime takes the result as plain data (HumanoidMap,
// RestPose, RestRotation).
#pragma once
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <utility>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include <ossa/format/result.h>
#include <ossa/retarget/humanoid.h>
#include <ossa/retarget/retarget.h>

namespace ossa::tools {

/// One rig's section of a map file.
struct RigMapSpec {
  std::vector<std::pair<HumanoidBone, std::string>> bones;  // bone -> joint name
  std::vector<HumanoidBone> cleared;                        // bones set to null
  std::optional<RestPose> rest;
  std::vector<std::pair<std::string, glm::quat>> rest_rotations;
};

struct HumanoidMapFile {
  std::optional<RigMapSpec> source, target, rig;
};

/// Parses a map file's text; `file` names it in errors.
Result<HumanoidMapFile> parse_humanoid_map_file(std::string_view text, std::string_view file);

/// Whether every joint the section names is among `names` (so a "rig" section fits this rig).
bool rig_map_fits(const RigMapSpec& spec, std::span<const std::string_view> names);

/// One rig ready for make_retarget_map's RetargetRig: the automatic mapping with the section's
/// overrides, the rest mode and rotations. Errors name `label` (the file and section) and the joint.
struct AppliedRigMap {
  HumanoidMap humanoid;
  RestPose rest = RestPose::Straighten;
  std::vector<RestRotation> rest_rotations;
};
Result<AppliedRigMap> apply_rig_map(const RigMapSpec* spec, std::span<const std::string_view> names,
                                    std::span<const int16_t> parents, std::string_view label);

/// The section of `file` for a rig in a role ("source" or "target"): that role's section if the
/// file has one, else "rig" when it fits the rig's names, else null.
const RigMapSpec* section_for(const HumanoidMapFile& file, std::string_view role,
                              std::span<const std::string_view> names);

/// One rig as the retarget job reads it: its joint names, parents and bind pose, its map applied,
/// and `rig`, the RetargetRig over them (set by finish_mapped_rig, whose spans point into this
/// struct: call it once the struct is where it stays).
struct MappedRig {
  std::vector<std::string_view> names;  // views of the caller's strings, which must outlive this
  std::vector<int16_t> parents;
  std::vector<Transform> bind;
  AppliedRigMap applied;
  RetargetRig rig;
};

/// A rig in `role` ("source" or "target") mapped with `map`'s section for it (section_for), or by
/// the humanoid profile's names when there is none; errors name the file and section, or `name`.
/// The cooker (a source skeleton) and the viewer (a cooked one) map rigs through this one path.
Result<MappedRig> map_rig(std::vector<std::string_view> names, std::vector<int16_t> parents,
                          std::vector<Transform> bind, const HumanoidMapFile* map, const std::string& map_name,
                          const char* role, std::string_view name);

/// Points r.rig at r's names, parents, bind pose and mapping, under `name`.
void finish_mapped_rig(MappedRig& r, std::string_view name);

}  // namespace ossa::tools
