// diff.h — comparing two cooks of one asset by what a player would see: the comparison as a
// library function that returns plain data, so tests call it directly and ossa-diff's command
// line (main.cpp) only parses options and prints (report.h).
//
// Why a result struct and not text: a regression test wants the figures (the worst joint, the
// millimetres) and a CI job wants a verdict; both come from the same DiffReport. Every figure is
// converted to millimetres (via each file's metres_per_unit), degrees or seconds here, once, so the
// text and JSON renderings never convert units. A Difference is recorded for every comparison
// that fails — a figure above the tolerance, a count or name that changed — and `same()` is true
// exactly when there is none. Figures that describe rather than judge (file sizes, the cooker's own
// compression report, provenance) are kept in the sections but never make a difference.
//
// Only the runtime and format are used (no Assimp, no cooker): clips are played with ossa::sample
// and measured with <ossa/anim/pose_error.h>, the measure the cooker's compression bounds.
#pragma once
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <ossa/format/result.h>
#include <ossa/loader/asset.h>

namespace ossa::diff {

/// Probe distance of the clip and bind-pose measure, in metres (the cooker's, cooker/clip/clip_compress.h).
inline constexpr double kProbeMetres = 0.1;
/// Morph weights (unitless, usually 0..1) differ when they differ by more than this.
inline constexpr double kMorphWeightTolerance = 1e-3;

struct Options {
  double tolerance_mm = 0.1;  // a joint, vertex or clip differs when its error exceeds this
  /// Skeletons for clip-only files (ossa-cook --skeleton): used for a side whose file has no
  /// skeleton of its own, or whose clips do not bind to it. Empty: none.
  std::string old_skeleton, new_skeleton;
};

/// One failed comparison. `value` is a figure (in `unit`) or, for a changed name or count, text.
struct Difference {
  std::string section;          // "file", "skeleton", "meshes", "clips", "materials", "graphs"
  std::string item;             // the joint, mesh, clip, material or graph; "" for the section as a whole
  std::string what;             // what differs: "bind pose", "topology", "joint error", "removed", ...
  std::optional<double> value;  // the figure, when there is one
  std::string text;             // the value as words when there is no figure ("'Hips' -> 'hips'")
  std::string unit;             // "mm", "deg", "s", "Hz", "count" or "" (no figure)
  std::optional<double> limit;  // the limit the figure exceeded, in `unit`
  std::string detail;           // where, and old -> new: "joint 'LeftHand' at 0.4417 s", "vertex 12"
};

struct FileFacts {
  std::string path;
  uint64_t bytes = 0;
  double metres_per_unit = 1.0;
  uint32_t format_version = 0;
  std::string source_name, cooker_version, options;  // provenance ("" when absent)
  uint64_t source_hash = 0;
};

struct JointBind {
  std::string name;             // the old name (renamed joints: see SkeletonSection::renamed)
  double translation_mm = 0.0;  // |local translation difference|
  double rotation_deg = 0.0;    // angle of the local rotation difference
  double scale_delta = 0.0;     // largest |local scale component difference| (unitless)
  double probe_mm = 0.0;        // the probe measure on the local transforms: what is judged
};

struct SkeletonSection {
  bool old_present = false, new_present = false;
  size_t old_joints = 0, new_joints = 0;
  uint64_t old_hash = 0, new_hash = 0;
  std::vector<std::string> added, removed;                   // by name
  std::vector<std::pair<std::string, std::string>> renamed;  // (old, new), same index and parent
  std::vector<std::string> reordered;                        // in both, at another index
  struct ParentChange {
    std::string joint, old_parent, new_parent;  // "" for a root
  };
  std::vector<ParentChange> parent_changed;
  std::vector<JointBind> bind;  // every joint in both (renames paired)
  double max_bind_mm = 0.0;     // largest JointBind::probe_mm
  std::string worst_joint;      // where it occurs ("" when none)
};

struct MeshShape {
  uint32_t vertex_count = 0, index_count = 0, submesh_count = 0, vertex_stride = 0;
  std::string layout;  // "Position Unorm16x4 @0, Normal Snorm16x2 @8, ..."
};

struct MeshItem {
  std::string name;
  MeshShape old_shape, new_shape;
  bool topology_same = false;                 // vertex, index and submesh counts, submesh ranges, index values
  bool index_data_same = false;               // index values (whatever their width)
  bool layout_same = false;                   // stride and every attribute's semantic, format and offset
  std::optional<double> max_displacement_mm;  // positions, vertex i to vertex i; none when skipped
  uint32_t worst_vertex = 0;
  std::string note;  // why displacement was skipped
};

struct MeshSection {
  size_t old_count = 0, new_count = 0;
  std::vector<std::string> added, removed;
  std::vector<MeshItem> items;  // meshes in both, matched by name
  double max_displacement_mm = 0.0;
};

struct ClipEventFact {
  std::string name;
  double time_s = 0.0;
};

struct ClipSide {
  double duration_s = 0.0, rate_hz = 0.0;
  uint32_t frame_count = 0;
  bool root_motion = false;
  std::vector<ClipEventFact> events;
  std::optional<double> cooker_max_error_mm;  // what the cooker measured against the source
};

struct ClipItem {
  std::string name;
  ClipSide old_side, new_side;
  bool sampled = false;  // false: not comparable (see note)
  size_t times = 0;      // sample times compared
  size_t joints_compared = 0, joints_skipped = 0;
  double max_error_mm = 0.0;            // over every compared joint at every time
  double max_error_at_frames_mm = 0.0;  // the same over the old clip's own frame times only
  std::string worst_joint;              // where max_error_mm occurs ("" when nothing compared)
  double worst_time_s = 0.0;
  std::optional<double> root_motion_mm;   // largest root-motion translation difference (both have it)
  std::optional<double> root_motion_deg;  // largest root-motion yaw difference
  bool events_same = true;
  size_t morph_tracks_compared = 0;     // weight tracks in both clips, paired by name
  double max_morph_weight_error = 0.0;  // largest |old - new| weight over those tracks and the times
  std::string note;
};

struct ClipSection {
  size_t old_count = 0, new_count = 0;
  std::vector<std::string> added, removed;
  std::vector<ClipItem> items;
  double max_error_mm = 0.0;
};

struct TextureFact {
  std::string role, path, mime;
  uint64_t bytes = 0, hash = 0;  // embedded bytes and their FNV-1a 64 (0 bytes: referenced by path)
  std::string encoding;          // "Source", "Bc1", ... (format v7)
  bool srgb = false;
  uint32_t width = 0, height = 0, mips = 0;
};

struct MaterialItem {
  std::string name;
  std::vector<std::string> changed;  // "diffuse", "shininess", "texture 0 (Diffuse) data", ...
  std::vector<TextureFact> old_textures, new_textures;
};

struct MaterialSection {
  size_t old_count = 0, new_count = 0;
  std::vector<std::string> added, removed;
  std::vector<MaterialItem> items;
};

struct GraphShape {
  size_t parameters = 0, clips = 0, nodes = 0, machines = 0, states = 0, transitions = 0;
};

struct GraphItem {
  std::string name;
  GraphShape old_shape, new_shape;
  std::vector<std::string> changed;  // "parameter 'speed'", "state machine 'locomotion'", ...
  bool same = true;                  // structural equality (ossa-inspect's graph description)
};

struct GraphSection {
  size_t old_count = 0, new_count = 0;
  std::vector<std::string> added, removed;
  std::vector<GraphItem> items;
};

struct DiffReport {
  FileFacts old_file, new_file;
  double tolerance_mm = 0.1;
  SkeletonSection skeleton;
  MeshSection meshes;
  ClipSection clips;
  MaterialSection materials;
  GraphSection graphs;
  std::vector<Difference> differences;
  std::vector<std::string> notes;  // what was skipped and why

  bool same() const { return differences.empty(); }
};

/// Opens both files (and the --skeleton files) with the runtime's verifying loader and compares
/// them. An error means the files cannot be compared: unreadable or invalid (the loader's message,
/// naming the file), or clip-only without a skeleton to play its clips on. Everything else,
/// a different rig included, is a difference in the report.
Result<DiffReport> diff_files(const std::string& old_path, const std::string& new_path, const Options& options);

/// The comparison of two opened assets. old_rig / new_rig (optional) are the skeleton files for
/// clip-only sides; paths are what the report names. Error only for clips with no skeleton to be
/// played on.
Result<DiffReport> diff_assets(const Asset& old_asset, const Asset& new_asset, const Options& options,
                               const Asset* old_rig = nullptr, const Asset* new_rig = nullptr);

}  // namespace ossa::diff
