// cook_record.h — what one cook reports: counts, sizes, errors, warnings, per-clip / per-morph /
// per-texture / per-retargeted-clip records, the inputs it read and its cook key.
//
// Part of the cooker's model: every stage adds what it learns (cook.cpp fills the counts as each
// stage finishes), the worker sends the record to the batch over a pipe (cli/worker.cpp), and the
// batch writes it into the --report document (cli/batch.cpp, docs/JSON.md). The fields are listed
// once, in the *_fields functions below, and every one of those readers and writers (and the tests)
// goes through that list: a field added to a record and to its list crosses the pipe, reaches the
// report and is compared by the round-trip test without another edit. The lists are in the order
// the report prints them.
#pragma once
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <type_traits>
#include <vector>

#include "cooker/model/input_log.h"

namespace ossa::cook {

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
  uint32_t vertices = 0;           // listed (stored) vertices
  uint32_t raw_bytes = 0;          // dense float deltas over the mesh's vertices
  uint32_t stored_bytes = 0;       // the sparse form in the file
  float position_error_mm = 0.0f;  // millimetres (via metres_per_unit)
  float position_bound_mm = 0.0f;  // what that error is held to: 0.02 mm or 2e-5 of the mesh's size
  float normal_error_deg = 0.0f;
};

/// One distinct texture as cooked (a source image used twice for one role is cooked once).
struct TextureRecord {
  std::string name;      // the image's file name, or the embedded image's name
  std::string role;      // "diffuse", "normal", "specular"
  std::string encoding;  // "BC1", "BC3", "BC4", "BC5", "RGBA8", "source"
  bool srgb = false;
  uint32_t width = 0, height = 0, mips = 0;
  uint64_t source_bytes = 0;     // the encoded image as the source had it
  uint64_t cooked_bytes = 0;     // what the file stores for it
  uint64_t gpu_rgba8_bytes = 0;  // RGBA8 + a full mip chain: what decoding the source puts on a GPU
  float psnr_db = 0.0f;          // level 0 against the source, over the channels kept (99: exact)
  float normal_mean_deg = 0.0f, normal_max_deg = 0.0f;  // normal maps: angle to the source's normals
};

/// One contact of a retargeted clip.
struct RetargetContactRecord {
  uint32_t foot = 0;               // 0 left, 1 right
  float start = 0.0f, end = 0.0f;  // seconds
  float held_mm = 0.0f;            // the target ankle's largest distance from where the contact holds it
  float slide_mm = 0.0f;           // the target ankle's largest distance from its mean (how far it slides)
  float source_slide_mm = 0.0f;    // the source ankle's largest distance from its mean (its own slide)
};

/// What a retarget achieved on one clip (--report "retarget"; docs/RETARGET.md).
struct RetargetRecord {
  std::string clip;
  float hips_ratio = 0.0f;  // target hips height / source's, both in metres over the ankles
  float floor_mm = 0.0f;    // the source clip's floor above its rest pose's (0: none)
  uint32_t frames = 0;
  float limb_max_deg = 0.0f;     // upper arm, forearm, thigh, shin: largest angle to the source's,
                                 // over the limbs the mid-plane guard left alone
  float guard_max_deg = 0.0f;    // the same over the limbs it swung back (what keeping them on their side cost)
  float hand_max_deg = 0.0f;     // hands' outward axis, either hand
  float foot_max_deg = 0.0f;     // feet's forward axis, either foot
  uint32_t crossing_frames = 0;  // frames with a hand or foot across the mid-plane where the source's is not
  uint32_t guarded_frames = 0;   // frames where the mid-plane guard swung a limb back
  std::vector<RetargetContactRecord> contacts;
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
  std::string error;  // when !ok: "<input>: what is wrong"
  std::vector<std::string> warnings;
  // Known after import: joints (of the imported rig; when ok, of the file's skeleton: 0 for a
  // clip-only file cooked against --skeleton), clips, materials, textures, vertices over 4 influences.
  std::optional<uint32_t> joints, clips, materials, textures, vertices_over_4_influences;
  // Known once meshes are built.
  std::optional<uint32_t> meshes, submeshes, vertices, triangles;
  uint64_t source_bytes = 0;  // every file read: the source, its sidecar, a graph's sources
  uint64_t cooked_bytes = 0;  // the written file (ok only)
  double seconds = 0.0;
  std::vector<ClipRecord> clip_records;          // one per clip compressed before any failure
  std::vector<MorphRecord> morph_records;        // one per morph target, once meshes are built
  std::vector<TextureRecord> texture_records;    // one per distinct embedded texture, once textures are cooked
  std::vector<RetargetRecord> retarget_records;  // --retarget-to: one per clip retargeted
  /// Every file the cook read or looked for (absolute paths, sorted), as far as it got; for an
  /// up-to-date output, the inputs its provenance lists. The depfile and --list-inputs print these.
  std::vector<InputFile> inputs_read;
  uint64_t cook_key = 0;    // of the written (or up-to-date) output
  bool up_to_date = false;  // ok without cooking: the output's cook key matched (nothing written)
  // The shared cook cache (cooker/cache/cook_cache.h), when the batch has one:
  bool cache_hit = false;            // ok without cooking: the output came from the cache, verified
  std::string cache_note;            // the first trouble the cache gave this input (a miss, never a failure)
  bool cache_down = false;           // that trouble was the cache being unreachable: the batch stops asking
  uint64_t cache_bytes_fetched = 0;  // manifest and output bytes read from the cache
  uint64_t cache_bytes_stored = 0;   // manifest and output bytes written to it
};

