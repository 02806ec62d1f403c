// cook_internal.h — the steps that cooking a source (cook.cpp) and cooking a graph file
// (cook_graph.cpp) share. Not an API: only those two files include it.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "cooker/clip/clip_compress.h"
#include "cooker/cook.h"
#include "cooker/model/source_scene.h"
#include "cooker/mesh/mesh_build.h"
#include "cooker/write/write_ossa.h"
#include <ossa/format/result.h>

namespace ossa::cook::detail {

/// The whole file. Errors name it.
Result<std::vector<uint8_t>> read_bytes(const std::filesystem::path& path);

/// Root motion (when the options ask for it) and compression of every clip of `scene`, in order;
/// adds a ClipRecord per clip and a warning per clip over its tolerance. Errors start with `label`.
Result<std::vector<CompressedClip>> cook_clips(SourceScene& scene, const CookOptions& options, CookRecord& record,
                                               const std::string& label);

/// The counts a record knows once the scene is imported: joints, clips, materials, textures,
/// vertices over 4 influences (set before later stages run, so a failure keeps them).
void count_scene(CookRecord& record, const SourceScene& scene);

/// The counts a record knows once the meshes are built: meshes, submeshes, vertices, triangles.
void count_meshes(CookRecord& record, const std::vector<CookedMesh>& meshes, const MeshBuildStats& stats);

/// verify_buffer, then (when `write`) write_file_atomic. On success sets record.cooked_bytes;
/// otherwise record.error, and returns false.
bool write_verified(CookRecord& record, const std::vector<uint8_t>& bytes, const std::filesystem::path& input,
                    const std::filesystem::path& output, bool write);

/// Fills the provenance from the current input log once every input is read: source name and
/// hash, canonical options, the inputs relative to the input's directory and the cook key; copies
/// the inputs (absolute) and the key into the record. False (with record.error) when the log holds
/// a refused read: the cook must not write an output that silently lacks what its source named.
bool finish_provenance(WriteProvenance& provenance, CookRecord& record, const std::filesystem::path& input,
                       const CookOptions& options);

/// "<input>: <first refusal> (and N more refused reads)".
std::string refusal_error(const std::filesystem::path& input, const InputLog& log);

/// cook_file for a graph file (cook_graph.cpp).
void cook_graph(CookRecord& record, const std::filesystem::path& input, const std::filesystem::path& output,
                const CookOptions& options);

}  // namespace ossa::cook::detail
