// validate.cpp — the semantic checks of a verified .ossa file (see validate.h for the list).
//
// Shape: one Validator walks the file once, skeleton first (meshes and clips check against it),
// and stops at the first failure with a message that names the mesh/clip/joint/field at fault, so
// a user can find the problem in the source asset. Everything here runs on bytes an attacker may
// have written, after flatbuffers::Verifier has proven every offset and vector lies inside the
// buffer; so the checks may read any vector element, but never trust a count or index stored in
// the file to address anything else until it has been compared with the thing it addresses.
//
// Two costs matter:
// - Per-vertex/per-index work is the only thing that grows with mesh size, so it is done by plain
//   max-reductions over the index array and over the joint-slot bytes, which the compiler turns
//   into SIMD code and which allocate nothing. Only when a maximum is out of range does a second,
//   scalar pass look for the first offender to name it.
// - FlatBuffers tables form a DAG: a crafted file can point a thousand meshes at one mesh with a
//   million indices. The verifier bounds the number of tables (max_tables), but not how often the
//   same big vector is reached, so the checks keep a budget of vector bytes they may scan (a few
//   times the buffer size, which a file without shared vectors can never reach) and reject a file
//   that would need more. That keeps validation O(buffer size) on any input.
#include <ossa/loader/validate.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include <ossa/loader/cloth_source.h>
#include <ossa/format/clip_codec.h>
#include <ossa/format/hash.h>
#include <ossa/format/vertex_format.h>
#include <ossa/loader/texture.h>
#include "common/message.h"
#include "internal/vector_clones.h"

