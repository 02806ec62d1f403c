// asset.cpp — Asset (mmap or aligned copy, then verify) and the typed views over it (asset.h).
//
// Loading order is cheapest-rejection first: size, alignment and identifier cost nothing and give
// the clearest messages for the common mistakes (wrong file, truncated file); the FlatBuffers
// verifier then proves every offset lies inside the buffer, and only then may validate_file and
// the views dereference anything. The views are thin: each accessor is a pointer cast or a span
// over a vector's bytes, because validation already proved what they could otherwise check.
//
// The operating system is reached only through internal/platform_file.h (POSIX or Win32, picked by
// CMake), so this file holds every decision and no system call. A mapped file that another process
// truncates while it is mapped faults on access; like every mmap-based loader we accept that by
// default (cooked assets are not rewritten in place: the cooker writes a new file and renames it),
// and OpenMode::kRead is there for callers who cannot promise it. Heap copies come from the
// installable Allocator (allocator.h).
//
// Cost: open is O(file size) (the verifier visits every table; the semantic checks scan indices
// and joint slots); from_bytes adds one copy; borrow is the checks alone; every view accessor is O(1) except find_joint
// (O(joints)) and ClipView::key_count (O(channels)).
#include <ossa/loader/asset.h>

#include <cassert>
#include <cstring>
#include <utility>

#include <ossa/version.h>
#include "internal/memory.h"
#include "common/message.h"
#include "internal/platform_file.h"
#include <ossa/loader/validate.h>