// The field lists. Each calls f(key, r.member...) once per field, in report order, for one record
// or several of the same type side by side (a comparison visits two): f("frames", a.frames, b.frames).
// Keys are the worker's wire names and the report's, except where the report renames (batch.cpp).

template <class F, class... R>
constexpr void clip_record_fields(F&& f, R&... r) {
  f("name", r.name...);
  f("joints", r.joints...);
  f("frames", r.frames...);
  f("raw_bytes", r.raw_bytes...);
  f("cooked_bytes", r.cooked_bytes...);
  f("max_error_mm", r.max_error_mm...);
  f("mean_error_mm", r.mean_error_mm...);
  f("worst_joint", r.worst_joint...);
}

template <class F, class... R>
constexpr void texture_record_fields(F&& f, R&... r) {
  f("name", r.name...);
  f("role", r.role...);
  f("encoding", r.encoding...);
  f("srgb", r.srgb...);
  f("width", r.width...);
  f("height", r.height...);
  f("mips", r.mips...);
  f("source_bytes", r.source_bytes...);
  f("cooked_bytes", r.cooked_bytes...);
  f("gpu_rgba8_bytes", r.gpu_rgba8_bytes...);
  f("psnr_db", r.psnr_db...);
  f("normal_mean_deg", r.normal_mean_deg...);
  f("normal_max_deg", r.normal_max_deg...);
}

template <class F, class... R>
constexpr void morph_record_fields(F&& f, R&... r) {
  f("mesh", r.mesh...);
  f("name", r.name...);
  f("vertices", r.vertices...);
  f("raw_bytes", r.raw_bytes...);
  f("stored_bytes", r.stored_bytes...);
  f("position_error_mm", r.position_error_mm...);
  f("position_bound_mm", r.position_bound_mm...);
  f("normal_error_deg", r.normal_error_deg...);
}

template <class F, class... R>
constexpr void retarget_contact_record_fields(F&& f, R&... r) {
  f("foot", r.foot...);
  f("start", r.start...);
  f("end", r.end...);
  f("held_mm", r.held_mm...);
  f("slide_mm", r.slide_mm...);
  f("source_slide_mm", r.source_slide_mm...);
}

template <class F, class... R>
constexpr void retarget_record_fields(F&& f, R&... r) {
  f("clip", r.clip...);
  f("frames", r.frames...);
  f("hips_ratio", r.hips_ratio...);
  f("floor_mm", r.floor_mm...);
  f("limb_max_deg", r.limb_max_deg...);
  f("guard_max_deg", r.guard_max_deg...);
  f("hand_max_deg", r.hand_max_deg...);
  f("foot_max_deg", r.foot_max_deg...);
  f("crossing_frames", r.crossing_frames...);
  f("guarded_frames", r.guarded_frames...);
  f("contacts", r.contacts...);
}

template <class F, class... R>
constexpr void input_file_fields(F&& f, R&... r) {
  f("path", r.path...);
  f("hash", r.hash...);
  f("size", r.size...);
  f("present", r.present...);
}

