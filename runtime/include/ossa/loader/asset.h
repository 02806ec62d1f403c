// asset.h — opening a .ossa file: map it, verify it, then read it through typed views.
//
// Loading is the whole point of the format: Asset::open memory-maps the file read-only (files
// up to 4 MiB are read into aligned memory instead: one read() is cheaper than mapping, faulting
// in the pages verification touches and unmapping; OpenMode forces either), or Asset::borrow takes bytes the caller
// owns (an engine's own file system or pack file), checks the identifier, runs flatbuffers::Verifier over every byte
// the reader could touch, checks the format version, and then the semantic invariants FlatBuffers cannot see
// (validate.h). Only then is an Asset handed out, so every view below can read without further checks. No per-vertex or
// per-key work happens here: views are spans straight into the file's bytes, ready for glBufferData.
//
// Assumes a little-endian host (as FlatBuffers' in-place struct access does).
#pragma once
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>

#include <ossa/format/ossa_generated.h>
#include <ossa/format/result.h>

namespace ossa {

/// Read-only view of the rig. Joint i's parent is parents()[i] < i, or -1 for a root.
struct SkeletonView {
  const fb::Skeleton* fb = nullptr;  // null when the file has no skeleton

  bool empty() const { return fb == nullptr; }
  size_t joint_count() const;
  std::string_view joint_name(size_t joint) const;  // "" when joint >= joint_count()
  std::span<const int16_t> parents() const;
  std::span<const fb::Vec3> bind_translations() const;
  std::span<const fb::Quat> bind_rotations() const;
  std::span<const fb::Vec3> bind_scales() const;
  std::span<const fb::Mat4> inverse_bind() const;
  uint64_t hash() const;
  /// Index of the joint with this name, or -1. O(joints).
  int find_joint(std::string_view name) const;
};

/// Read-only view of one mesh: GPU-ready byte ranges and the layout that describes them.
struct MeshView {
  const fb::Mesh* fb = nullptr;

  std::string_view name() const;
  uint32_t vertex_count() const;
  uint32_t vertex_stride() const;
  std::span<const fb::VertexAttribute> layout() const;
  /// The attribute with this semantic, or null.
  const fb::VertexAttribute* attribute(fb::VertexSemantic semantic) const;
  std::span<const uint8_t> vertex_bytes() const;  // 16-byte aligned, vertex_count * stride bytes
  fb::IndexFormat index_format() const;
  uint32_t index_count() const;
  std::span<const uint8_t> index_bytes() const;  // 16-byte aligned
  std::span<const fb::Submesh> submeshes() const;
  std::span<const uint16_t> joints() const;        // skeleton joint of each mesh-local slot
  std::span<const fb::Mat4> inverse_bind() const;  // one per slot
  /// Morph targets (format v5; ossa/anim/morph.h applies them). Validated: listed vertices
  /// strictly increasing and < vertex_count(), three deltas per listed vertex, names unique.
  size_t morph_target_count() const;
  const fb::MorphTarget& morph_target(size_t i) const;
  /// Index of the target with this name, -1 if none. O(targets).
  int find_morph_target(std::string_view name) const;
};

/// Read-only view of one compressed clip (format v2, ossa.fbs "Clip"). Validation proved every
/// invariant the sampler relies on (sorted disjoint channels, key ranges inside key_frames and
/// key_values, frames strictly increasing from 0 to frame_count - 1), so these are plain reads.
struct ClipView {
  const fb::Clip* fb = nullptr;

