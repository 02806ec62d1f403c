// map_file.cpp — reading and applying humanoid map files (map_file.h).
#include "tools/retarget/map_file.h"

#include <algorithm>
#include <cmath>
#include <set>

#include <nlohmann/json.hpp>

#include "common/edit_distance.h"

namespace ossa::tools {
namespace {

using json = nlohmann::json;

/// The profile bone name closest to `name` by edit distance (for "did you mean").
std::string closest_bone(std::string_view name) {
  std::string best;
  size_t best_distance = SIZE_MAX;
  for (size_t b = 0; b < kHumanoidBoneCount; ++b) {
    const std::string_view bone = humanoid_bone_name(static_cast<HumanoidBone>(b));
    const size_t d = edit_distance(name, bone);
    if (d < best_distance) best_distance = d, best = std::string(bone);
  }
  return best_distance <= std::max<size_t>(2, name.size() / 3) ? best : std::string();
}

Result<RigMapSpec> parse_section(const json& j, const std::string& where) {
  if (!j.is_object()) return Error{where + ": must be an object"};
  RigMapSpec spec;
  for (const auto& [key, value] : j.items()) {
    if (key == "bones") {
      if (!value.is_object()) return Error{where + ".bones: must be an object of bone: joint name (or null)"};
      for (const auto& [bone_name, joint] : value.items()) {
        const HumanoidBone bone = find_humanoid_bone(bone_name);
        if (bone == HumanoidBone::Count) {
          const std::string guess = closest_bone(bone_name);
          return Error{
              where + ".bones: '" + bone_name + "' is not a humanoid bone" +
              (guess.empty() ? std::string(" (docs/RETARGET.md lists them)") : " (did you mean '" + guess + "'?)")};
        }
        if (joint.is_null()) {
          spec.cleared.push_back(bone);
        } else if (joint.is_string() && !joint.get<std::string>().empty()) {
          spec.bones.emplace_back(bone, joint.get<std::string>());
        } else {
          return Error{where + ".bones." + bone_name + ": must be a joint name or null"};
        }
      }
    } else if (key == "rest") {
      if (value == "straighten") spec.rest = RestPose::Straighten;
      else if (value == "bind") spec.rest = RestPose::Bind;
      else return Error{where + ".rest: must be \"straighten\" or \"bind\""};
    } else if (key == "rest_rotations") {
      if (!value.is_object()) return Error{where + ".rest_rotations: must be an object of joint: [x, y, z, w]"};
      for (const auto& [joint, q] : value.items()) {
        const std::string at = where + ".rest_rotations." + joint;
        if (!q.is_array() || q.size() != 4) return Error{at + ": must be a quaternion [x, y, z, w]"};
        float c[4];
        for (size_t k = 0; k < 4; ++k) {
          if (!q[k].is_number()) return Error{at + ": must be a quaternion [x, y, z, w] of numbers"};
          c[k] = q[k].get<float>();
        }
        const float len = std::sqrt(c[0] * c[0] + c[1] * c[1] + c[2] * c[2] + c[3] * c[3]);
        if (!std::isfinite(len) || std::fabs(len - 1.0f) > 1e-3f) return Error{at + ": is not a unit quaternion"};
        spec.rest_rotations.emplace_back(joint, glm::quat(c[3], c[0], c[1], c[2]));
      }
    } else {
      return Error{where + ": unknown key '" + key + "' (bones, rest, rest_rotations)"};
    }
  }
  return spec;
}

}  // namespace

Result<HumanoidMapFile> parse_humanoid_map_file(std::string_view text, std::string_view file) {
  const std::string name(file);
  // Duplicate keys are refused: nlohmann would keep the last one without a word.
  std::vector<std::set<std::string>> keys;
  std::string duplicate;
  json::parser_callback_t check = [&](int /*depth*/, json::parse_event_t event, json& parsed) {
    if (event == json::parse_event_t::object_start) keys.emplace_back();
    else if (event == json::parse_event_t::object_end && !keys.empty()) keys.pop_back();
    else if (event == json::parse_event_t::key && !keys.empty() && parsed.is_string() &&
             !keys.back().insert(parsed.get<std::string>()).second && duplicate.empty())
      duplicate = parsed.get<std::string>();
    return true;
  };
  json doc;
  try {
    doc = json::parse(text.begin(), text.end(), check);
  } catch (const json::exception& e) {
    return Error{name + ": not valid JSON: " + e.what()};
  }
  if (!duplicate.empty()) return Error{name + ": key '" + duplicate + "' appears twice in one object"};
  if (!doc.is_object()) return Error{name + ": must be a JSON object"};
  const auto version = doc.find("ossa_humanoid_map");
  if (version == doc.end() || !version->is_number_integer() || version->get<int>() != 1)
    return Error{name + ": needs \"ossa_humanoid_map\": 1"};
  HumanoidMapFile out;
  for (const auto& [key, value] : doc.items()) {
    if (key == "ossa_humanoid_map") continue;
    std::optional<RigMapSpec>* slot = key == "source"   ? &out.source
                                      : key == "target" ? &out.target
                                      : key == "rig"    ? &out.rig
                                                        : nullptr;
    if (slot == nullptr) return Error{name + ": unknown key '" + key + "' (source, target, rig)"};
    auto spec = parse_section(value, name + ": " + key);
    if (!spec) return spec.error();
    *slot = std::move(*spec);
  }
  return out;
}

bool rig_map_fits(const RigMapSpec& spec, std::span<const std::string_view> names) {
  auto has = [&](const std::string& n) { return std::find(names.begin(), names.end(), n) != names.end(); };
  for (const auto& [bone, joint] : spec.bones)
    if (!has(joint)) return false;
  for (const auto& [joint, q] : spec.rest_rotations)
    if (!has(joint)) return false;
  return true;
}

const RigMapSpec* section_for(const HumanoidMapFile& file, std::string_view role,
                              std::span<const std::string_view> names) {
  const std::optional<RigMapSpec>& own = role == "source" ? file.source : file.target;
  if (own) return &*own;
  if (file.rig && rig_map_fits(*file.rig, names)) return &*file.rig;
  return nullptr;
}

Result<AppliedRigMap> apply_rig_map(const RigMapSpec* spec, std::span<const std::string_view> names,
                                    std::span<const int16_t> parents, std::string_view label) {
  AppliedRigMap out;
  out.humanoid = map_humanoid(names, parents);
  if (spec == nullptr) return out;
  const std::string where(label);
  auto find = [&](const std::string& joint) -> int {
    const auto it = std::find(names.begin(), names.end(), joint);
    return it == names.end() ? -1 : static_cast<int>(it - names.begin());
  };
  for (HumanoidBone b : spec->cleared) out.humanoid[b] = -1;
  for (const auto& [bone, joint] : spec->bones) {
    const int j = find(joint);
    if (j < 0)
      return Error{where + ": bones." + std::string(humanoid_bone_name(bone)) + ": the rig has no joint '" + joint +
                   "'"};
    // A joint named for one bone leaves whatever bone the automatic mapping gave it.
    for (int16_t& other : out.humanoid.joints)
      if (other == j) other = -1;
    out.humanoid[bone] = static_cast<int16_t>(j);
  }
  if (spec->rest) out.rest = *spec->rest;
  for (const auto& [joint, q] : spec->rest_rotations) {
    const int j = find(joint);
    if (j < 0) return Error{where + ": rest_rotations: the rig has no joint '" + joint + "'"};
    out.rest_rotations.push_back(RestRotation{static_cast<int16_t>(j), q});
  }
  return out;
}

Result<MappedRig> map_rig(std::vector<std::string_view> names, std::vector<int16_t> parents,
                          std::vector<Transform> bind, const HumanoidMapFile* map, const std::string& map_name,
                          const char* role, std::string_view name) {
  MappedRig r;
  r.names = std::move(names);
  r.parents = std::move(parents);
  r.bind = std::move(bind);
  const RigMapSpec* spec = map != nullptr ? section_for(*map, role, r.names) : nullptr;
  auto applied =
      apply_rig_map(spec, r.names, r.parents, spec != nullptr ? map_name + " (" + role + ")" : std::string(name));
  if (!applied) return applied.error();
  r.applied = std::move(*applied);
  return r;
}

void finish_mapped_rig(MappedRig& r, std::string_view name) {
  r.rig.name = name;
  r.rig.parents = r.parents;
  r.rig.bind = r.bind;
  r.rig.names = r.names;
  r.rig.humanoid = r.applied.humanoid;
  r.rig.rest = r.applied.rest;
  r.rig.rest_rotations = r.applied.rest_rotations;
}

}  // namespace ossa::tools