namespace ossa {
namespace {

using detail::format;

template <class V>
size_t count_of(const V* v) {
  return v ? v->size() : 0;
}


/// "mesh 2 'Body'", or "mesh 2" when unnamed.
std::string label(const char* kind, size_t index, const flatbuffers::String* name) {
  std::string out = format("%s %zu", kind, index);
  if (name && name->size() != 0) out += " '" + detail::printable(flatbuffers::GetStringView(name)) + "'";
  return out;
}

/// The part of a file a message is about ("mesh 0 'body': morph target 2 'smile'"), formatted only
/// when a message is made: a valid file pays for no label (they were ~8% of opening a small file).
struct Where {
  const Where* parent;
  const char* kind;
  size_t index;
  const flatbuffers::String* name;
  std::string text() const { return (parent ? parent->text() + ": " : std::string()) + label(kind, index, name); }
};

bool finite3(const fb::Vec3& v) { return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z()); }

/// Pose values (translations, scales) are bounded so that blending, layering and adding poses —
/// differences, weighted sums, ratios — stay finite: a finite but astronomically large value
/// (a flipped exponent bit) would overflow there. 1e7 source units is 100 km in centimetres.
constexpr float kMaxPoseValue = 1e7f;
bool bounded(float v) { return std::isfinite(v) && std::fabs(v) <= kMaxPoseValue; }
bool bounded3(const fb::Vec3& v) { return bounded(v.x()) && bounded(v.y()) && bounded(v.z()); }

bool finite4(const fb::Quat& q) {
  return std::isfinite(q.x()) && std::isfinite(q.y()) && std::isfinite(q.z()) && std::isfinite(q.w());
}

/// A rotation the sampler can normalize: finite, and a squared norm that neither underflows to
/// zero nor overflows to infinity in float, which is where normalize() would produce NaN or 0.
bool normalizable(const fb::Quat& q) {
  if (!finite4(q)) return false;
  const float n2 = q.x() * q.x() + q.y() * q.y() + q.z() * q.z() + q.w() * q.w();
  return n2 >= std::numeric_limits<float>::min() && n2 <= std::numeric_limits<float>::max();
}

bool finite_matrix(const fb::Mat4& m) {
  const auto* a = m.m();
  for (flatbuffers::uoffset_t k = 0; k < 16; ++k)
    if (!std::isfinite(a->Get(k))) return false;
  return true;
}

/// Array forms of bounded() / std::isfinite / normalizable() for the fast path of a valid file:
/// no early exit, so the compiler vectorizes them; each gives exactly the per-value answer ANDed
/// over the array (|v| <= limit is false for NaN, and for infinity when limit is finite).
/// `values` may be unaligned FlatBuffers struct storage. O(n).
bool all_abs_at_most(const float* values, size_t n, float limit) {
  // On the bits: for a sign-cleared float (NaN and infinity included) the integer order is the
  // float order, NaN above infinity above every finite value; so |v| <= limit exactly when
  // limit_bits - (bits & 0x7fffffff) is non-negative as a signed 32-bit number. ORing those
  // differences keeps the sign bit of any that is not: subtract, and, or per float, which
  // SSE2 vectorizes (a float compare-and-branch per value ran ~4x slower).
  uint32_t limit_bits;
  std::memcpy(&limit_bits, &limit, 4);
  constexpr size_t kLanes = 8;
  uint32_t lanes[kLanes] = {};
  size_t i = 0;
  for (; i + kLanes <= n; i += kLanes)
    for (size_t k = 0; k < kLanes; ++k) {
      uint32_t b;
      std::memcpy(&b, values + i + k, 4);
      lanes[k] |= limit_bits - (b & 0x7fffffffu);
    }
  uint32_t acc = 0;
  for (size_t k = 0; k < kLanes; ++k) acc |= lanes[k];
  for (; i < n; ++i) {
    uint32_t b;
    std::memcpy(&b, values + i, 4);
    acc |= limit_bits - (b & 0x7fffffffu);
  }
  return (acc & 0x80000000u) == 0;
}
bool all_bounded(const float* values, size_t n) { return all_abs_at_most(values, n, kMaxPoseValue); }
bool all_finite(const float* values, size_t n) {
  return all_abs_at_most(values, n, std::numeric_limits<float>::max());
}
/// normalizable() over n quaternions stored as (x, y, z, w) floats. A NaN or infinite component
/// makes the squared norm NaN or infinite, so the range test alone is normalizable()'s answer.
bool all_normalizable(const float* q, size_t n) {
  bool bad = false;
  for (size_t i = 0; i < n; ++i, q += 4) {
    const float n2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
    bad |= !(n2 >= std::numeric_limits<float>::min() && n2 <= std::numeric_limits<float>::max());
  }
  return !bad;
}
static_assert(sizeof(fb::Vec3) == 12 && sizeof(fb::Quat) == 16 && sizeof(fb::Mat4) == 64,
              "the array checks read FlatBuffers structs as packed floats");

/// "1 joint", "3 joints".
std::string count_text(size_t n, const char* noun) { return format("%zu %s%s", n, noun, n == 1 ? "" : "s"); }

std::string vec3_text(const fb::Vec3& v) { return format("(%g, %g, %g)", v.x(), v.y(), v.z()); }

const char* semantic_name(fb::VertexSemantic s) {
  const char* n = fb::EnumNameVertexSemantic(s);
  return *n ? n : "unknown semantic";
}
const char* format_name(fb::VertexFormat f) {
  const char* n = fb::EnumNameVertexFormat(f);
  return *n ? n : "unknown format";
}

// ---- the O(n) loops -------------------------------------------------------------------------
//
// Written as fixed-width blocks so that GCC's -O2 "very cheap" vectorizer (which refuses loops
// needing a scalar epilogue) still vectorizes the block, and Clang at any level; the tail is at
// most one block of scalar work.

template <class T>
OSSA_INLINE T max_value(const T* values, size_t n) {
  constexpr size_t kLanes = 32;
  T lanes[kLanes] = {};
  size_t i = 0;
  for (; i + kLanes <= n; i += kLanes)
    for (size_t k = 0; k < kLanes; ++k) lanes[k] = values[i + k] > lanes[k] ? values[i + k] : lanes[k];
  T m = 0;
  for (size_t k = 0; k < kLanes; ++k) m = lanes[k] > m ? lanes[k] : m;
  for (; i < n; ++i) m = values[i] > m ? values[i] : m;
  return m;
}

/// Largest index in an index buffer. `bytes` is 16-byte aligned (checked before) and holds n
/// indices of type T. Compiled for AVX2 and the baseline (internal/vector_clones.h): SSE2 has no
/// unsigned 16- or 32-bit max, so the baseline emulates it in three operations per vector, where
/// AVX2's vpmaxuw / vpmaxud take one for twice the lanes; the scan was ~10% of opening a small
/// file.
OSSA_INLINE static void max_index_u16_body(const uint8_t* bytes, size_t n, uint32_t* out) {
  *out = max_value(reinterpret_cast<const uint16_t*>(bytes), n);
}
OSSA_INLINE static void max_index_u32_body(const uint8_t* bytes, size_t n, uint32_t* out) {
  *out = max_value(reinterpret_cast<const uint32_t*>(bytes), n);
}
OSSA_VECTOR_DISPATCH(max_index_u16, (const uint8_t* bytes, size_t n, uint32_t* out), (bytes, n, out))
OSSA_VECTOR_DISPATCH(max_index_u32, (const uint8_t* bytes, size_t n, uint32_t* out), (bytes, n, out))

template <class T>
uint32_t max_index(const uint8_t* bytes, size_t n) {
  uint32_t m = 0;
  if constexpr (sizeof(T) == 2) max_index_u16(bytes, n, &m);
  else max_index_u32(bytes, n, &m);
  return m;
}

/// Largest joint slot over 4 components of n vertices: `first` points at vertex 0's Joints
/// attribute, vertices are `stride` bytes apart. T is uint8_t or uint16_t; memcpy keeps the read
/// defined whatever the attribute's alignment and compiles to one load.
template <class T>
uint32_t max_joint_slot(const uint8_t* first, size_t n, size_t stride) {
  T m[4] = {0, 0, 0, 0};
  for (size_t v = 0; v < n; ++v) {
    T s[4];
    std::memcpy(s, first + v * stride, sizeof s);
    for (int k = 0; k < 4; ++k) m[k] = s[k] > m[k] ? s[k] : m[k];
  }
  T r = m[0];
  for (int k = 1; k < 4; ++k) r = m[k] > r ? m[k] : r;
  return r;
}

/// Largest 8-bit joint slot of n vertices, scanning the vertex buffer as contiguous bytes: each
/// 64-byte chunk is ANDed with a mask that keeps only the Joints bytes (the mask repeats every
/// lcm(stride, 64) bytes) and folded into 64 byte-wise maxima. Loads are whole vectors instead of
/// one 4-byte load per vertex, so the scan runs at the cache's bandwidth: ~0.2 cycles a byte, where
/// the strided SWAR loop took ~1.6 cycles a 24-byte vertex (~6% of opening Pab's skeleton file).
/// Compiled for AVX2 and the baseline (SSE2 has the byte max). `masks` holds `period` bytes
/// (a multiple of 64); bytes past the last whole chunk are left to the caller. O(n * stride).
OSSA_INLINE static void max_masked_bytes_body(const uint8_t* bytes, size_t chunks, const uint8_t* masks,
                                              size_t period, uint32_t* out) {
  constexpr size_t kChunk = 64;
  uint8_t lanes[kChunk] = {};
  size_t m = 0;
  for (size_t c = 0; c < chunks; ++c, bytes += kChunk) {
    const uint8_t* mask = masks + m;
    for (size_t k = 0; k < kChunk; ++k) {
      const auto b = static_cast<uint8_t>(bytes[k] & mask[k]);
      lanes[k] = b > lanes[k] ? b : lanes[k];
    }
    m += kChunk;
    if (m == period) m = 0;
  }
  uint8_t r = 0;
  for (size_t k = 0; k < kChunk; ++k) r = lanes[k] > r ? lanes[k] : r;
  *out = r;
}
OSSA_VECTOR_DISPATCH(max_masked_bytes,
                     (const uint8_t* bytes, size_t chunks, const uint8_t* masks, size_t period, uint32_t* out),
                     (bytes, chunks, masks, period, out))

/// Largest 8-bit joint slot of n vertices whose Joints attribute sits `offset` bytes into each
/// `stride`-byte vertex of `vertices`: max_masked_bytes over the whole 64-byte chunks, the strided
/// loop over the vertices the last partial chunk touches. Strides whose mask period exceeds 4 KiB
/// (more than 256 bytes) take the strided loop throughout.
uint32_t max_u8_joint_slot(const uint8_t* vertices, size_t n, size_t stride, size_t offset) {
  constexpr size_t kChunk = 64, kMaxPeriod = 4096;
  size_t period = stride;
  while (period % kChunk != 0) period += stride;  // lcm(stride, 64): stride is a multiple of 4
  const size_t chunks = n * stride / kChunk;
  if (period > kMaxPeriod || chunks == 0) return max_joint_slot<uint8_t>(vertices + offset, n, stride);
  alignas(16) uint8_t masks[kMaxPeriod];
  std::memset(masks, 0, period);
  for (size_t at = offset; at < period; at += stride) std::memset(masks + at, 0xff, 4);
  uint32_t m = 0;
  max_masked_bytes(vertices, chunks, masks, period, &m);
  const size_t done = chunks * kChunk / stride;  // vertices wholly inside the scanned chunks
  const uint32_t rest = max_joint_slot<uint8_t>(vertices + done * stride + offset, n - done, stride);
  return rest > m ? rest : m;
}

template <class T>
size_t first_joint_slot_at_least(const uint8_t* first, size_t n, size_t stride, uint32_t limit,
                                 uint32_t* slot) {
  for (size_t v = 0; v < n; ++v) {
    T s[4];
    std::memcpy(s, first + v * stride, sizeof s);
    for (int k = 0; k < 4; ++k)
      if (s[k] >= limit) {
        *slot = s[k];
        return v;
      }
  }
  return n;
}

// ---------------------------------------------------------------------------------------------

class Validator {
 public:
  Validator(const fb::File& file, std::string_view name, size_t buffer_size)
      : file_(file), name_(name) {
    // Every vector element is scanned once in a file without shared vectors, and a few vectors
    // may legitimately be shared (one times vector for several channels); 4x leaves room for
    // that while bounding a crafted DAG. 0 = the caller gave no size: no bound.
    budget_ = buffer_size ? 4 * static_cast<uint64_t>(buffer_size) + 4096 : UINT64_MAX;
  }