  std::string_view name() const;
  float duration() const;
  float sample_rate() const;
  uint32_t frame_count() const;
  uint64_t skeleton_hash() const;
  uint32_t joint_count() const;
  /// Channels holding one value, sorted by (joint, channel); ossa::constant_value
  /// (<ossa/format/clip_codec.h>) decodes one.
  std::span<const fb::ConstantChannel> constants() const;
  /// Channels with keys, sorted by (joint, channel), disjoint from constants().
  std::span<const fb::AnimatedChannel> animated() const;
  /// Key frames of the animated channels that are not keyed at every frame (those store none);
  /// channel c owns [first_key, first_key + key_count). ossa::key_frame (<ossa/format/clip_codec.h>)
  /// gives any channel's key frame.
  std::span<const uint16_t> key_frames() const;
  /// Packed key values (ossa/format/clip_codec.h), followed by kKeyValuePadding zero bytes.
  std::span<const uint8_t> key_values() const;
  /// What the cooker measured, or null.
  const fb::ClipCompression* compression() const;
  /// Extracted root motion, or null.
  const fb::RootMotion* root_motion() const;
  /// Keys over all channels: each animated channel's key_count plus one per constant. O(channels).
  size_t key_count() const;
  /// Morph weight tracks (format v5), sorted by name; ossa/anim/morph.h samples them.
  size_t morph_track_count() const;
  const fb::MorphTrack& morph_track(size_t i) const;
};

/// How Asset::open gets a file's bytes into memory.
enum class OpenMode : uint8_t {
  /// Read files up to 4 MiB into memory, map larger ones (the fastest load for each size).
  kAuto,
  /// Always read into memory the Asset owns (the installed Allocator). Costs one O(size) read and
  /// the memory; in exchange the Asset never depends on the file again. Use it when another
  /// process may rewrite the file in place while the Asset lives.
  kRead,
  /// Always map read-only. Costs no copy and pages in only what is touched, but the mapping
  /// contract applies: the file must not be truncated or overwritten in place while the Asset
  /// lives. A mapped file truncated under it faults on access (SIGBUS on POSIX), and one overwritten
  /// in place changes bytes that were verified. Replacing it by writing a new file and renaming it
  /// over the old one (what ossa-cook does) is safe on POSIX; on Windows a mapped file cannot be
  /// replaced or deleted until the Asset is destroyed.
  kMap,
};

/// A verified .ossa file. Owns its bytes: a read-only memory map or a 16-byte aligned heap copy
/// (open, from_bytes), or borrows the caller's (borrow). Move-only; views stay valid while the Asset lives (a move does
/// not move the bytes, so views taken before a move stay valid too). A moved-from Asset is empty: no skeleton, no
/// meshes, clips or materials, and file() must not be called. mesh(i), clip(i) and material(i) need i < the matching
/// count.
class Asset {
 public:
  /// Read or map (OpenMode) + verify + validate. `path` is UTF-8 on every platform. Only regular
  /// files are accepted (no FIFOs, devices or directories). Errors name the path and what is
  /// wrong. O(file size) for the verifier, O(joints + meshes*joints + keys) for the semantic
  /// checks; the only per-vertex and per-index work is the index and joint-slot bounds checks
  /// (vectorized max-reductions). kRead adds the O(size) read; kMap adds page faults on first touch.
  static Result<Asset> open(const std::string& path, OpenMode mode = OpenMode::kAuto);
  /// Same checks over a 16-byte aligned heap copy of bytes (one allocation through the installed
  /// Allocator and one O(size) copy); `name` is used in messages.
  static Result<Asset> from_bytes(std::span<const uint8_t> bytes, std::string name = "<memory>");
  /// Same checks over the caller's bytes, without a copy: bytes().data() == bytes.data(). For
  /// engines that load files through their own file system or pack files. The bytes must be 16-byte
  /// aligned (an error otherwise: copy them with from_bytes instead), must outlive the Asset and
  /// must not change while it lives. Cost: the verification only, no allocation for the bytes.
  static Result<Asset> borrow(std::span<const uint8_t> bytes, std::string name = "<memory>");

  Asset(Asset&& other) noexcept;
  Asset& operator=(Asset&& other) noexcept;
  Asset(const Asset&) = delete;
  Asset& operator=(const Asset&) = delete;
  ~Asset();

  const std::string& name() const { return name_; }
  std::span<const uint8_t> bytes() const { return {data_, size_}; }
  const fb::File& file() const { return *file_; }

  SkeletonView skeleton() const;
  size_t mesh_count() const;
  MeshView mesh(size_t i) const;
  size_t clip_count() const;
  ClipView clip(size_t i) const;
  size_t material_count() const;
  const fb::Material& material(size_t i) const;

 private:
  Asset() = default;
  void release();
  /// Verifies bytes the Asset will own (an aligned heap block or a mapping, at most one non-null;
  /// both null: borrowed `data`) and wraps them, or frees them and returns the error.
  static Result<Asset> adopt(std::string name, const uint8_t* data, size_t size, void* heap, void* mapping);

  std::string name_;
  const uint8_t* data_ = nullptr;
  size_t size_ = 0;
  void* mapping_ = nullptr;  // mapping base when memory-mapped
  void* heap_ = nullptr;     // aligned heap copy (installed Allocator) when read or copied
  const fb::File* file_ = nullptr;
};

/// Checks a buffer in place without keeping it: identifier, FlatBuffers verification, version,
/// then validate_file (validate.h). The buffer must be 16-byte aligned for the verifier's alignment
/// checks to mean what they say. `name` prefixes every message.
Status verify_buffer(std::span<const uint8_t> bytes, std::string_view name);

/// A clip can be played on a skeleton when its skeleton_hash equals the skeleton's hash and its
/// joint count equals the skeleton's (a crafted clip could match the hash but claim more joints,
/// and its channel joints were only checked against its own count). Errors name the clip. O(1).
Status check_clip_binding(const ClipView& clip, const SkeletonView& skeleton, std::string_view name);

}  // namespace ossa
