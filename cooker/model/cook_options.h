// cook_options.h — what a cook makes of its input (--float-vertices, --clip-tolerance, --texture-format,
// --root-motion, --skeleton, ...) and how it runs (the read sandbox, --force, --list-inputs).
//
// Part of the cooker's model: the command line and the batch (cli/) fill it, per-asset settings
// (cook_settings.h) layer over it, every stage reads the part it needs. canonical() is the text of
// the options that change output bytes: it is recorded in each output's provenance and enters the
// cook key, so two cooks with equal canonical text and inputs make equal bytes.
#pragma once
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cooker/model/cloth_options.h"
#include "cooker/model/input_log.h"
#include "cooker/model/source_scene.h"

namespace ossa::tools {
struct HumanoidMapFile;  // tools/retarget/map_file.h (--map)
}

namespace ossa::cook {

struct CookCache;  // cooker/cache/cook_cache.h (--cache)

/// What the cooker makes of a texture (--texture-format; cooker/texture/texture_cook.h).
enum class TextureOutput : uint8_t {
  Compressed,  // "bc": mip chains in BC1 / BC3 / BC4 / BC5 by role (the default)
  Rgba8,       // "rgba8": mip chains of uncompressed RGBA8
  Source,      // "source": the source's PNG / JPEG bytes, decoded by the loader
};

/// How clips are compressed (--clip-tolerance, --no-clip-compression; cooker/clip/clip_compress.h).
struct ClipCompressionOptions {
  bool enabled = true;                    // false: lossless (bind/constant only when bit-equal, every
                                          // other channel raw floats at every frame)
  float tolerance_metres = 0.0001f;       // 0.1 mm ...
  float probe_metres = 0.1f;              // ... at 10 cm
  float morph_weight_tolerance = 0.001f;  // largest error of a morph weight at any frame
};

/// "bc" | "rgba8" | "source" -> the output; nullopt for anything else.
std::optional<TextureOutput> parse_texture_output(std::string_view name);
const char* texture_output_name(TextureOutput output);

/// True for `*.graph.json` (case-insensitive): an animation graph file rather than a source.
bool is_graph_file(const std::filesystem::path& path);

/// True for a source named as its folder's rig: stem `skeleton`, or the folder's own name
/// (`Pab/Pab.fbx`), case-insensitive; never a graph file (the folder-rig convention, docs/COOKING.md).
bool has_folder_rig_name(const std::filesystem::path& path);

struct CookOptions {
  bool float_vertices = false;
  TextureOutput textures = TextureOutput::Compressed;  // --texture-format
  ClipCompressionOptions clips;                        // --clip-tolerance, --no-clip-compression
  bool root_motion = false;                            // --root-motion: extract root motion from every clip
  /// --up-axis: the sources' up axis (0 x, 1 y, 2 z) over what each file states; -1: the file's.
  /// Every output is Y-up (import_axes.cpp), so root motion and cloth gravity are about Y.
  int up_axis = -1;
  /// --metres-per-unit: the sources' length unit, overriding the file (BVH states none); 0: the file's.
  float metres_per_unit = 0.0f;
  /// Clip-only cooking against this rig (loaded from --skeleton REF.ossa); null otherwise.
  const SourceSkeleton* reference = nullptr;
  /// A batch's folder rig for this input (cli/batch.h: assign_folder_rigs), a cooked .ossa: the
  /// input is cooked against it, as with --skeleton, when it holds clips and no mesh; then the rig
  /// enters canonical() through `reference`. Empty: none.
  std::filesystem::path folder_rig;
  std::string reference_name;  // REF.ossa's file name, recorded in the options string
  InputFile reference_input;   // REF.ossa as read (absolute path, hash): its hash is in canonical()
  ClothOptions cloth;          // the "cloth" cook setting (docs/CLOTH.md)
  /// --retarget-to TARGET.ossa: the source's clips are retargeted onto this rig
  /// (cooker/retarget/retarget_clips.h) and cooked as clip-only files of it; null otherwise.
  const SourceSkeleton* retarget_target = nullptr;
  std::string retarget_name;                             // TARGET.ossa's file name
  InputFile retarget_input;                              // TARGET.ossa as read: its hash is in canonical()
  const tools::HumanoidMapFile* retarget_map = nullptr;  // --map FILE.json, or null
  std::string retarget_map_name;
  InputFile retarget_map_input;  // the map file as read: its hash is in canonical()
  /// Canonical text of the options that change output bytes, recorded in provenance.
  std::string canonical() const;

  // How to run, not what to make (not in canonical(), not in the key):
  /// The read sandbox (input_log.h): a cook reads only inside `root` (--root) or, without one, the
  /// input's own folder tree, and inside each of `allow_dirs` (--allow-dir).
  std::filesystem::path root;
  std::vector<std::filesystem::path> allow_dirs;
  /// --allow-hard-links: read regular files that have other links (refused by default: a hard
  /// link is another name for bytes that may lie outside the allowed folders).
  bool allow_hard_links = false;
  bool force = false;  // --force: cook even when the output is up to date (and do not look in the cache)
  /// --cache: the shared cook cache to look outputs up in and store them into; null: none. Not
  /// const: the batch marks it down when a worker finds it unreachable.
  CookCache* cache = nullptr;
  /// The batch looked this input up in the cache already (a miss): the worker only stores.
  bool cache_looked_up = false;
  bool write = true;  // false (--list-inputs): cook in memory, write nothing
};

}  // namespace ossa::cook