  Status run() {
    if (!std::isfinite(file_.metres_per_unit()) || !(file_.metres_per_unit() > 0.0f))
      return fail("", format("metres_per_unit %g must be a finite number > 0", file_.metres_per_unit()));
    material_count_ = count_of(file_.materials());
    if (const fb::Skeleton* s = file_.skeleton()) {
      if (Status st = check_skeleton(*s); !st) return st;
    }
    if (const auto* meshes = file_.meshes()) {
      for (flatbuffers::uoffset_t i = 0; i < meshes->size(); ++i)
        if (Status st = check_mesh(*meshes->Get(i), i); !st) return st;
    }
    if (const auto* clips = file_.clips()) {
      for (flatbuffers::uoffset_t i = 0; i < clips->size(); ++i)
        if (Status st = check_clip(*clips->Get(i), i); !st) return st;
    }
    if (const auto* materials = file_.materials()) {
      for (flatbuffers::uoffset_t i = 0; i < materials->size(); ++i)
        if (Status st = check_material(*materials->Get(i), i); !st) return st;
    }
    if (const auto* graphs = file_.graphs()) {
      for (flatbuffers::uoffset_t i = 0; i < graphs->size(); ++i)
        if (Status st = validate_graph(*graphs->Get(i), i, name_, budget_); !st) return st;
    }
    return {};
  }

 private:
  Error fail(const std::string& where, const std::string& what) const {
    return Error{std::string(name_) + ": " + (where.empty() ? what : where + ": " + what)};
  }

  /// Charges `bytes` of scanning to the budget; false once it is spent.
  bool spend(uint64_t bytes) {
    if (bytes > budget_) return false;
    budget_ -= bytes;
    return true;
  }
  Error fail(const Where& where, const std::string& what) const { return fail(where.text(), what); }
  Error over_budget(const Where& where) const { return over_budget(where.text()); }
  Error over_budget(const std::string& where) const {
    return fail(where, "tables reference far more data than the file holds (vectors shared between "
                       "tables); refusing to scan it");
  }

  std::string joint_label(size_t joint) const {
    std::string out = format("joint %zu", joint);
    if (skeleton_ && joint < joint_count_) {
      const auto name = flatbuffers::GetStringView(skeleton_->joint_names()->Get(static_cast<flatbuffers::uoffset_t>(joint)));
      out += " '" + detail::printable(name) + "'";
    }
    return out;
  }

  // ---- skeleton ----

  Status check_skeleton(const fb::Skeleton& s) {
    const std::string where = "skeleton";
    const size_t n = s.joint_names()->size();
    const struct {
      const char* field;
      size_t size;
    } arrays[] = {{"parents", s.parents()->size()},
                  {"bind_translations", s.bind_translations()->size()},
                  {"bind_rotations", s.bind_rotations()->size()},
                  {"bind_scales", s.bind_scales()->size()},
                  {"inverse_bind", s.inverse_bind()->size()}};
    for (const auto& a : arrays)
      if (a.size != n) return fail(where, format("has %zu joint names but %zu %s", n, a.size, a.field));
    if (!spend(static_cast<uint64_t>(n) * (4 + 2 + 12 + 16 + 12 + 64))) return over_budget(where);

    const int16_t* parents = s.parents()->data();
    // The pose values are checked as whole arrays first (branch-free scans the compiler
    // vectorizes); only a file that fails one walks the joints again to name the culprit.
    const bool values_ok = all_bounded(reinterpret_cast<const float*>(s.bind_translations()->Data()), 3 * n) &&
                           all_bounded(reinterpret_cast<const float*>(s.bind_scales()->Data()), 3 * n) &&
                           all_finite(reinterpret_cast<const float*>(s.inverse_bind()->Data()), 16 * n) &&
                           all_normalizable(reinterpret_cast<const float*>(s.bind_rotations()->Data()), n);
    uint64_t hash_sum = 0;
    for (size_t i = 0; i < n; ++i) {
      const auto idx = static_cast<flatbuffers::uoffset_t>(i);
      const std::string_view name = flatbuffers::GetStringView(s.joint_names()->Get(idx));
      if (name.empty()) return fail(where, format("joint %zu has an empty name", i));
      const auto jl = [&] { return format("joint %zu '%s'", i, detail::printable(name).c_str()); };
      const int parent = parents[i];
      if (parent != -1 && (parent < 0 || static_cast<size_t>(parent) >= i)) {
        if (i == 0)
          return fail(where, jl() + format(" has parent %d, must be -1 (the first joint is a root)", parent));
        return fail(where, jl() + format(" has parent %d, must be -1 or < %zu (parents come first)", parent, i));
      }
      hash_sum += skeleton_hash_joint(i, name, parents[i]);
      if (values_ok) continue;
      if (!bounded3(*s.bind_translations()->Get(idx)))
        return fail(where, jl() + ": bind translation is not finite");
      if (!normalizable(*s.bind_rotations()->Get(idx)))
        return fail(where, jl() + ": bind rotation is not a finite, non-zero quaternion");
      if (!bounded3(*s.bind_scales()->Get(idx))) return fail(where, jl() + ": bind scale is not finite (or beyond 1e7)");
      if (!finite_matrix(*s.inverse_bind()->Get(idx)))
        return fail(where, jl() + ": inverse bind matrix is not finite");
    }
    const uint64_t computed = skeleton_hash_finish(hash_sum, n);
    if (computed != s.hash())
      return fail(where, format("stored hash %016llx does not match the joints' hash %016llx (names or "
                                "parents changed after cooking)",
                                static_cast<unsigned long long>(s.hash()),
                                static_cast<unsigned long long>(computed)));
    skeleton_ = &s;
    joint_count_ = n;
    return {};
  }

  // ---- meshes ----

