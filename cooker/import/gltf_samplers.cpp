// gltf_samplers.cpp — reading glTF animation samplers (JSON, GLB container, buffers, accessors)
// and evaluating them; see gltf_samplers.h for why the cooker does this beside Assimp.
//
// Written here rather than taken from a library: Debian 12 packages no glTF reader but Assimp
// (which is the thing dropping the data) and tinygltf is not packaged; what is needed is small —
// accessors of scalar/vec3/vec4 keys, with bounds checks — and nlohmann_json does the parsing.
//
// Every number from the file is checked before it is used as an offset, a count or an index:
// a hostile file must give an error message, never a read out of bounds or a huge allocation.
// All arithmetic on offsets is in uint64_t after checking each term, so nothing overflows.
#include "cooker/import/gltf_samplers.h"
#include "cooker/model/input_log.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <exception>
#include <filesystem>
#include <fstream>
#include <map>
#include <optional>
#include <span>

#include <nlohmann/json.hpp>

namespace ossa::cook::gltf {
namespace {

using Json = nlohmann::json;

// GLB container (glTF 2.0 spec, "Binary glTF Layout"): all little-endian.
constexpr uint32_t kGlbMagic = 0x46546C67;   // "glTF"
constexpr uint32_t kChunkJson = 0x4E4F534A;  // "JSON"
constexpr uint32_t kChunkBin = 0x004E4942;   // "BIN\0"

// Accessor component types.
constexpr uint64_t kByte = 5120, kUnsignedByte = 5121, kShort = 5122, kUnsignedShort = 5123,
                   kUnsignedInt = 5125, kFloat = 5126;

/// An accessor without a bufferView is all zeros (then usually sparse); its count is capped so a
/// hostile file cannot ask for gigabytes of zeros. Animation keys are far below this.
constexpr uint64_t kMaxZeroAccessorElements = uint64_t{1} << 24;

uint32_t read_u32(const uint8_t* p) {
  return static_cast<uint32_t>(p[0]) | static_cast<uint32_t>(p[1]) << 8 |
         static_cast<uint32_t>(p[2]) << 16 | static_cast<uint32_t>(p[3]) << 24;
}

/// A non-negative integer member, or nullopt when absent or of another type.
std::optional<uint64_t> get_uint(const Json& obj, const char* key) {
  if (!obj.is_object()) return std::nullopt;
  const auto it = obj.find(key);
  if (it == obj.end()) return std::nullopt;
  if (it->is_number_unsigned()) return it->get<uint64_t>();
  if (it->is_number_integer() && it->get<int64_t>() >= 0) {
    return static_cast<uint64_t>(it->get<int64_t>());
  }
  return std::nullopt;
}

std::string get_string(const Json& obj, const char* key) {
  if (!obj.is_object()) return {};
  const auto it = obj.find(key);
  return it != obj.end() && it->is_string() ? it->get<std::string>() : std::string{};
}

const Json* get_array(const Json& obj, const char* key) {
  if (!obj.is_object()) return nullptr;
  const auto it = obj.find(key);
  return it != obj.end() && it->is_array() ? &*it : nullptr;
}

const Json* get_object(const Json& obj, const char* key) {
  if (!obj.is_object()) return nullptr;
  const auto it = obj.find(key);
  return it != obj.end() && it->is_object() ? &*it : nullptr;
}

/// The i-th element of a top-level array ("accessors", "bufferViews", ...) if it is an object.
const Json* element(const Json& root, const char* array, uint64_t i) {
  const Json* a = get_array(root, array);
  if (!a || i >= a->size()) return nullptr;
  const Json& e = (*a)[static_cast<size_t>(i)];
  return e.is_object() ? &e : nullptr;
}

// ---------------------------------------------------------------------------------------------
// URIs

int hex_digit(char c) {
  if (c >= '0' && c <= '9') return c - '0';
  if (c >= 'a' && c <= 'f') return c - 'a' + 10;
  if (c >= 'A' && c <= 'F') return c - 'A' + 10;
  return -1;
}

/// glTF URIs are percent-encoded (RFC 3986): "my%20file.bin" names "my file.bin".
std::string percent_decode(const std::string& s) {
  std::string out;
  for (size_t i = 0; i < s.size(); ++i) {
    if (s[i] == '%' && i + 2 < s.size()) {
      const int hi = hex_digit(s[i + 1]), lo = hex_digit(s[i + 2]);
      if (hi >= 0 && lo >= 0) {
        out += static_cast<char>(hi * 16 + lo);
        i += 2;
        continue;
      }
    }
    out += s[i];
  }
  return out;
}

int base64_value(char c) {
  if (c >= 'A' && c <= 'Z') return c - 'A';
  if (c >= 'a' && c <= 'z') return c - 'a' + 26;
  if (c >= '0' && c <= '9') return c - '0' + 52;
  if (c == '+' || c == '-') {
    return 62;  // '-' and '_': the URL-safe alphabet, which some tools write
  }
  if (c == '/' || c == '_') return 63;
  return -1;
}

/// Standard base64; '=' padding optional, whitespace ignored. nullopt on any other character.
std::optional<std::vector<uint8_t>> base64_decode(const std::string& s, size_t begin) {
  std::vector<uint8_t> out;
  out.reserve((s.size() - begin) / 4 * 3 + 3);
  uint32_t bits = 0;
  int count = 0;
  bool padding = false;
  for (size_t i = begin; i < s.size(); ++i) {
    const char c = s[i];
    if (c == ' ' || c == '\n' || c == '\r' || c == '\t') continue;
    if (c == '=') {
      padding = true;
      continue;
    }
    const int v = base64_value(c);
    if (v < 0 || padding) return std::nullopt;  // data after padding is not base64 either
    bits = bits << 6 | static_cast<uint32_t>(v);
    if (++count == 4) {
      out.push_back(static_cast<uint8_t>(bits >> 16));
      out.push_back(static_cast<uint8_t>(bits >> 8));
      out.push_back(static_cast<uint8_t>(bits));
      bits = 0;
      count = 0;
    }
  }
  if (count == 1) return std::nullopt;  // 6 bits cannot end a byte
  if (count == 2) out.push_back(static_cast<uint8_t>(bits >> 4));
  if (count == 3) {
    out.push_back(static_cast<uint8_t>(bits >> 10));
    out.push_back(static_cast<uint8_t>(bits >> 2));
  }
  return out;
}

std::optional<std::vector<uint8_t>> read_bytes(const std::filesystem::path& path) {
  auto bytes = read_input(path);  // recorded in the cook's input log
  if (!bytes) return std::nullopt;
  return std::move(*bytes);
}

// ---------------------------------------------------------------------------------------------
// Buffers and accessors

/// The parsed JSON plus the buffers, loaded on first use (only samplers that need them ask).
struct Reader {
  const Json& root;
  std::string directory;
  /// The GLB's BIN chunk, inside the file's bytes (not copied); nullopt for a .gltf.
  std::optional<std::span<const uint8_t>> glb_bin;
  std::map<uint64_t, std::vector<uint8_t>> loaded;  // external and data-URI buffers
  std::map<uint64_t, std::span<const uint8_t>> ready;
  std::map<uint64_t, std::string> failed;

