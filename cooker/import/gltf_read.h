// gltf_read.h — what gltf_samplers.cpp (the file: GLB container, JSON, animations) and
// gltf_accessors.cpp (buffers, accessors, a sampler's keys) share; nothing else includes it.
// Every number read from the file is checked before it is used as an offset, a count or an index.
#pragma once
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cooker/import/gltf_samplers.h"

namespace ossa::cook::gltf::detail {

using Json = nlohmann::json;

uint32_t read_u32(const uint8_t* p);
/// A non-negative integer member, or nullopt when absent or of another type.
std::optional<uint64_t> get_uint(const Json& obj, const char* key);
/// A string member, or "" when absent or of another type.
std::string get_string(const Json& obj, const char* key);
/// An array / object member, or null when absent or of another type.
const Json* get_array(const Json& obj, const char* key);
const Json* get_object(const Json& obj, const char* key);
/// The i-th element of a top-level array ("accessors", "bufferViews", ...) if it is an object.
const Json* element(const Json& root, const char* array, uint64_t i);

/// A file's bytes through the cook's input log (read_input), or nullopt.
std::optional<std::vector<uint8_t>> read_bytes(const std::filesystem::path& path);

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
  std::optional<std::span<const uint8_t>> buffer(uint64_t index, std::string* error);
  /// Reads buffer `index` (the GLB chunk, a data: URI or a file beside the source); nullopt with why.
  std::optional<std::span<const uint8_t>> load(uint64_t index, std::string* why);
};

/// Decodes the keys of a STEP / CUBICSPLINE or weights sampler into *s; a problem with this one
/// sampler is recorded in s->error (naming the accessor at fault), never thrown.
void read_sampler_keys(Reader& r, const Json& sampler, Sampler* s);

}  // namespace ossa::cook::gltf::detail
