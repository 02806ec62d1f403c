// cook_options.cpp — see cook_options.h.
#include "cooker/model/cook_options.h"

#include <algorithm>
#include <cctype>
#include <cstdio>

namespace ossa::cook {

bool is_graph_file(const std::filesystem::path& path) {
  std::string name = path.filename().string();
  std::transform(name.begin(), name.end(), name.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  constexpr std::string_view kSuffix = ".graph.json";
  return name.size() > kSuffix.size() && name.compare(name.size() - kSuffix.size(), kSuffix.size(), kSuffix) == 0;
}

bool has_folder_rig_name(const std::filesystem::path& path) {
  const auto lower = [](std::string s) {
    for (char& c : s) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    return s;
  };
  if (is_graph_file(path)) return false;
  const std::string stem = lower(path.stem().string());
  return stem == "skeleton" || stem == lower(path.parent_path().filename().string());
}

std::optional<TextureOutput> parse_texture_output(std::string_view name) {
  if (name == "bc") return TextureOutput::Compressed;
  if (name == "rgba8") return TextureOutput::Rgba8;
  if (name == "source") return TextureOutput::Source;
  return std::nullopt;
}

const char* texture_output_name(TextureOutput output) {
  switch (output) {
    case TextureOutput::Rgba8: return "rgba8";
    case TextureOutput::Source: return "source";
    default: return "bc";
  }
}

std::string CookOptions::canonical() const {
  std::string s = float_vertices ? "vertices=float32" : "vertices=quantized";
  if (!clips.enabled) {
    s += ";clips=lossless";
  } else {
    char buf[96];
    std::snprintf(buf, sizeof buf, ";clips=%gm@%gm", static_cast<double>(clips.tolerance_metres),
                  static_cast<double>(clips.probe_metres));
    s += buf;
  }
  if (root_motion) s += ";root_motion=y";  // outputs are Y-up
  if (up_axis >= 0) s += std::string(";up_axis=") + "xyz"[up_axis % 3];
  if (textures != TextureOutput::Compressed) s += std::string(";textures=") + texture_output_name(textures);
  if (metres_per_unit > 0.0f) {
    char unit[64];
    std::snprintf(unit, sizeof unit, ";unit=%gm", static_cast<double>(metres_per_unit));
    s += unit;
  }
  // The rig by name and content: the reference usually lives in the output tree, outside the
  // input's directory, so it enters the key through its hash here rather than as a relative path.
  if (reference != nullptr) {
    s += ";skeleton=" + reference_name;
    if (reference_input.present) {
      s += '@';  // not "@" + hex64(...): GCC 12's false -Wrestrict at -O3 (GCC bug 105329)
      s += hex64(reference_input.hash);
    }
  }
  if (retarget_target != nullptr) {
    s += ";retarget=" + retarget_name;
    if (retarget_input.present) {
      s += '@';
      s += hex64(retarget_input.hash);
    }
  }
  if (retarget_map != nullptr) {
    s += ";map=" + retarget_map_name;
    if (retarget_map_input.present) {
      s += '@';
      s += hex64(retarget_map_input.hash);
    }
  }
  s += cloth.canonical();
  return s;
}

}  // namespace ossa::cook