  /// Buffer `index`'s first byteLength bytes, or nullopt with an error message.
  std::optional<std::span<const uint8_t>> buffer(uint64_t index, std::string* error) {
    if (const auto it = ready.find(index); it != ready.end()) return it->second;
    if (const auto it = failed.find(index); it != failed.end()) {
      *error = it->second;
      return std::nullopt;
    }
    std::string why;
    const std::optional<std::span<const uint8_t>> bytes = load(index, &why);
    if (!bytes) {
      failed[index] = why;
      *error = why;
      return std::nullopt;
    }
    ready[index] = *bytes;
    return bytes;
  }

  std::optional<std::span<const uint8_t>> load(uint64_t index, std::string* why) {
    const std::string label = "buffer " + std::to_string(index);
    const Json* b = element(root, "buffers", index);
    if (!b) {
      *why = label + " does not exist";
      return std::nullopt;
    }
    const std::optional<uint64_t> length = get_uint(*b, "byteLength");
    if (!length) {
      *why = label + " has no byteLength";
      return std::nullopt;
    }
    std::optional<std::vector<uint8_t>> bytes;
    std::span<const uint8_t> span;
    const std::string uri = get_string(*b, "uri");
    if (uri.empty()) {
      if (index != 0 || !glb_bin) {
        *why = label + " has no uri and the file has no GLB binary chunk";
        return std::nullopt;
      }
      span = *glb_bin;
    } else if (uri.rfind("data:", 0) == 0) {
      const size_t comma = uri.find(',');
      if (comma == std::string::npos || uri.rfind(";base64", comma) == std::string::npos ||
          uri.rfind(";base64", comma) + 7 != comma) {
        *why = label + " has a data URI that is not base64";
        return std::nullopt;
      }
      bytes = base64_decode(uri, comma + 1);
      if (!bytes) {
        *why = label + " has a data URI with invalid base64";
        return std::nullopt;
      }
    } else {
      // A scheme ("http:", "file:") is a URI this offline tool will not fetch.
      const size_t colon = uri.find(':');
      const size_t slash = uri.find('/');
      if (colon != std::string::npos && (slash == std::string::npos || colon < slash) &&
          colon > 1) {
        *why = label + " has a URI the cooker cannot read: " + uri;
        return std::nullopt;
      }
      // URIs are percent-encoded ("my%20keys.bin" is "my keys.bin"), but Assimp 5.2.5 opens the
      // URI as written, so a file that Assimp could read may carry the encoded name: try both.
      std::filesystem::path file = std::filesystem::path(directory) / percent_decode(uri);
      bytes = read_bytes(file);
      if (!bytes && percent_decode(uri) != uri) {
        file = std::filesystem::path(directory) / uri;
        bytes = read_bytes(file);
      }
      if (!bytes) {
        *why = label + " cannot be read from " + file.string();
        return std::nullopt;
      }
    }
    if (bytes) span = loaded[index] = std::move(*bytes);
    if (span.size() < *length) {
      *why = label + " holds " + std::to_string(span.size()) + " bytes, byteLength says " +
             std::to_string(*length);
      return std::nullopt;
    }
    return span.first(static_cast<size_t>(*length));  // views are checked against byteLength
  }
};

int component_size(uint64_t type) {
  switch (type) {
    case kByte:
    case kUnsignedByte:
      return 1;
    case kShort:
    case kUnsignedShort:
      return 2;
    case kUnsignedInt:
    case kFloat:
      return 4;
    default:
      return 0;
  }
}

int component_count(const std::string& type) {
  if (type == "SCALAR") return 1;
  if (type == "VEC2") return 2;
  if (type == "VEC3") return 3;
  if (type == "VEC4") return 4;
  return 0;  // matrices never hold animation keys
}

/// One component as float. Normalized integers use the specification's decoding
/// (e.g. max(c / 127, -1) for signed bytes); others convert the integer's value.
float decode_component(const uint8_t* p, uint64_t type, bool normalized) {
  switch (type) {
    case kFloat: {
      float f;
      const uint32_t u = read_u32(p);
      std::memcpy(&f, &u, sizeof f);
      return f;
    }
    case kByte: {
      const auto c = static_cast<int8_t>(p[0]);
      return normalized ? std::max(static_cast<float>(c) / 127.0f, -1.0f) : static_cast<float>(c);
    }
    case kUnsignedByte:
      return normalized ? static_cast<float>(p[0]) / 255.0f : static_cast<float>(p[0]);
    case kShort: {
      const auto c = static_cast<int16_t>(static_cast<uint16_t>(p[0] | p[1] << 8));
      return normalized ? std::max(static_cast<float>(c) / 32767.0f, -1.0f) : static_cast<float>(c);
    }
    case kUnsignedShort: {
      const auto c = static_cast<uint16_t>(p[0] | p[1] << 8);
      return normalized ? static_cast<float>(c) / 65535.0f : static_cast<float>(c);
    }
    case kUnsignedInt:
      return static_cast<float>(read_u32(p));
    default:
      return 0.0f;
  }
}

struct ViewBytes {
  const uint8_t* data = nullptr;
  uint64_t size = 0;    // bytes of the view available from `data`
  uint64_t stride = 0;  // byteStride, 0 when the view does not set one
};

/// bufferView `index` as a checked byte range.
std::optional<ViewBytes> view_bytes(Reader& r, uint64_t index, std::string* why) {
  const std::string label = "bufferView " + std::to_string(index);
  const Json* v = element(r.root, "bufferViews", index);
  if (!v) {
    *why = label + " does not exist";
    return std::nullopt;
  }
  const std::optional<uint64_t> buffer = get_uint(*v, "buffer");
  const std::optional<uint64_t> length = get_uint(*v, "byteLength");
  const uint64_t offset = get_uint(*v, "byteOffset").value_or(0);
  if (!buffer || !length) {
    *why = label + " has no buffer or byteLength";
    return std::nullopt;
  }
  const std::optional<std::span<const uint8_t>> bytes = r.buffer(*buffer, why);
  if (!bytes) return std::nullopt;
  if (offset > bytes->size() || *length > bytes->size() - offset) {
    *why = label + " (offset " + std::to_string(offset) + ", length " + std::to_string(*length) +
           ") lies outside buffer " + std::to_string(*buffer) + " (" +
           std::to_string(bytes->size()) + " bytes)";
    return std::nullopt;
  }
  ViewBytes out;
  out.data = bytes->data() + offset;
  out.size = *length;
  out.stride = get_uint(*v, "byteStride").value_or(0);
  return out;
}

/// Accessor `index` decoded to floats: count * components values. `want_components` (when not 0)
/// and `float_only` are what the caller's semantics allow.
std::optional<std::vector<float>> read_accessor(Reader& r, uint64_t index, int want_components,
                                                bool float_only, int* components,
                                                std::string* why) {
  const std::string label = "accessor " + std::to_string(index);
  const Json* a = element(r.root, "accessors", index);
  if (!a) {
    *why = label + " does not exist";
    return std::nullopt;
  }
  const std::optional<uint64_t> type = get_uint(*a, "componentType");
  const std::optional<uint64_t> count = get_uint(*a, "count");
  const int n = component_count(get_string(*a, "type"));
  const int size = type ? component_size(*type) : 0;
  const auto normalized_it = a->find("normalized");
  const bool normalized =
      normalized_it != a->end() && normalized_it->is_boolean() && normalized_it->get<bool>();
  if (!count || size == 0 || n == 0) {
    *why = label + " has no valid count, componentType or type";
    return std::nullopt;
  }
  if (want_components && n != want_components) {
    *why = label + " has " + std::to_string(n) + " components, " + std::to_string(want_components) +
           " expected";
    return std::nullopt;
  }
  if (float_only && *type != kFloat) {
    *why = label + " is not FLOAT";
    return std::nullopt;
  }
  *components = n;
  const uint64_t element_size = static_cast<uint64_t>(size) * static_cast<uint64_t>(n);
  std::vector<float> out;
  if (const std::optional<uint64_t> view = get_uint(*a, "bufferView")) {
    const std::optional<ViewBytes> bytes = view_bytes(r, *view, why);
    if (!bytes) return std::nullopt;
    const uint64_t stride = bytes->stride ? bytes->stride : element_size;
    const uint64_t offset = get_uint(*a, "byteOffset").value_or(0);
    if (stride < element_size) {
      *why = label + ": byteStride " + std::to_string(stride) + " is smaller than an element";
      return std::nullopt;
    }
    // offset + stride * (count - 1) + element_size <= view size, without overflow.
    const bool fits =
        *count == 0 || (offset <= bytes->size && element_size <= bytes->size - offset &&
                        (*count - 1) <= (bytes->size - offset - element_size) / stride);
    if (!fits) {
      *why = label + " (" + std::to_string(*count) +
             " elements) reads past the end of bufferView " + std::to_string(*view);
      return std::nullopt;
    }
    out.resize(static_cast<size_t>(*count * static_cast<uint64_t>(n)));
    for (uint64_t e = 0; e < *count; ++e) {
      const uint8_t* p = bytes->data + offset + e * stride;
      for (int c = 0; c < n; ++c) {
        out[static_cast<size_t>(e * static_cast<uint64_t>(n) + static_cast<uint64_t>(c))] =
            decode_component(p + c * size, *type, normalized);
      }
    }
  } else {
    if (*count > kMaxZeroAccessorElements) {
      *why = label + " has no bufferView and " + std::to_string(*count) + " elements";
      return std::nullopt;
    }
    out.assign(static_cast<size_t>(*count * static_cast<uint64_t>(n)), 0.0f);
  }
  if (const Json* sparse = get_object(*a, "sparse")) {
    const std::optional<uint64_t> sparse_count = get_uint(*sparse, "count");
    const Json* indices = get_object(*sparse, "indices");
    const Json* values = get_object(*sparse, "values");
    const uint64_t index_type = indices ? get_uint(*indices, "componentType").value_or(0) : 0;
    const std::optional<uint64_t> index_view =
        indices ? get_uint(*indices, "bufferView") : std::nullopt;
    const std::optional<uint64_t> value_view =
        values ? get_uint(*values, "bufferView") : std::nullopt;
    const int index_size = component_size(index_type);
    if (!sparse_count || !index_view || !value_view ||
        !(index_type == kUnsignedByte || index_type == kUnsignedShort ||
          index_type == kUnsignedInt)) {
      *why = label + " has an incomplete sparse section";
      return std::nullopt;
    }
    const std::optional<ViewBytes> ib = view_bytes(r, *index_view, why);
    if (!ib) return std::nullopt;
    const std::optional<ViewBytes> vb = view_bytes(r, *value_view, why);
    if (!vb) return std::nullopt;
    const uint64_t io = get_uint(*indices, "byteOffset").value_or(0);
    const uint64_t vo = get_uint(*values, "byteOffset").value_or(0);
    const uint64_t isz = static_cast<uint64_t>(index_size);
    if (io > ib->size || *sparse_count > (ib->size - io) / isz || vo > vb->size ||
        *sparse_count > (vb->size - vo) / element_size) {
      *why = label + ": sparse indices or values read past their bufferViews";
      return std::nullopt;
    }
    for (uint64_t s = 0; s < *sparse_count; ++s) {
      const uint8_t* ip = ib->data + io + s * isz;
      const uint64_t target = index_size == 1   ? ip[0]
                              : index_size == 2 ? static_cast<uint64_t>(ip[0] | ip[1] << 8)
                                                : read_u32(ip);
      if (target >= *count) {
        *why = label + ": sparse index " + std::to_string(target) + " is out of range";
        return std::nullopt;
      }
      for (int c = 0; c < n; ++c) {
        out[static_cast<size_t>(target * static_cast<uint64_t>(n) + static_cast<uint64_t>(c))] =
            decode_component(vb->data + vo + s * element_size + static_cast<uint64_t>(c * size),
                             *type, normalized);
      }
    }
  }
  return out;
}

/// Decodes one STEP / CUBICSPLINE sampler's keys into `s`, or sets s->error.
void read_sampler_keys(Reader& r, const Json& sampler, Sampler* s) {
  const std::optional<uint64_t> input = get_uint(sampler, "input");
  const std::optional<uint64_t> output = get_uint(sampler, "output");
  if (!input || !output) {
    s->error = "the sampler has no input or output accessor";
    return;
  }
  int components = 0;
  std::optional<std::vector<float>> times =
      read_accessor(r, *input, 1, true, &components, &s->error);
  if (!times) return;
  std::optional<std::vector<float>> values =
      read_accessor(r, *output, 0, false, &components, &s->error);
  if (!values) return;
  const std::string in_label = "accessor " + std::to_string(*input);
  const std::string out_label = "accessor " + std::to_string(*output);
  if (times->empty()) {
    s->error = in_label + " holds no key times";
    return;
  }
  for (size_t i = 0; i < times->size(); ++i) {
    if (!std::isfinite((*times)[i]) || (i > 0 && !((*times)[i] > (*times)[i - 1]))) {
      s->error = in_label + ": key times are not finite and strictly increasing (key " +
                 std::to_string(i) + ")";
      return;
    }
  }
  if (s->weights) {
    if (components != 1) {
      s->error = out_label + " is not SCALAR (morph weights)";
      return;
    }
    if (s->width <= 0) {
      s->error = "the weights it animates belong to no mesh with morph targets";
      return;
    }
    components = s->width;  // one element = one weight per target
  } else if (components != 3 && components != 4) {
    s->error = out_label + " is neither VEC3 nor VEC4";
    return;
  }
  const size_t per_key = s->interpolation == Interpolation::CubicSpline ? 3 : 1;
  const size_t elements = values->size() / static_cast<size_t>(components);
  if (elements != times->size() * per_key) {
    s->error = out_label + " holds " + std::to_string(elements) + " elements, " +
               std::to_string(times->size() * per_key) + " expected for " +
               std::to_string(times->size()) + " keys";
    return;
  }
  for (float v : *values) {
    if (!std::isfinite(v)) {
      s->error = out_label + " holds a non-finite value";
      return;
    }
  }
  s->times = std::move(*times);
  s->values = std::move(*values);
  s->width = components;
}

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
        const bool named = names && i < names->size() && (*names)[i].is_string() && !(*names)[i].get<std::string>().empty();
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

Result<Animations> parse_gltf_animations(const std::vector<uint8_t>& bytes,
                                         const std::string& directory, const std::string& label) {
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

std::string assimp_node_name(const Animations& file, int index) {
  if (index >= 0 && static_cast<size_t>(index) < file.nodes.size() &&
      !file.nodes[static_cast<size_t>(index)].name.empty()) {
    return file.nodes[static_cast<size_t>(index)].name;
  }
  return "nodes[" + std::to_string(index) + "]";
}

void evaluate(const Sampler& s, double time, double snap, double* out) {
  const size_t w = static_cast<size_t>(s.width);
  const size_t n = s.times.size();
  const size_t per_key = s.interpolation == Interpolation::CubicSpline ? 3 : 1;
  // The value element of key k (the middle of the triple for CUBICSPLINE).
  auto value = [&](size_t k, size_t c) -> double {
    return s.values[(k * per_key + (per_key == 3 ? 1 : 0)) * w + c];
  };
  // Keys reached: times[k] <= time + snap.
  const size_t reached = static_cast<size_t>(
      std::upper_bound(s.times.begin(), s.times.end(), time + snap,
                       [](double t, float key) { return t < static_cast<double>(key); }) -
      s.times.begin());
  if (reached == 0 || reached == n || s.interpolation == Interpolation::Step) {
    const size_t k = reached == 0 ? 0 : reached - 1;
    for (size_t c = 0; c < w; ++c) out[c] = value(k, c);
  } else {
    const size_t k = reached - 1;
    const double t0 = s.times[k], t1 = s.times[k + 1];
    const double delta = t1 - t0;
    const double u = std::clamp((time - t0) / delta, 0.0, 1.0);
    if (s.interpolation == Interpolation::CubicSpline) {
      // glTF 2.0, Appendix C: p(u) = (2u³-3u²+1)v_k + (u³-2u²+u)Δ·b_k + (-2u³+3u²)v_k+1 +
      // (u³-u²)Δ·a_k+1, b_k the out-tangent of key k, a_k+1 the in-tangent of key k+1.
      const double u2 = u * u, u3 = u2 * u;
      const double h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u, h01 = -2 * u3 + 3 * u2,
                   h11 = u3 - u2;
      for (size_t c = 0; c < w; ++c) {
        const double b = s.values[(k * 3 + 2) * w + c];
        const double a = s.values[((k + 1) * 3 + 0) * w + c];
        out[c] = h00 * value(k, c) + h10 * delta * b + h01 * value(k + 1, c) + h11 * delta * a;
      }
    } else if (w == 4 && !s.weights) {
      // LINEAR rotation: slerp on the shorter arc.
      double dot = 0.0;
      for (size_t c = 0; c < 4; ++c) dot += value(k, c) * value(k + 1, c);
      const double sign = dot < 0.0 ? -1.0 : 1.0;
      dot = std::abs(dot);
      double wa = 1.0 - u, wb = u;
      if (dot < 1.0 - 1e-9) {
        const double angle = std::acos(std::min(dot, 1.0));
        wa = std::sin((1.0 - u) * angle) / std::sin(angle);
        wb = std::sin(u * angle) / std::sin(angle);
      }
      for (size_t c = 0; c < 4; ++c) out[c] = wa * value(k, c) + sign * wb * value(k + 1, c);
    } else {
      for (size_t c = 0; c < w; ++c) out[c] = (1.0 - u) * value(k, c) + u * value(k + 1, c);
    }
  }
  if (w == 4 && !s.weights) {
    const double len =
        std::sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2] + out[3] * out[3]);
    if (len > 1e-12 && std::isfinite(len)) {
      for (size_t c = 0; c < 4; ++c) out[c] /= len;
    }
  }
}

bool is_linear_equivalent(const Sampler& s, double tolerance) {
  if (s.interpolation == Interpolation::Linear) return true;
  const size_t w = static_cast<size_t>(s.width);
  const size_t n = s.times.size();
  const size_t per_key = s.interpolation == Interpolation::CubicSpline ? 3 : 1;
  auto element = [&](size_t k, size_t part, size_t c) {
    return static_cast<double>(s.values[(k * per_key + part) * w + c]);
  };
  const size_t mid = per_key == 3 ? 1 : 0;
  auto near = [&](double a, double b) {
    return std::abs(a - b) <= tolerance * std::max({1.0, std::abs(a), std::abs(b)});
  };
  // Rotations: the straight line between two different quaternions is an nlerp, not the slerp
  // Assimp's keys give, so only a constant rotation counts (q and -q being the same rotation).
  if (w == 4) {
    for (size_t k = 1; k < n; ++k) {
      bool same = true, opposite = true;
      for (size_t c = 0; c < 4; ++c) {
        same = same && near(element(k, mid, c), element(k - 1, mid, c));
        opposite = opposite && near(element(k, mid, c), -element(k - 1, mid, c));
      }
      if (!same && !opposite) return false;
    }
    if (per_key == 3) {
      for (size_t k = 0; k < n; ++k) {
        for (size_t c = 0; c < 4; ++c) {
          if (!near(element(k, 0, c), 0.0) || !near(element(k, 2, c), 0.0)) return false;
        }
      }
    }
    return true;
  }
  for (size_t k = 0; k + 1 < n; ++k) {
    const double delta = static_cast<double>(s.times[k + 1]) - static_cast<double>(s.times[k]);
    for (size_t c = 0; c < w; ++c) {
      const double chord = element(k + 1, mid, c) - element(k, mid, c);
      if (per_key == 1) {
        if (!near(chord, 0.0)) return false;
      } else {
        // Out-tangent of k and in-tangent of k+1, scaled to the segment, equal to the chord.
        if (!near(element(k, 2, c) * delta, chord) || !near(element(k + 1, 0, c) * delta, chord)) {
          return false;
        }
      }
    }
  }
  return true;
}

}  // namespace ossa::cook::gltf
