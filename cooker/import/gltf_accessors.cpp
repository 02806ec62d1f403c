// gltf_accessors.cpp — a glTF file's buffers and accessors, and a sampler's keys decoded from
// them (see gltf_samplers.h for why the cooker reads glTF beside Assimp, gltf_read.h for the parts
// gltf_samplers.cpp shares).
//
// Written here rather than taken from a library: Debian 12 packages no glTF reader but Assimp
// (which is the thing dropping the data) and tinygltf is not packaged; what is needed is small —
// accessors of scalar/vec3/vec4 keys, with bounds checks — and nlohmann_json does the parsing.
//
// Every number from the file is checked before it is used as an offset, a count or an index:
// a hostile file must give an error message, never a read out of bounds or a huge allocation.
// All arithmetic on offsets is in uint64_t after checking each term, so nothing overflows.
#include "cooker/import/gltf_read.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>

#include "cooker/model/input_log.h"

namespace ossa::cook::gltf::detail {
namespace {

// Accessor component types.
constexpr uint64_t kByte = 5120, kUnsignedByte = 5121, kShort = 5122, kUnsignedShort = 5123, kUnsignedInt = 5125,
                   kFloat = 5126;

/// An accessor without a bufferView is all zeros (then usually sparse); its count is capped so a
/// hostile file cannot ask for gigabytes of zeros. Animation keys are far below this.
constexpr uint64_t kMaxZeroAccessorElements = uint64_t{1} << 24;

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

}  // namespace

uint32_t read_u32(const uint8_t* p) {
  return static_cast<uint32_t>(p[0]) | static_cast<uint32_t>(p[1]) << 8 | static_cast<uint32_t>(p[2]) << 16 |
         static_cast<uint32_t>(p[3]) << 24;
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

std::optional<std::vector<uint8_t>> read_bytes(const std::filesystem::path& path) {
  auto bytes = read_input(path);  // recorded in the cook's input log
  if (!bytes) return std::nullopt;
  return std::move(*bytes);
}

// ---------------------------------------------------------------------------------------------
// Buffers and accessors

/// Buffer `index`'s first byteLength bytes, or nullopt with an error message.
std::optional<std::span<const uint8_t>> Reader::buffer(uint64_t index, std::string* error) {
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

std::optional<std::span<const uint8_t>> Reader::load(uint64_t index, std::string* why) {
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
    if (colon != std::string::npos && (slash == std::string::npos || colon < slash) && colon > 1) {
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
    *why = label + " holds " + std::to_string(span.size()) + " bytes, byteLength says " + std::to_string(*length);
    return std::nullopt;
  }
  return span.first(static_cast<size_t>(*length));  // views are checked against byteLength
}

namespace {

int component_size(uint64_t type) {
  switch (type) {
    case kByte:
    case kUnsignedByte: return 1;
    case kShort:
    case kUnsignedShort: return 2;
    case kUnsignedInt:
    case kFloat: return 4;
    default: return 0;
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
    case kUnsignedByte: return normalized ? static_cast<float>(p[0]) / 255.0f : static_cast<float>(p[0]);
    case kShort: {
      const auto c = static_cast<int16_t>(static_cast<uint16_t>(p[0] | p[1] << 8));
      return normalized ? std::max(static_cast<float>(c) / 32767.0f, -1.0f) : static_cast<float>(c);
    }
    case kUnsignedShort: {
      const auto c = static_cast<uint16_t>(p[0] | p[1] << 8);
      return normalized ? static_cast<float>(c) / 65535.0f : static_cast<float>(c);
    }
    case kUnsignedInt: return static_cast<float>(read_u32(p));
    default: return 0.0f;
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
           ") lies outside buffer " + std::to_string(*buffer) + " (" + std::to_string(bytes->size()) + " bytes)";
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
std::optional<std::vector<float>> read_accessor(Reader& r, uint64_t index, int want_components, bool float_only,
                                                int* components, std::string* why) {
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
  const bool normalized = normalized_it != a->end() && normalized_it->is_boolean() && normalized_it->get<bool>();
  if (!count || size == 0 || n == 0) {
    *why = label + " has no valid count, componentType or type";
    return std::nullopt;
  }
  if (want_components && n != want_components) {
    *why = label + " has " + std::to_string(n) + " components, " + std::to_string(want_components) + " expected";
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
    const bool fits = *count == 0 || (offset <= bytes->size && element_size <= bytes->size - offset &&
                                      (*count - 1) <= (bytes->size - offset - element_size) / stride);
    if (!fits) {
      *why = label + " (" + std::to_string(*count) + " elements) reads past the end of bufferView " +
             std::to_string(*view);
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
    const std::optional<uint64_t> index_view = indices ? get_uint(*indices, "bufferView") : std::nullopt;
    const std::optional<uint64_t> value_view = values ? get_uint(*values, "bufferView") : std::nullopt;
    const int index_size = component_size(index_type);
    if (!sparse_count || !index_view || !value_view ||
        !(index_type == kUnsignedByte || index_type == kUnsignedShort || index_type == kUnsignedInt)) {
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
            decode_component(vb->data + vo + s * element_size + static_cast<uint64_t>(c * size), *type, normalized);
      }
    }
  }
  return out;
}

}  // namespace

/// Decodes one STEP / CUBICSPLINE sampler's keys into `s`, or sets s->error.
void read_sampler_keys(Reader& r, const Json& sampler, Sampler* s) {
  const std::optional<uint64_t> input = get_uint(sampler, "input");
  const std::optional<uint64_t> output = get_uint(sampler, "output");
  if (!input || !output) {
    s->error = "the sampler has no input or output accessor";
    return;
  }
  int components = 0;
  std::optional<std::vector<float>> times = read_accessor(r, *input, 1, true, &components, &s->error);
  if (!times) return;
  std::optional<std::vector<float>> values = read_accessor(r, *output, 0, false, &components, &s->error);
  if (!values) return;
  const std::string in_label = "accessor " + std::to_string(*input);
  const std::string out_label = "accessor " + std::to_string(*output);
  if (times->empty()) {
    s->error = in_label + " holds no key times";
    return;
  }
  for (size_t i = 0; i < times->size(); ++i) {
    if (!std::isfinite((*times)[i]) || (i > 0 && !((*times)[i] > (*times)[i - 1]))) {
      s->error = in_label + ": key times are not finite and strictly increasing (key " + std::to_string(i) + ")";
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
               std::to_string(times->size() * per_key) + " expected for " + std::to_string(times->size()) + " keys";
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

}  // namespace ossa::cook::gltf::detail
