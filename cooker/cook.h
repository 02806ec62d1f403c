// cook.h — cook one source file into one .ossa file: import, build meshes, write, atomically.
//
// The batch (cli/batch.h) calls cook_file once per input, each in a worker process of its own
// (cli/worker.h); a call touches nothing shared (it is also safe on several threads at once), so
// the bytes written do not depend on --jobs. The output is written
// to a temporary file beside the target and renamed over it only when complete: a failed input
// leaves no output file, and a reader never sees a half-written one.
#pragma once
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "cooker/clip/clip_compress.h"
#include "cooker/import/input_log.h"
#include "cooker/import/source_scene.h"
#include "cooker/retarget/retarget_clips.h"
#include <ossa/format/result.h>

namespace ossa::cook {

/// What the cooker makes of a texture (--texture-format; cooker/texture/texture_cook.h).
enum class TextureOutput : uint8_t {
  Compressed,  // "bc": mip chains in BC1 / BC3 / BC4 / BC5 by role (the default)
  Rgba8,       // "rgba8": mip chains of uncompressed RGBA8
  Source,      // "source": the source's PNG / JPEG bytes, decoded by the loader
};

struct CookOptions {
  bool float_vertices = false;
  TextureOutput textures = TextureOutput::Compressed;  // --texture-format
  ClipCompressionOptions clips;       // --clip-tolerance, --no-clip-compression
  bool root_motion = false;           // --root-motion: extract root motion from every clip
  uint8_t up_axis = 1;                // --up-axis: 0 x, 1 y, 2 z
  /// --metres-per-unit: the sources' length unit, overriding the file (BVH states none); 0: the file's.
  float metres_per_unit = 0.0f;
  /// Clip-only cooking against this rig (loaded from --skeleton REF.ossa); null otherwise.
  const SourceSkeleton* reference = nullptr;
  std::string reference_name;  // REF.ossa's file name, recorded in the options string
  InputFile reference_input;   // REF.ossa as read (absolute path, hash): its hash is in canonical()
  /// --retarget-to TARGET.ossa: the source's clips are retargeted onto this rig
  /// (cooker/retarget/retarget_clips.h) and cooked as clip-only files of it; null otherwise.
  const SourceSkeleton* retarget_target = nullptr;
  std::string retarget_name;          // TARGET.ossa's file name
  InputFile retarget_input;           // TARGET.ossa as read: its hash is in canonical()
  const tools::HumanoidMapFile* retarget_map = nullptr;  // --map FILE.json, or null
  std::string retarget_map_name;
  InputFile retarget_map_input;       // the map file as read: its hash is in canonical()
  /// Canonical text of the options that change output bytes, recorded in provenance.
  std::string canonical() const;