  Status check_mesh(const fb::Mesh& m, size_t mesh_index) {
    const Where where{nullptr, "mesh", mesh_index, m.name()};
    const uint32_t vertex_count = m.vertex_count();
    const uint32_t stride = m.vertex_stride();

    // Layout.
    const auto* layout = m.layout();
    if (!spend(static_cast<uint64_t>(layout->size()) * sizeof(fb::VertexAttribute))) return over_budget(where);
    if (stride % 4 != 0) return fail(where, format("vertex stride %u is not a multiple of 4", stride));
    const fb::VertexAttribute* by_semantic[8] = {};
    for (flatbuffers::uoffset_t k = 0; k < layout->size(); ++k) {
      const fb::VertexAttribute& a = *layout->Get(k);
      const auto sem = static_cast<unsigned>(a.semantic());
      if (sem > static_cast<unsigned>(fb::VertexSemantic::MAX))
        return fail(where, format("layout attribute %u has unknown semantic %u", k, sem));
      const VertexFormatInfo info = vertex_format_info(a.format());
      // Labels are formatted only for a message: a valid file pays for none of them.
      const auto al = [&] { return format("layout attribute %u (%s)", k, semantic_name(a.semantic())); };
      if (info.size == 0)
        return fail(where, al() + format(" has unknown format %u", static_cast<unsigned>(a.format())));
      if (by_semantic[sem]) return fail(where, format("layout has two %s attributes", semantic_name(a.semantic())));
      by_semantic[sem] = &a;
      const auto fl = [&] { return al() + format(" %s @%u", format_name(a.format()), a.offset()); };
      if (static_cast<uint32_t>(a.offset()) + info.size > stride)
        return fail(where, fl() + format(" ends at byte %u, past the vertex stride %u",
                                         static_cast<unsigned>(a.offset() + info.size), stride));
      const unsigned component = info.size / info.components;
      if (a.offset() % component != 0)
        return fail(where, fl() + format(" is not aligned to its %u-byte components", component));
      // Formats a reader can interpret for this semantic: integer formats only for joint slots
      // (glVertexAttribIPointer), never for anything else; positions need x, y and z.
      const bool joints = a.semantic() == fb::VertexSemantic::Joints;
      if (joints != info.integer)
        return fail(where, fl() + (joints ? " must use an integer format (Uint8x4 or Uint16x4)"
                                          : " must not use an integer format"));
      if (a.semantic() == fb::VertexSemantic::Position && info.components < 3)
        return fail(where, fl() + " has fewer than 3 components");
    }
    const fb::VertexAttribute* joints_attr = by_semantic[static_cast<int>(fb::VertexSemantic::Joints)];
    const fb::VertexAttribute* weights_attr = by_semantic[static_cast<int>(fb::VertexSemantic::Weights)];
    if (vertex_count > 0 && !by_semantic[static_cast<int>(fb::VertexSemantic::Position)])
      return fail(where, format("has %u vertices but no Position attribute", vertex_count));

    // Vertex bytes.
    const auto* vertices = m.vertices();
    const uint64_t expected = static_cast<uint64_t>(vertex_count) * stride;
    if (vertices->size() != expected)
      return fail(where, format("vertex data is %u bytes, expected vertex_count %u * stride %u = %llu",
                                vertices->size(), vertex_count, stride,
                                static_cast<unsigned long long>(expected)));
    if (vertices->size() != 0 && reinterpret_cast<uintptr_t>(vertices->Data()) % 16 != 0)
      return fail(where, "vertex data is not 16-byte aligned");

    // Indices.
    const auto* indices = m.indices();
    size_t index_size = 0;
    switch (m.index_format()) {
      case fb::IndexFormat::Uint16: index_size = 2; break;
      case fb::IndexFormat::Uint32: index_size = 4; break;
    }
    if (index_size == 0)
      return fail(where, format("unknown index format %u", static_cast<unsigned>(m.index_format())));
    const char* index_format = fb::EnumNameIndexFormat(m.index_format());
    if (indices->size() % index_size != 0)
      return fail(where, format("index data is %u bytes, not a multiple of %zu (%s)", indices->size(), index_size,
                                index_format));
    const size_t index_count = indices->size() / index_size;
    if (index_count % 3 != 0)
      return fail(where, format("has %zu indices, not a multiple of 3 (triangle list)", index_count));
    if (index_count != 0) {
      if (reinterpret_cast<uintptr_t>(indices->Data()) % 16 != 0)
        return fail(where, "index data is not 16-byte aligned");
      if (!spend(indices->size())) return over_budget(where);
      const uint32_t max = index_size == 2 ? max_index<uint16_t>(indices->Data(), index_count)
                                           : max_index<uint32_t>(indices->Data(), index_count);
      if (max >= vertex_count) {
        for (size_t i = 0; i < index_count; ++i) {
          uint32_t v = 0;
          if (index_size == 2) {
            uint16_t v16;
            std::memcpy(&v16, indices->Data() + 2 * i, 2);
            v = v16;
          } else {
            std::memcpy(&v, indices->Data() + 4 * i, 4);
          }
          if (v >= vertex_count)
            return fail(where, format("index %zu is %u, past the vertex count %u", i, v, vertex_count));
        }
      }
    }

    // Submeshes.
    const auto* submeshes = m.submeshes();
    if (!spend(static_cast<uint64_t>(submeshes->size()) * sizeof(fb::Submesh))) return over_budget(where);
    const size_t material_limit = material_count_ > 0 ? material_count_ : 1;
    for (flatbuffers::uoffset_t k = 0; k < submeshes->size(); ++k) {
      const fb::Submesh& sm = *submeshes->Get(k);
      const uint64_t end = static_cast<uint64_t>(sm.first_index()) + sm.index_count();
      if (end > index_count)
        return fail(where, format("submesh %u covers indices [%u, %llu), past the index count %zu", k,
                                  sm.first_index(), static_cast<unsigned long long>(end), index_count));
      if (sm.index_count() % 3 != 0)
        return fail(where, format("submesh %u has %u indices, not a multiple of 3", k, sm.index_count()));
      if (sm.material() >= material_limit)
        return fail(where, material_count_ == 0
                               ? format("submesh %u uses material %u, but the file has no materials (only 0 "
                                        "is allowed)", k, sm.material())
                               : format("submesh %u uses material %u, the file has %s", k, sm.material(),
                                        count_text(material_count_, "material").c_str()));
    }

    // Joint slots.
    const size_t slot_count = count_of(m.joints());
    const size_t inverse_bind_count = count_of(m.inverse_bind());
    if (slot_count != inverse_bind_count)
      return fail(where, format("has %zu joint slots but %zu inverse bind matrices", slot_count, inverse_bind_count));
    if (!spend(static_cast<uint64_t>(slot_count) * (2 + 64))) return over_budget(where);
    if (slot_count > 0) {
      if (!skeleton_) return fail(where, format("has %zu joint slots but the file has no skeleton", slot_count));
      const bool matrices_ok = all_finite(reinterpret_cast<const float*>(m.inverse_bind()->Data()), 16 * slot_count);
      for (size_t k = 0; k < slot_count; ++k) {
        const auto idx = static_cast<flatbuffers::uoffset_t>(k);
        const uint16_t joint = m.joints()->Get(idx);
        if (joint >= joint_count_)
          return fail(where, format("joint slot %zu names joint %u, the skeleton has %s", k, joint,
                                    count_text(joint_count_, "joint").c_str()));
        if (!matrices_ok && !finite_matrix(*m.inverse_bind()->Get(idx)))
          return fail(where, format("joint slot %zu (", k) + joint_label(joint) + "): inverse bind matrix is not finite");
      }
    }
    if (weights_attr && !joints_attr) return fail(where, "has a Weights attribute but no Joints attribute");
    if (joints_attr) {
      if (!weights_attr) return fail(where, "has a Joints attribute but no Weights attribute");
      if (slot_count == 0) return fail(where, "has a Joints attribute but no joint slots");
      if (vertex_count > 0) {
        if (!spend(vertices->size())) return over_budget(where);
        const uint8_t* first = vertices->Data() + joints_attr->offset();
        const bool wide = joints_attr->format() == fb::VertexFormat::Uint16x4;
        const bool out_of_range =
            (wide ? max_joint_slot<uint16_t>(first, vertex_count, stride)
                  : max_u8_joint_slot(vertices->Data(), vertex_count, stride, joints_attr->offset())) >= slot_count;
        if (out_of_range) {
          uint32_t slot = 0;
          const auto limit = static_cast<uint32_t>(slot_count);
          const size_t v = wide ? first_joint_slot_at_least<uint16_t>(first, vertex_count, stride, limit, &slot)
                                : first_joint_slot_at_least<uint8_t>(first, vertex_count, stride, limit, &slot);
          return fail(where, format("vertex %zu uses joint slot %u, the mesh has %s", v, slot,
                                    count_text(slot_count, "slot").c_str()));
        }
      }
    }

    // Bounds and the position de-quantization.
    const struct {
      const char* field;
      const fb::Vec3* value;
    } vectors[] = {{"bounds_min", m.bounds_min()},
                   {"bounds_max", m.bounds_max()},
                   {"position_offset", m.position_offset()},
                   {"position_scale", m.position_scale()}};
    for (const auto& v : vectors)
      if (v.value && !finite3(*v.value)) return fail(where, format("%s is not finite", v.field));
    if (const fb::Cloth* cloth = m.cloth()) {  // format v9: ossa/anim/cloth.h's check_cloth
      const uint64_t bytes = 4 * (count_of(cloth->particle_vertices()) + count_of(cloth->inverse_masses()) +
                                  count_of(cloth->max_distances()) + count_of(cloth->backstops()) +
                                  count_of(cloth->vertices())) +
                             2 * (count_of(cloth->vertex_particles()) + count_of(cloth->triangles())) +
                             count_of(cloth->flipped()) +
                             8 * (count_of(cloth->stretch()) + count_of(cloth->bend()) + count_of(cloth->tethers())) +
                             32 * count_of(cloth->colliders());
      if (!spend(bytes)) return over_budget(where);
      if (Status st = check_cloth(cloth_source(MeshView{&m}), vertex_count, joint_count_); !st)
        return fail(where, st.message());
    }
    return check_morph_targets(m, where);
  }

