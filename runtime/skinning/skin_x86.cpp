// skin_x86.cpp — skin_cpu's x86 fast paths for the cooker's quantized layout (Position Unorm16x4,
// Normal Snorm16x2, Tangent Snorm16x4, Joints Uint8x4 / Uint16x4, Weights Unorm8x4): the per-class
// loops and the drivers that run them over a class-ordered mesh or a classified batch.
//
// Why it is shaped so: intrinsics rather than target_clones, picked at run time with internal/cpu.h's
// queries (the default build runs on any x86-64) through target attributes on each function, so no
// per-file flags. Every vertex has its own matrices, so the work is array-of-structures per vertex
// (a structure-of-arrays form needs 12 gathers per influence, and gathers measured ~1.4 cycles per
// element on Zen 4), and what makes it fast is in-register shuffles and rsqrt, which
// auto-vectorized clones do not produce. Influence counts vary from vertex to vertex with no
// pattern, so each influence class runs a loop specialized for it (skin_internal.h's Batch).
// The batch-level steps (classification, direction decoding, renormalization) are in
// skin_x86_batch.cpp; the eight-vertex structure-of-arrays kernel is soa_kernel.h.
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
// influence class" below); one skinned for positions alone, where 512-bit operations run at full
// width, takes skin_positions_quad: four vertices a step, their sums done two vertices per register.
// The per-vertex transforms use 256-bit registers on both paths: on Zen 4, which executes a
// 512-bit operation as two 256-bit halves, a 16-wide per-vertex kernel measured ~25% slower (more
// cross-lane shuffles for the same arithmetic). The range loops' AVX-512 copy blends a vertex's
// matrix in one 512-bit register (one FMA per influence instead of two): positions alone ~8%
// faster on Zen 5, whose 512-bit units are full width, and used only where they are full width
// (not on Zen 4: cpu_avx512_split). The classification is where AVX-512 pays most. Scalar word
// loads rather than gathers in steps 1 and 2: measured faster on Zen 4.
// Palette matrices are 64 bytes read as 32- or 64-byte loads; skin_quantized copies a palette
// that is not 64-byte aligned (a std::vector<glm::mat4> is aligned to 16) to one that is, since a
// load across two cache lines costs two (~7-10% of a call on arnaud, Zen 5, for a 3.4 KB copy).

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <type_traits>

#include <ossa/format/vertex_codec.h>

#include "skinning/skin_internal.h"

#if OSSA_SKIN_X86
#include "skinning/soa_kernel.h"

