// validate_mesh.cpp — the loader's checks of a file's meshes (validate.h lists them): vertex layout,
// index and joint-slot ranges, bounds, and morph targets (format v5). Part of the Validator
// (internal/validator.h) that validate.cpp runs.
//
// Why it is a file of its own: meshes are the one table family whose checks grow with the data
// (every index and every vertex's joint slots), so it holds the O(n) loops, written for the
// vectorizer and compiled for AVX2 and the baseline (internal/vector_clones.h).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <ossa/format/vertex_format.h>
#include <ossa/loader/cloth_source.h>
#include "common/message.h"
#include "internal/validator.h"
#include "internal/vector_clones.h"

namespace ossa::validate_detail {
namespace {

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
/// Compiled for AVX2 and the baseline. With GCC and Clang the maxima are two 32-byte vectors of
/// the compilers' vector extension (one AVX2 register each, two SSE2 ones in the baseline):
/// left to the vectorizer, GCC 12 vectorized the byte loop at -O2 but kept it scalar at -O3, which
/// made Asset::borrow of Pab's skeleton 5.8x slower in Release builds (16.7 against 2.9 us).
/// `masks` holds `period` bytes (a multiple of 64); bytes past the last whole chunk are left to the
/// caller. O(n * stride).
OSSA_INLINE static void max_masked_bytes_body(const uint8_t* bytes, size_t chunks, const uint8_t* masks, size_t period,
                                              uint32_t* out) {
  constexpr size_t kChunk = 64;
  uint8_t lanes[kChunk] = {};
  size_t m = 0;
#if defined(__GNUC__)
  typedef uint8_t Bytes32 __attribute__((vector_size(32)));
  Bytes32 lo = {}, hi = {}, b0, b1, k0, k1;
  for (size_t c = 0; c < chunks; ++c, bytes += kChunk) {
    std::memcpy(&b0, bytes, 32);
    std::memcpy(&b1, bytes + 32, 32);
    std::memcpy(&k0, masks + m, 32);
    std::memcpy(&k1, masks + m + 32, 32);
    b0 &= k0;
    b1 &= k1;
    lo = b0 > lo ? b0 : lo;
    hi = b1 > hi ? b1 : hi;
    m += kChunk;
    if (m == period) m = 0;
  }
  std::memcpy(lanes, &lo, 32);
  std::memcpy(lanes + 32, &hi, 32);
#else
  for (size_t c = 0; c < chunks; ++c, bytes += kChunk) {
    const uint8_t* mask = masks + m;
    for (size_t k = 0; k < kChunk; ++k) {
      const auto b = static_cast<uint8_t>(bytes[k] & mask[k]);
      lanes[k] = b > lanes[k] ? b : lanes[k];
    }
    m += kChunk;
    if (m == period) m = 0;
  }
#endif
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
size_t first_joint_slot_at_least(const uint8_t* first, size_t n, size_t stride, uint32_t limit, uint32_t* slot) {
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

}  // namespace

// ---- meshes ----

Status Validator::check_mesh(const fb::Mesh& m, size_t mesh_index) {
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
    if (info.size == 0) return fail(where, al() + format(" has unknown format %u", static_cast<unsigned>(a.format())));
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
    return fail(where, format("vertex data is %u bytes, expected vertex_count %u * stride %u = %llu", vertices->size(),
                              vertex_count, stride, static_cast<unsigned long long>(expected)));
  if (vertices->size() != 0 && reinterpret_cast<uintptr_t>(vertices->Data()) % 16 != 0)
    return fail(where, "vertex data is not 16-byte aligned");

  // Indices.
  const auto* indices = m.indices();
  size_t index_size = 0;
  switch (m.index_format()) {
    case fb::IndexFormat::Uint16: index_size = 2; break;
    case fb::IndexFormat::Uint32: index_size = 4; break;
  }
  if (index_size == 0) return fail(where, format("unknown index format %u", static_cast<unsigned>(m.index_format())));
  const char* index_format = fb::EnumNameIndexFormat(m.index_format());
  if (indices->size() % index_size != 0)
    return fail(
        where, format("index data is %u bytes, not a multiple of %zu (%s)", indices->size(), index_size, index_format));
  const size_t index_count = indices->size() / index_size;
  if (index_count % 3 != 0)
    return fail(where, format("has %zu indices, not a multiple of 3 (triangle list)", index_count));
  if (index_count != 0) {
    if (reinterpret_cast<uintptr_t>(indices->Data()) % 16 != 0) return fail(where, "index data is not 16-byte aligned");
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
      return fail(where, format("submesh %u covers indices [%u, %llu), past the index count %zu", k, sm.first_index(),
                                static_cast<unsigned long long>(end), index_count));
    if (sm.index_count() % 3 != 0)
      return fail(where, format("submesh %u has %u indices, not a multiple of 3", k, sm.index_count()));
    if (sm.material() >= material_limit)
      return fail(where, material_count_ == 0
                             ? format("submesh %u uses material %u, but the file has no materials (only 0 "
                                      "is allowed)",
                                      k, sm.material())
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
  if (const fb::Cloth* cloth = m.cloth()) {  // format v10: ossa/anim/cloth.h's check_cloth
    const uint64_t bytes =
        4 * (count_of(cloth->particle_vertices()) + count_of(cloth->inverse_masses()) +
             count_of(cloth->max_distances()) + count_of(cloth->backstops()) + count_of(cloth->vertices())) +
        2 * (count_of(cloth->vertex_particles()) + count_of(cloth->triangles())) + count_of(cloth->flipped()) +
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

/// Whether a morph step is finite, >= 0 and at most kMaxMorphStep per axis.
bool Validator::step_ok(const fb::Vec3& s) {
  const float v[3] = {s.x(), s.y(), s.z()};
  for (float x : v)
    if (!std::isfinite(x) || x < 0.0f || x > kMaxMorphStep) return false;
  return true;
}

Status Validator::check_morph_targets(const fb::Mesh& m, const Where& mesh_where) {
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
        return fail(where, format("entry %zu names vertex %u after vertex %u: vertices must strictly increase", i, v[i],
                                  v[i - 1]));
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
      return fail(where,
                  format("default weight %g must be finite and within +-%g", target.default_weight(), kMaxMorphWeight));
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

}  // namespace ossa::validate_detail