  // ---- morph targets (format v5) ----
  //
  // apply_morphs (runtime/anim/morph.cpp) indexes the caller's vertex arrays by each listed vertex
  // and reads three deltas per listed vertex, so both are proven here: vertices strictly increasing
  // and below the vertex count, every delta array exactly three per listed vertex. Steps and
  // weights are bounded so that a sum of weighted deltas over any number of targets stays finite.

  /// Largest |weight| a file may store (defaults, weight keys): far past any authored face (glTF
  /// weights are usually in [0, 1], sometimes [-1, 1]), and small enough that weights * deltas stay
  /// finite.
  static constexpr float kMaxMorphWeight = 1e3f;
  /// Largest per-axis step: 32767 steps stay within the pose bound.
  static constexpr float kMaxMorphStep = kMaxPoseValue / 32767.0f;

  static bool step_ok(const fb::Vec3& s) {
    const float v[3] = {s.x(), s.y(), s.z()};
    for (float x : v)
      if (!std::isfinite(x) || x < 0.0f || x > kMaxMorphStep) return false;
    return true;
  }

  Status check_morph_targets(const fb::Mesh& m, const Where& mesh_where) {
    const auto* targets = m.morph_targets();
    if (!targets) return {};
    if (!spend(static_cast<uint64_t>(targets->size()) * 64)) return over_budget(mesh_where);
    std::vector<std::string_view> names;
    names.reserve(targets->size());
    for (flatbuffers::uoffset_t t = 0; t < targets->size(); ++t) {
      const fb::MorphTarget& target = *targets->Get(t);
      const std::string_view name = flatbuffers::GetStringView(target.name());
      const Where where{&mesh_where, "morph target", t, target.name()};
      if (name.empty()) return fail(where, "has an empty name");
      names.push_back(name);
      const size_t n = target.vertices()->size();
      if (!spend(static_cast<uint64_t>(n) * 4)) return over_budget(where);
      const uint32_t* v = target.vertices()->data();
      for (size_t i = 0; i < n; ++i) {
        if (v[i] >= m.vertex_count())
          return fail(where, format("moves vertex %u (entry %zu), past the vertex count %u", v[i], i, m.vertex_count()));
        if (i > 0 && !(v[i] > v[i - 1]))
          return fail(where, format("entry %zu names vertex %u after vertex %u: vertices must strictly increase", i,
                                    v[i], v[i - 1]));
      }
      const struct {
        const char* field;
        const flatbuffers::Vector<int16_t>* deltas;
        const fb::Vec3* step;
        bool required;
      } streams[] = {{"position", target.position_deltas(), target.position_step(), true},
                     {"normal", target.normal_deltas(), target.normal_step(), false},
                     {"tangent", target.tangent_deltas(), target.tangent_step(), false}};
      for (const auto& st : streams) {
        const size_t count = count_of(st.deltas);
        if (count == 0 && !st.required) continue;
        if (count != 3 * n)
          return fail(where, format("has %zu %s deltas for %zu listed vertices; expected 3 per vertex (%zu)", count,
                                    st.field, n, 3 * n));
        if (!st.step || !step_ok(*st.step))
          return fail(where, format("%s step %s must be finite, >= 0 and at most %g", st.field,
                                    st.step ? vec3_text(*st.step).c_str() : "(missing)", kMaxMorphStep));
      }
      if (!std::isfinite(target.default_weight()) || std::fabs(target.default_weight()) > kMaxMorphWeight)
        return fail(where, format("default weight %g must be finite and within +-%g", target.default_weight(),
                                  kMaxMorphWeight));
      if (!(target.position_error() >= 0.0f) || !std::isfinite(target.position_error()) ||
          !(target.normal_error() >= 0.0f) || !std::isfinite(target.normal_error()))
        return fail(where, format("recorded errors %g / %g must be finite and >= 0", target.position_error(),
                                  target.normal_error()));
    }
    std::sort(names.begin(), names.end());
    for (size_t i = 1; i < names.size(); ++i)
      if (names[i] == names[i - 1])
        return fail(mesh_where, "has two morph targets named '" + detail::printable(names[i]) + "'");
    return {};
  }