/// CookRecord's fields; the vectors of records hold ClipRecord, TextureRecord, MorphRecord and
/// InputFile, whose own lists are above.
template <class F, class... R>
constexpr void cook_record_fields(F&& f, R&... r) {
  f("input", r.input...);
  f("ok", r.ok...);
  f("output", r.output...);
  f("error", r.error...);
  f("joints", r.joints...);
  f("meshes", r.meshes...);
  f("submeshes", r.submeshes...);
  f("vertices", r.vertices...);
  f("triangles", r.triangles...);
  f("clips", r.clips...);
  f("materials", r.materials...);
  f("textures", r.textures...);
  f("vertices_over_4_influences", r.vertices_over_4_influences...);
  f("clip_records", r.clip_records...);
  f("texture_records", r.texture_records...);
  f("morph_records", r.morph_records...);
  f("retarget_records", r.retarget_records...);
  f("source_bytes", r.source_bytes...);
  f("cooked_bytes", r.cooked_bytes...);
  f("up_to_date", r.up_to_date...);
  f("cook_key", r.cook_key...);
  f("cache_hit", r.cache_hit...);
  f("cache_note", r.cache_note...);
  f("cache_down", r.cache_down...);
  f("cache_bytes_fetched", r.cache_bytes_fetched...);
  f("cache_bytes_stored", r.cache_bytes_stored...);
  f("inputs_read", r.inputs_read...);
  f("seconds", r.seconds...);
  f("warnings", r.warnings...);
}

/// Calls the field list of `Record`'s type (one of the seven above).
template <class F, class Record, class... More>
constexpr void record_fields(F&& f, Record& r, More&... more) {
  using T = std::remove_const_t<Record>;
  if constexpr (std::is_same_v<T, ClipRecord>) clip_record_fields(f, r, more...);
  else if constexpr (std::is_same_v<T, TextureRecord>) texture_record_fields(f, r, more...);
  else if constexpr (std::is_same_v<T, MorphRecord>) morph_record_fields(f, r, more...);
  else if constexpr (std::is_same_v<T, RetargetRecord>) retarget_record_fields(f, r, more...);
  else if constexpr (std::is_same_v<T, RetargetContactRecord>) retarget_contact_record_fields(f, r, more...);
  else if constexpr (std::is_same_v<T, InputFile>) input_file_fields(f, r, more...);
  else {
    static_assert(std::is_same_v<T, CookRecord>, "not a record with a field list");
    cook_record_fields(f, r, more...);
  }
}

namespace record_check {

/// Converts to any member type: T{AnyField{}, ...} compiles for up to as many initializers as the
/// aggregate T has members, which counts them without naming them.
struct AnyField {
  template <class T>
  operator T() const;
};

template <class T, class... A>
constexpr size_t member_count() {
  if constexpr (requires { T{A{}..., AnyField{}}; }) return member_count<T, A..., AnyField>();
  else return sizeof...(A);
}

template <class T>
constexpr size_t listed_count() {
  size_t n = 0;
  const auto count = [&n](const char*) { ++n; };
  if constexpr (std::is_same_v<T, ClipRecord>) clip_record_fields(count);
  else if constexpr (std::is_same_v<T, TextureRecord>) texture_record_fields(count);
  else if constexpr (std::is_same_v<T, MorphRecord>) morph_record_fields(count);
  else if constexpr (std::is_same_v<T, RetargetRecord>) retarget_record_fields(count);
  else if constexpr (std::is_same_v<T, RetargetContactRecord>) retarget_contact_record_fields(count);
  else if constexpr (std::is_same_v<T, InputFile>) input_file_fields(count);
  else cook_record_fields(count);
  return n;
}

}  // namespace record_check

// A member added to a record and not to its list would silently stay out of the wire, the report
// and the round-trip test: refuse to compile instead.
static_assert(record_check::member_count<ClipRecord>() == record_check::listed_count<ClipRecord>(),
              "ClipRecord: add the new member to clip_record_fields");
static_assert(record_check::member_count<TextureRecord>() == record_check::listed_count<TextureRecord>(),
              "TextureRecord: add the new member to texture_record_fields");
static_assert(record_check::member_count<MorphRecord>() == record_check::listed_count<MorphRecord>(),
              "MorphRecord: add the new member to morph_record_fields");
static_assert(record_check::member_count<RetargetRecord>() == record_check::listed_count<RetargetRecord>(),
              "RetargetRecord: add the new member to retarget_record_fields");
static_assert(record_check::member_count<RetargetContactRecord>() ==
                  record_check::listed_count<RetargetContactRecord>(),
              "RetargetContactRecord: add the new member to retarget_contact_record_fields");
static_assert(record_check::member_count<InputFile>() == record_check::listed_count<InputFile>(),
              "InputFile: add the new member to input_file_fields");
static_assert(record_check::member_count<CookRecord>() == record_check::listed_count<CookRecord>(),
              "CookRecord: add the new member to cook_record_fields");

}  // namespace ossa::cook