namespace ossa::skin_detail {
namespace {

// ---- the per-class loops ----

/// Blended matrix of the first K influences (K = 0: the first slot's matrix as it is), as
/// columns 0-1 and 2-3. `wb` receives the vertex's four weight bytes (loaded for K = 0 only when
/// kNeedWeights). Slots and weights are read byte by byte (16-bit slots word by word): a load
/// each, where taking a word apart costs two or three shifts and masks per influence (the slots'
/// 32-bit word taken apart measured 3-8% slower for positions on Zen 2 too).
template <int K, Slots kSlots, bool kNeedWeights>
OSSA_TARGET_AVX2 inline void blend_matrix(const float* palette, const uint8_t* vx, ptrdiff_t off_joints,
                                          ptrdiff_t off_weights, __m256& a01, __m256& a23, uint32_t& wb) {
  const uint8_t* const j = vx + off_joints;
  const uint8_t* const w = kSlots == Slots::Packed ? j + 4 : vx + off_weights;
  const auto matrix = [&](int k) { return soa::slot_matrix<kSlots == Slots::Wide>(palette, j, k); };
  wb = 0;
  if constexpr (K > 0 || kNeedWeights) wb = load_u32(w);
  const float* p = matrix(0);
  if constexpr (K == 0) {
    a01 = _mm256_loadu_ps(p);
    a23 = _mm256_loadu_ps(p + 8);
  } else {
    __m256 wk = _mm256_broadcast_ss(&kWeight[w[0]]);
    a01 = _mm256_mul_ps(wk, _mm256_loadu_ps(p));
    a23 = _mm256_mul_ps(wk, _mm256_loadu_ps(p + 8));
#pragma GCC unroll 4
    for (int k = 1; k < K; ++k) {
      p = matrix(k);
      wk = _mm256_broadcast_ss(&kWeight[w[k]]);
      a01 = _mm256_fmadd_ps(wk, _mm256_loadu_ps(p), a01);
      a23 = _mm256_fmadd_ps(wk, _mm256_loadu_ps(p + 8), a23);
    }
  }
}

/// soa::blend512 of the class-K vertex whose joints are at j; `wb` receives its weight word.
template <int K, Slots kSlots>
[[gnu::always_inline]] OSSA_TARGET_AVX512 inline __m512 matrix512(const float* palette, const uint8_t* j,
                                                                  ptrdiff_t off_weights, uint32_t& wb) {
  const uint8_t* const w = kSlots == Slots::Packed ? j + 4 : j + off_weights;
  wb = load_u32(w);
  return soa::blend512<K, kSlots == Slots::Wide>(j, w, palette, kWeight.data());
}

/// blend_matrix for the AVX-512 copy of the range loops: the blend in one 512-bit register (one
/// FMA per influence where the 256-bit form needs two), split into the same columns. Rounds as
/// blend_matrix does (the same products and sums per element). Not always_inline (an AVX2
/// function may not inline it): skin_range_avx512 flattens its calls.
template <int K, Slots kSlots, bool kNeedWeights>
OSSA_TARGET_AVX512 inline void blend_matrix512(const float* palette, const uint8_t* vx, ptrdiff_t off_joints,
                                               ptrdiff_t off_weights, __m256& a01, __m256& a23, uint32_t& wb) {
  if constexpr (K == 0) {
    blend_matrix<K, kSlots, kNeedWeights>(palette, vx, off_joints, off_weights, a01, a23, wb);
  } else {
    const __m512 m = matrix512<K, kSlots>(palette, vx + off_joints, off_weights - off_joints, wb);
    a01 = _mm512_castps512_ps256(m);
    a23 = _mm512_extractf32x8_ps(m, 1);
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

/// What one vertex's loop body reads and writes: a pointer into the vertex's bytes (the attribute
/// offsets are relative to it), its decoded directions (in the batch) and its outputs.
struct VertexPointers {
  const uint8_t* vx;
  const float* normal;   // b.normal row
  const float* tangent;  // b.tangent row
  float* position_out;
  float* normal_out;
  float* tangent_out;
};

/// Skins one vertex of class K. kWide: the xyz outputs may be stored as 16 bytes (another vertex
/// follows in memory order and is written later). Returns its weight word (loaded only when
/// kCheck; the range loop checks the words' OR and AND once, soa::outside_class).
template <int K, bool kCheck, bool kWide, Slots kSlots, bool kPositions, bool kNormals, bool kTangents,
          bool kAvx512 = false>
[[gnu::always_inline]] OSSA_TARGET_AVX2 inline uint32_t skin_vertex(const float* palette, const VertexPointers& at,
                                                                    ptrdiff_t off_position, ptrdiff_t off_joints,
                                                                    ptrdiff_t off_weights) {
  __m256 a01, a23;
  uint32_t wb;
  if constexpr (kAvx512) blend_matrix512<K, kSlots, kCheck>(palette, at.vx, off_joints, off_weights, a01, a23, wb);
  else blend_matrix<K, kSlots, kCheck>(palette, at.vx, off_joints, off_weights, a01, a23, wb);
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
    store_xyz<kWide>(at.normal_out,
                     transform_dup(a01, a23, _mm256_broadcast_ps(reinterpret_cast<const __m128*>(at.normal))));
  if constexpr (kTangents) {
    const __m128 t = _mm_load_ps(at.tangent);
    // w of t is the sign: transform xyz only, then put the sign back.
    const __m128 r = transform_dup(
        a01, a23,
        _mm256_blend_ps(_mm256_broadcast_ps(reinterpret_cast<const __m128*>(at.tangent)), _mm256_setzero_ps(), 0x88));
    _mm_storeu_ps(at.tangent_out, _mm_blend_ps(r, t, 0x8));
  }
  return wb;
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
    skin_vertex<K, false, false, kSlots, kPositions, kNormals, kTangents>(palette, at, off_position, off_joints,
                                                                          off_weights);
  }
}

/// Class K's loop over the contiguous vertices [b.first, b.first + b.n) of a class-ordered mesh,
/// walking every pointer forward (no index arithmetic per vertex). Returns soa::outside_class<K>
/// of the OR and AND of their weight words: non-zero means some vertex did not belong to the
/// range (and its outputs are wrong). Checking the words once per range, not per vertex, saved a
/// shift per vertex: with the pointer below, positions alone ~2.5% faster on Zen 5 (arnaud).
template <int K, Slots kSlots, bool kPositions, bool kNormals, bool kTangents, bool kAvx512>
[[gnu::always_inline]] OSSA_TARGET_AVX2 inline uint32_t range_loop(const float* palette, const FastMesh& mesh,
                                                                   const Batch& b, Outputs out) {
  const size_t stride = mesh.stride;
  // The walk's pointer is the vertex's joints, the other attributes at offsets from it: the slot
  // bytes, the most loaded, then need no address arithmetic, and nor does anything else (GCC
  // otherwise walks the joints and rebuilds the vertex's address, two operations a vertex).
  const ptrdiff_t off_joints = 0, off_position = ptrdiff_t{mesh.off_position} - ptrdiff_t{mesh.off_joints},
                  off_weights = ptrdiff_t{mesh.off_weights} - ptrdiff_t{mesh.off_joints};
  const size_t first = b.first;
  VertexPointers at{mesh.base + first * stride + mesh.off_joints,
                    b.normal[0],
                    b.tangent[0],
                    kPositions ? out.positions + 3 * first : nullptr,
                    kNormals ? out.normals + 3 * first : nullptr,
                    kTangents ? out.tangents + 4 * first : nullptr};
  // The mesh's very last vertex stores 12 bytes per stream; every other one may store 16.
  const uint32_t wide = b.first + b.n == mesh.count ? b.n - 1 : b.n;
  uint32_t any = 0, all = ~0u;
#pragma GCC unroll 2
  for (uint32_t i = 0; i < wide; ++i) {
    const uint32_t wb = skin_vertex<K, true, true, kSlots, kPositions, kNormals, kTangents, kAvx512>(
        palette, at, off_position, off_joints, off_weights);
    any |= wb;
    if constexpr (K == 0) all &= wb;
    at.vx += stride;
    at.normal += 4;
    at.tangent += 4;
    if constexpr (kPositions) at.position_out += 3;
    if constexpr (kNormals) at.normal_out += 3;
    if constexpr (kTangents) at.tangent_out += 4;
  }
  if (wide < b.n) {
    const uint32_t wb = skin_vertex<K, true, false, kSlots, kPositions, kNormals, kTangents, kAvx512>(
        palette, at, off_position, off_joints, off_weights);
    any |= wb;
    all &= wb;
  }
  return soa::outside_class<K>(any, all);
}

/// range_loop compiled for AVX2 + FMA, and for AVX-512 (the 512-bit blend, flattened into it).
template <int K, Slots kSlots, bool kPositions, bool kNormals, bool kTangents>
OSSA_TARGET_AVX2 uint32_t skin_range(const float* palette, const FastMesh& mesh, const Batch& b, Outputs out) {
  return range_loop<K, kSlots, kPositions, kNormals, kTangents, false>(palette, mesh, b, out);
}
template <int K, Slots kSlots, bool kPositions, bool kNormals, bool kTangents>
OSSA_TARGET_AVX512 OSSA_SOA_FLATTEN uint32_t skin_range_avx512(const float* palette, const FastMesh& mesh,
                                                               const Batch& b, Outputs out) {
  return range_loop<K, kSlots, kPositions, kNormals, kTangents, true>(palette, mesh, b, out);
}

/// Two consecutive vertices' halves for skin_positions_quad: (a.lo | a.hi | b.lo | b.hi) with
/// lo = fma(c2, z, c0 * x) and hi = fma(c3, 1, c1 * y), each vertex's position being lo + hi, the
/// products and sums transform_dup rounds. The matrices' columns are regrouped by pairs of
/// vertices, (a.c0 | a.c1 | b.c0 | b.c1) and (a.c2 | a.c3 | b.c2 | b.c3), and the two positions
/// spread to match, so one multiply and one FMA serve both vertices.
template <int K, Slots kSlots>
[[gnu::always_inline]] OSSA_TARGET_AVX512 inline __m512 pair_halves(const float* palette, const uint8_t* j,
                                                                    size_t stride, ptrdiff_t off_position,
                                                                    ptrdiff_t off_weights, uint32_t& wa, uint32_t& wb) {
  const __m512 ma = matrix512<K, kSlots>(palette, j, off_weights, wa);
  const __m512 mb = matrix512<K, kSlots>(palette, j + stride, off_weights, wb);
  const __m512 c01 = _mm512_shuffle_f32x4(ma, mb, 0x44), c23 = _mm512_shuffle_f32x4(ma, mb, 0xee);
  // Both positions' unorm16 words, widened: (a.x a.y a.z a.w b.x b.y b.z b.w), scaled, w = 1.
  const __m128i q = _mm_castpd_si128(
      _mm_loadh_pd(_mm_castsi128_pd(_mm_loadl_epi64(reinterpret_cast<const __m128i*>(j + off_position))),
                   reinterpret_cast<const double*>(j + stride + off_position)));
  const float s = 1.0f / 65535.0f;
  const __m256 p = _mm256_fmadd_ps(_mm256_cvtepi32_ps(_mm256_cvtepu16_epi32(q)), _mm256_setr_ps(s, s, s, 0, s, s, s, 0),
                                   _mm256_setr_ps(0, 0, 0, 1, 0, 0, 0, 1));
  const __m512 xy = _mm512_permutexvar_ps(_mm512_setr_epi32(0, 0, 0, 0, 1, 1, 1, 1, 4, 4, 4, 4, 5, 5, 5, 5),
                                          _mm512_castps256_ps512(p));
  const __m512 zw = _mm512_permutexvar_ps(_mm512_setr_epi32(2, 2, 2, 2, 3, 3, 3, 3, 6, 6, 6, 6, 7, 7, 7, 7),
                                          _mm512_castps256_ps512(p));
  return _mm512_fmadd_ps(c23, zw, _mm512_mul_ps(c01, xy));
}

/// Class K's positions alone for the contiguous vertices [first, first + n) of a class-ordered mesh,
/// four at a time (where 512-bit operations run at full width). Two pairs' halves (pair_halves)
/// are added by one round of 128-bit lane shuffles into one register of four (x, y, z, 1), packed
/// to 12 floats and written with one masked store: after the blends, ~7 operations a vertex
/// (a quarter of them shuffles) where skin_vertex's position decode and transform_dup take 12
/// (half of them shuffles). Positions alone ~7% faster on Pab's arnaud (Zen 5); a full 16-float
/// store, its last 4 floats overwritten later, measured slower (it crosses a cache line 3 times in
/// 4). The last n % 4 vertices take skin_vertex. Returns soa::outside_class<K> of the weight
/// words' OR and AND.
template <int K, Slots kSlots>
OSSA_TARGET_AVX512 OSSA_SOA_FLATTEN uint32_t skin_positions_quad(const float* palette, const FastMesh& mesh,
                                                                 uint32_t first, uint32_t n, float* positions) {
  const size_t stride = mesh.stride;
  const ptrdiff_t off_position = ptrdiff_t{mesh.off_position} - ptrdiff_t{mesh.off_joints},
                  off_weights = ptrdiff_t{mesh.off_weights} - ptrdiff_t{mesh.off_joints};
  const uint8_t* vx = mesh.base + first * stride + mesh.off_joints;
  float* out = positions + 3 * static_cast<size_t>(first);
  const __m512i pack = _mm512_setr_epi32(0, 1, 2, 4, 5, 6, 8, 9, 10, 12, 13, 14, 0, 0, 0, 0);
  uint32_t any = 0, all = ~0u, i = 0;
  for (; i + 4 <= n; i += 4) {
    uint32_t w0, w1, w2, w3;
    const __m512 h01 = pair_halves<K, kSlots>(palette, vx, stride, off_position, off_weights, w0, w1);
    const __m512 h23 = pair_halves<K, kSlots>(palette, vx + 2 * stride, stride, off_position, off_weights, w2, w3);
    any |= w0 | w1 | w2 | w3;
    if constexpr (K == 0) all &= w0 & w1 & w2 & w3;
    // (lo of vertices 0-3) + (hi of vertices 0-3): four (x, y, z, 1).
    const __m512 r = _mm512_add_ps(_mm512_shuffle_f32x4(h01, h23, 0x88), _mm512_shuffle_f32x4(h01, h23, 0xdd));
    _mm512_mask_storeu_ps(out, 0x0fff, _mm512_permutexvar_ps(pack, r));
    vx += 4 * stride;
    out += 12;
  }
  for (; i < n; ++i) {
    const VertexPointers at{vx, nullptr, nullptr, out, nullptr, nullptr};
    const uint32_t wb =
        skin_vertex<K, true, false, kSlots, true, false, false, true>(palette, at, off_position, 0, off_weights);
    any |= wb;
    if constexpr (K == 0) all &= wb;
    vx += stride;
    out += 3;
  }
  return soa::outside_class<K>(any, all);
}

/// Class K's loop over the contiguous vertices [first, first + n) of a class-ordered mesh, eight at
/// a time (soa_kernel.h), positions and normals (renormalized as out asks) written directly.
/// Returns n, or the index (from first) of the block where a vertex did not belong to the class:
/// outputs from there on are not written, or wrong.
template <int K, Slots kSlots, bool kPositions, bool kNormals>
OSSA_TARGET_AVX2 uint32_t skin_range_soa(const float* palette, const FastMesh& m, uint32_t first, uint32_t n,
                                         Outputs out, bool avx512) {
  constexpr bool kWide = kSlots == Slots::Wide, kPacked = kSlots == Slots::Packed;
  const soa::Layout l{palette,        kWeight.data(), m.stride,      m.off_position,
                      m.off_normal,   m.off_joints,   m.off_weights, {m.prescale[0], m.prescale[1], m.prescale[2]},
                      out.renormalize};
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
OSSA_TARGET_AVX2 void skin_classified(const float* palette, const FastMesh& m, Outputs out, bool avx512,
                                      uint32_t first) {
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
// vertex it skins against its class (soa::outside_class of the OR and AND of the weight words
// it loads anyway).
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
  // The per-vertex range loops' 512-bit blend only where 512-bit operations run at full width: on
  // Zen 4, which splits them in two, it is the same work plus an extract per vertex (positions
  // alone measured 8-14% slower than the 256-bit blend there, Pab's arnaud).
  const bool blend512 = avx512 && !detail::cpu_avx512_split();
  const auto run = [&](auto k) -> bool {
    constexpr int K = decltype(k)::value;
    const uint32_t end = K == kClasses - 1 ? m.count : class_end(m, begin, K);
    if constexpr (kNormals && !kTangents) {
      const uint32_t done =
          skin_range_soa<K, kSlots, kPositions, kNormals>(palette, m, begin, end - begin, out, avx512);
      if (done != end - begin) {
        skin_classified<kSlots, kPositions, kNormals, kTangents>(palette, m, out, avx512, begin + done);
        return false;
      }
      begin = end;
      return true;
    }
    if constexpr (kPositions && !kNormals && !kTangents) {
      if (blend512) {
        if (skin_positions_quad<K, kSlots>(palette, m, begin, end - begin, out.positions) != 0) {
          skin_classified<kSlots, kPositions, kNormals, kTangents>(palette, m, out, avx512, begin);
          return false;
        }
        begin = end;
        return true;
      }
    }
    for (b.first = begin; b.first < end; b.first += kBatch) {
      b.n = std::min(kBatch, end - b.first);
      if constexpr (kNormals || kTangents) decode_directions<kTangents>(m, b);
      const uint32_t outside = blend512
                                   ? skin_range_avx512<K, kSlots, kPositions, kNormals, kTangents>(palette, m, b, out)
                                   : skin_range<K, kSlots, kPositions, kNormals, kTangents>(palette, m, b, out);
      if (outside != 0) {
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

constexpr size_t kAlignedSlots = 256;  // 16 KB of stack

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
                m.joints->format() == VertexFormat::Uint16x4                            ? Slots::Wide
                : m.weights->offset() == static_cast<uint32_t>(m.joints->offset()) + 4u ? Slots::Packed
                                                                                        : Slots::Narrow,
                {m.direction_prescale.x, m.direction_prescale.y, m.direction_prescale.z}};
  return true;
}

}  // namespace

bool skin_quantized(const MeshFacts& m, const float* palette, Outputs out, bool avx512) {
  FastMesh f;
  if (!fast_layout(m, out, &f)) return false;
  // The kernels load palette matrices as 32- and 64-byte words, and a load that straddles two
  // cache lines costs two: a palette not 64-byte aligned (a std::vector<glm::mat4> is 16-byte
  // aligned) is copied to one that is, when it has at most kAlignedSlots slots (on Pab's arnaud,
  // Zen 5: ~7% faster with normals, ~10% positions alone, for a 3.4 KB copy).
  alignas(64) float aligned[16 * kAlignedSlots];
  if (reinterpret_cast<uintptr_t>(palette) % 64 != 0 && m.slot_count <= kAlignedSlots) {
    std::memcpy(aligned, palette, 64 * m.slot_count);
    palette = aligned;
  }
  switch (f.slots) {
    case Slots::Narrow: skin_fast_streams<Slots::Narrow>(palette, f, out, avx512); break;
    case Slots::Wide: skin_fast_streams<Slots::Wide>(palette, f, out, avx512); break;
    case Slots::Packed: skin_fast_streams<Slots::Packed>(palette, f, out, avx512); break;
  }
  return true;
}

}  // namespace ossa::skin_detail

#endif  // OSSA_SKIN_X86