  // ---- clips ----
  //
  // Everything the sampler (runtime/anim/sample.cpp) and root_motion.cpp dereference is proven here,
  // before any of them runs: channel joints < joint_count, each animated channel's key range
  // inside key_frames and its bit range inside key_values minus the 8 padding bytes the decoder's
  // 64-bit reads may touch, frames strictly increasing from 0 to frame_count - 1 (so a cursor or a
  // binary search always finds a bracketing pair), ranges finite (so decoded values are), raw-float
  // keys finite, rotations bounded (so normalizing never divides by zero or infinity).

  /// "animated channel 3 (joint 5 'Hips' rotation)".
  std::string channel_label(const char* kind, size_t index, size_t joint, unsigned channel, bool binds_here) const {
    const char* cn = channel <= static_cast<unsigned>(fb::Channel::MAX)
                         ? fb::EnumNameChannel(static_cast<fb::Channel>(channel))
                         : "unknown channel";
    return format("%s channel %zu (", kind, index) + (binds_here ? joint_label(joint) : format("joint %zu", joint)) +
           " " + cn + ")";
  }

  /// Sort key of a (joint, channel) pair.
  static uint32_t channel_key(uint16_t joint, fb::Channel channel) {
    return (static_cast<uint32_t>(joint) << 8) | static_cast<uint8_t>(channel);
  }

  /// A rotation component bound: xyz of a unit quaternion lie in [-1, 1]; the slack admits a
  /// cooker's rounding. Bounding them keeps the squared norm far from overflow when normalizing.
  static constexpr float kRotationComponentLimit = 1.01f;

