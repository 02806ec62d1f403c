// cook_settings.cpp — reading and layering ossa.cook.json / <stem>.cook.json (see cook_settings.h).
#include "cooker/model/cook_settings.h"
#include "cooker/model/reference_skeleton.h"

#include <fnmatch.h>

#include <algorithm>
#include <optional>
#include <set>
#include <vector>

#include "cooker/json/json_check.h"
#include "cooker/json/json_source.h"
#include "cooker/model/cloth_settings.h"

namespace ossa::cook {
namespace fs = std::filesystem;

namespace {

constexpr std::string_view kFolderFile = "ossa.cook.json";

const std::initializer_list<std::string_view> kSettingKeys = {
    "float_vertices", "clip_compression", "clip_tolerance_mm", "root_motion",    "up_axis",
    "skeleton",       "clip_names",       "metres_per_unit",   "texture_format", "cloth"};

/// One layer of settings, checked; applied in order.
struct Layer {
  std::optional<bool> float_vertices, clip_compression, root_motion;
  std::optional<double> clip_tolerance_mm, metres_per_unit;
  std::optional<uint8_t> up_axis;
  std::optional<TextureOutput> texture_format;
  std::optional<fs::path> skeleton;  // resolved against the settings file's folder
  std::map<std::string, std::string> clip_names;
  std::optional<ClothOptions> cloth;  // the whole "cloth" object of the latest layer with one
};

bool read_bool(json::Checker& check, const json::Value& v, std::string_view what, std::optional<bool>& out) {
  if (!check.expect(v, json::Type::Bool, what)) return false;
  out = v.boolean;
  return true;
}

/// The settings members of `object` (other keys are the caller's: "match").
void read_layer(json::Checker& check, const json::Value& object, const fs::path& dir, Layer& layer) {
  for (const json::Member& m : object.members) {
    const std::string what = "\"" + m.key + "\"";
    const json::Value& v = m.value;
    if (m.key == "float_vertices") {
      read_bool(check, v, what, layer.float_vertices);
    } else if (m.key == "clip_compression") {
      read_bool(check, v, what, layer.clip_compression);
    } else if (m.key == "root_motion") {
      read_bool(check, v, what, layer.root_motion);
    } else if (m.key == "clip_tolerance_mm") {
      double mm = 0.0;
      if (check.expect_number(v, what, &mm)) {
        if (!(mm >= 1e-6 && mm <= 1e4)) check.error(v.pos, what + " must be within [1e-6, 1e4] millimetres");
        else layer.clip_tolerance_mm = mm;
      }
    } else if (m.key == "metres_per_unit") {
      double unit = 0.0;
      if (check.expect_number(v, what, &unit)) {
        if (!(unit >= 1e-6 && unit <= 1e6)) check.error(v.pos, what + " must be within [1e-6, 1e6] metres");
        else layer.metres_per_unit = unit;
      }
    } else if (m.key == "up_axis") {
      if (check.expect(v, json::Type::String, what)) {
        if (v.string == "x" || v.string == "y" || v.string == "z") layer.up_axis = uint8_t(v.string[0] - 'x');
        else check.error(v.pos, what + " must be \"x\", \"y\" or \"z\"");
      }
    } else if (m.key == "texture_format") {
      if (check.expect(v, json::Type::String, what)) {
        if (auto t = parse_texture_output(v.string)) layer.texture_format = *t;
        else check.error(v.pos, what + " must be \"bc\", \"rgba8\" or \"source\"");
      }
    } else if (m.key == "skeleton") {
      std::string path;
      if (check.expect_name(v, what, &path)) layer.skeleton = (dir / path).lexically_normal();
    } else if (m.key == "cloth") {
      ClothOptions cloth;
      if (read_cloth_settings(check, v, cloth)) layer.cloth = std::move(cloth);
    } else if (m.key == "clip_names") {
      if (check.expect(v, json::Type::Object, what))
        for (const json::Member& c : v.members) {
          std::string to;
          if (check.expect_name(c.value, "the new name of clip '" + c.key + "'", &to)) layer.clip_names[c.key] = to;
        }
    }
  }
}

/// Reads one settings file (absent: no layers). `folder` selects the ossa.cook.json shape.
Result<std::vector<Layer>> read_settings(const fs::path& file, bool folder, const std::string& input_name) {
  std::vector<Layer> layers;
  if (!probe_input(file)) return layers;  // looked for: its absence is part of the key
  auto bytes = read_input(file);
  if (!bytes) return bytes.error();
  auto doc = json::parse(std::string_view(reinterpret_cast<const char*>(bytes->data()), bytes->size()), file.string());
  if (!doc) return doc.error();
  json::Checker check(*doc);
  const json::Value& root = doc->root;
  const fs::path dir = file.parent_path();
  if (!check.expect(root, json::Type::Object, "a cook settings file")) return Error{check.message()};
  const json::Value* version = root.find("ossa_cook");
  if (!version) check.error(root.pos, "not a cook settings file: \"ossa_cook\": 1 is missing");
  else if (!version->is(json::Type::Number) || version->number != 1.0)
    check.error(version->pos, "\"ossa_cook\" must be 1 (the only version this cooker reads)");
  if (folder) {
    check.expect_keys(root, {"ossa_cook", "defaults", "files"}, "a folder's ossa.cook.json");
    if (const json::Value* defaults = root.find("defaults");
        defaults && check.expect(*defaults, json::Type::Object, "\"defaults\"")) {
      check.expect_keys(*defaults, kSettingKeys, "\"defaults\"");
      read_layer(check, *defaults, dir, layers.emplace_back());
    }
    if (const json::Value* files = root.find("files"); files && check.expect(*files, json::Type::Array, "\"files\"")) {
      for (const json::Value& entry : files->items) {
        if (!check.expect(entry, json::Type::Object, "a \"files\" entry")) continue;
        std::vector<std::string_view> keys(kSettingKeys);
        keys.push_back("match");
        bool keys_ok = true;
        for (const json::Member& m : entry.members)
          if (std::find(keys.begin(), keys.end(), m.key) == keys.end()) {
            const std::string near = json::closest_name(m.key, keys);
            check.error(m.key_pos, "unknown key \"" + m.key + "\" in a \"files\" entry" +
                                       (near.empty() ? "" : " (did you mean \"" + near + "\"?)"));
            keys_ok = false;
          }
        const json::Value* match = entry.find("match");
        std::string pattern;
        if (!match) {
          check.error(entry.pos, "a \"files\" entry needs \"match\": \"<glob on the file name>\"");
          continue;
        }
        if (!check.expect_name(*match, "\"match\"", &pattern) || !keys_ok) continue;
        Layer layer;
        read_layer(check, entry, dir, layer);
        if (::fnmatch(pattern.c_str(), input_name.c_str(), 0) == 0) layers.push_back(std::move(layer));
      }
    }
  } else {
    check.expect_keys(root,
                      {"ossa_cook", "float_vertices", "clip_compression", "clip_tolerance_mm", "root_motion",
                       "metres_per_unit", "up_axis", "skeleton", "clip_names", "texture_format", "cloth"},
                      "a cook settings file");
    read_layer(check, root, dir, layers.emplace_back());
  }
  if (!check.ok()) return Error{check.message()};
  return layers;
}

std::string settings_stem(const fs::path& input) {
  const std::string name = input.filename().string();
  if (is_graph_file(input)) return name.substr(0, name.size() - std::string_view(".graph.json").size());
  return input.stem().string();
}

}  // namespace

Status apply_cook_settings(const fs::path& input, CookOptions& options, AppliedSettings& applied) {
  const fs::path dir = input.parent_path();
  const std::string name = input.filename().string();
  auto folder = read_settings(dir / kFolderFile, true, name);
  if (!folder) return folder.error();
  auto own = read_settings(dir / (settings_stem(input) + ".cook.json"), false, name);
  if (!own) return own.error();
  std::optional<fs::path> skeleton;
  for (const std::vector<Layer>* list : {&*folder, &*own}) {
    for (const Layer& l : *list) {
      if (l.float_vertices) options.float_vertices = *l.float_vertices;
      if (l.clip_compression) options.clips.enabled = *l.clip_compression;
      if (l.clip_tolerance_mm) options.clips.tolerance_metres = static_cast<float>(*l.clip_tolerance_mm / 1000.0);
      if (l.root_motion) options.root_motion = *l.root_motion;
      if (l.up_axis) options.up_axis = *l.up_axis;
      if (l.texture_format) options.textures = *l.texture_format;
      if (l.metres_per_unit) options.metres_per_unit = static_cast<float>(*l.metres_per_unit);
      if (l.skeleton) skeleton = l.skeleton;
      for (const auto& [from, to] : l.clip_names) applied.clip_names[from] = to;
      if (l.cloth) options.cloth = *l.cloth;
    }
  }
  options.cloth.up_axis = 1;  // outputs are Y-up (import_axes.cpp)
  if (skeleton) {
    InputFile as_read;
    auto rig = load_reference_skeleton(*skeleton, &as_read);
    if (!rig) return Error{"\"skeleton\": " + rig.error().message};
    applied.reference = std::make_unique<SourceSkeleton>(std::move(*rig));
    options.reference = applied.reference.get();
    options.reference_name = skeleton->filename().string();
    options.reference_input = as_read;
  }
  return {};
}

Status rename_clips(const std::map<std::string, std::string>& names, std::vector<SourceClip>& clips,
                    const std::string& label) {
  for (const auto& [from, to] : names) {
    bool found = false;
    for (const SourceClip& c : clips) found = found || clip_named(c, from);
    if (!found) return Error{label + ": cook settings rename clip '" + from + "', which it does not have"};
  }
  for (SourceClip& c : clips) {  // all at once, so {"a": "b", "b": "a"} swaps
    auto it = names.find(c.name);
    if (it == names.end() && !c.source_name.empty()) it = names.find(c.source_name);
    if (it != names.end()) c.name = it->second;
  }
  std::set<std::string> seen;
  for (const SourceClip& c : clips)
    if (!seen.insert(c.name).second) return Error{label + ": two clips are named '" + c.name + "' after renaming"};
  return {};
}

}  // namespace ossa::cook
