// skinning.cpp — skinning palettes, and CPU skinning: linear blend (the GPU's reference) and dual
// quaternion.
//
// Why it is shaped so:
// - A portable path decodes any valid layout as OpenGL fetches it (unorm16 / 65535, snorm16
//   max(v / 32767, -1), octahedral directions via ossa/format/vertex_codec.h, unorm8 weights / 255,
//   integer joint slots, missing components (0, 0, 0, 1)), a batch of 64 vertices at a time with
//   one loop per attribute format, and skins in plain float code. It serves float cooks, static
//   meshes, unusual layouts, dual quaternions, and CPUs without AVX2.
// - The cooker's quantized layout (Position Unorm16x4, Normal Snorm16x2, Tangent Snorm16x4, Joints
//   Uint8x4 / Uint16x4, Weights Unorm8x4) has a hand-vectorized path, picked at run time with
//   internal/cpu.h's queries (the default build runs on any x86-64). Intrinsics rather than
//   target_clones: every vertex has its own matrices, so the work is array-of-structures per
//   vertex (a structure-of-arrays form needs 12 gathers per influence, and gathers measured ~1.4
//   cycles per element on this Zen 4), and what makes it fast is in-register shuffles and rsqrt,
//   which auto-vectorized clones do not produce.
// - Influence counts vary from vertex to vertex with no pattern (Pab's arnaud: 35% one, 41% two,
//   18% three, 6% four; consecutive vertices differ 32% of the time), so a branch per vertex on
//   the count mispredicts often, and always blending four doubles the work. Each class runs a loop
//   specialized for it (see "Fast paths" below), including a class for single influences of weight
//   255 that uses the palette matrix as it is. The cooker orders a skinned mesh's vertices by class
//   (as ozz-animation splits skinning jobs by influence count), so each class is one contiguous
//   range, checked as it is skinned; a file in any other order is classified per batch, branch-free.
//
// The de-quantizing affine D (translate(position_offset) * scale(position_scale)) is folded into
// the palette for positions. Directions must not see D's scale, so they are pre-multiplied by its
// inverse, 1 / position_scale per axis (a per-mesh constant): palette3x3 * (n / s) = M3x3 * n with
// M = model * inverse_bind. A GPU shader has to do the same (one uniform) to agree with skin_cpu.
//
// Dual quaternion skinning needs rigid transforms. Each palette matrix is split back into
// M = palette * D^-1, and M into translation, rotation R and a 3x3 stretch S = R^T * M3x3 (R from a
// Gram-Schmidt orthonormalization of M's columns, so S is identity for rigid M and carries scale
// and mirroring otherwise). A vertex is D-applied, stretched by the weight-blended S (linear, like
// Kavan et al.'s scale handling), then moved by the blended, normalized dual quaternion. Dual
// quaternions are aligned to the first influence's hemisphere (shortest arc). For one influence,
// or identical rigid matrices, this equals linear blending up to rounding.
//
// Costs: skinning_matrices O(slots). skin_cpu O(vertices * influences), allocation-free (stack
// buffers: ~18 KB on the fast path, ~22 KB for dual quaternions), no virtual calls, no
// per-vertex branches on the fast path. Measured on Pab's arnaud (3748 vertices, ossa-bench-anim,
// Zen 5 VM at ~3.2 GHz, medians of 5): ~1.6 ns per vertex for positions, ~2.9 ns with normals
// (~2.5 without renormalizing: soa_kernel.h), as cooked (class-ordered); ~2.8 / ~4.9 ns
// classified per batch; portable ~19 / ~32 ns; dual quaternions ~69 ns.
#include <ossa/skinning/skinning.h>

#include <algorithm>
#include <array>
#include <atomic>
#include <cassert>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <type_traits>

#include "internal/cpu.h"
#include "internal/float_env.h"

#if OSSA_CPU_X86
// GCC 12's AVX-512 headers trip -Wmaybe-uninitialized on their own _mm512_undefined_* helpers
// (GCC bug 105593, fixed in 13); the diagnostic points into the header, so silence it there.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <immintrin.h>
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif
#define OSSA_SKIN_X86 1
#include "skinning/soa_kernel.h"
#else
#define OSSA_SKIN_X86 0
#endif

#include <glm/gtc/quaternion.hpp>

#include <ossa/format/vertex_codec.h>
#include <ossa/format/vertex_format.h>
#include <ossa/skinning/vertex_fetch.h>