  Status check_clip(const fb::Clip& c, size_t clip_index) {
    const Where where{nullptr, "clip", clip_index, c.name()};
    const float rate = c.sample_rate();
    if (!std::isfinite(rate) || !(rate > 0.0f))
      return fail(where, format("sample rate %g must be a finite number > 0", rate));
    const uint32_t frame_count = c.frame_count();
    if (frame_count < 1 || frame_count > 65536)
      return fail(where, format("frame count %u must be in 1..65536 (frames are 16-bit)", frame_count));
    const float duration = c.duration();
    const double expected = static_cast<double>(frame_count - 1) / rate;
    if (!std::isfinite(duration) || std::fabs(duration - expected) > 1e-4 * expected + 1e-7)
      return fail(where, format("duration %g s does not match %u frames at %g frames/s (%g s)", duration, frame_count,
                                rate, expected));
    const size_t joint_count = c.joint_count();
    const bool binds_here = skeleton_ && c.skeleton_hash() == skeleton_->hash();
    if (binds_here && joint_count != joint_count_)
      return fail(where, format("addresses %s, but its skeleton (this file's, by hash) has %zu",
                                count_text(joint_count, "joint").c_str(), joint_count_));

    // Constant channels.
    const size_t constant_count = count_of(c.constants());
    if (!spend(static_cast<uint64_t>(constant_count) * sizeof(fb::ConstantChannel))) return over_budget(where);
    for (size_t k = 0; k < constant_count; ++k) {
      const fb::ConstantChannel& ch = *c.constants()->Get(static_cast<flatbuffers::uoffset_t>(k));
      const auto channel = static_cast<unsigned>(ch.channel());
      const auto cl = [&] { return channel_label("constant", k, ch.joint(), channel, binds_here); };
      if (channel > static_cast<unsigned>(fb::Channel::MAX))
        return fail(where, cl() + format(" has unknown channel %u", channel));
      if (ch.joint() >= joint_count)
        return fail(where, cl() + format(" addresses a joint past the clip's joint count %zu", joint_count));
      if (k > 0) {
        const fb::ConstantChannel& prev = *c.constants()->Get(static_cast<flatbuffers::uoffset_t>(k - 1));
        if (channel_key(ch.joint(), ch.channel()) <= channel_key(prev.joint(), prev.channel()))
          return fail(where, cl() + format(" is not after constant channel %zu: channels are sorted by (joint, "
                                         "channel), each at most once", k - 1));
      }
      if (ch.channel() == fb::Channel::Rotation) {
        if (!normalizable(ch.value())) return fail(where, cl() + ": value is not a finite, non-zero quaternion");
      } else if (!bounded(ch.value().x()) || !bounded(ch.value().y()) || !bounded(ch.value().z())) {
        return fail(where, cl() + ": value is not finite (or beyond 1e7)");
      }
    }

    // Animated channels.
    const size_t animated_count = count_of(c.animated());
    const size_t frame_total = count_of(c.key_frames());
    const size_t value_bytes = count_of(c.key_values());
    if (!spend(static_cast<uint64_t>(animated_count) * sizeof(fb::AnimatedChannel))) return over_budget(where);
    if (animated_count > 0 && value_bytes < kKeyValuePadding)
      return fail(where, format("key values are %zu bytes, less than the %u padding bytes decoders read past the "
                                "last key", value_bytes, kKeyValuePadding));
    const uint64_t value_bits = value_bytes >= kKeyValuePadding ? 8ull * (value_bytes - kKeyValuePadding) : 0;
    const uint16_t* frames = c.key_frames() ? c.key_frames()->data() : nullptr;
    const uint8_t* values = c.key_values() ? c.key_values()->data() : nullptr;
    size_t next_constant = 0;  // merge walk: both lists are sorted, so disjointness is one pass
    for (size_t k = 0; k < animated_count; ++k) {
      const fb::AnimatedChannel& ch = *c.animated()->Get(static_cast<flatbuffers::uoffset_t>(k));
      const auto channel = static_cast<unsigned>(ch.channel());
      const auto cl = [&] { return channel_label("animated", k, ch.joint(), channel, binds_here); };
      if (channel > static_cast<unsigned>(fb::Channel::MAX))
        return fail(where, cl() + format(" has unknown channel %u", channel));
      if (ch.joint() >= joint_count)
        return fail(where, cl() + format(" addresses a joint past the clip's joint count %zu", joint_count));
      const uint32_t key = channel_key(ch.joint(), ch.channel());
      if (k > 0) {
        const fb::AnimatedChannel& prev = *c.animated()->Get(static_cast<flatbuffers::uoffset_t>(k - 1));
        if (key <= channel_key(prev.joint(), prev.channel()))
          return fail(where, cl() + format(" is not after animated channel %zu: channels are sorted by (joint, "
                                         "channel), each at most once", k - 1));
      }
      while (next_constant < constant_count) {
        const fb::ConstantChannel& cc = *c.constants()->Get(static_cast<flatbuffers::uoffset_t>(next_constant));
        const uint32_t ck = channel_key(cc.joint(), cc.channel());
        if (ck > key) break;
        if (ck == key) return fail(where, cl() + format(" is also constant channel %zu", next_constant));
        ++next_constant;
      }

      // Keys: range inside key_frames, frames strictly increasing from 0 to the last frame.
      const uint32_t n = ch.key_count();
      if (n < 2) return fail(where, cl() + format(" has %u keys; an animated channel has at least 2", n));
      const uint64_t first = ch.first_key();
      if (first + n > frame_total)
        return fail(where, cl() + format(" uses keys [%llu, %llu), past the %zu key frames", static_cast<unsigned long long>(first),
                                       static_cast<unsigned long long>(first + n), frame_total));
      if (!spend(static_cast<uint64_t>(n) * sizeof(uint16_t))) return over_budget(where);
      const uint16_t* f = frames + first;
      if (f[0] != 0) return fail(where, cl() + format(": first key is at frame %u, must be 0", f[0]));
      for (uint32_t i = 1; i < n; ++i)
        if (!(f[i] > f[i - 1]))
          return fail(where, cl() + format(": key %u at frame %u is not after key %u at frame %u (frames must strictly "
                                         "increase)", i, f[i], i - 1, f[i - 1]));
      if (f[n - 1] != frame_count - 1)
        return fail(where, cl() + format(": last key is at frame %u, must be the last frame %u", f[n - 1], frame_count - 1));

      // Bits: inside key_values, minus the padding.
      const uint32_t bits = ch.bits();
      if (!((bits >= 1 && bits <= kMaxQuantBits) || bits == kRawFloatBits))
        return fail(where, cl() + format(" has %u bits per component; must be 1..%u or 32", bits, kMaxQuantBits));
      // Rotations name the component they leave out (0..3). Other channels ignore the field (the
      // schema asks writers for 0 there, but nothing reads it, so a reader need not insist).
      const bool rotation = ch.channel() == fb::Channel::Rotation;
      if (rotation && ch.dropped() > 3)
        return fail(where, cl() + format(" has dropped component %u; must be 0..3 (x, y, z, w)", ch.dropped()));
      const uint64_t offset = ch.bit_offset();
      if (bits == kRawFloatBits && offset % 8 != 0)
        return fail(where, cl() + format(": raw-float keys start at bit %llu, not on a byte boundary",
                                       static_cast<unsigned long long>(offset)));
      const uint64_t end = offset + key_bits(bits) * n;
      if (end > value_bits)
        return fail(where, cl() + format(" needs key value bits [%llu, %llu), the clip has %llu (before padding)",
                                       static_cast<unsigned long long>(offset), static_cast<unsigned long long>(end),
                                       static_cast<unsigned long long>(value_bits)));

      // Ranges: finite, extents >= 0, and the top of the range finite, so every decoded value
      // (lo + extent * q / max <= lo + extent) is.
      const fb::Vec3& lo = ch.range_min();
      const fb::Vec3& ex = ch.range_extent();
      const float los[3] = {lo.x(), lo.y(), lo.z()}, exs[3] = {ex.x(), ex.y(), ex.z()};
      if (bits != kRawFloatBits) {
        for (int i = 0; i < 3; ++i) {
          if (!bounded(los[i]) || !bounded(exs[i]) || !(exs[i] >= 0.0f) || !bounded(los[i] + exs[i]))
            return fail(where, cl() + format(": range min %s extent %s must be finite (within 1e7) with extents >= 0",
                                           vec3_text(lo).c_str(), vec3_text(ex).c_str()));
          if (rotation && (los[i] < -kRotationComponentLimit || los[i] + exs[i] > kRotationComponentLimit))
            return fail(where, cl() + format(": rotation range min %s extent %s leaves [-1, 1]", vec3_text(lo).c_str(),
                                           vec3_text(ex).c_str()));
        }
      } else {
        // Raw floats carry their own values: scan them (O(keys), once, at load).
        if (!spend(static_cast<uint64_t>(n) * 12)) return over_budget(where);
        const uint8_t* raw = values + offset / 8;
        for (uint32_t i = 0; i < n; ++i) {
          float v[3];
          std::memcpy(v, raw + 12ull * i, sizeof v);
          for (int j = 0; j < 3; ++j) {
            if (!bounded(v[j])) return fail(where, cl() + format(": raw key %u is not finite (or beyond 1e7)", i));
            if (rotation && std::fabs(v[j]) > kRotationComponentLimit)
              return fail(where, cl() + format(": raw rotation key %u component %g leaves [-1, 1]", i, v[j]));
          }
        }
      }
    }

    // Root motion: one sample per frame, finite.
    if (const fb::RootMotion* rm = c.root_motion()) {
      const size_t nt = rm->translations()->size(), ny = rm->yaws()->size();
      if (nt != frame_count || ny != frame_count)
        return fail(where, format("root motion has %zu translations and %zu yaws, the clip has %u frames", nt, ny,
                                  frame_count));
      if (rm->up_axis() > 2) return fail(where, format("root motion up axis %u must be 0, 1 or 2", rm->up_axis()));
      if (!spend(static_cast<uint64_t>(frame_count) * 16)) return over_budget(where);
      for (size_t i = 0; i < nt; ++i) {
        const auto idx = static_cast<flatbuffers::uoffset_t>(i);
        if (!finite3(*rm->translations()->Get(idx)) || !std::isfinite(rm->yaws()->Get(idx)))
          return fail(where, format("root motion frame %zu is not finite", i));
      }
    }

    // Events: named, finite, inside the clip, sorted by time (the graph's event scan relies on it).
    if (const auto* events = c.events()) {
      if (!spend(static_cast<uint64_t>(events->size()) * 8)) return over_budget(where);
      float previous = 0.0f;
      for (flatbuffers::uoffset_t i = 0; i < events->size(); ++i) {
        const fb::ClipEvent& e = *events->Get(i);
        if (flatbuffers::GetStringView(e.name()).empty()) return fail(where, format("event %u has an empty name", i));
        const float t = e.time();
        if (!std::isfinite(t) || t < 0.0f || t > duration)
          return fail(where, format("event %u '%s' at %g s lies outside the clip [0, %g s]", i,
                                    detail::printable(flatbuffers::GetStringView(e.name())).c_str(), t, duration));
        if (t < previous) return fail(where, format("event %u at %g s comes before event %u's %g s: not sorted", i, t,
                                                    i - 1, previous));
        previous = t;
      }
    }
    return check_morph_weights(c, where);
  }

