// source_precheck.cpp — depth limits and glTF repairs before Assimp (see source_precheck.h).
#include "cooker/import/source_precheck.h"

#include <algorithm>
#include <cctype>
#include <cstring>
#include <string_view>
#include <unordered_map>

#include <nlohmann/json.hpp>

namespace ossa::cook {
namespace {

using Json = nlohmann::json;

constexpr uint32_t kGlbMagic = 0x46546C67;   // "glTF"
constexpr uint32_t kChunkJson = 0x4E4F534A;  // "JSON"

uint32_t u32(const uint8_t* p) {
  return uint32_t(p[0]) | uint32_t(p[1]) << 8 | uint32_t(p[2]) << 16 | uint32_t(p[3]) << 24;
}
void put_u32(std::vector<uint8_t>& out, uint32_t v) {
  for (int i = 0; i < 4; ++i) out.push_back(static_cast<uint8_t>(v >> (8 * i)));
}

Error too_deep(uint64_t depth, const char* what) {
  return Error{std::string("its ") + what + " is nested " + (depth > kMaxHierarchyDepth ? "over " : "") +
               std::to_string(std::min<uint64_t>(depth, kMaxHierarchyDepth + 1) - 1) + "+ levels deep, more than the " +
               std::to_string(kMaxHierarchyDepth) + " the importer can take without overflowing its stack"};
}

/// Deepest brace nesting of text (BVH, ASCII FBX), ignoring quoted strings and ';' comments.
uint64_t brace_depth(std::span<const uint8_t> bytes, bool semicolon_comments) {
  uint64_t depth = 0, deepest = 0;
  bool quoted = false, comment = false;
  for (uint8_t c : bytes) {
    if (comment) {
      comment = c != '\n';
      continue;
    }
    if (quoted) {
      quoted = c != '"';
      continue;
    }
    if (c == '"') quoted = true;
    else if (c == ';' && semicolon_comments) comment = true;
    else if (c == '{') deepest = std::max(deepest, ++depth);
    else if (c == '}' && depth > 0) --depth;
  }
  return deepest;
}

/// Deepest record nesting of a binary FBX (header "Kaydara FBX Binary  \0", version at 23; each
/// record: end offset, property count, property bytes, name length, name, properties, nested
/// records, then a null record). Iterative: a stack of the end offsets of the open records.
/// Stops where the bytes no longer read as records (Assimp will say why) with the depth so far.
uint64_t fbx_binary_depth(std::span<const uint8_t> b) {
  if (b.size() < 27) return 0;
  const uint32_t version = u32(b.data() + 23);
  const bool wide = version >= 7500;  // 64-bit offsets
  const size_t header = wide ? 25 : 13;
  const auto read_offset = [&](size_t at) -> uint64_t {
    if (!wide) return u32(b.data() + at);
    uint64_t v = 0;
    for (int i = 7; i >= 0; --i) v = v << 8 | b[at + size_t(i)];
    return v;
  };
  std::vector<uint64_t> open;  // end offsets of the records being read
  uint64_t deepest = 0;
  size_t at = 27;
  while (at + header <= b.size()) {
    while (!open.empty() && at >= open.back()) open.pop_back();
    const uint64_t end = read_offset(at);
    const uint64_t property_bytes = wide ? read_offset(at + 16) : u32(b.data() + at + 8);
    const uint8_t name_length = b[at + header - 1];
    if (end == 0) {  // a null record closes the current list; at the top level, the last one
      if (open.empty()) break;
      at += header;
      open.pop_back();
      continue;
    }
    if (end <= at || end > b.size()) return deepest;  // unreadable from here: Assimp will say why
    open.push_back(end);
    deepest = std::max<uint64_t>(deepest, open.size());
    if (deepest > kMaxHierarchyDepth) return deepest;
    const uint64_t children = at + header + name_length + property_bytes;
    if (children > end) return deepest;
    at = static_cast<size_t>(children);
  }
  return deepest;
}

/// The value of attribute `name` in the attribute text of one tag (between the name and '>'),
/// or empty. Enough for Collada's `id="..."` and `url="#..."`.
std::string_view attribute(std::string_view attrs, std::string_view name) {
  for (size_t at = attrs.find(name); at != std::string_view::npos; at = attrs.find(name, at + 1)) {
    const bool starts = at == 0 || std::isspace(static_cast<unsigned char>(attrs[at - 1]));
    size_t i = at + name.size();
    while (i < attrs.size() && std::isspace(static_cast<unsigned char>(attrs[i]))) ++i;
    if (!starts || i >= attrs.size() || attrs[i] != '=') continue;
    ++i;
    while (i < attrs.size() && std::isspace(static_cast<unsigned char>(attrs[i]))) ++i;
    if (i >= attrs.size() || (attrs[i] != '"' && attrs[i] != '\'')) continue;
    const size_t end = attrs.find(attrs[i], i + 1);
    if (end == std::string_view::npos) return {};
    return attrs.substr(i + 1, end - i - 1);
  }
  return {};
}

/// The deepest node hierarchy a Collada file makes: `<node>` elements nested in each other, and
/// through `<instance_node url="#id">`, which Assimp expands in place (a chain of library nodes
/// each instancing the next is as deep as a nested chain). By a scan of the XML's tags (comments,
/// CDATA, processing instructions and declarations skipped; quoted values may hold '>'), then the
/// longest path over that graph, iteratively. A cycle of instances (Assimp would recurse forever)
/// counts as too deep. Malformed XML is scanned as far as it reads; Assimp reports the rest.
uint64_t collada_node_depth(std::span<const uint8_t> bytes) {
  const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
  struct Node {
    std::vector<uint32_t> children;           // nested <node>s
    std::vector<std::string_view> instances;  // ids named by <instance_node> directly inside
  };
  std::vector<Node> nodes;
  std::unordered_map<std::string_view, uint32_t> by_id;
  std::vector<int64_t> open;  // per open element: its node index, or -1
  const auto skip_to = [&](size_t from, std::string_view end) {
    const size_t at = text.find(end, from);
    return at == std::string_view::npos ? text.size() : at + end.size();
  };
  const auto is_name_char = [](char c) {
    return std::isalnum(static_cast<unsigned char>(c)) || c == '_' || c == '-' || c == '.' || c == ':' ||
           static_cast<unsigned char>(c) >= 0x80;
  };
  const auto enclosing_node = [&]() -> int64_t {
    for (auto it = open.rbegin(); it != open.rend(); ++it)
      if (*it >= 0) return *it;
    return -1;
  };
  size_t i = 0;
  while ((i = text.find('<', i)) != std::string_view::npos) {
    const std::string_view rest = text.substr(i);
    if (rest.substr(0, 4) == "<!--") {
      i = skip_to(i + 4, "-->");
      continue;
    }
    if (rest.substr(0, 9) == "<![CDATA[") {
      i = skip_to(i + 9, "]]>");
      continue;
    }
    if (rest.substr(0, 2) == "<?") {
      i = skip_to(i + 2, "?>");
      continue;
    }
    if (rest.substr(0, 2) == "<!") {
      i = skip_to(i + 2, ">");
      continue;
    }
    const bool closing = rest.substr(0, 2) == "</";
    const size_t name_at = i + (closing ? 2 : 1);
    size_t name_end = name_at;
    while (name_end < text.size() && is_name_char(text[name_end])) ++name_end;
    const std::string_view name = text.substr(name_at, name_end - name_at);
    size_t j = name_end;  // the tag's '>', past quoted attribute values
    for (char quote = 0; j < text.size(); ++j) {
      if (quote) {
        if (text[j] == quote) quote = 0;
      } else if (text[j] == '"' || text[j] == '\'') {
        quote = text[j];
      } else if (text[j] == '>') {
        break;
      }
    }
    if (j >= text.size()) break;  // a tag never closed
    const std::string_view attrs = text.substr(name_end, j - name_end);
    if (closing) {
      if (!open.empty()) open.pop_back();
    } else if (name == "instance_node") {
      const std::string_view url = attribute(attrs, "url");
      if (const int64_t parent = enclosing_node(); parent >= 0 && url.size() > 1 && url[0] == '#')
        nodes[static_cast<size_t>(parent)].instances.push_back(url.substr(1));
      if (text[j - 1] != '/') open.push_back(-1);
    } else if (!name.empty() && text[j - 1] != '/') {
      int64_t index = -1;
      if (name == "node") {
        index = static_cast<int64_t>(nodes.size());
        if (const int64_t parent = enclosing_node(); parent >= 0)
          nodes[static_cast<size_t>(parent)].children.push_back(static_cast<uint32_t>(index));
        nodes.emplace_back();
        if (const std::string_view id = attribute(attrs, "id"); !id.empty())
          by_id.emplace(id, static_cast<uint32_t>(index));
      }
      open.push_back(index);
    }
    i = j + 1;
  }
  // Longest path (in nodes) from each node, by an explicit stack; 0 = not started, 1 = on the
  // stack (seen again: a cycle), 2 = done.
  std::vector<uint64_t> depth(nodes.size(), 0);
  std::vector<uint8_t> state(nodes.size(), 0);
  const auto edges = [&](uint32_t n, auto&& visit) {
    for (uint32_t c : nodes[n].children) visit(c);
    for (std::string_view id : nodes[n].instances)
      if (const auto it = by_id.find(id); it != by_id.end()) visit(it->second);
  };
  uint64_t deepest = 0;
  for (uint32_t start = 0; start < nodes.size(); ++start) {
    if (state[start] != 0) continue;
    std::vector<uint32_t> stack{start};
    while (!stack.empty()) {
      const uint32_t n = stack.back();
      if (state[n] == 0) {
        state[n] = 1;
        bool cycle = false;
        edges(n, [&](uint32_t c) {
          if (state[c] == 0) stack.push_back(c);
          else if (state[c] == 1) cycle = true;
        });
        if (cycle) return uint64_t{kMaxHierarchyDepth} + 1;
        continue;
      }
      stack.pop_back();
      if (state[n] == 2) continue;
      uint64_t below = 0;
      edges(n, [&](uint32_t c) { below = std::max(below, depth[c]); });
      depth[n] = below + 1;
      state[n] = 2;
      deepest = std::max(deepest, depth[n]);
      if (deepest > kMaxHierarchyDepth) return deepest;
    }
  }
  return deepest;
}

/// Deepest glTF node nesting, iteratively over "children"; cycles and bad indices are left to
/// Assimp's validation (a node seen twice is not descended again).
uint64_t gltf_depth(const Json& root) {
  const Json* nodes = root.contains("nodes") && root["nodes"].is_array() ? &root["nodes"] : nullptr;
  if (!nodes) return 0;
  const size_t n = nodes->size();
  std::vector<uint8_t> has_parent(n, 0), seen(n, 0);
  for (const Json& node : *nodes)
    if (node.is_object() && node.contains("children") && node["children"].is_array())
      for (const Json& c : node["children"])
        if (c.is_number_unsigned() && c.get<uint64_t>() < n) has_parent[c.get<size_t>()] = 1;
  uint64_t deepest = 0;
  std::vector<std::pair<size_t, uint64_t>> stack;
  for (size_t r = 0; r < n; ++r) {
    if (has_parent[r]) continue;
    stack.push_back({r, 1});
    while (!stack.empty()) {
      const auto [i, depth] = stack.back();
      stack.pop_back();
      if (seen[i]) continue;
      seen[i] = 1;
      deepest = std::max(deepest, depth);
      if (deepest > kMaxHierarchyDepth) return deepest;
      const Json& node = (*nodes)[i];
      if (node.is_object() && node.contains("children") && node["children"].is_array())
        for (const Json& c : node["children"])
          if (c.is_number_unsigned() && c.get<uint64_t>() < n) stack.push_back({c.get<size_t>(), depth + 1});
    }
  }
  return deepest;
}

std::string base64(const std::vector<uint8_t>& in) {
  static const char* k = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  out.reserve((in.size() + 2) / 3 * 4);
  for (size_t i = 0; i < in.size(); i += 3) {
    const uint32_t v = uint32_t(in[i]) << 16 | (i + 1 < in.size() ? uint32_t(in[i + 1]) << 8 : 0) |
                       (i + 2 < in.size() ? uint32_t(in[i + 2]) : 0);
    out += k[v >> 18 & 63];
    out += k[v >> 12 & 63];
    out += i + 1 < in.size() ? k[v >> 6 & 63] : '=';
    out += i + 2 < in.size() ? k[v & 63] : '=';
  }
  return out;
}

/// Gives every skin without inverseBindMatrices an accessor of identity matrices (a buffer of its
/// own, as a data URI). True when anything changed.
bool add_identity_inverse_binds(Json& root) {
  if (!root.contains("skins") || !root["skins"].is_array()) return false;
  bool changed = false;
  for (Json& skin : root["skins"]) {
    if (!skin.is_object() || skin.contains("inverseBindMatrices")) continue;
    if (!skin.contains("joints") || !skin["joints"].is_array() || skin["joints"].empty()) continue;
    const size_t count = skin["joints"].size();
    if (count > 65535) continue;  // Assimp refuses such a skin itself
    std::vector<uint8_t> bytes(count * 64, 0);
    for (size_t j = 0; j < count; ++j)
      for (int d = 0; d < 4; ++d) {
        const float one = 1.0f;
        std::memcpy(bytes.data() + j * 64 + size_t(d) * 20, &one, 4);  // column-major diagonal
      }
    for (const char* key : {"buffers", "bufferViews", "accessors"})
      if (!root.contains(key) || !root[key].is_array()) root[key] = Json::array();
    const size_t buffer = root["buffers"].size(), view = root["bufferViews"].size(),
                 accessor = root["accessors"].size();
    root["buffers"].push_back(
        {{"byteLength", bytes.size()}, {"uri", "data:application/octet-stream;base64," + base64(bytes)}});
    root["bufferViews"].push_back({{"buffer", buffer}, {"byteLength", bytes.size()}});
    root["accessors"].push_back({{"bufferView", view}, {"componentType", 5126}, {"count", count}, {"type", "MAT4"}});
    skin["inverseBindMatrices"] = accessor;
    changed = true;
  }
  return changed;
}

/// Skins Assimp 5.2 dereferences without checking: "joints" missing, empty or naming no node, an
/// "inverseBindMatrices" that is not an accessor index. The spec requires what is checked here.
std::optional<Error> check_skins(const Json& root) {
  if (!root.contains("skins")) return std::nullopt;
  if (!root["skins"].is_array()) return Error{"its \"skins\" is not an array"};
  const size_t nodes = root.contains("nodes") && root["nodes"].is_array() ? root["nodes"].size() : 0;
  const size_t accessors = root.contains("accessors") && root["accessors"].is_array() ? root["accessors"].size() : 0;
  for (size_t i = 0; i < root["skins"].size(); ++i) {
    const Json& skin = root["skins"][i];
    const std::string at = "skin " + std::to_string(i);
    if (!skin.is_object()) return Error{at + " is not an object"};
    if (!skin.contains("joints") || !skin["joints"].is_array() || skin["joints"].empty())
      return Error{at + " has no \"joints\" (the glTF spec requires at least one)"};
    for (const Json& j : skin["joints"])
      if (!j.is_number_unsigned() || j.get<uint64_t>() >= nodes)
        return Error{at + ": a joint is not the index of a node (" + j.dump().substr(0, 40) + ")"};
    if (skin.contains("inverseBindMatrices")) {
      const Json& ibm = skin["inverseBindMatrices"];
      if (!ibm.is_number_unsigned() || ibm.get<uint64_t>() >= accessors)
        return Error{at + ": \"inverseBindMatrices\" is not the index of an accessor (" + ibm.dump().substr(0, 40) +
                     ")"};
    }
  }
  return std::nullopt;
}

Result<std::optional<std::vector<uint8_t>>> precheck_gltf(std::span<const uint8_t> bytes) {
  const bool glb = bytes.size() >= 4 && u32(bytes.data()) == kGlbMagic;
  size_t json_at = 0, json_length = bytes.size();
  if (glb) {
    // Assimp's messages for a broken container are about its consequences ("no meshes"); the
    // container's own story is plain: say it.
    if (bytes.size() < 20)
      return Error{"is a GLB file shorter than its 20-byte header (" + std::to_string(bytes.size()) + " bytes)"};
    const uint32_t declared = u32(bytes.data() + 8);
    if (declared > bytes.size())
      return Error{"is a GLB file that declares " + std::to_string(declared) + " bytes but has " +
                   std::to_string(bytes.size()) + ": it is truncated"};
    // Binary glTF 1.0 (KHR_binary_glTF) has no chunks; Assimp's glTF 1.0 reader checks it itself.
    if (u32(bytes.data() + 4) == 1) return std::optional<std::vector<uint8_t>>{};
    if (u32(bytes.data() + 16) != kChunkJson) return Error{"is a GLB file whose first chunk is not JSON"};
    json_length = u32(bytes.data() + 12);
    json_at = 20;
    if (json_length > bytes.size() - json_at) return Error{"is a GLB file whose JSON chunk runs past its end"};
  }
  Json root;
  try {
    root = Json::parse(bytes.begin() + static_cast<std::ptrdiff_t>(json_at),
                       bytes.begin() + static_cast<std::ptrdiff_t>(json_at + json_length));
  } catch (const Json::parse_error& e) {
    // Assimp would say "No suitable reader found" for a .gltf that is not JSON.
    std::string what = e.what();
    if (const size_t at = what.find("parse error"); at != std::string::npos) what = what.substr(at);
    return Error{std::string("is not valid glTF JSON (") + (json_at + e.byte >= bytes.size() ? "truncated? " : "") +
                 what + ")"};
  }
  if (!root.is_object()) return Error{"is not a glTF document (its JSON is not an object)"};
  if (const uint64_t depth = gltf_depth(root); depth > kMaxHierarchyDepth) return too_deep(depth, "node tree");
  // glTF 1.0 keys its top-level collections ("skins", "nodes", ...) by id in objects, and its skins
  // name joints rather than index them: the 2.0 checks and fix-ups below do not apply (Assimp's
  // glTF 1.0 reader has its own). 1.0 is told by asset.version, or by a file with no "asset" at all.
  const Json* version = root.contains("asset") && root["asset"].is_object() && root["asset"].contains("version")
                            ? &root["asset"]["version"]
                            : nullptr;
  const bool gltf1 =
      !root.contains("asset") || (version && version->is_string() && version->get<std::string>().starts_with("1"));
  if (gltf1) return std::optional<std::vector<uint8_t>>{};
  if (auto bad = check_skins(root)) return *bad;
  if (!add_identity_inverse_binds(root)) return std::optional<std::vector<uint8_t>>{};
  std::string text = root.dump();
  if (!glb) return std::optional<std::vector<uint8_t>>(std::vector<uint8_t>(text.begin(), text.end()));
  while (text.size() % 4 != 0) text += ' ';  // GLB chunks are padded to 4 bytes (JSON with spaces)
  const size_t rest_at = json_at + ((json_length + 3) & ~size_t{3});
  const size_t rest = rest_at <= bytes.size() ? bytes.size() - rest_at : 0;
  std::vector<uint8_t> out;
  out.reserve(12 + 8 + text.size() + rest);
  put_u32(out, kGlbMagic);
  put_u32(out, 2);
  put_u32(out, static_cast<uint32_t>(12 + 8 + text.size() + rest));
  put_u32(out, static_cast<uint32_t>(text.size()));
  put_u32(out, kChunkJson);
  out.insert(out.end(), text.begin(), text.end());
  if (rest > 0) out.insert(out.end(), bytes.begin() + static_cast<std::ptrdiff_t>(rest_at), bytes.end());
  return std::optional<std::vector<uint8_t>>(std::move(out));
}

}  // namespace

Result<std::optional<std::vector<uint8_t>>> precheck_source(std::span<const uint8_t> bytes,
                                                            const std::string& extension) {
  try {
    if (extension == ".gltf" || extension == ".glb") return precheck_gltf(bytes);
    if (extension == ".bvh") {
      if (const uint64_t d = brace_depth(bytes, false); d > kMaxHierarchyDepth) return too_deep(d, "joint hierarchy");
      // "Frames: 0" (or a negative count) reads as 4 billion frames in Assimp's BVH loader.
      const std::string_view text(reinterpret_cast<const char*>(bytes.data()), bytes.size());
      if (const size_t at = text.find("Frames:"); at != std::string_view::npos) {
        size_t i = at + 7;
        while (i < text.size() && (text[i] == ' ' || text[i] == '\t')) ++i;
        const bool negative = i < text.size() && text[i] == '-';
        const bool zero = i < text.size() && text[i] == '0' &&
                          (i + 1 >= text.size() || !std::isdigit(static_cast<unsigned char>(text[i + 1])));
        if (negative || zero)
          return Error{"declares \"Frames: " +
                       std::string(text.substr(i, std::min<size_t>(12, text.find_first_of("\r\n", i) - i))) +
                       "\": a BVH motion needs at least one frame"};
      }
    } else if (extension == ".dae") {
      if (const uint64_t d = collada_node_depth(bytes); d > kMaxHierarchyDepth)
        return too_deep(d, "node tree (nested <node>s and the <instance_node>s they expand)");
    } else if (extension == ".fbx") {
      constexpr std::string_view kBinary = "Kaydara FBX Binary  ";
      const bool binary =
          bytes.size() >= kBinary.size() && std::memcmp(bytes.data(), kBinary.data(), kBinary.size()) == 0;
      const uint64_t d = binary ? fbx_binary_depth(bytes) : brace_depth(bytes, true);
      if (d > kMaxHierarchyDepth) return too_deep(d, "record tree");
    }
  } catch (const std::exception&) {
    // A scan that cannot read the file leaves it to Assimp, which reports its own error.
  }
  return std::optional<std::vector<uint8_t>>{};
}

}  // namespace ossa::cook
