// describe.h — what ossa-inspect reports about a cooked file, as data.
//
// The description is built once, as JSON with a stable key order, and the readable text is
// rendered from that JSON, so the two outputs cannot disagree and the golden regression tests
// (which compare the JSON) cover everything a person reads. To keep goldens identical across
// machines the description holds nothing machine-dependent: the file is named without its
// directory, floats are rounded to 6 significant digits, hashes are 16-digit hex strings.
//
// The JSON document is described field by field, with units, in
// docs/schemas/ossa-inspect.schema.json (docs/JSON.md); it starts with "schema": "ossa-inspect" and
// "schema_version", which moves only on an incompatible change (an added optional field keeps it).
//
// Cost: describe is O(joints + meshes*layout + submeshes + clip channels + textures); nothing per vertex
// or per key unless DescribeOptions::influences asks (then O(vertices)). describe_text is linear in
// the size of the description.
#pragma once
#include <cstdint>
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include <ossa/loader/asset.h>

namespace ossa::inspect {

inline constexpr const char* kSchema = "ossa-inspect";
inline constexpr int kSchemaVersion = 1;

struct DescribeOptions {
  /// Each clip also lists its channels ("channels": joint, channel, constant or animated, keys,
  /// bits): ossa-inspect -v. Still O(channels), so cheap, but long for big rigs.
  bool channels = false;
  /// Each skinned mesh with unorm8 weights also reports its influence classes ("influences": the
  /// vertices of each class and whether they run in class order, which skin_cpu's range loops
  /// need): ossa-inspect -v. O(vertices).
  bool influences = false;
};

/// Everything ossa-inspect reports about a verified asset. `file_name` is what "file" says
/// (callers pass the file name without directories).
nlohmann::ordered_json describe(const Asset& asset, std::string_view file_name, const DescribeOptions& options = {});

/// The same description as readable text, one section per skeleton / mesh / clip / material,
/// joints as an indented tree.
std::string describe_text(const nlohmann::ordered_json& description);

/// A float as JSON: rounded to 6 significant digits, -0 as 0, so goldens are stable.
double round6(double value);

/// A 64-bit hash as the 16 lower-case hex digits every description and diff report prints.
std::string hex16(uint64_t value);

}  // namespace ossa::inspect