  /// Weight tracks: sorted by name (so a binder can merge-walk them), keys as for animated channels
  /// but a single key is a constant, values one per key, ranges bounded (see kMaxMorphWeight).
  Status check_morph_weights(const fb::Clip& c, const Where& clip_where) {
    const auto* tracks = c.morph_weights();
    if (!tracks) return {};
    if (!spend(static_cast<uint64_t>(tracks->size()) * 48)) return over_budget(clip_where);
    std::string_view previous;
    for (flatbuffers::uoffset_t t = 0; t < tracks->size(); ++t) {
      const fb::MorphTrack& track = *tracks->Get(t);
      const std::string_view name = flatbuffers::GetStringView(track.name());
      const Where where{&clip_where, "morph weight track", t, track.name()};
      if (name.empty()) return fail(where, "has an empty name");
      if (t > 0 && !(name > previous))
        return fail(where, "is not after track " + std::to_string(t - 1) + " '" + detail::printable(previous) +
                               "': tracks are sorted by name, each name once");
      previous = name;
      const size_t n = track.key_frames()->size();
      if (n < 1) return fail(where, "has no keys");
      if (track.values()->size() != n)
        return fail(where, format("has %zu key frames but %u values", n, track.values()->size()));
      if (!spend(static_cast<uint64_t>(n) * 4)) return over_budget(where);
      const uint16_t* f = track.key_frames()->data();
      if (f[0] != 0) return fail(where, format("first key is at frame %u, must be 0", f[0]));
      for (size_t i = 1; i < n; ++i)
        if (!(f[i] > f[i - 1]))
          return fail(where, format("key %zu at frame %u is not after key %zu at frame %u (frames must strictly "
                                    "increase)", i, f[i], i - 1, f[i - 1]));
      if (n > 1 && f[n - 1] != c.frame_count() - 1)
        return fail(where, format("last key is at frame %u, must be the last frame %u", f[n - 1], c.frame_count() - 1));
      const float lo = track.range_min(), ex = track.range_extent();
      if (!std::isfinite(lo) || !std::isfinite(ex) || ex < 0.0f || std::fabs(lo) > kMaxMorphWeight ||
          std::fabs(lo + ex) > kMaxMorphWeight)
        return fail(where, format("weight range min %g extent %g must be finite within +-%g, extent >= 0", lo, ex,
                                  kMaxMorphWeight));
      if (!std::isfinite(track.max_error()) || !(track.max_error() >= 0.0f))
        return fail(where, format("recorded error %g must be finite and >= 0", track.max_error()));
    }
    return {};
  }

  // ---- materials ----

  /// A cooked mip chain (texture.h): a known encoding, a size within kMaxTextureSide, a mip
  /// count from 1 to the full chain, and data exactly the chain's bytes. A Source texture carries
  /// no size or levels. O(mip count).
  static Status check_texture(const fb::Texture& t, size_t data_size) {
    const fb::TextureEncoding e = t.encoding();
    if (static_cast<unsigned>(e) > static_cast<unsigned>(fb::TextureEncoding::MAX))
      return Error{format("unknown encoding %u", static_cast<unsigned>(e))};
    if (e == fb::TextureEncoding::Source) {
      if (t.mip_count() != 0) return Error{"source bytes cannot have mip levels"};
      return {};
    }
    const char* name = fb::EnumNameTextureEncoding(e);
    if (data_size == 0) return Error{format("%s texture has no data", name)};
    if (t.width() == 0 || t.height() == 0 || t.width() > kMaxTextureSide || t.height() > kMaxTextureSide)
      return Error{format("%s texture is %u x %u texels (each side must be 1 to %u)", name, t.width(), t.height(),
                          kMaxTextureSide)};
    const uint32_t full = texture_full_mip_count(t.width(), t.height());
    if (t.mip_count() == 0 || t.mip_count() > full)
      return Error{format("%u mip levels for %u x %u texels (1 to %u)", static_cast<unsigned>(t.mip_count()), t.width(),
                          t.height(), full)};
    const uint64_t expected = texture_chain_bytes(e, t.width(), t.height(), t.mip_count());
    if (expected != data_size)
      return Error{format("%s chain of %u levels from %u x %u is %llu bytes, the data is %zu", name,
                          static_cast<unsigned>(t.mip_count()), t.width(), t.height(),
                          static_cast<unsigned long long>(expected), data_size)};
    return {};
  }

  Status check_material(const fb::Material& m, size_t material_index) {
    const Where where{nullptr, "material", material_index, m.name()};
    const struct {
      const char* field;
      const fb::Vec3* value;
    } colours[] = {{"ambient", m.ambient()}, {"diffuse", m.diffuse()}, {"specular", m.specular()}};
    for (const auto& c : colours)
      if (c.value && !finite3(*c.value)) return fail(where, format("%s colour %s is not finite", c.field, vec3_text(*c.value).c_str()));
    if (!std::isfinite(m.shininess())) return fail(where, "shininess is not finite");
    if (!std::isfinite(m.opacity())) return fail(where, "opacity is not finite");
    const auto* textures = m.textures();
    if (!textures) return {};
    if (!spend(static_cast<uint64_t>(textures->size()) * 4)) return over_budget(where);
    for (flatbuffers::uoffset_t k = 0; k < textures->size(); ++k) {
      const fb::Texture& t = *textures->Get(k);
      if (static_cast<unsigned>(t.role()) > static_cast<unsigned>(fb::TextureRole::MAX))
        return fail(where, format("texture %u has unknown role %u", k, static_cast<unsigned>(t.role())));
      const size_t data_size = count_of(t.data());
      if (data_size == 0 && flatbuffers::GetStringView(t.path()).empty())
        return fail(where, format("texture %u (%s) has neither embedded data nor a path", k,
                                  fb::EnumNameTextureRole(t.role())));
      if (data_size != 0 && reinterpret_cast<uintptr_t>(t.data()->Data()) % 16 != 0)
        return fail(where, format("texture %u (%s): embedded data is not 16-byte aligned", k,
                                  fb::EnumNameTextureRole(t.role())));
      if (Status s = check_texture(t, data_size); !s)
        return fail(where, format("texture %u (%s): %s", k, fb::EnumNameTextureRole(t.role()), s.message().c_str()));
    }
    return {};
  }

  const fb::File& file_;
  std::string_view name_;
  uint64_t budget_ = 0;
  size_t material_count_ = 0;
  const fb::Skeleton* skeleton_ = nullptr;  // set once the skeleton checked out
  size_t joint_count_ = 0;
};

}  // namespace

Status validate_file(const fb::File& file, std::string_view name, size_t buffer_size) {
  return Validator(file, name, buffer_size).run();
}

}  // namespace ossa