namespace ossa {
namespace {

constexpr size_t kAlignment = 16;
// A FlatBuffer with an identifier is at least a root offset and the identifier.
constexpr size_t kMinSize = 8;

template <class V>
size_t count_of(const V* v) {
  return v ? v->size() : 0;
}

/// Span over a vector of FlatBuffers structs. The structs are laid out exactly as the generated
/// C++ types (that is what FlatBuffers structs are), so the vector's bytes are an array of them.
template <class T>
std::span<const T> struct_span(const flatbuffers::Vector<const T*>* v) {
  if (!v) return {};
  return {reinterpret_cast<const T*>(v->Data()), v->size()};
}

template <class T>
std::span<const T> scalar_span(const flatbuffers::Vector<T>* v) {
  if (!v) return {};
  return {v->data(), v->size()};
}

Error error(std::string_view name, const std::string& what) { return Error{std::string(name) + ": " + what}; }

}  // namespace

// ---- verification ------------------------------------------------------------------------------

Status verify_buffer(std::span<const uint8_t> bytes, std::string_view name) {
  if (bytes.size() < kMinSize)
    return error(name, detail::format("too small to be an .ossa file (%zu bytes)", bytes.size()));
  // FlatBuffers offsets are 32-bit signed: the verifier requires size < 2^31 - 1.
  if (bytes.size() >= FLATBUFFERS_MAX_BUFFER_SIZE)
    return error(name, detail::format("too large for a FlatBuffer (%zu bytes, the limit is 2 GiB)", bytes.size()));
  if (reinterpret_cast<uintptr_t>(bytes.data()) % kAlignment != 0)
    return error(name, "buffer is not 16-byte aligned in memory (copy it, or use Asset::from_bytes)");
  if (!fb::FileBufferHasIdentifier(bytes.data())) {
    const std::string_view id(reinterpret_cast<const char*>(bytes.data()) + 4, 4);
    return error(name, "not an .ossa file (identifier '" + detail::printable(id) + "')");
  }

  flatbuffers::Verifier::Options options;
  options.check_alignment = true;
  // Every table costs at least 8 bytes (its vtable offset and the offset that reaches it), so
  // size / 8 admits any real file, while still bounding the work on tables shared many times.
  const size_t table_limit = bytes.size() / 8;
  if (table_limit > options.max_tables) options.max_tables = static_cast<flatbuffers::uoffset_t>(table_limit);
  flatbuffers::Verifier verifier(bytes.data(), bytes.size(), options);
  if (!fb::VerifyFileBuffer(verifier))
    return error(name,
                 "corrupt: the FlatBuffers verifier rejected it (an offset, size or alignment is "
                 "outside the buffer, or a required field is missing)");

  const fb::File* file = fb::GetFile(bytes.data());
  if (file->version() != kFormatVersion)
    return error(name, detail::format("format version %u, this build reads %u (re-cook the asset)", file->version(),
                                      kFormatVersion));
  return validate_file(*file, name, bytes.size());
}

Status check_clip_binding(const ClipView& clip, const SkeletonView& skeleton, std::string_view name) {
  const std::string label = "clip '" + detail::printable(clip.name()) + "'";
  if (skeleton.empty()) return error(name, label + " needs a skeleton to play on, and none was given");
  if (clip.skeleton_hash() != skeleton.hash())
    return error(name, detail::format("%s was cooked for skeleton %016llx, not this one (%016llx)", label.c_str(),
                                      static_cast<unsigned long long>(clip.skeleton_hash()),
                                      static_cast<unsigned long long>(skeleton.hash())));
  // Equal hashes mean equal rigs for honest files; a crafted clip could still claim more joints
  // than the rig has, and its channel joints are only checked against its own joint count.
  if (clip.fb->joint_count() != skeleton.joint_count())
    return error(name, detail::format("%s addresses %u joints, the skeleton has %zu", label.c_str(),
                                      static_cast<unsigned>(clip.fb->joint_count()), skeleton.joint_count()));
  return {};
}

// ---- Asset -------------------------------------------------------------------------------------

/// Files up to this size are read rather than memory-mapped (see Asset::open).
// Measured with OpenMode forced each way on the 2-core AMD EPYC VM (median of 2,000 opens):
// CesiumMan 311 KB 130 us mapped / 24 us read, Smooth_Male_Casual 418 KB 110 / 37 us, Eagle
// 1.15 MB 459 / 76 us, AnimeBoy 2.1 MB (mostly textures verification never touches) 127 / 111 us.
// Mapping costs the page-table set-up, a fault per touched page and the unmap's TLB flush; past
// a few MB of mostly untouched bytes (textures) it wins.
constexpr uint64_t kReadBelow = 4 * 1024 * 1024;

Result<Asset> Asset::open(const std::string& path, OpenMode mode) {
  detail::PlatformFile file;
  std::string what;
  if (!file.open(path, &what)) return error(path, what);
  const uint64_t size = file.size();
  if (size == 0) return error(path, "empty file");
  if (size < kMinSize || size >= FLATBUFFERS_MAX_BUFFER_SIZE)
    return error(path, size < kMinSize ? detail::format("too small to be an .ossa file (%llu bytes)",
                                                        static_cast<unsigned long long>(size))
                                       : detail::format("too large for a FlatBuffer (%llu bytes, the limit is 2 GiB)",
                                                        static_cast<unsigned long long>(size)));
  const bool read = mode == OpenMode::kRead || (mode == OpenMode::kAuto && size <= kReadBelow);
  if (read) {
    // Files up to 4 MiB are read into aligned memory: one read() costs less than setting up a
    // mapping, faulting its pages in and unmapping it (figures above kReadBelow); for larger
    // files the mapping wins, since verification touches only the pages it reads.
    void* heap = detail::allocate(static_cast<size_t>(size), kAlignment);
    if (!heap)
      return error(path, detail::format("out of memory reading %llu bytes", static_cast<unsigned long long>(size)));
    if (!file.read_all(heap, static_cast<size_t>(size), &what)) {
      detail::deallocate(heap, static_cast<size_t>(size), kAlignment);
      return error(path, what);
    }
    file.close();
    return adopt(path, static_cast<const uint8_t*>(heap), static_cast<size_t>(size), heap, nullptr);
  }
  void* mapping = file.map(static_cast<size_t>(size), &what);
  file.close();  // the mapping keeps the file alive; the handle is no longer needed
  if (mapping == nullptr) return error(path, what);
  return adopt(path, static_cast<const uint8_t*>(mapping), static_cast<size_t>(size), nullptr, mapping);
}

Result<Asset> Asset::from_bytes(std::span<const uint8_t> bytes, std::string name) {
  // Reject what verify_buffer would reject before allocating for it.
  if (bytes.size() < kMinSize || bytes.size() >= FLATBUFFERS_MAX_BUFFER_SIZE) {
    if (Status s = verify_buffer(bytes, name); !s) return s.error();
  }
  void* heap = detail::allocate(bytes.size(), kAlignment);
  if (!heap) return error(name, detail::format("out of memory copying %zu bytes", bytes.size()));
  std::memcpy(heap, bytes.data(), bytes.size());
  return adopt(std::move(name), static_cast<const uint8_t*>(heap), bytes.size(), heap, nullptr);
}

Result<Asset> Asset::borrow(std::span<const uint8_t> bytes, std::string name) {
  if (reinterpret_cast<uintptr_t>(bytes.data()) % kAlignment != 0)
    return error(name,
                 "borrowed bytes are not 16-byte aligned in memory (align them, or copy them with "
                 "Asset::from_bytes)");
  return adopt(std::move(name), bytes.data(), bytes.size(), nullptr, nullptr);
}

Result<Asset> Asset::adopt(std::string name, const uint8_t* data, size_t size, void* heap, void* mapping) {
  const std::span<const uint8_t> bytes(data, size);
  if (Status s = verify_buffer(bytes, name); !s) {
    if (heap != nullptr) detail::deallocate(heap, size, kAlignment);
    if (mapping != nullptr) detail::unmap_file(mapping, size);
    return s.error();
  }
  Asset asset;
  asset.name_ = std::move(name);
  asset.data_ = bytes.data();
  asset.size_ = size;
  asset.heap_ = heap;
  asset.mapping_ = mapping;
  asset.file_ = fb::GetFile(bytes.data());
  return asset;
}

Asset::Asset(Asset&& other) noexcept
    : name_(std::move(other.name_)),
      data_(std::exchange(other.data_, nullptr)),
      size_(std::exchange(other.size_, 0)),
      mapping_(std::exchange(other.mapping_, nullptr)),
      heap_(std::exchange(other.heap_, nullptr)),
      file_(std::exchange(other.file_, nullptr)) {}

Asset& Asset::operator=(Asset&& other) noexcept {
  if (this != &other) {
    release();
    name_ = std::move(other.name_);
    data_ = std::exchange(other.data_, nullptr);
    size_ = std::exchange(other.size_, 0);
    mapping_ = std::exchange(other.mapping_, nullptr);
    heap_ = std::exchange(other.heap_, nullptr);
    file_ = std::exchange(other.file_, nullptr);
  }
  return *this;
}

Asset::~Asset() { release(); }

void Asset::release() {
  if (mapping_) detail::unmap_file(mapping_, size_);
  if (heap_) detail::deallocate(heap_, size_, kAlignment);
  data_ = nullptr;
  size_ = 0;
  mapping_ = nullptr;
  heap_ = nullptr;
  file_ = nullptr;
}

SkeletonView Asset::skeleton() const { return SkeletonView{file_ ? file_->skeleton() : nullptr}; }
size_t Asset::mesh_count() const { return file_ ? count_of(file_->meshes()) : 0; }
MeshView Asset::mesh(size_t i) const {
  assert(i < mesh_count());
  return MeshView{file_->meshes()->Get(static_cast<flatbuffers::uoffset_t>(i))};
}
size_t Asset::clip_count() const { return file_ ? count_of(file_->clips()) : 0; }
ClipView Asset::clip(size_t i) const {
  assert(i < clip_count());
  return ClipView{file_->clips()->Get(static_cast<flatbuffers::uoffset_t>(i))};
}
size_t Asset::material_count() const { return file_ ? count_of(file_->materials()) : 0; }
const fb::Material& Asset::material(size_t i) const {
  assert(i < material_count());
  return *file_->materials()->Get(static_cast<flatbuffers::uoffset_t>(i));
}

// ---- SkeletonView ------------------------------------------------------------------------------

size_t SkeletonView::joint_count() const { return fb ? fb->joint_names()->size() : 0; }

std::string_view SkeletonView::joint_name(size_t joint) const {
  if (joint >= joint_count()) return {};
  return flatbuffers::GetStringView(fb->joint_names()->Get(static_cast<flatbuffers::uoffset_t>(joint)));
}

std::span<const int16_t> SkeletonView::parents() const {
  return fb ? scalar_span(fb->parents()) : std::span<const int16_t>();
}
std::span<const fb::Vec3> SkeletonView::bind_translations() const {
  return fb ? struct_span(fb->bind_translations()) : std::span<const fb::Vec3>();
}
std::span<const fb::Quat> SkeletonView::bind_rotations() const {
  return fb ? struct_span(fb->bind_rotations()) : std::span<const fb::Quat>();
}
std::span<const fb::Vec3> SkeletonView::bind_scales() const {
  return fb ? struct_span(fb->bind_scales()) : std::span<const fb::Vec3>();
}
std::span<const fb::Mat4> SkeletonView::inverse_bind() const {
  return fb ? struct_span(fb->inverse_bind()) : std::span<const fb::Mat4>();
}
uint64_t SkeletonView::hash() const { return fb ? fb->hash() : 0; }

int SkeletonView::find_joint(std::string_view name) const {
  const size_t n = joint_count();
  for (size_t i = 0; i < n; ++i)
    if (flatbuffers::GetStringView(fb->joint_names()->Get(static_cast<flatbuffers::uoffset_t>(i))) == name)
      return static_cast<int>(i);
  return -1;
}

// ---- MeshView ----------------------------------------------------------------------------------

std::string_view MeshView::name() const { return flatbuffers::GetStringView(fb->name()); }
uint32_t MeshView::vertex_count() const { return fb->vertex_count(); }
uint32_t MeshView::vertex_stride() const { return fb->vertex_stride(); }
std::span<const fb::VertexAttribute> MeshView::layout() const { return struct_span(fb->layout()); }

const fb::VertexAttribute* MeshView::attribute(fb::VertexSemantic semantic) const {
  for (const fb::VertexAttribute& a : layout())
    if (a.semantic() == semantic) return &a;
  return nullptr;
}

std::span<const uint8_t> MeshView::vertex_bytes() const { return scalar_span(fb->vertices()); }
fb::IndexFormat MeshView::index_format() const { return fb->index_format(); }
uint32_t MeshView::index_count() const {
  const size_t index_size = fb->index_format() == fb::IndexFormat::Uint32 ? 4 : 2;
  return static_cast<uint32_t>(fb->indices()->size() / index_size);
}
std::span<const uint8_t> MeshView::index_bytes() const { return scalar_span(fb->indices()); }
std::span<const fb::Submesh> MeshView::submeshes() const { return struct_span(fb->submeshes()); }
std::span<const uint16_t> MeshView::joints() const { return scalar_span(fb->joints()); }
std::span<const fb::Mat4> MeshView::inverse_bind() const { return struct_span(fb->inverse_bind()); }
size_t MeshView::morph_target_count() const { return fb->morph_targets() ? fb->morph_targets()->size() : 0; }
const fb::MorphTarget& MeshView::morph_target(size_t i) const {
  return *fb->morph_targets()->Get(static_cast<flatbuffers::uoffset_t>(i));
}
int MeshView::find_morph_target(std::string_view name) const {
  for (size_t i = 0; i < morph_target_count(); ++i)
    if (flatbuffers::GetStringView(morph_target(i).name()) == name) return static_cast<int>(i);
  return -1;
}

// ---- ClipView ----------------------------------------------------------------------------------

std::string_view ClipView::name() const { return flatbuffers::GetStringView(fb->name()); }
float ClipView::duration() const { return fb->duration(); }
float ClipView::sample_rate() const { return fb->sample_rate(); }
uint32_t ClipView::frame_count() const { return fb->frame_count(); }
uint64_t ClipView::skeleton_hash() const { return fb->skeleton_hash(); }
uint32_t ClipView::joint_count() const { return fb->joint_count(); }
std::span<const fb::ConstantChannel> ClipView::constants() const { return struct_span(fb->constants()); }
std::span<const fb::AnimatedChannel> ClipView::animated() const { return struct_span(fb->animated()); }
std::span<const uint16_t> ClipView::key_frames() const { return scalar_span(fb->key_frames()); }
std::span<const uint8_t> ClipView::key_values() const { return scalar_span(fb->key_values()); }
const fb::ClipCompression* ClipView::compression() const { return fb->compression(); }
const fb::RootMotion* ClipView::root_motion() const { return fb->root_motion(); }
size_t ClipView::morph_track_count() const { return fb->morph_weights() ? fb->morph_weights()->size() : 0; }
const fb::MorphTrack& ClipView::morph_track(size_t i) const {
  return *fb->morph_weights()->Get(static_cast<flatbuffers::uoffset_t>(i));
}

size_t ClipView::key_count() const {
  size_t keys = constants().size();
  for (const fb::AnimatedChannel& a : animated()) keys += a.key_count();
  return keys;
}

}  // namespace ossa
