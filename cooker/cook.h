// cook.h — cook one source file into one .ossa file: import, build meshes, write, atomically.
//
// The batch driver (main.cpp) calls cook_file once per input, possibly from several threads; a
// call touches nothing shared, so the bytes written do not depend on --jobs. The output is written
// to a temporary file beside the target and renamed over it only when complete: a failed input
// leaves no output file, and a reader never sees a half-written one.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "cooker/clip_compress.h"
#include "cooker/source_scene.h"
#include "format/result.h"

namespace ossa::cook {

struct CookOptions {
  bool float_vertices = false;
  ClipCompressionOptions clips;       // --clip-tolerance, --no-clip-compression
  bool root_motion = false;           // --root-motion: extract root motion from every clip
  uint8_t up_axis = 1;                // --up-axis: 0 x, 1 y, 2 z
  /// Clip-only cooking against this rig (loaded from --skeleton REF.ossa); null otherwise.
  const SourceSkeleton* reference = nullptr;
  std::string reference_name;  // REF.ossa's file name, recorded in the options string
  /// Canonical text of the options that change output bytes, recorded in provenance.
  std::string canonical() const;
};

/// What compression achieved on one clip (--report, ossa-bench-compression).
struct ClipRecord {
  std::string name;
  uint32_t joints = 0, frames = 0;
  uint32_t raw_bytes = 0, cooked_bytes = 0;
  float max_error_mm = 0.0f, mean_error_mm = 0.0f;  // in millimetres (via metres_per_unit)
  std::string worst_joint;
};

/// One line of the --report file.
struct CookRecord {
  std::string input;
  std::string output;
  bool ok = false;
  std::string error;                  // when !ok: "<input>: what is wrong"
  std::vector<std::string> warnings;
  uint32_t joints = 0, meshes = 0, submeshes = 0, vertices = 0, triangles = 0, clips = 0,
           materials = 0, textures = 0;
  uint32_t vertices_over_4_influences = 0;
  uint64_t source_bytes = 0, cooked_bytes = 0;
  double seconds = 0.0;
  std::vector<ClipRecord> clip_records;
};

/// Cooks `input` to `output` (parent directories are created). Never throws.
///
/// A source file's clips get the events of its sidecar `<stem>.events.json` when there is one
/// (cooker/clip_events.h; the sidecar's bytes are part of the provenance hash). A graph file
/// (is_graph_file) cooks into a self-contained character: its rig, meshes, clips and the compiled
/// graph (docs/GRAPH.md); `reference` is then not used, the graph names its own rig.
CookRecord cook_file(const std::filesystem::path& input, const std::filesystem::path& output,
                     const CookOptions& options);

/// True for `*.graph.json` (case-insensitive): an animation graph file rather than a source.
bool is_graph_file(const std::filesystem::path& path);

/// Loads the skeleton of a cooked file (for --skeleton). Errors name the file.
Result<SourceSkeleton> load_reference_skeleton(const std::filesystem::path& ossa_file);

/// Writes bytes to a temporary file in path's directory, flushes, then renames it onto path.
/// On any failure the temporary is removed and path is untouched.
Status write_file_atomic(const std::filesystem::path& path, const std::vector<uint8_t>& bytes);

}  // namespace ossa::cook