namespace ossa {
namespace {

using fb::VertexFormat;
using fb::VertexSemantic;

uint32_t load_u32(const uint8_t* p) {
  uint32_t v;
  std::memcpy(&v, p, 4);
  return v;
}
uint64_t load_u64(const uint8_t* p) {
  uint64_t v;
  std::memcpy(&v, p, 8);
  return v;
}

// ---------------------------------------------------------------------------------------------
// What a mesh holds, resolved once per call.

struct MeshFacts {
  const uint8_t* base = nullptr;
  uint32_t count = 0;
  uint32_t stride = 0;
  const fb::VertexAttribute* position = nullptr;
  const fb::VertexAttribute* normal = nullptr;
  const fb::VertexAttribute* tangent = nullptr;
  const fb::VertexAttribute* joints = nullptr;   // both or neither (validate.cpp)
  const fb::VertexAttribute* weights = nullptr;
  size_t slot_count = 0;                         // mesh.joints().size()
  bool dequantize = false;                       // D applies: a normalized position format
  glm::vec3 offset{0.0f}, scale{1.0f};           // D
  glm::vec3 direction_prescale{1.0f};            // 1 / scale (0 on a zero axis)
};

MeshFacts mesh_facts(const MeshView& mesh) {
  MeshFacts f;
  f.base = mesh.vertex_bytes().data();
  f.count = mesh.vertex_count();
  f.stride = mesh.vertex_stride();
  f.position = mesh.attribute(VertexSemantic::Position);
  f.normal = mesh.attribute(VertexSemantic::Normal);
  f.tangent = mesh.attribute(VertexSemantic::Tangent);
  f.joints = mesh.attribute(VertexSemantic::Joints);
  f.weights = mesh.attribute(VertexSemantic::Weights);
  if (f.joints == nullptr || f.weights == nullptr) f.joints = f.weights = nullptr;
  f.slot_count = mesh.joints().size();
  f.dequantize = f.position != nullptr && vertex_format_info(f.position->format()).normalized;
  if (f.dequantize) {
    if (const fb::Vec3* o = mesh.fb->position_offset()) f.offset = {o->x(), o->y(), o->z()};
    if (const fb::Vec3* s = mesh.fb->position_scale()) f.scale = {s->x(), s->y(), s->z()};
    for (int a = 0; a < 3; ++a) f.direction_prescale[a] = f.scale[a] != 0.0f ? 1.0f / f.scale[a] : 0.0f;
  }
  return f;
}

// ---------------------------------------------------------------------------------------------
/// unorm8 weight -> float, exactly b / 255.0f as OpenGL normalizes it.
constexpr std::array<float, 256> make_weight_table() {
  std::array<float, 256> t{};
  for (int i = 0; i < 256; ++i) t[static_cast<size_t>(i)] = static_cast<float>(i) / 255.0f;
  return t;
}
alignas(64) constexpr std::array<float, 256> kWeight = make_weight_table();

/// v / |v|, or zero for a zero vector (what the fast paths' guarded rsqrt gives too).
glm::vec3 normalize_or_zero(glm::vec3 v) {
  const float len2 = glm::dot(v, v);
  return len2 > 0.0f ? v * (1.0f / std::sqrt(len2)) : glm::vec3(0.0f);
}

/// Where skin_cpu writes; null streams are not written.
struct Outputs {
  float* positions = nullptr;
  float* normals = nullptr;
  float* tangents = nullptr;
  bool renormalize = true;  // SkinnedStreams::renormalize
};

/// A transformed direction as the caller asked for it: unit length, or as transformed.
inline glm::vec3 finish_direction(glm::vec3 v, const Outputs& out) { return out.renormalize ? normalize_or_zero(v) : v; }

// ---------------------------------------------------------------------------------------------
// Portable path: any layout, decoded a batch at a time as OpenGL fetches attributes.
//
// Each attribute of a batch of kPortableBatch vertices is decoded in one loop specialized for its
// format (the cooker's two layouts have their own loops; anything else goes through
// fetch_vertex_attribute, ossa/skinning/vertex_fetch.h), into plain float arrays; skinning then
// runs over those arrays with no format switch per vertex.

glm::vec3 octahedral(float x, float y) {
  const Float3 n = octahedral_decode({x, y});
  return {n.x, n.y, n.z};
}

constexpr uint32_t kPortableBatch = 64;

struct Decoded {
  uint32_t first = 0, n = 0;
  glm::vec3 position[kPortableBatch];  // as stored (normalized for quantized layouts: D is in the palette)
  glm::vec3 normal[kPortableBatch];    // unit
  glm::vec4 tangent[kPortableBatch];   // unit xyz, sign
  uint32_t slot[kPortableBatch][4];
  glm::vec4 weight[kPortableBatch];
};

void decode_positions(const MeshFacts& m, Decoded& d) {
  const uint8_t* p = m.base + static_cast<size_t>(d.first) * m.stride + m.position->offset();
  switch (m.position->format()) {
    case VertexFormat::Unorm16x4:
      for (uint32_t i = 0; i < d.n; ++i, p += m.stride) {
        uint16_t q[3];
        std::memcpy(q, p, 6);
        d.position[i] = glm::vec3(unorm16_to_float(q[0]), unorm16_to_float(q[1]), unorm16_to_float(q[2]));
      }
      break;
    case VertexFormat::Float32x3:
      for (uint32_t i = 0; i < d.n; ++i, p += m.stride) std::memcpy(&d.position[i][0], p, 12);
      break;
    default:
      for (uint32_t i = 0; i < d.n; ++i, p += m.stride)
        d.position[i] = glm::vec3(fetch_vertex_attribute(p, m.position->format()));
      break;
  }
}

/// A direction attribute: two components can only be the octahedral encoding, more are xyz.
void decode_normals(const MeshFacts& m, Decoded& d) {
  const uint8_t* p = m.base + static_cast<size_t>(d.first) * m.stride + m.normal->offset();
  const VertexFormat f = m.normal->format();
  if (f == VertexFormat::Snorm16x2) {
    for (uint32_t i = 0; i < d.n; ++i, p += m.stride) {
      int16_t e[2];
      std::memcpy(e, p, 4);
      d.normal[i] = octahedral(snorm16_to_float(e[0]), snorm16_to_float(e[1]));
    }
  } else if (f == VertexFormat::Float32x3) {
    for (uint32_t i = 0; i < d.n; ++i, p += m.stride) std::memcpy(&d.normal[i][0], p, 12);
  } else {
    const bool two = vertex_format_info(f).components == 2;
    for (uint32_t i = 0; i < d.n; ++i, p += m.stride) {
      const glm::vec4 v = fetch_vertex_attribute(p, f);
      d.normal[i] = two ? octahedral(v.x, v.y) : glm::vec3(v);
    }
  }
}

/// Tangent xyz and bitangent sign (+-1): Snorm16x4 is octahedral xy + sign z (the cooker's), two
/// components octahedral with sign +1, otherwise xyz + sign of w.
void decode_tangents(const MeshFacts& m, Decoded& d) {
  const uint8_t* p = m.base + static_cast<size_t>(d.first) * m.stride + m.tangent->offset();
  const VertexFormat f = m.tangent->format();
  const bool octa = f == VertexFormat::Snorm16x4 || vertex_format_info(f).components == 2;
  for (uint32_t i = 0; i < d.n; ++i, p += m.stride) {
    const glm::vec4 v = fetch_vertex_attribute(p, f);
    if (octa) d.tangent[i] = glm::vec4(octahedral(v.x, v.y), f == VertexFormat::Snorm16x4 && v.z < 0.0f ? -1.0f : 1.0f);
    else d.tangent[i] = glm::vec4(glm::vec3(v), v.w < 0.0f ? -1.0f : 1.0f);
  }
}

/// Joint slots and weights; a static mesh (no Joints) is slot 0 with weight 1.
void decode_influences(const MeshFacts& m, Decoded& d) {
  if (m.joints == nullptr) {
    for (uint32_t i = 0; i < d.n; ++i) {
      d.slot[i][0] = d.slot[i][1] = d.slot[i][2] = d.slot[i][3] = 0;
      d.weight[i] = glm::vec4(1.0f, 0.0f, 0.0f, 0.0f);
    }
    return;
  }
  const uint8_t* j = m.base + static_cast<size_t>(d.first) * m.stride + m.joints->offset();
  const uint8_t* w = m.base + static_cast<size_t>(d.first) * m.stride + m.weights->offset();
  const bool wide = m.joints->format() == VertexFormat::Uint16x4;
  for (uint32_t i = 0; i < d.n; ++i, j += m.stride) {
    if (wide) {
      uint16_t q[4];
      std::memcpy(q, j, 8);
      for (int k = 0; k < 4; ++k) d.slot[i][k] = q[k];
    } else {
      for (int k = 0; k < 4; ++k) d.slot[i][k] = j[k];
    }
  }
  const VertexFormat wf = m.weights->format();
  if (wf == VertexFormat::Unorm8x4) {
    for (uint32_t i = 0; i < d.n; ++i, w += m.stride)
      d.weight[i] = glm::vec4(kWeight[w[0]], kWeight[w[1]], kWeight[w[2]], kWeight[w[3]]);
  } else if (wf == VertexFormat::Float32x4) {
    for (uint32_t i = 0; i < d.n; ++i, w += m.stride) std::memcpy(&d.weight[i][0], w, 16);
  } else {
    for (uint32_t i = 0; i < d.n; ++i, w += m.stride) d.weight[i] = fetch_vertex_attribute(w, wf);
  }
}

void decode_batch(const MeshFacts& m, Outputs out, bool positions_too, Decoded& d) {
  if (out.positions != nullptr || positions_too) decode_positions(m, d);
  if (out.normals != nullptr) decode_normals(m, d);
  if (out.tangents != nullptr) decode_tangents(m, d);
  decode_influences(m, d);
}

// ---------------------------------------------------------------------------------------------
// Portable linear blend skinning.

void skin_linear_portable(const MeshFacts& m, const glm::mat4* palette, Outputs out) {
  Decoded d;
  for (d.first = 0; d.first < m.count; d.first += kPortableBatch) {
    d.n = std::min(kPortableBatch, m.count - d.first);
    decode_batch(m, out, false, d);
    for (uint32_t i = 0; i < d.n; ++i) {
      const size_t v = d.first + i;
      // Columns 0-3 (xyz only) of the blended matrix. All four influences, zero weights too: a
      // branch per influence mispredicts more than the multiply-adds it would save.
      float a[16] = {};
      for (int k = 0; k < 4; ++k) {
        const float* p = &palette[d.slot[i][k]][0][0];
        const float w = d.weight[i][k];
        for (int e = 0; e < 16; ++e) a[e] += p[e] * w;  // 4-wide vector code at -O2
      }
      const glm::vec3 c0(a[0], a[1], a[2]), c1(a[4], a[5], a[6]), c2(a[8], a[9], a[10]), c3(a[12], a[13], a[14]);
      if (out.positions != nullptr) {
        const glm::vec3& q = d.position[i];
        const glm::vec3 p = c0 * q.x + c1 * q.y + c2 * q.z + c3;
        std::memcpy(out.positions + 3 * v, &p[0], 12);
      }
      if (out.normals != nullptr) {
        const glm::vec3 n = d.normal[i] * m.direction_prescale;
        const glm::vec3 r = finish_direction(c0 * n.x + c1 * n.y + c2 * n.z, out);
        std::memcpy(out.normals + 3 * v, &r[0], 12);
      }
      if (out.tangents != nullptr) {
        const glm::vec3 t = glm::vec3(d.tangent[i]) * m.direction_prescale;
        const glm::vec4 r(finish_direction(c0 * t.x + c1 * t.y + c2 * t.z, out), d.tangent[i].w);
        std::memcpy(out.tangents + 4 * v, &r[0], 16);
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Dual quaternion skinning (portable; an option, not the hot path).

struct SlotDq {
  glm::quat real{1.0f, 0.0f, 0.0f, 0.0f};
  glm::quat dual{0.0f, 0.0f, 0.0f, 0.0f};
  glm::mat3 stretch{1.0f};
};

/// palette = M * D  ->  M = T(t) * R * S, as a unit dual quaternion (R, t) and the stretch S.
SlotDq make_slot_dq(const glm::mat4& palette, const MeshFacts& m) {
  glm::vec3 c[3];
  for (int a = 0; a < 3; ++a) c[a] = glm::vec3(palette[a]) * m.direction_prescale[a];
  const glm::vec3 t = glm::vec3(palette[3]) - (c[0] * m.offset.x + c[1] * m.offset.y + c[2] * m.offset.z);
  const glm::mat3 m3(c[0], c[1], c[2]);
  // Gram-Schmidt: a proper rotation whatever M holds (a mirror ends up in S's determinant).
  glm::vec3 r0 = normalize_or_zero(c[0]);
  if (r0 == glm::vec3(0.0f)) r0 = glm::vec3(1.0f, 0.0f, 0.0f);
  glm::vec3 r1 = normalize_or_zero(c[1] - glm::dot(c[1], r0) * r0);
  if (r1 == glm::vec3(0.0f)) {
    const glm::vec3 helper = std::fabs(r0.x) < 0.9f ? glm::vec3(1.0f, 0.0f, 0.0f) : glm::vec3(0.0f, 1.0f, 0.0f);
    r1 = glm::normalize(glm::cross(helper, r0));
  }
  const glm::mat3 r(r0, r1, glm::cross(r0, r1));
  SlotDq d;
  d.real = glm::normalize(glm::quat_cast(r));
  d.stretch = glm::transpose(glm::mat3_cast(d.real)) * m3;
  d.dual = glm::quat(0.0f, t.x, t.y, t.z) * d.real * 0.5f;
  return d;
}

void skin_dual_quaternion(const MeshFacts& m, std::span<const glm::mat4> palette, Outputs out) {
  // Per-slot conversions on the stack for meshes with up to 256 slots (every 8-bit-slot mesh);
  // larger palettes convert per influence.
  constexpr size_t kCached = 256;
  SlotDq cache[kCached];
  const size_t slots = m.joints != nullptr ? std::min(palette.size(), m.slot_count) : 1;
  const bool cached = slots <= kCached;
  if (cached)
    for (size_t s = 0; s < slots; ++s) cache[s] = make_slot_dq(palette[s], m);

  Decoded d;
  for (d.first = 0; d.first < m.count; d.first += kPortableBatch) {
    d.n = std::min(kPortableBatch, m.count - d.first);
    decode_batch(m, out, false, d);
    for (uint32_t i = 0; i < d.n; ++i) {
      const size_t v = d.first + i;
      glm::quat real(0.0f, 0.0f, 0.0f, 0.0f), dual(0.0f, 0.0f, 0.0f, 0.0f);
      glm::mat3 stretch(0.0f);
      bool have_first = false;
      glm::quat first(1.0f, 0.0f, 0.0f, 0.0f);
      for (int k = 0; k < 4; ++k) {
        const float w = d.weight[i][k];
        if (w == 0.0f) continue;
        const SlotDq s = cached ? cache[d.slot[i][k]] : make_slot_dq(palette[d.slot[i][k]], m);
        if (!have_first) {
          first = s.real;
          have_first = true;
        }
        const float signed_w = glm::dot(s.real, first) < 0.0f ? -w : w;  // shortest arc
        real = real + s.real * signed_w;
        dual = dual + s.dual * signed_w;
        stretch += s.stretch * w;
      }
      const float len = glm::length(real);
      if (len > 1e-20f) {
        real = real * (1.0f / len);
        dual = dual * (1.0f / len);
      } else {
        real = glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
        dual = glm::quat(0.0f, 0.0f, 0.0f, 0.0f);
      }
      const glm::vec3 rv(real.x, real.y, real.z), dv(dual.x, dual.y, dual.z);
      if (out.positions != nullptr) {
        const glm::vec3 p = m.dequantize ? m.offset + m.scale * d.position[i] : d.position[i];
        const glm::vec3 moved = real * (stretch * p) + 2.0f * (real.w * dv - dual.w * rv + glm::cross(rv, dv));
        std::memcpy(out.positions + 3 * v, &moved[0], 12);
      }
      if (out.normals != nullptr) {
        const glm::vec3 n = finish_direction(real * (stretch * d.normal[i]), out);
        std::memcpy(out.normals + 3 * v, &n[0], 12);
      }
      if (out.tangents != nullptr) {
        const glm::vec4 r(finish_direction(real * (stretch * glm::vec3(d.tangent[i])), out), d.tangent[i].w);
        std::memcpy(out.tangents + 4 * v, &r[0], 16);
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// Fast paths for the cooker's quantized layout.
//
// A call runs batch by batch (kBatch vertices, a contiguous range):
//   1. classify: load each vertex's four weight bytes as one word, derive the classes of 8 (AVX2)
//      or 16 (AVX-512) vertices with vector compares, and left-pack the vertex indices of each
//      class into its list (a permute table on AVX2, vpcompressd on AVX-512);
//   2. with normals or tangents: decode the batch's octahedral words structure-of-arrays, 8 at a
//      time, into float4 temporaries already multiplied by the direction prescale;
//   3. one loop per class over its list: blend the palette matrices (two 8-wide FMAs per
//      influence, columns 0-1 and 2-3), transform the position by spreading (x, y, z, 1) over the
//      column layout and adding the halves, likewise the normal and tangent; store (directions
//      unnormalized);
//   4. renormalize the batch's output normals (8 at a time, structure-of-arrays) and tangents
//      (rsqrt + one Newton step).
// A class-ordered mesh skinned for normals without tangents takes soa_kernel.h instead of steps
// 2-4: eight vertices at a time, structure-of-arrays after the blend (see "meshes ordered by
// influence class" below).
// The per-vertex loops use 256-bit registers on both paths: on Zen 4, which executes a 512-bit
// operation as two 256-bit halves, a 16-wide per-vertex kernel measured ~25% slower (more
// cross-lane shuffles for the same arithmetic). The classification is where AVX-512 pays.
// Scalar word loads rather than gathers in steps 1 and 2: measured faster on Zen 4.

#if OSSA_SKIN_X86

// internal/cpu.h: target attributes on GCC / Clang, nothing on MSVC (which needs none).
#define OSSA_TARGET_AVX2 OSSA_TARGET("avx2,fma,bmi,bmi2,popcnt")
#define OSSA_TARGET_AVX512 OSSA_TARGET("avx2,fma,bmi,bmi2,popcnt,avx512f,avx512vl,avx512bw,avx512dq")
#if defined(_MSC_VER) && !defined(__clang__)
#define OSSA_POPCOUNT(x) static_cast<int>(__popcnt(x))
#else
#define OSSA_POPCOUNT(x) __builtin_popcount(x)
#endif

/// How joint slots and weights sit in a vertex: Uint8x4 slots, Uint16x4 slots, or Uint8x4 slots
/// directly followed by the weights (the cooker's layout: one 8-byte load fetches both).
enum class Slots { Narrow, Wide, Packed };

struct FastMesh {
  const uint8_t* base;
  uint32_t count, stride;
  uint32_t off_position, off_normal, off_tangent, off_joints, off_weights;
  Slots slots;
  float prescale[3];     // direction_prescale
};

/// 256 vertices per batch: lists, classes and decoded directions stay in L1 (~13 KB), and the
/// five list loops' exit mispredictions are paid once per batch.
constexpr uint32_t kBatch = 256;

/// Classes: 0 = one influence of weight exactly 255 (the palette matrix itself: no blending);
/// c = 1..4: the last non-zero weight is influence c - 1, so influences 0..c-1 are blended (zero
/// weights below it blend as 0, harmlessly). All-zero weights are class 1: a zero matrix, as
/// OpenGL would blend them.
constexpr int kClasses = 5;

struct Batch {
  uint32_t first = 0, n = 0;
  uint32_t count[kClasses] = {};
  alignas(32) uint32_t lists[kClasses][kBatch + 16];
  alignas(32) float normal[kBatch][4];   // x, y, z, 0
  alignas(32) float tangent[kBatch][4];  // x, y, z, bitangent sign
};

template <Slots kSlots>
inline uint32_t slot_of(uint64_t slot_bits, int k) {
  return kSlots == Slots::Wide ? static_cast<uint32_t>(slot_bits >> (16 * k)) & 0xffffu
                               : static_cast<uint32_t>(slot_bits >> (8 * k)) & 0xffu;
}

// ---- classification ----

/// Left-pack table for AVX2: for each 8-bit lane mask, the indices of its set lanes, packed low,
/// one per byte.
constexpr std::array<uint64_t, 256> make_pack_table() {
  std::array<uint64_t, 256> t{};
  for (uint32_t m = 0; m < 256; ++m) {
    uint64_t packed = 0;
    int n = 0;
    for (uint32_t lane = 0; lane < 8; ++lane)
      if (m & (1u << lane)) packed |= static_cast<uint64_t>(lane) << (8 * n++);
    t[m] = packed;
  }
  return t;
}
alignas(64) constexpr std::array<uint64_t, 256> kPack = make_pack_table();

/// The weight bytes of the batch's vertices, one 32-bit word each, padded to whole vectors with
/// 255 (class 0, never listed: the lists only take lanes below n). Scalar loads: on Zen 4 they
/// measured faster than a gather.
inline void load_weight_words(const FastMesh& m, Batch& b, uint32_t* words) {
  const uint8_t* w = m.base + static_cast<size_t>(b.first) * m.stride + m.off_weights;
  for (uint32_t i = 0; i < b.n; ++i) words[i] = load_u32(w + static_cast<size_t>(i) * m.stride);
  for (uint32_t i = b.n; i < ((b.n + 15) & ~15u); ++i) words[i] = 255u;
}

OSSA_TARGET_AVX2 void classify_avx2(const FastMesh& m, Batch& b) {
  alignas(32) uint32_t words[kBatch];
  load_weight_words(m, b, words);
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256i zero = _mm256_setzero_si256();
  uint32_t count[kClasses] = {0, 0, 0, 0, 0};  // locals: list stores cannot alias them
  for (uint32_t c = 0; c < b.n; c += 8) {
    const uint32_t valid = b.n - c >= 8 ? 0xffu : (1u << (b.n - c)) - 1u;
    const __m256i g = _mm256_load_si256(reinterpret_cast<const __m256i*>(words + c));
    const uint32_t z24 = static_cast<uint32_t>(_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(_mm256_srli_epi32(g, 24), zero))));
    const uint32_t z16 = static_cast<uint32_t>(_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(_mm256_srli_epi32(g, 16), zero))));
    const uint32_t z8 = static_cast<uint32_t>(_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(_mm256_srli_epi32(g, 8), zero))));
    const uint32_t rigid = static_cast<uint32_t>(_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(g, _mm256_set1_epi32(255))))) & valid;
    const uint32_t masks[kClasses] = {rigid, valid & z8 & ~rigid, valid & z16 & ~z8, valid & z24 & ~z16, valid & ~z24};
    const __m256i index = _mm256_add_epi32(lane, _mm256_set1_epi32(static_cast<int>(b.first + c)));
    for (int k = 0; k < kClasses; ++k) {
      const __m256i pick = _mm256_cvtepu8_epi32(_mm_cvtsi64_si128(static_cast<long long>(kPack[masks[k]])));
      _mm256_storeu_si256(reinterpret_cast<__m256i*>(b.lists[k] + count[k]), _mm256_permutevar8x32_epi32(index, pick));
      count[k] += static_cast<uint32_t>(OSSA_POPCOUNT(masks[k]));
    }
  }
  for (int k = 0; k < kClasses; ++k) b.count[k] = count[k];
}

OSSA_TARGET_AVX512 void classify_avx512(const FastMesh& m, Batch& b) {
  alignas(64) uint32_t words[kBatch];
  load_weight_words(m, b, words);
  const __m512i lane = _mm512_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  uint32_t count[kClasses] = {0, 0, 0, 0, 0};
  for (uint32_t c = 0; c < b.n; c += 16) {
    const __mmask16 valid = b.n - c >= 16 ? __mmask16(0xffff) : static_cast<__mmask16>((1u << (b.n - c)) - 1u);
    const __m512i g = _mm512_load_si512(words + c);
    const __mmask16 nz24 = _mm512_mask_cmpge_epu32_mask(valid, g, _mm512_set1_epi32(1 << 24));
    const __mmask16 nz16 = _mm512_mask_cmpge_epu32_mask(valid, g, _mm512_set1_epi32(1 << 16));
    const __mmask16 nz8 = _mm512_mask_cmpge_epu32_mask(valid, g, _mm512_set1_epi32(1 << 8));
    const __mmask16 rigid = _mm512_mask_cmpeq_epi32_mask(valid, g, _mm512_set1_epi32(255));
    const __mmask16 masks[kClasses] = {rigid, static_cast<__mmask16>(valid & ~nz8 & ~rigid),
                                       static_cast<__mmask16>(nz8 & ~nz16), static_cast<__mmask16>(nz16 & ~nz24), nz24};
    const __m512i index = _mm512_add_epi32(lane, _mm512_set1_epi32(static_cast<int>(b.first + c)));
    for (int k = 0; k < kClasses; ++k) {
      _mm512_storeu_si512(b.lists[k] + count[k], _mm512_maskz_compress_epi32(masks[k], index));
      count[k] += static_cast<uint32_t>(OSSA_POPCOUNT(masks[k]));
    }
  }
  for (int k = 0; k < kClasses; ++k) b.count[k] = count[k];
}

// ---- direction decoding, 8 vertices at a time ----

using soa::unfold_octahedral;

/// The low (lo) or high 16 bits of each lane as a snorm16, decoded as OpenGL does.
OSSA_TARGET_AVX2 inline __m256 snorm16_lanes(__m256i g, bool high) {
  const __m256i v = high ? _mm256_srai_epi32(g, 16) : _mm256_srai_epi32(_mm256_slli_epi32(g, 16), 16);
  return _mm256_max_ps(_mm256_mul_ps(_mm256_cvtepi32_ps(v), _mm256_set1_ps(1.0f / 32767.0f)), _mm256_set1_ps(-1.0f));
}

/// Eight (x, y, z, w) from structure-of-arrays into out[0..7][4].
OSSA_TARGET_AVX2 inline void store_aos4(__m256 x, __m256 y, __m256 z, __m256 w, float (*out)[4]) {
  const __m256 t0 = _mm256_unpacklo_ps(x, y), t1 = _mm256_unpackhi_ps(x, y);
  const __m256 t2 = _mm256_unpacklo_ps(z, w), t3 = _mm256_unpackhi_ps(z, w);
  const __m256 v0 = _mm256_shuffle_ps(t0, t2, 0x44), v1 = _mm256_shuffle_ps(t0, t2, 0xee);
  const __m256 v2 = _mm256_shuffle_ps(t1, t3, 0x44), v3 = _mm256_shuffle_ps(t1, t3, 0xee);
  _mm256_store_ps(out[0], _mm256_permute2f128_ps(v0, v1, 0x20));
  _mm256_store_ps(out[2], _mm256_permute2f128_ps(v2, v3, 0x20));
  _mm256_store_ps(out[4], _mm256_permute2f128_ps(v0, v1, 0x31));
  _mm256_store_ps(out[6], _mm256_permute2f128_ps(v2, v3, 0x31));
}

/// Normals (and tangents) of the batch into b.normal / b.tangent, times the prescale. The words
/// are fetched with scalar loads (faster than gathers on Zen 4), then decoded 8 at a time.
template <bool kTangents>
OSSA_TARGET_AVX2 void decode_directions(const FastMesh& m, Batch& b) {
  alignas(32) uint32_t normal_words[kBatch];
  alignas(32) uint32_t tangent_words[kTangents ? 2 * kBatch : 1];
  const uint8_t* first = m.base + static_cast<size_t>(b.first) * m.stride;
  for (uint32_t i = 0; i < b.n; ++i) {
    const uint8_t* vx = first + static_cast<size_t>(i) * m.stride;
    normal_words[i] = load_u32(vx + m.off_normal);
    if constexpr (kTangents) {
      tangent_words[i] = load_u32(vx + m.off_tangent);
      tangent_words[kBatch + i] = load_u32(vx + m.off_tangent + 4);
    }
  }
  for (uint32_t i = b.n; i < ((b.n + 7) & ~7u); ++i) {
    normal_words[i] = 0;
    if constexpr (kTangents) tangent_words[i] = tangent_words[kBatch + i] = 0;
  }
  const __m256 sx = _mm256_set1_ps(m.prescale[0]), sy = _mm256_set1_ps(m.prescale[1]), sz = _mm256_set1_ps(m.prescale[2]);
  for (uint32_t c = 0; c < b.n; c += 8) {
    const __m256i gn = _mm256_load_si256(reinterpret_cast<const __m256i*>(normal_words + c));
    __m256 x = snorm16_lanes(gn, false), y = snorm16_lanes(gn, true), z;
    unfold_octahedral(x, y, z);
    store_aos4(_mm256_mul_ps(x, sx), _mm256_mul_ps(y, sy), _mm256_mul_ps(z, sz), _mm256_setzero_ps(), b.normal + c);
    if constexpr (kTangents) {
      const __m256i gt = _mm256_load_si256(reinterpret_cast<const __m256i*>(tangent_words + c));
      const __m256i gs = _mm256_load_si256(reinterpret_cast<const __m256i*>(tangent_words + kBatch + c));
      __m256 tx = snorm16_lanes(gt, false), ty = snorm16_lanes(gt, true), tz;
      unfold_octahedral(tx, ty, tz);
      // Bitangent sign: the sign of the third snorm16 (the low half of the second word).
      const __m256 sign = _mm256_or_ps(_mm256_set1_ps(1.0f),
                                       _mm256_castsi256_ps(_mm256_and_si256(_mm256_slli_epi32(gs, 16), _mm256_set1_epi32(INT32_MIN))));
      store_aos4(_mm256_mul_ps(tx, sx), _mm256_mul_ps(ty, sy), _mm256_mul_ps(tz, sz), sign, b.tangent + c);
    }
  }
}

// ---- the per-class loops ----

/// Blended matrix of the first K influences (K = 0: the first slot's matrix as it is), as
/// columns 0-1 and 2-3. `wb` receives the vertex's four weight bytes (loaded for K = 0 only when
/// kNeedWeights).
template <int K, Slots kSlots, bool kNeedWeights>
OSSA_TARGET_AVX2 inline void blend_matrix(const float* palette, const uint8_t* vx, uint32_t off_joints,
                                          uint32_t off_weights, __m256& a01, __m256& a23, uint32_t& wb) {
  uint64_t sb;
  wb = 0;
  if constexpr (kSlots == Slots::Packed) {
    const uint64_t both = load_u64(vx + off_joints);
    sb = both & 0xffffffffu;
    wb = static_cast<uint32_t>(both >> 32);
  } else {
    sb = kSlots == Slots::Wide ? load_u64(vx + off_joints) : load_u32(vx + off_joints);
    if constexpr (K > 0 || kNeedWeights) wb = load_u32(vx + off_weights);
  }
  const float* p0 = palette + 16 * slot_of<kSlots>(sb, 0);
  if constexpr (K == 0) {
    a01 = _mm256_loadu_ps(p0);
    a23 = _mm256_loadu_ps(p0 + 8);
  } else {
    __m256 w = _mm256_broadcast_ss(&kWeight[wb & 0xffu]);
    a01 = _mm256_mul_ps(w, _mm256_loadu_ps(p0));
    a23 = _mm256_mul_ps(w, _mm256_loadu_ps(p0 + 8));
    if constexpr (K > 1) {
      const float* p = palette + 16 * slot_of<kSlots>(sb, 1);
      w = _mm256_broadcast_ss(&kWeight[(wb >> 8) & 0xffu]);
      a01 = _mm256_fmadd_ps(w, _mm256_loadu_ps(p), a01);
      a23 = _mm256_fmadd_ps(w, _mm256_loadu_ps(p + 8), a23);
    }
    if constexpr (K > 2) {
      const float* p = palette + 16 * slot_of<kSlots>(sb, 2);
      w = _mm256_broadcast_ss(&kWeight[(wb >> 16) & 0xffu]);
      a01 = _mm256_fmadd_ps(w, _mm256_loadu_ps(p), a01);
      a23 = _mm256_fmadd_ps(w, _mm256_loadu_ps(p + 8), a23);
    }
    if constexpr (K > 3) {
      const float* p = palette + 16 * slot_of<kSlots>(sb, 3);
      w = _mm256_broadcast_ss(&kWeight[wb >> 24]);
      a01 = _mm256_fmadd_ps(w, _mm256_loadu_ps(p), a01);
      a23 = _mm256_fmadd_ps(w, _mm256_loadu_ps(p + 8), a23);
    }
  }
}

/// c0 * v.x + c1 * v.y + c2 * v.z + c3 * v.w for the blended columns a01 = (c0, c1), a23 = (c2, c3)
/// and v given in both 128-bit lanes (x, y, z, w, x, y, z, w): in-lane permutes only (vpermilps),
/// which a broadcast or duplicating load sets up for free. (Lane-crossing vpermps from one xmm
/// measured ~10% slower per vertex on Zen 5.)
OSSA_TARGET_AVX2 inline __m128 transform_dup(__m256 a01, __m256 a23, __m256 v) {
  const __m256 xy = _mm256_permutevar_ps(v, _mm256_setr_epi32(0, 0, 0, 0, 1, 1, 1, 1));
  const __m256 zw = _mm256_permutevar_ps(v, _mm256_setr_epi32(2, 2, 2, 2, 3, 3, 3, 3));
  const __m256 t = _mm256_fmadd_ps(a23, zw, _mm256_mul_ps(a01, xy));
  return _mm_add_ps(_mm256_castps256_ps128(t), _mm256_extractf128_ps(t, 1));
}

OSSA_TARGET_AVX2 inline void store3(float* out, __m128 r) {
  _mm_storel_pi(reinterpret_cast<__m64*>(out), r);
  _mm_store_ss(out + 2, _mm_movehl_ps(r, r));
}

/// Stores xyz of r at out. A range loop writes vertices in increasing order, so when another
/// vertex follows it may store all 16 bytes (kWide: one store, no shuffle): the stray w lands on
/// the next vertex's x, which that vertex overwrites later. The buffer's last vertex stores 12.
template <bool kWide>
OSSA_TARGET_AVX2 inline void store_xyz(float* out, __m128 r) {
  if constexpr (kWide) _mm_storeu_ps(out, r);
  else store3(out, r);
}

/// Whether a vertex with weight bytes wb may be skinned by class K's loop: K = 0 needs the single
/// weight 255; K = 1..3 needs every weight past influence K - 1 zero (a lower class blends its zero
/// weights harmlessly); K = 4 takes anything. Accumulated as bits that must stay zero.
template <int K>
inline uint32_t outside_class(uint32_t wb) {
  if constexpr (K == 0) return wb ^ 255u;
  else if constexpr (K < 4) return wb >> (8 * K);
  else return 0;
}

/// What one vertex's loop body reads and writes: the vertex's bytes, its decoded directions (in
/// the batch) and its outputs.
struct VertexPointers {
  const uint8_t* vx;
  const float* normal;   // b.normal row
  const float* tangent;  // b.tangent row
  float* position_out;
  float* normal_out;
  float* tangent_out;
};

/// Skins one vertex of class K. kWide: the xyz outputs may be stored as 16 bytes (another vertex
/// follows in memory order and is written later). Returns outside_class<K> of its weights (only
/// computed when kCheck).
template <int K, bool kCheck, bool kWide, Slots kSlots, bool kPositions, bool kNormals, bool kTangents>
[[gnu::always_inline]] OSSA_TARGET_AVX2 inline uint32_t skin_vertex(const float* palette, const VertexPointers& at,
                                                                    uint32_t off_position, uint32_t off_joints,
                                                                    uint32_t off_weights) {
  __m256 a01, a23;
  uint32_t wb;
  blend_matrix<K, kSlots, kCheck>(palette, at.vx, off_joints, off_weights, a01, a23, wb);
  if constexpr (kPositions) {
    // The four unorm16 words twice (one duplicating load), widened: (x, y, z, 1) in both lanes.
    const __m256 scale = _mm256_setr_ps(1.0f / 65535.0f, 1.0f / 65535.0f, 1.0f / 65535.0f, 0.0f, 1.0f / 65535.0f,
                                        1.0f / 65535.0f, 1.0f / 65535.0f, 0.0f);
    const __m256 w_one = _mm256_setr_ps(0.0f, 0.0f, 0.0f, 1.0f, 0.0f, 0.0f, 0.0f, 1.0f);
    const __m128i q2 = _mm_castpd_si128(_mm_loaddup_pd(reinterpret_cast<const double*>(at.vx + off_position)));
    const __m256 p = _mm256_fmadd_ps(_mm256_cvtepi32_ps(_mm256_cvtepu16_epi32(q2)), scale, w_one);
    store_xyz<kWide>(at.position_out, transform_dup(a01, a23, p));
  }
  if constexpr (kNormals)
    store_xyz<kWide>(at.normal_out, transform_dup(a01, a23, _mm256_broadcast_ps(reinterpret_cast<const __m128*>(at.normal))));
  if constexpr (kTangents) {
    const __m128 t = _mm_load_ps(at.tangent);
    // w of t is the sign: transform xyz only, then put the sign back.
    const __m128 r = transform_dup(a01, a23, _mm256_blend_ps(_mm256_broadcast_ps(reinterpret_cast<const __m128*>(at.tangent)), _mm256_setzero_ps(), 0x88));
    _mm_storeu_ps(at.tangent_out, _mm_blend_ps(r, t, 0x8));
  }
  return kCheck ? outside_class<K>(wb) : 0u;
}

/// Class K's loop over a batch's list of n vertices (any order).
template <int K, Slots kSlots, bool kPositions, bool kNormals, bool kTangents>
OSSA_TARGET_AVX2 void skin_class(const uint32_t* list, uint32_t n, const float* palette, const FastMesh& mesh,
                                 const Batch& b, Outputs out) {
  const uint8_t* const base = mesh.base;
  const size_t stride = mesh.stride;
  const uint32_t off_position = mesh.off_position, off_joints = mesh.off_joints, off_weights = mesh.off_weights;
  for (uint32_t i = 0; i < n; ++i) {
    const size_t v = list[i];
    const VertexPointers at{base + v * stride,
                            b.normal[v - b.first],
                            b.tangent[v - b.first],
                            kPositions ? out.positions + 3 * v : nullptr,
                            kNormals ? out.normals + 3 * v : nullptr,
                            kTangents ? out.tangents + 4 * v : nullptr};
    skin_vertex<K, false, false, kSlots, kPositions, kNormals, kTangents>(palette, at, off_position, off_joints, off_weights);
  }
}

/// Class K's loop over the contiguous vertices [b.first, b.first + b.n) of a class-ordered mesh,
/// walking every pointer forward (no index arithmetic per vertex). Returns the OR of
/// outside_class<K> over them: non-zero means some vertex did not belong to the range (and its
/// outputs are wrong).
template <int K, Slots kSlots, bool kPositions, bool kNormals, bool kTangents>
OSSA_TARGET_AVX2 uint32_t skin_range(const float* palette, const FastMesh& mesh, const Batch& b, Outputs out) {
  const size_t stride = mesh.stride;
  const uint32_t off_position = mesh.off_position, off_joints = mesh.off_joints, off_weights = mesh.off_weights;
  const size_t first = b.first;
  VertexPointers at{mesh.base + first * stride,
                    b.normal[0],
                    b.tangent[0],
                    kPositions ? out.positions + 3 * first : nullptr,
                    kNormals ? out.normals + 3 * first : nullptr,
                    kTangents ? out.tangents + 4 * first : nullptr};
  // The mesh's very last vertex stores 12 bytes per stream; every other one may store 16.
  const uint32_t wide = b.first + b.n == mesh.count ? b.n - 1 : b.n;
  uint32_t outside = 0;
#pragma GCC unroll 2
  for (uint32_t i = 0; i < wide; ++i) {
    outside |= skin_vertex<K, true, true, kSlots, kPositions, kNormals, kTangents>(palette, at, off_position, off_joints, off_weights);
    at.vx += stride;
    at.normal += 4;
    at.tangent += 4;
    if constexpr (kPositions) at.position_out += 3;
    if constexpr (kNormals) at.normal_out += 3;
    if constexpr (kTangents) at.tangent_out += 4;
  }
  if (wide < b.n)
    outside |= skin_vertex<K, true, false, kSlots, kPositions, kNormals, kTangents>(palette, at, off_position, off_joints, off_weights);
  return outside;
}

/// Class K's loop over the contiguous vertices [first, first + n) of a class-ordered mesh, eight at
/// a time (soa_kernel.h), positions and normals (renormalized as out asks) written directly.
/// Returns n, or the index (from first) of the block where a vertex did not belong to the class:
/// outputs from there on are not written, or wrong.
template <int K, Slots kSlots, bool kPositions, bool kNormals>
OSSA_TARGET_AVX2 uint32_t skin_range_soa(const float* palette, const FastMesh& m, uint32_t first, uint32_t n, Outputs out,
                                          bool avx512) {
  constexpr bool kWide = kSlots == Slots::Wide, kPacked = kSlots == Slots::Packed;
  const soa::Layout l{palette, kWeight.data(), m.stride, m.off_position, m.off_normal, m.off_joints, m.off_weights,
                      {m.prescale[0], m.prescale[1], m.prescale[2]}, out.renormalize};
  const uint8_t* vx = m.base + static_cast<size_t>(first) * m.stride;
  const soa::Cursor<kPacked> at{vx + m.off_joints, vx + m.off_weights, vx + m.off_position, vx + m.off_normal};
  float* const p = kPositions ? out.positions + 3 * static_cast<size_t>(first) : nullptr;
  float* const q = kNormals ? out.normals + 3 * static_cast<size_t>(first) : nullptr;
  // The cooker's layout: 16 bytes from the position stay inside the vertex, and hold the normal.
  if (m.off_position + 16 <= m.stride && (!kNormals || m.off_normal == m.off_position + 8))
    return avx512 ? soa::range_avx512<K, kWide, kPacked, kPositions, kNormals, true>(at, n, l, p, q)
                  : soa::range_avx2<K, kWide, kPacked, kPositions, kNormals, true>(at, n, l, p, q);
  return avx512 ? soa::range_avx512<K, kWide, kPacked, kPositions, kNormals, false>(at, n, l, p, q)
                : soa::range_avx2<K, kWide, kPacked, kPositions, kNormals, false>(at, n, l, p, q);
}

// ---- renormalization of the batch's outputs ----

using soa::inverse_length;

/// Normalizes 8 packed xyz vectors in place (rsqrt + one Newton step, as soa_kernel.h does).
OSSA_TARGET_AVX2 inline void normalize_xyz8(float* p) {
  const __m256 a = _mm256_loadu_ps(p), b = _mm256_loadu_ps(p + 8), c = _mm256_loadu_ps(p + 16);
  const __m256 qa = _mm256_mul_ps(a, a), qb = _mm256_mul_ps(b, b), qc = _mm256_mul_ps(c, c);
  // a = x0 y0 z0 x1 y1 z1 x2 y2 | b = z2 x3 y3 z3 x4 y4 z4 x5 | c = y5 z5 x6 y6 z6 x7 y7 z7
  const __m256 xx = _mm256_blend_ps(_mm256_blend_ps(_mm256_permutevar8x32_ps(qa, _mm256_setr_epi32(0, 3, 6, 0, 0, 0, 0, 0)),
                                                    _mm256_permutevar8x32_ps(qb, _mm256_setr_epi32(0, 0, 0, 1, 4, 7, 0, 0)), 0x38),
                                    _mm256_permutevar8x32_ps(qc, _mm256_setr_epi32(0, 0, 0, 0, 0, 0, 2, 5)), 0xc0);
  const __m256 yy = _mm256_blend_ps(_mm256_blend_ps(_mm256_permutevar8x32_ps(qa, _mm256_setr_epi32(1, 4, 7, 0, 0, 0, 0, 0)),
                                                    _mm256_permutevar8x32_ps(qb, _mm256_setr_epi32(0, 0, 0, 2, 5, 0, 0, 0)), 0x18),
                                    _mm256_permutevar8x32_ps(qc, _mm256_setr_epi32(0, 0, 0, 0, 0, 0, 3, 6)), 0xe0);
  const __m256 zz = _mm256_blend_ps(_mm256_blend_ps(_mm256_permutevar8x32_ps(qa, _mm256_setr_epi32(2, 5, 0, 0, 0, 0, 0, 0)),
                                                    _mm256_permutevar8x32_ps(qb, _mm256_setr_epi32(0, 0, 0, 3, 6, 0, 0, 0)), 0x1c),
                                    _mm256_permutevar8x32_ps(qc, _mm256_setr_epi32(0, 0, 0, 0, 0, 1, 4, 7)), 0xe0);
  const __m256 inv = inverse_length(_mm256_add_ps(_mm256_add_ps(xx, yy), zz));
  _mm256_storeu_ps(p, _mm256_mul_ps(a, _mm256_permutevar8x32_ps(inv, _mm256_setr_epi32(0, 0, 0, 1, 1, 1, 2, 2))));
  _mm256_storeu_ps(p + 8, _mm256_mul_ps(b, _mm256_permutevar8x32_ps(inv, _mm256_setr_epi32(2, 3, 3, 3, 4, 4, 4, 5))));
  _mm256_storeu_ps(p + 16, _mm256_mul_ps(c, _mm256_permutevar8x32_ps(inv, _mm256_setr_epi32(5, 5, 6, 6, 6, 7, 7, 7))));
}

/// Normalizes n packed xyz vectors in place, 8 at a time; the tail through a zero-padded copy, so
/// that every vector is rounded alike (the structure-of-arrays kernel's results are bit-identical).
OSSA_TARGET_AVX2 void normalize_xyz(float* p, uint32_t n) {
  uint32_t i = 0;
  for (; i + 8 <= n; i += 8, p += 24) normalize_xyz8(p);
  if (i < n) {
    float tail[24] = {};
    std::memcpy(tail, p, 12 * (n - i));
    normalize_xyz8(tail);
    std::memcpy(p, tail, 12 * (n - i));
  }
}

/// Normalizes the xyz of n packed xyzw vectors in place (w kept), 2 per register.
OSSA_TARGET_AVX2 void normalize_xyz_w(float* p, uint32_t n) {
  uint32_t i = 0;
  for (; i + 2 <= n; i += 2, p += 8) {
    const __m256 t = _mm256_loadu_ps(p);
    const __m256 xyz = _mm256_blend_ps(t, _mm256_setzero_ps(), 0x88);
    __m256 len2 = _mm256_mul_ps(xyz, xyz);
    len2 = _mm256_add_ps(len2, _mm256_permute_ps(len2, 0xb1));
    len2 = _mm256_add_ps(len2, _mm256_permute_ps(len2, 0x4e));
    _mm256_storeu_ps(p, _mm256_blend_ps(_mm256_mul_ps(xyz, inverse_length(len2)), t, 0x88));
  }
  if (i < n) {
    glm::vec3 v;
    std::memcpy(&v[0], p, 12);
    v = normalize_or_zero(v);
    std::memcpy(p, &v[0], 12);
  }
}

template <bool kNormals, bool kTangents>
OSSA_TARGET_AVX2 void normalize_batch(const Batch& b, Outputs out) {
  if (!out.renormalize) return;
  if constexpr (kNormals) normalize_xyz(out.normals + 3 * static_cast<size_t>(b.first), b.n);
  if constexpr (kTangents) normalize_xyz_w(out.tangents + 4 * static_cast<size_t>(b.first), b.n);
}

template <Slots kSlots, bool kPositions, bool kNormals, bool kTangents>
OSSA_TARGET_AVX2 void skin_batch(const float* palette, const FastMesh& m, const Batch& b, Outputs out) {
  skin_class<0, kSlots, kPositions, kNormals, kTangents>(b.lists[0], b.count[0], palette, m, b, out);
  skin_class<1, kSlots, kPositions, kNormals, kTangents>(b.lists[1], b.count[1], palette, m, b, out);
  skin_class<2, kSlots, kPositions, kNormals, kTangents>(b.lists[2], b.count[2], palette, m, b, out);
  skin_class<3, kSlots, kPositions, kNormals, kTangents>(b.lists[3], b.count[3], palette, m, b, out);
  skin_class<4, kSlots, kPositions, kNormals, kTangents>(b.lists[4], b.count[4], palette, m, b, out);
  normalize_batch<kNormals, kTangents>(b, out);
}

/// Vertices [first, count) batch by batch, each classified first (any vertex order).
template <Slots kSlots, bool kPositions, bool kNormals, bool kTangents>
OSSA_TARGET_AVX2 void skin_classified(const float* palette, const FastMesh& m, Outputs out, bool avx512, uint32_t first) {
  Batch b;
  for (; first < m.count; first += kBatch) {
    b.first = first;
    b.n = std::min(kBatch, m.count - first);
    if (avx512) classify_avx512(m, b);
    else classify_avx2(m, b);
    if constexpr (kNormals || kTangents) decode_directions<kTangents>(m, b);
    skin_batch<kSlots, kPositions, kNormals, kTangents>(palette, m, b, out);
  }
}

// ---- meshes ordered by influence class ----
//
// The cooker orders a skinned mesh's vertices by class (cooker/mesh/mesh_build.cpp,
// influence_class_order), so the classes are five contiguous ranges and each runs its loop straight
// through: no classification pass, no lists, outputs written in order. Nothing is trusted: the
// range ends come from a binary search that assumes the order, and every range loop checks each
// vertex it skins against its class (outside_class, one shift and OR on bytes it loads anyway).
// A range that fails is redone, with everything after it, by the classified path; a mesh whose
// first kOrderProbe vertices are out of order (an older cook, another tool's file) goes there
// from the start, so it pays a 64-vertex probe and nothing else. With normals and no tangents a
// range runs soa_kernel.h's eight-vertex blocks (skin_range_soa), which check their vertices the
// same way and report the first failing block; positions alone, or with tangents, run skin_range.

constexpr uint32_t kOrderProbe = 64;

inline uint32_t weight_word(const FastMesh& m, uint32_t v) {
  return load_u32(m.base + static_cast<size_t>(v) * m.stride + m.off_weights);
}

/// Whether the first kOrderProbe vertices' classes never decrease.
inline bool ordered_start(const FastMesh& m) {
  const uint32_t n = std::min(m.count, kOrderProbe);
  int last = 0;
  for (uint32_t v = 0; v < n; ++v) {
    const int c = influence_class(weight_word(m, v));
    if (c < last) return false;
    last = c;
  }
  return true;
}

/// First vertex in [lo, count) whose class exceeds c, assuming classes never decrease.
inline uint32_t class_end(const FastMesh& m, uint32_t lo, int c) {
  uint32_t hi = m.count;
  while (lo < hi) {
    const uint32_t mid = lo + (hi - lo) / 2;
    if (influence_class(weight_word(m, mid)) > c) hi = mid;
    else lo = mid + 1;
  }
  return lo;
}

template <Slots kSlots, bool kPositions, bool kNormals, bool kTangents>
OSSA_TARGET_AVX2 void skin_fast(const float* palette, const FastMesh& m, Outputs out, bool avx512) {
  if (!ordered_start(m)) {
    skin_classified<kSlots, kPositions, kNormals, kTangents>(palette, m, out, avx512, 0);
    return;
  }
  Batch b;
  uint32_t begin = 0;
  const auto run = [&](auto k) -> bool {
    constexpr int K = decltype(k)::value;
    const uint32_t end = K == kClasses - 1 ? m.count : class_end(m, begin, K);
    if constexpr (kNormals && !kTangents) {
      const uint32_t done = skin_range_soa<K, kSlots, kPositions, kNormals>(palette, m, begin, end - begin, out, avx512);
      if (done != end - begin) {
        skin_classified<kSlots, kPositions, kNormals, kTangents>(palette, m, out, avx512, begin + done);
        return false;
      }
      begin = end;
      return true;
    }
    for (b.first = begin; b.first < end; b.first += kBatch) {
      b.n = std::min(kBatch, end - b.first);
      if constexpr (kNormals || kTangents) decode_directions<kTangents>(m, b);
      if (skin_range<K, kSlots, kPositions, kNormals, kTangents>(palette, m, b, out) != 0) {
        skin_classified<kSlots, kPositions, kNormals, kTangents>(palette, m, out, avx512, b.first);
        return false;
      }
      normalize_batch<kNormals, kTangents>(b, out);
    }
    begin = end;
    return true;
  };
  run(std::integral_constant<int, 0>{}) && run(std::integral_constant<int, 1>{}) &&
      run(std::integral_constant<int, 2>{}) && run(std::integral_constant<int, 3>{}) &&
      run(std::integral_constant<int, 4>{});
}

template <Slots kSlots, bool kPositions>
void skin_fast_directions(const float* palette, const FastMesh& m, Outputs out, bool avx512) {
  if (out.tangents != nullptr) {
    if (out.normals != nullptr) skin_fast<kSlots, kPositions, true, true>(palette, m, out, avx512);
    else skin_fast<kSlots, kPositions, false, true>(palette, m, out, avx512);
  } else if (out.normals != nullptr) {
    skin_fast<kSlots, kPositions, true, false>(palette, m, out, avx512);
  } else if constexpr (kPositions) {
    skin_fast<kSlots, true, false, false>(palette, m, out, avx512);
  }
}

template <Slots kSlots>
void skin_fast_streams(const float* palette, const FastMesh& m, Outputs out, bool avx512) {
  if (out.positions != nullptr) skin_fast_directions<kSlots, true>(palette, m, out, avx512);
  else skin_fast_directions<kSlots, false>(palette, m, out, avx512);
}

SkinningIsa best_isa() {
  if (detail::cpu_has_avx512()) return SkinningIsa::Avx512;
  return detail::cpu_has_avx2_fma() ? SkinningIsa::Avx2 : SkinningIsa::Portable;
}

/// The fast paths read the cooker's quantized layout (8- or 16-bit slots), nothing else.
bool fast_layout(const MeshFacts& m, Outputs out, FastMesh* f) {
  if (m.joints == nullptr || m.position == nullptr || m.position->format() != VertexFormat::Unorm16x4) return false;
  if (m.weights->format() != VertexFormat::Unorm8x4) return false;
  if ((out.normals != nullptr || out.tangents != nullptr) &&
      (m.normal == nullptr || m.normal->format() != VertexFormat::Snorm16x2))
    return false;
  if (out.tangents != nullptr && m.tangent->format() != VertexFormat::Snorm16x4) return false;
  *f = FastMesh{m.base,
                m.count,
                m.stride,
                m.position->offset(),
                m.normal != nullptr ? m.normal->offset() : 0u,
                m.tangent != nullptr ? m.tangent->offset() : 0u,
                m.joints->offset(),
                m.weights->offset(),
                m.joints->format() == VertexFormat::Uint16x4                   ? Slots::Wide
                : m.weights->offset() == static_cast<uint32_t>(m.joints->offset()) + 4u ? Slots::Packed
                                                                                         : Slots::Narrow,
                {m.direction_prescale.x, m.direction_prescale.y, m.direction_prescale.z}};
  return true;
}

#endif  // OSSA_SKIN_X86

/// The selected implementation; the first read detects the CPU (thread-safe static init).
std::atomic<SkinningIsa>& selected_isa() {
  static std::atomic<SkinningIsa> selected{best_isa()};
  return selected;
}

}  // namespace

SkinningIsa skinning_isa() { return selected_isa().load(std::memory_order_relaxed); }

bool set_skinning_isa(SkinningIsa isa) {
  if (static_cast<uint8_t>(isa) > static_cast<uint8_t>(best_isa())) return false;
  selected_isa().store(isa, std::memory_order_relaxed);
  return true;
}

// ---------------------------------------------------------------------------------------------

namespace {

/// Slot s's constant palette half: inverse_bind[s] * D, D = translate(offset) * scale(scale) applied
/// on the right (scale columns 0-2, move column 3). A mesh without slots gets D alone.
glm::mat4 bind_matrix(const MeshFacts& m, std::span<const fb::Mat4> inverse_bind, size_t s) {
  glm::mat4 a(1.0f);
  if (!inverse_bind.empty()) std::memcpy(&a[0][0], inverse_bind[s].m()->data(), sizeof a);
  if (m.dequantize) {
    a[3] = a[0] * m.offset.x + a[1] * m.offset.y + a[2] * m.offset.z + a[3];
    for (int c = 0; c < 3; ++c) a[c] = a[c] * m.scale[c];
  }
  return a;
}

/// out = a * b, column-major. Column c of the product is sum_k a.col(k) * b[c][k]: four broadcasts
/// and multiply-adds per column in SSE (x86-64's baseline); GLM's generic product runs scalar.
inline void palette_product(const glm::mat4& a, const glm::mat4& b, glm::mat4& out) {
#if OSSA_SKIN_X86
  const __m128 a0 = _mm_loadu_ps(&a[0][0]), a1 = _mm_loadu_ps(&a[1][0]), a2 = _mm_loadu_ps(&a[2][0]),
               a3 = _mm_loadu_ps(&a[3][0]);
  for (int c = 0; c < 4; ++c) {
    const __m128 lo = _mm_add_ps(_mm_mul_ps(a0, _mm_set1_ps(b[c][0])), _mm_mul_ps(a1, _mm_set1_ps(b[c][1])));
    const __m128 hi = _mm_add_ps(_mm_mul_ps(a2, _mm_set1_ps(b[c][2])), _mm_mul_ps(a3, _mm_set1_ps(b[c][3])));
    _mm_storeu_ps(&out[c][0], _mm_add_ps(lo, hi));
  }
#else
  out = a * b;
#endif
}

const glm::mat4 kIdentity(1.0f);

#if OSSA_SKIN_X86
/// palette[s] = model[joints[s]] * bind[s] for n slots, two output columns per 256-bit register:
/// model's columns duplicated into both lanes (broadcast loads), bind's columns c and c + 1
/// loaded as one register and each element k spread over its lane with an in-lane permute. Four
/// multiply-adds per column pair instead of SSE's broadcast, multiply and add per element:
/// about half the instructions (53 slots: ~120 ns on Zen 5, BM_SkinningMatricesPrepared; BM_Frame,
/// which builds this palette, ran ~7% faster with it, back to back).
OSSA_TARGET_AVX2 void palettes_avx2(const uint16_t* joints, const glm::mat4* bind, const glm::mat4* model,
                                    size_t model_count, glm::mat4* palette, size_t n) {
  for (size_t s = 0; s < n; ++s) {
    const float* a = joints[s] < model_count ? &model[joints[s]][0][0] : &kIdentity[0][0];
    const __m256 a0 = _mm256_broadcast_ps(reinterpret_cast<const __m128*>(a));
    const __m256 a1 = _mm256_broadcast_ps(reinterpret_cast<const __m128*>(a + 4));
    const __m256 a2 = _mm256_broadcast_ps(reinterpret_cast<const __m128*>(a + 8));
    const __m256 a3 = _mm256_broadcast_ps(reinterpret_cast<const __m128*>(a + 12));
    const float* b = &bind[s][0][0];
    float* out = &palette[s][0][0];
    for (int c = 0; c < 4; c += 2) {
      const __m256 bc = _mm256_loadu_ps(b + 4 * c);  // columns c, c + 1
      __m256 r = _mm256_mul_ps(a0, _mm256_permute_ps(bc, 0x00));
      r = _mm256_fmadd_ps(a1, _mm256_permute_ps(bc, 0x55), r);
      r = _mm256_fmadd_ps(a2, _mm256_permute_ps(bc, 0xaa), r);
      r = _mm256_fmadd_ps(a3, _mm256_permute_ps(bc, 0xff), r);
      _mm256_storeu_ps(out + 4 * c, r);
    }
  }
}
#endif

}  // namespace

void skinning_matrices(const MeshView& mesh, std::span<const glm::mat4> model, std::span<glm::mat4> palette) {
  const detail::FlushDenormals flush;  // internal/float_env.h
  const MeshFacts m = mesh_facts(mesh);
  const std::span<const uint16_t> joints = mesh.joints();
  const std::span<const fb::Mat4> inverse_bind = mesh.inverse_bind();
  if (joints.empty()) {
    assert(!palette.empty());
    if (!palette.empty()) palette[0] = bind_matrix(m, inverse_bind, 0);
    return;
  }
  assert(palette.size() >= joints.size());
  const size_t n = std::min(palette.size(), joints.size());
  for (size_t s = 0; s < n; ++s) {
    assert(joints[s] < model.size());
    palette_product(joints[s] < model.size() ? model[joints[s]] : kIdentity, bind_matrix(m, inverse_bind, s),
                    palette[s]);
  }
}

void prepare_bind_matrices(const MeshView& mesh, std::span<glm::mat4> bind) {
  const MeshFacts m = mesh_facts(mesh);
  const std::span<const fb::Mat4> inverse_bind = mesh.inverse_bind();
  const size_t slots = std::max<size_t>(1, inverse_bind.size());
  assert(bind.size() >= slots);
  for (size_t s = 0; s < std::min(bind.size(), slots); ++s) bind[s] = bind_matrix(m, inverse_bind, s);
}

void skinning_matrices(std::span<const uint16_t> joints, std::span<const glm::mat4> bind,
                       std::span<const glm::mat4> model, std::span<glm::mat4> palette) {
  const detail::FlushDenormals flush;  // internal/float_env.h
  if (joints.empty()) {
    if (!palette.empty() && !bind.empty()) palette[0] = bind[0];
    return;
  }
  const size_t n = std::min({joints.size(), bind.size(), palette.size()});
#if OSSA_SKIN_X86
  if (skinning_isa() != SkinningIsa::Portable) {
    palettes_avx2(joints.data(), bind.data(), model.data(), model.size(), palette.data(), n);
    return;
  }
#endif
  for (size_t s = 0; s < n; ++s)
    palette_product(joints[s] < model.size() ? model[joints[s]] : kIdentity, bind[s], palette[s]);
}

void skin_cpu(const MeshView& mesh, std::span<const glm::mat4> palette, SkinningMethod method, SkinnedStreams out) {
  const MeshFacts m = mesh_facts(mesh);
  if (m.count == 0 || m.position == nullptr) return;
  // Size preconditions: asserted in debug builds; a release build skips a stream that does not
  // fit (or, with too small a palette, everything) rather than read or write out of bounds.
  const size_t n = m.count;
  Outputs o;
  o.renormalize = out.renormalize;
  if (!out.positions.empty()) {
    assert(out.positions.size() >= 3 * n);
    if (out.positions.size() >= 3 * n) o.positions = out.positions.data();
  }
  if (!out.normals.empty()) {
    assert(m.normal != nullptr && out.normals.size() >= 3 * n);
    if (m.normal != nullptr && out.normals.size() >= 3 * n) o.normals = out.normals.data();
  }
  if (!out.tangents.empty()) {
    assert(m.tangent != nullptr && out.tangents.size() >= 4 * n);
    if (m.tangent != nullptr && out.tangents.size() >= 4 * n) o.tangents = out.tangents.data();
  }
  if (o.positions == nullptr && o.normals == nullptr && o.tangents == nullptr) return;
  const detail::FlushDenormals flush;  // internal/float_env.h
  const size_t needed = m.joints != nullptr ? m.slot_count : 1;
  assert(palette.size() >= needed);
  if (palette.size() < needed || needed == 0) return;

  if (method == SkinningMethod::DualQuaternion) {
    skin_dual_quaternion(m, palette, o);
    return;
  }
#if OSSA_SKIN_X86
  FastMesh f;
  const SkinningIsa which = skinning_isa();
  if (which != SkinningIsa::Portable && fast_layout(m, o, &f)) {
    const bool avx512 = which == SkinningIsa::Avx512;
    switch (f.slots) {
      case Slots::Narrow: skin_fast_streams<Slots::Narrow>(&palette[0][0][0], f, o, avx512); break;
      case Slots::Wide: skin_fast_streams<Slots::Wide>(&palette[0][0][0], f, o, avx512); break;
      case Slots::Packed: skin_fast_streams<Slots::Packed>(&palette[0][0][0], f, o, avx512); break;
    }
    return;
  }
#endif
  skin_linear_portable(m, palette.data(), o);
}

}  // namespace ossa