  // How to run, not what to make (not in canonical(), not in the key):
  /// The read sandbox (input_log.h): a cook reads only inside `root` (--root) or, without one, the
  /// input's own folder tree, and inside each of `allow_dirs` (--allow-dir).
  std::filesystem::path root;
  std::vector<std::filesystem::path> allow_dirs;
  bool force = false;  // --force: cook even when the output is up to date
  bool write = true;   // false (--list-inputs): cook in memory, write nothing
};

/// What compression achieved on one clip (--report, ossa-bench-compression).
struct ClipRecord {
  std::string name;
  uint32_t joints = 0, frames = 0;
  uint32_t raw_bytes = 0, cooked_bytes = 0;
  float max_error_mm = 0.0f, mean_error_mm = 0.0f;  // in millimetres (via metres_per_unit)
  std::string worst_joint;
};

/// One morph target as cooked: how many vertices it stores and the error its bounds allowed.
struct MorphRecord {
  std::string mesh, name;
  uint32_t vertices = 0;              // listed (stored) vertices
  uint32_t raw_bytes = 0;             // dense float deltas over the mesh's vertices
  uint32_t stored_bytes = 0;          // the sparse form in the file
  float position_error_mm = 0.0f;     // millimetres (via metres_per_unit)
  float normal_error_deg = 0.0f;
};

/// One distinct texture as cooked (a source image used twice for one role is cooked once).
struct TextureRecord {
  std::string name;                   // the image's file name, or the embedded image's name
  std::string role;                   // "diffuse", "normal", "specular"
  std::string encoding;               // "BC1", "BC3", "BC4", "BC5", "RGBA8", "source"
  bool srgb = false;
  uint32_t width = 0, height = 0, mips = 0;
  uint64_t source_bytes = 0;          // the encoded image as the source had it
  uint64_t cooked_bytes = 0;          // what the file stores for it
  uint64_t gpu_rgba8_bytes = 0;       // RGBA8 + a full mip chain: what decoding the source puts on a GPU
  float psnr_db = 0.0f;               // level 0 against the source, over the channels kept (99: exact)
  float normal_mean_deg = 0.0f, normal_max_deg = 0.0f;  // normal maps: angle to the source's normals
};

/// One line of the --report file (docs/schemas/ossa-cook-report.schema.json).
///
/// A failed cook keeps what it learnt before it stopped: the counts are filled in as each stage
/// finishes (an empty optional: that stage was not reached), source_bytes counts what was read,
/// seconds is always set. `output` is where the file goes; only a record with `ok` has written it
/// (report_json names it only then), and cooked_bytes is 0 otherwise.
struct CookRecord {
  std::string input;
  std::string output;
  bool ok = false;
  std::string error;                  // when !ok: "<input>: what is wrong"
  std::vector<std::string> warnings;
  // Known after import: joints (of the imported rig; when ok, of the file's skeleton: 0 for a
  // clip-only file cooked against --skeleton), clips, materials, textures, vertices over 4 influences.
  std::optional<uint32_t> joints, clips, materials, textures, vertices_over_4_influences;
  // Known once meshes are built.
  std::optional<uint32_t> meshes, submeshes, vertices, triangles;
  uint64_t source_bytes = 0;          // every file read: the source, its sidecar, a graph's sources
  uint64_t cooked_bytes = 0;          // the written file (ok only)
  double seconds = 0.0;
  std::vector<ClipRecord> clip_records;  // one per clip compressed before any failure
  std::vector<MorphRecord> morph_records;  // one per morph target, once meshes are built
  std::vector<TextureRecord> texture_records;  // one per distinct embedded texture, once textures are cooked
  std::vector<RetargetRecord> retarget_records;  // --retarget-to: one per clip retargeted
  /// Every file the cook read or looked for (absolute paths, sorted), as far as it got; for an
  /// up-to-date output, the inputs its provenance lists. The depfile and --list-inputs print these.
  std::vector<InputFile> inputs_read;
  uint64_t cook_key = 0;   // of the written (or up-to-date) output
  bool up_to_date = false; // ok without cooking: the output's cook key matched (nothing written)
};

/// Cooks `input` to `output` (parent directories are created). Never throws.
///
/// Unless options.force, an existing `output` whose provenance cook key equals the key of the
/// inputs it lists as they are now (re-hashed) is up to date: it is neither cooked nor rewritten
/// (its mtime stays), and the record says so. Every file read goes into the record's inputs_read
/// and, relative to the input's directory, into the output's provenance with the cook key
/// (input_log.h).
///
/// A source file's clips get the events of its sidecar `<stem>.events.json` when there is one
/// (cooker/clip/clip_events.h; the sidecar's bytes are part of the provenance hash). A graph file
/// (is_graph_file) cooks into a self-contained character: its rig, meshes, clips and the compiled
/// graph (docs/GRAPH.md); `reference` is then not used, the graph names its own rig.
CookRecord cook_file(const std::filesystem::path& input, const std::filesystem::path& output,
                     const CookOptions& options);

/// True for `*.graph.json` (case-insensitive): an animation graph file rather than a source.
/// The record cook_file would return for an output that is up to date (settings applied, the
/// output's listed inputs re-read and re-hashed inside the read sandbox, the key recomputed), or
/// nullopt when it would cook (or fail). Reads only the output and the files it lists, parses only
/// the output (through the verifying loader) and settings files (ossa's own JSON reader): no
/// importer runs, so the batch calls it in its own process before starting a worker for an input,
/// and an all-up-to-date run costs no process per input. O(bytes of the listed inputs).
std::optional<CookRecord> up_to_date_record(const std::filesystem::path& input, const std::filesystem::path& output,
                                            const CookOptions& options);

bool is_graph_file(const std::filesystem::path& path);

/// Loads the skeleton of a cooked file (for --skeleton). Errors name the file. `as_read`, when
/// given, receives the file's input record (absolute path, hash, size) for the cooks' input logs.
Result<SourceSkeleton> load_reference_skeleton(const std::filesystem::path& ossa_file, InputFile* as_read = nullptr);

/// Reads and parses a humanoid map file (for --map; runtime/tools/retarget/map_file.h). Errors name
/// the file. `as_read`, when given, receives its input record (absolute path, hash, size).
Result<tools::HumanoidMapFile> load_humanoid_map_file(const std::filesystem::path& path, InputFile* as_read = nullptr);

/// Writes bytes to a temporary file in path's directory, flushes, then renames it onto path.
/// On any failure the temporary is removed and path is untouched. A read-only file at path is
/// refused, not replaced; temporaries of path left by processes that no longer exist are removed.
Status write_file_atomic(const std::filesystem::path& path, const std::vector<uint8_t>& bytes);

}  // namespace ossa::cook
