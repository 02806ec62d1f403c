// gltf_samplers.cpp — a glTF file's animations: the GLB container, the JSON, every animation's
// channels and samplers, with the keys of the samplers Assimp mishandles decoded
// (gltf_accessors.cpp); see gltf_samplers.h for why the cooker does this beside Assimp. Evaluating
// a sampler is gltf_evaluate.cpp.
//
// Every number from the file is checked before it is used as an offset, a count or an index:
// a hostile file must give an error message, never a read out of bounds or a huge allocation.
#include "cooker/import/gltf_samplers.h"

#include <exception>
#include <filesystem>
#include <optional>
#include <span>

#include "cooker/import/gltf_read.h"

namespace ossa::cook::gltf {
namespace {

using namespace detail;

// GLB container (glTF 2.0 spec, "Binary glTF Layout"): all little-endian.
constexpr uint32_t kGlbMagic = 0x46546C67;   // "glTF"
constexpr uint32_t kChunkJson = 0x4E4F534A;  // "JSON"
constexpr uint32_t kChunkBin = 0x004E4942;   // "BIN\0"

TargetPath target_path(const std::string& path) {
  if (path == "translation") return TargetPath::Translation;
  if (path == "rotation") return TargetPath::Rotation;
  if (path == "scale") return TargetPath::Scale;
  if (path == "weights") return TargetPath::Weights;
  return TargetPath::Other;
}

Result<Animations> parse_json(const Json& root, std::optional<std::span<const uint8_t>> glb_bin,
                              const std::string& directory, const std::string& label) {
  if (!root.is_object()) return Error{label + ": the glTF JSON is not an object"};
  Animations out;
  if (const Json* nodes = get_array(root, "nodes")) {
    out.nodes.resize(nodes->size());
    for (size_t i = 0; i < nodes->size(); ++i) {
      const Json& n = (*nodes)[i];
      out.nodes[i].name = get_string(n, "name");
      if (const std::optional<uint64_t> mesh = get_uint(n, "mesh")) out.nodes[i].mesh = static_cast<int>(*mesh);
      if (const Json* children = get_array(n, "children")) {
        for (const Json& c : *children) {
          const bool valid = c.is_number_unsigned() && c.get<uint64_t>() < nodes->size();
          out.nodes[i].children.push_back(valid ? static_cast<int>(c.get<uint64_t>()) : -1);
        }
      }
    }
  }
  if (const Json* meshes = get_array(root, "meshes")) {
    for (const Json& m : *meshes) {
      MeshTargets targets;
      size_t count = 0;
      if (const Json* primitives = get_array(m, "primitives"))
        for (const Json& p : *primitives)
          if (const Json* t = get_array(p, "targets")) count = std::max(count, t->size());
      const Json* extras = get_object(m, "extras");
      const Json* names = extras ? get_array(*extras, "targetNames") : nullptr;
      for (size_t i = 0; i < count; ++i) {
        const bool named =
            names && i < names->size() && (*names)[i].is_string() && !(*names)[i].get<std::string>().empty();
        targets.names.push_back(named ? (*names)[i].get<std::string>() : "target" + std::to_string(i));
      }
      out.meshes.push_back(std::move(targets));
    }
  }
  for (Node& node : out.nodes)
    if (node.mesh >= 0 && static_cast<size_t>(node.mesh) >= out.meshes.size()) node.mesh = -1;
  const uint64_t scene_index = get_uint(root, "scene").value_or(0);
  if (const Json* scene = element(root, "scenes", scene_index)) {
    if (const Json* roots = get_array(*scene, "nodes")) {
      for (const Json& n : *roots) {
        const bool valid = n.is_number_unsigned() && n.get<uint64_t>() < out.nodes.size();
        out.scene_roots.push_back(valid ? static_cast<int>(n.get<uint64_t>()) : -1);
      }
    }
  }
  Reader reader{root, directory, glb_bin, {}, {}, {}};
  if (const Json* animations = get_array(root, "animations")) {
    for (const Json& a : *animations) {
      Animation anim;
      anim.name = get_string(a, "name");
      const Json* samplers = get_array(a, "samplers");
      const size_t sampler_count = samplers ? samplers->size() : 0;
      for (size_t s = 0; s < sampler_count; ++s) {
        Sampler sampler;
        const std::string mode = get_string((*samplers)[s], "interpolation");
        if (mode == "STEP") {
          sampler.interpolation = Interpolation::Step;
        } else if (mode == "CUBICSPLINE") {
          sampler.interpolation = Interpolation::CubicSpline;
        } else if (!mode.empty() && mode != "LINEAR") {
          sampler.error = "unknown interpolation '" + mode + "'";
        }
        anim.samplers.push_back(std::move(sampler));
      }
      if (const Json* channels = get_array(a, "channels")) {
        for (const Json& c : *channels) {
          Channel ch;
          const std::optional<uint64_t> sampler = get_uint(c, "sampler");
          if (sampler && *sampler < sampler_count) ch.sampler = static_cast<int>(*sampler);
          if (const Json* target = get_object(c, "target")) {
            const std::optional<uint64_t> node = get_uint(*target, "node");
            if (node && *node < out.nodes.size()) ch.node = static_cast<int>(*node);
            ch.path = target_path(get_string(*target, "path"));
          }
          anim.channels.push_back(ch);
        }
      }
      out.animations.push_back(std::move(anim));
    }
  }
  // Weights samplers: as wide as the target count of the mesh their node holds.
  for (Animation& anim : out.animations) {
    for (const Channel& ch : anim.channels) {
      if (ch.path != TargetPath::Weights || ch.sampler < 0) continue;
      Sampler& sampler = anim.samplers[static_cast<size_t>(ch.sampler)];
      sampler.weights = true;
      const int mesh = ch.node >= 0 ? out.nodes[static_cast<size_t>(ch.node)].mesh : -1;
      sampler.width = mesh >= 0 ? static_cast<int>(out.meshes[static_cast<size_t>(mesh)].names.size()) : 0;
    }
  }
  // Decode the keys of the samplers Assimp mishandles, and only those.
  const Json* animations = get_array(root, "animations");
  for (size_t a = 0; a < out.animations.size(); ++a) {
    for (size_t s = 0; s < out.animations[a].samplers.size(); ++s) {
      Sampler& sampler = out.animations[a].samplers[s];
      if ((sampler.interpolation == Interpolation::Linear && !sampler.weights) || !sampler.error.empty()) continue;
      if (sampler.interpolation != Interpolation::Linear) out.any_nonlinear = true;
      read_sampler_keys(reader, (*get_array((*animations)[a], "samplers"))[s], &sampler);
    }
  }
  return out;
}

}  // namespace

Result<Animations> parse_gltf_animations(const std::vector<uint8_t>& bytes, const std::string& directory,
                                         const std::string& label) {
  try {
    std::optional<std::span<const uint8_t>> glb_bin;
    Json root;
    if (bytes.size() >= 4 && read_u32(bytes.data()) == kGlbMagic) {
      // Header: magic, version, length; then chunks of (length, type, data padded to 4).
      if (bytes.size() < 20) return Error{label + ": the GLB file is shorter than its header"};
      const uint32_t version = read_u32(bytes.data() + 4);
      const uint64_t total = std::min<uint64_t>(read_u32(bytes.data() + 8), bytes.size());
      if (version != 2) {
        return Error{label + ": GLB version " + std::to_string(version) + ", 2 expected"};
      }
      uint64_t at = 12;
      bool have_json = false;
      while (at + 8 <= total) {
        const uint64_t length = read_u32(bytes.data() + at);
        const uint32_t type = read_u32(bytes.data() + at + 4);
        if (length > total - at - 8) {
          return Error{label + ": a GLB chunk runs past the end of the file"};
        }
        const uint8_t* data = bytes.data() + at + 8;
        if (type == kChunkJson && !have_json) {
          root = Json::parse(data, data + length, nullptr, false);
          have_json = true;
        } else if (type == kChunkBin && !glb_bin && have_json) {
          glb_bin = std::span<const uint8_t>(data, static_cast<size_t>(length));
        }
        at += 8 + length;
      }
      if (!have_json) return Error{label + ": the GLB file has no JSON chunk"};
    } else {
      root = Json::parse(bytes.begin(), bytes.end(), nullptr, false);
    }
    if (root.is_discarded()) return Error{label + ": the glTF JSON does not parse"};
    return parse_json(root, glb_bin, directory, label);
  } catch (const std::exception& e) {
    return Error{label + ": reading the glTF animations failed: " + e.what()};
  } catch (...) {
    return Error{label + ": reading the glTF animations failed"};
  }
}

Result<Animations> read_gltf_animations(const std::string& path) {
  std::optional<std::vector<uint8_t>> bytes;
  try {
    bytes = read_bytes(path);
  } catch (const std::exception& e) {
    return Error{path + ": " + e.what()};
  }
  if (!bytes) return Error{path + ": cannot be read"};
  const std::string directory = std::filesystem::path(path).parent_path().string();
  return parse_gltf_animations(*bytes, directory, path);
}

}  // namespace ossa::cook::gltf
