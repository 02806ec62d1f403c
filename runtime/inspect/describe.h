// describe.h — what ossa-inspect reports about a cooked file, as data.
//
// The description is built once, as JSON with a stable key order, and the readable text is
// rendered from that JSON, so the two outputs cannot disagree and the golden regression tests
// (which compare the JSON) cover everything a person reads. To keep goldens identical across
// machines the description holds nothing machine-dependent: the file is named without its
// directory, floats are rounded to 6 significant digits, hashes are 16-digit hex strings.
//
// Cost: describe is O(joints + meshes*layout + submeshes + clip channels + textures); nothing per vertex
// or per key. describe_text is linear in the size of the description.
#pragma once
#include <string>
#include <string_view>

#include <nlohmann/json.hpp>

#include "runtime/asset.h"

namespace ossa::inspect {

/// Everything ossa-inspect reports about a verified asset. `file_name` is what "file" says
/// (callers pass the file name without directories).
nlohmann::ordered_json describe(const Asset& asset, std::string_view file_name);

/// The same description as readable text, one section per skeleton / mesh / clip / material,
/// joints as an indented tree.
std::string describe_text(const nlohmann::ordered_json& description);

/// A float as JSON: rounded to 6 significant digits, -0 as 0, so goldens are stable.
double round6(double value);

}  // namespace ossa::inspect
