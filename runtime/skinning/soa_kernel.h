// soa_kernel.h — skin_cpu's structure-of-arrays kernel: eight vertices of one influence class at a
// time, for positions with normals, or normals alone (the cooker's quantized layout, class-ordered
// ranges, no tangents). Internal to runtime/skinning (skin_x86*.cpp include it after <immintrin.h>).
//
// Why it is shaped so:
// - Blending stays array-of-structures, one vertex at a time (two 8-wide FMAs per influence,
//   columns 0-1 and 2-3; one 16-wide FMA in the AVX-512 copy): a structure-of-arrays blend would
//   need 12 gathers per influence, and gathers are slow on Zen. What goes structure-of-arrays is
//   everything after it: the eight blended matrices are transposed once (the w row dropped), and
//   each output component of eight vertices is then a few FMAs.
// - The per-vertex kernel (skin_x86.cpp) spreads (x, y, z, 1) over the columns and adds the
//   halves, per vertex and stream; it also decodes the normals to memory first and renormalizes
//   in a second pass over the output. Here the normals are decoded eight at a time in registers
//   (from the same 16-byte load as the position when the normal follows it, the cooker's layout),
//   transformed with the matrices already transposed for the positions, and renormalized in
//   registers (rsqrt + one Newton step).
// - A block's outputs are stored, and its normals renormalized, by the next block (Pending), after
//   that block's loads, blends and transposes: the renormalization's chain (squares, rsqrt, Newton
//   step, products, shuffles) is long, and at the end of its own block it held up retirement
//   while the next block waited (profiled: most samples sat on it). On Pab's arnaud (Zen 5 VM,
//   AVX-512 copy) positions + normals went from ~2.9 to ~2.5 ns a vertex.
// - The AVX-512 copy (block512) blends a vertex's whole matrix in one 512-bit register and moves
//   the eight matrices to rows with two-source permutes (vpermt2ps: 20 where the 256-bit
//   transposes take 40 shuffles), decodes positions and normals as (x | y) and (z | w) pairs of
//   halves, and stores eight xyz in three permutes instead of eleven shuffles: ~2.5 to ~2.0 ns a
//   vertex with normals. Its 512-bit functions are not always_inline (an AVX2 function may not
//   inline them); range_avx512 flattens its calls, so they end up inline all the same.
// - Positions alone stay with the per-vertex kernel: this one measured ~15-30% slower for them
//   (the transposes cost about what the per-vertex spreading does), so it is used only where
//   normals pay for the transposes.
// - Every value is rounded as the per-vertex kernel rounds it (the same operations, in the same
//   order, FMA contraction blocked), so what skin_cpu writes does not depend on which streams
//   were asked for (skinning_test checks it bit for bit).
// - Outputs go out as three packed 256-bit stores per stream (24 floats: eight xyz), made with
//   in-lane shuffles (AVX2: the lane-crossing variable permute, vpermps, measured several times
//   slower here) or two-source permutes (AVX-512). A block of fewer than eight vertices (a range's
//   tail) repeats its last vertex in the missing lanes and writes through a stack buffer, so the
//   tail runs the same arithmetic.
// - Slots and weights are read byte by byte and the pointers walk by the stride: fewer registers
//   live than shifting a 64-bit word apart, which mattered (the AVX2 copy spilled otherwise).
#pragma once
#include <cstddef>
#include <cstdint>
#include <cstring>

#include "internal/cpu.h"

namespace ossa::soa {

#define OSSA_SOA_TARGET OSSA_TARGET("avx2,fma,bmi,bmi2,popcnt")
#if defined(__GNUC__) || defined(__clang__)
#define OSSA_SOA_INLINE \
  __attribute__((       \
      always_inline)) inline  // GNU form: it follows OSSA_TARGET, and Clang takes no [[...]] after __attribute__
#define OSSA_SOA_FLATTEN __attribute__((flatten))
#else
#define OSSA_SOA_INLINE __forceinline
#define OSSA_SOA_FLATTEN
#endif

/// The palette matrix (16 floats) of influence k of a vertex whose slots start at j: 8-bit slots
/// read as bytes, 16-bit slots (kWideSlots) as unaligned words. Every blend kernel reads its
/// matrices through this one function.
template <bool kWideSlots>
OSSA_SOA_INLINE const float* slot_matrix(const float* palette, const uint8_t* j, int k) {
  uint32_t s;
  if constexpr (kWideSlots) {
    uint16_t q;
    std::memcpy(&q, j + 2 * k, 2);
    s = q;
  } else {
    s = j[k];
  }
  return palette + 16 * static_cast<size_t>(s);
}

/// 1 / sqrt(len2) to float precision (rsqrt's 12 bits + one Newton step), 0 for len2 = 0.
OSSA_SOA_TARGET OSSA_SOA_INLINE __m256 inverse_length(__m256 len2) {
  len2 = _mm256_max_ps(len2, _mm256_set1_ps(1e-30f));
  const __m256 y = _mm256_rsqrt_ps(len2);
  const __m256 half_len2_y = _mm256_mul_ps(_mm256_mul_ps(len2, _mm256_set1_ps(0.5f)), y);
  return _mm256_mul_ps(y, _mm256_fnmadd_ps(half_len2_y, y, _mm256_set1_ps(1.5f)));
}

/// Octahedral (x, y) in [-1, 1]^2 -> unnormalized direction (ossa/format/vertex_codec.h's unfolding).
OSSA_SOA_TARGET OSSA_SOA_INLINE void unfold_octahedral(__m256& x, __m256& y, __m256& z) {
  const __m256 sign_bit = _mm256_set1_ps(-0.0f);
  const __m256 l1 = _mm256_add_ps(_mm256_andnot_ps(sign_bit, x), _mm256_andnot_ps(sign_bit, y));
  z = _mm256_sub_ps(_mm256_set1_ps(1.0f), l1);
  const __m256 fold = _mm256_max_ps(_mm256_sub_ps(l1, _mm256_set1_ps(1.0f)), _mm256_setzero_ps());
  // x >= 0 ? x - fold : x + fold (snorm decoding never yields -0).
  x = _mm256_sub_ps(x, _mm256_or_ps(fold, _mm256_and_ps(sign_bit, x)));
  y = _mm256_sub_ps(y, _mm256_or_ps(fold, _mm256_and_ps(sign_bit, y)));
}

/// Rows x, y, z of two columns for eight vertices, from a[v] = (column lo xyzw, column hi xyzw):
/// out[0..2] = lo's x, y, z, out[3..5] = hi's.
OSSA_SOA_TARGET OSSA_SOA_INLINE void transpose_columns(const __m256 (&a)[8], __m256 (&out)[6]) {
  const __m256 t0 = _mm256_unpacklo_ps(a[0], a[1]), t1 = _mm256_unpackhi_ps(a[0], a[1]);
  const __m256 t2 = _mm256_unpacklo_ps(a[2], a[3]), t3 = _mm256_unpackhi_ps(a[2], a[3]);
  const __m256 t4 = _mm256_unpacklo_ps(a[4], a[5]), t5 = _mm256_unpackhi_ps(a[4], a[5]);
  const __m256 t6 = _mm256_unpacklo_ps(a[6], a[7]), t7 = _mm256_unpackhi_ps(a[6], a[7]);
  // (lo.x of vertices 0-3 | hi.x of vertices 0-3), and so on.
  const __m256 x03 = _mm256_shuffle_ps(t0, t2, 0x44), y03 = _mm256_shuffle_ps(t0, t2, 0xee);
  const __m256 z03 = _mm256_shuffle_ps(t1, t3, 0x44);
  const __m256 x47 = _mm256_shuffle_ps(t4, t6, 0x44), y47 = _mm256_shuffle_ps(t4, t6, 0xee);
  const __m256 z47 = _mm256_shuffle_ps(t5, t7, 0x44);
  out[0] = _mm256_permute2f128_ps(x03, x47, 0x20);
  out[1] = _mm256_permute2f128_ps(y03, y47, 0x20);
  out[2] = _mm256_permute2f128_ps(z03, z47, 0x20);
  out[3] = _mm256_permute2f128_ps(x03, x47, 0x31);
  out[4] = _mm256_permute2f128_ps(y03, y47, 0x31);
  out[5] = _mm256_permute2f128_ps(z03, z47, 0x31);
}

/// Eight xyz from structure-of-arrays (lane v: vertex v) to 24 packed floats at out. In-lane
/// shuffles do the work (each 128-bit lane turns four xyz into three quads), and only two
/// operations cross lanes: variable lane-crossing permutes (vpermps) measured ~3x slower here.
OSSA_SOA_TARGET OSSA_SOA_INLINE void store_xyz8(float* out, __m256 x, __m256 y, __m256 z) {
  // Per lane (vertices 0-3, and 4-7): q0 = x0 y0 z0 x1, q1 = y1 z1 x2 y2, q2 = z2 x3 y3 z3.
  const __m256 xy_lo = _mm256_unpacklo_ps(x, y), xy_hi = _mm256_unpackhi_ps(x, y);  // x0 y0 x1 y1, x2 y2 x3 y3
  const __m256 q0 =
      _mm256_shuffle_ps(xy_lo, _mm256_shuffle_ps(z, xy_lo, _MM_SHUFFLE(2, 2, 0, 0)), _MM_SHUFFLE(2, 0, 1, 0));
  const __m256 q1 =
      _mm256_shuffle_ps(_mm256_shuffle_ps(xy_lo, z, _MM_SHUFFLE(1, 1, 3, 3)), xy_hi, _MM_SHUFFLE(1, 0, 2, 0));
  const __m256 q2 = _mm256_shuffle_ps(_mm256_shuffle_ps(z, xy_hi, _MM_SHUFFLE(2, 2, 2, 2)),
                                      _mm256_shuffle_ps(xy_hi, z, _MM_SHUFFLE(3, 3, 3, 3)), _MM_SHUFFLE(2, 0, 2, 0));
  _mm256_storeu_ps(out, _mm256_insertf128_ps(q0, _mm256_castps256_ps128(q1), 1));  // q0 | q1 of vertices 0-3
  _mm256_storeu_ps(out + 8, _mm256_blend_ps(q2, q0, 0xf0));                        // q2 of 0-3 | q0 of 4-7
  _mm256_storeu_ps(out + 16, _mm256_permute2f128_ps(q1, q2, 0x31));                // q1 | q2 of 4-7
}

/// store_xyz8 with AVX-512's two-source permutes: three shuffles instead of eleven. Not
/// always_inline (it is inlined where range_avx512 flattens its calls: an AVX2 function may not
/// inline it).
OSSA_TARGET("avx2,fma,bmi,bmi2,popcnt,avx512f,avx512vl,avx512bw,avx512dq")
inline void store_xyz8_avx512(float* out, __m256 x, __m256 y, __m256 z) {
  const __m512 xy = _mm512_insertf32x8(_mm512_castps256_ps512(x), y, 1);
  const __m512 zz = _mm512_castps256_ps512(z);
  // Float k of the output: vertex k / 3, component k % 3 (x: xy[v], y: xy[8 + v], z: zz[v], index 16 + v).
  const __m512i i0 = _mm512_setr_epi32(0, 8, 16, 1, 9, 17, 2, 10, 18, 3, 11, 19, 4, 12, 20, 5);
  const __m512i i1 = _mm512_setr_epi32(13, 21, 6, 14, 22, 7, 15, 23, 0, 0, 0, 0, 0, 0, 0, 0);
  _mm512_storeu_ps(out, _mm512_permutex2var_ps(xy, i0, zz));
  _mm256_storeu_ps(out + 16, _mm512_castps512_ps256(_mm512_permutex2var_ps(xy, i1, zz)));
}

template <bool kAvx512>
OSSA_SOA_TARGET OSSA_SOA_INLINE void store_xyz8_any(float* out, __m256 x, __m256 y, __m256 z) {
  if constexpr (kAvx512) store_xyz8_avx512(out, x, y, z);
  else store_xyz8(out, x, y, z);
}

/// v as it is, hidden from the optimizer: GCC contracts a multiply feeding an add into an FMA
/// (C++ defaults to -ffp-contract=fast), which would round differently from the per-vertex kernel.
OSSA_SOA_TARGET OSSA_SOA_INLINE __m256 rounded(__m256 v) {
#if defined(__GNUC__) || defined(__clang__)
  __asm__("" : "+x"(v));
#endif
  return v;
}

/// One component of a point: c0 * x + c1 * y + c2 * z + c3, rounded as skin_x86.cpp's per-vertex
/// kernel rounds it (fma(c2, z, c0 * x) + (c1 * y + c3)), so that every path of skin_cpu gives
/// bit-identical outputs whichever streams are asked for.
OSSA_SOA_TARGET OSSA_SOA_INLINE __m256 transform_point(__m256 c0, __m256 c1, __m256 c2, __m256 c3, __m256 x, __m256 y,
                                                       __m256 z) {
  return _mm256_add_ps(_mm256_fmadd_ps(c2, z, _mm256_mul_ps(c0, x)), _mm256_add_ps(rounded(_mm256_mul_ps(c1, y)), c3));
}

/// One component of a direction, c0 * x + c1 * y + c2 * z (+ c3 * 0), rounded likewise, down to
/// the sign of a zero.
OSSA_SOA_TARGET OSSA_SOA_INLINE __m256 transform_direction(__m256 c0, __m256 c1, __m256 c2, __m256 c3, __m256 x,
                                                           __m256 y, __m256 z) {
  return _mm256_add_ps(_mm256_fmadd_ps(c2, z, _mm256_mul_ps(c0, x)),
                       _mm256_fmadd_ps(c3, _mm256_setzero_ps(), _mm256_mul_ps(c1, y)));
}

/// Where the kernel reads and writes.
struct Layout {
  const float* palette;  // 16 floats per slot
  const float* weight;   // unorm8 -> float table (b / 255.0f)
  size_t stride;
  uint32_t off_position, off_normal, off_joints, off_weights;
  float prescale[3];  // 1 / position_scale per axis, for directions
  bool renormalize;
};

/// Where vertex 0 of a block keeps what the kernel reads; vertex v's bytes are at the same
/// addresses plus v * stride. kPacked (the cooker's layout): the weights directly follow the
/// joint slots, so one pointer serves both and the loop keeps fewer registers live.
template <bool kPacked>
struct Cursor {
  const uint8_t* joints;
  const uint8_t* weights_;  // unused when kPacked
  const uint8_t* position;
  const uint8_t* normal;  // used when the normal does not follow the position (not kFused)
  const uint8_t* weights() const { return kPacked ? joints + 4 : weights_; }
  void advance(size_t d) {
    joints += d;
    if constexpr (!kPacked) weights_ += d;
    position += d;
    normal += d;
  }
};

/// A vertex's position words x y z w (unorm16) and, with kNormals, its normal's nx ny (snorm16)
/// in words 4-5. kFused: the normal directly follows the position and a 16-byte load stays in the
/// vertex (the cooker's layout), one load for both.
template <bool kNormals, bool kFused>
OSSA_SOA_TARGET OSSA_SOA_INLINE __m128i words_of(const uint8_t* position, const uint8_t* normal) {
  if constexpr (kFused) {
    return _mm_loadu_si128(reinterpret_cast<const __m128i*>(position));
  } else {
    __m128i q = _mm_loadl_epi64(reinterpret_cast<const __m128i*>(position));
    if constexpr (kNormals) {
      int32_t n;
      std::memcpy(&n, normal, 4);
      q = _mm_insert_epi32(q, n, 2);
    }
    return q;
  }
}

/// Blended matrix of a vertex's first K influences (K = 0: its first slot's matrix as it is), as
/// columns 0-1 and 2-3; slots and weights read byte by byte (no shifts and masks of a wide word).
template <int K, bool kWideSlots>
OSSA_SOA_TARGET OSSA_SOA_INLINE void blend(const uint8_t* j, const uint8_t* w, const Layout& l, __m256& a01,
                                           __m256& a23) {
  const auto matrix = [&](int k) { return slot_matrix<kWideSlots>(l.palette, j, k); };
  const float* p = matrix(0);
  if constexpr (K == 0) {
    a01 = _mm256_loadu_ps(p);
    a23 = _mm256_loadu_ps(p + 8);
  } else {
    __m256 wk = _mm256_broadcast_ss(l.weight + w[0]);
    a01 = _mm256_mul_ps(wk, _mm256_loadu_ps(p));
    a23 = _mm256_mul_ps(wk, _mm256_loadu_ps(p + 8));
#pragma GCC unroll 4
    for (int k = 1; k < K; ++k) {
      p = matrix(k);
      wk = _mm256_broadcast_ss(l.weight + w[k]);
      a01 = _mm256_fmadd_ps(wk, _mm256_loadu_ps(p), a01);
      a23 = _mm256_fmadd_ps(wk, _mm256_loadu_ps(p + 8), a23);
    }
  }
}

/// A block's transformed normals not yet renormalized and stored: the next block does it, after
/// its own loads, blends and positions, so that the renormalization's long dependency chain
/// (squares, rsqrt, Newton step, products, shuffles) overlaps independent work instead of
/// stalling retirement at the end of every block.
struct Pending {
  __m256 x, y, z;
  float* out = nullptr;  // null: nothing pending
  __m256 px, py, pz;
  float* position_out = nullptr;
};

/// Renormalizes (when the layout asks) and stores what is pending, and clears it.
template <bool kAvx512>
OSSA_SOA_TARGET OSSA_SOA_INLINE void flush_positions(Pending& p) {
  if (p.position_out == nullptr) return;
  store_xyz8_any<kAvx512>(p.position_out, p.px, p.py, p.pz);
  p.position_out = nullptr;
}

template <bool kAvx512>
OSSA_SOA_TARGET OSSA_SOA_INLINE void flush_normals(Pending& p, const Layout& l) {
  if (p.out == nullptr) return;
  __m256 nx = p.x, ny = p.y, nz = p.z;
  if (l.renormalize) {
    const __m256 inv = inverse_length(_mm256_add_ps(
        _mm256_add_ps(rounded(_mm256_mul_ps(nx, nx)), rounded(_mm256_mul_ps(ny, ny))), rounded(_mm256_mul_ps(nz, nz))));
    nx = _mm256_mul_ps(nx, inv);
    ny = _mm256_mul_ps(ny, inv);
    nz = _mm256_mul_ps(nz, inv);
  }
  store_xyz8_any<kAvx512>(p.out, nx, ny, nz);
  p.out = nullptr;
}

template <bool kAvx512>
OSSA_SOA_TARGET OSSA_SOA_INLINE void flush(Pending& p, const Layout& l) {
  flush_positions<kAvx512>(p);
  flush_normals<kAvx512>(p, l);
}

/// Eight vertices of class K from at (kTail: only vertices 0..last exist, the missing ones repeat
/// the last). Writes 24 floats per requested stream. Returns non-zero when a vertex does not
/// belong to the class (K = 0: weights other than (255, 0, 0, 0); K = 1..3: a non-zero weight
/// past influence K - 1), and its outputs are then wrong.
/// Positions x, y, z (unorm16 / 65535) of a block's eight vertices from its words A: (x0 x1 y0 y1
/// z0 z1 w0 w1 | x4 x5 ...), (x2 x3 ... | x6 x7 ...) -> x of 0-3 | 4-7.
OSSA_SOA_TARGET OSSA_SOA_INLINE void positions_of(const __m256i (&A)[4], __m256& x, __m256& y, __m256& z) {
  const __m256i zero = _mm256_setzero_si256();
  const __m256i t0 = _mm256_unpacklo_epi16(A[0], A[1]), t2 = _mm256_unpacklo_epi16(A[2], A[3]);
  const __m256i xy = _mm256_unpacklo_epi32(t0, t2), zw = _mm256_unpackhi_epi32(t0, t2);
  const __m256 unit = _mm256_set1_ps(1.0f / 65535.0f);
  x = _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_unpacklo_epi16(xy, zero)), unit);
  y = _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_unpackhi_epi16(xy, zero)), unit);
  z = _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_unpacklo_epi16(zw, zero)), unit);
}

/// Normals of a block's eight vertices from its words A, decoded (snorm16 as OpenGL decodes it:
/// max(v / 32767, -1), the word moved to the top and shifted down; octahedral unfolding) and
/// multiplied by the prescale.
OSSA_SOA_TARGET OSSA_SOA_INLINE void normals_of(const __m256i (&A)[4], const Layout& l, __m256& x, __m256& y,
                                                __m256& z) {
  const __m256i zero = _mm256_setzero_si256();
  const __m256i t1 = _mm256_unpackhi_epi16(A[0], A[1]), t3 = _mm256_unpackhi_epi16(A[2], A[3]);
  const __m256i n = _mm256_unpacklo_epi32(t1, t3);  // nx0..3 ny0..3 | nx4..7 ny4..7
  const __m256 unit = _mm256_set1_ps(1.0f / 32767.0f), minus_one = _mm256_set1_ps(-1.0f);
  x = _mm256_max_ps(_mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_srai_epi32(_mm256_unpacklo_epi16(zero, n), 16)), unit),
                    minus_one);
  y = _mm256_max_ps(_mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_srai_epi32(_mm256_unpackhi_epi16(zero, n), 16)), unit),
                    minus_one);
  unfold_octahedral(x, y, z);
  x = _mm256_mul_ps(x, _mm256_set1_ps(l.prescale[0]));
  y = _mm256_mul_ps(y, _mm256_set1_ps(l.prescale[1]));
  z = _mm256_mul_ps(z, _mm256_set1_ps(l.prescale[2]));
}

/// Vertex v of a block: the cursor at it and the distance d4 to vertex v + 4 (a tail block, with
/// only vertices 0..last, repeats its last vertex).
template <bool kPacked, bool kTail>
OSSA_SOA_TARGET OSSA_SOA_INLINE Cursor<kPacked> vertex_of(Cursor<kPacked> first, uint32_t v, uint32_t last,
                                                          size_t stride, size_t& d4) {
  if constexpr (kTail) {
    const uint32_t a = v < last ? v : last, b = v + 4 < last ? v + 4 : last;
    first.advance(a * stride);
    d4 = (b - a) * stride;
  } else {
    first.advance(v * stride);
    d4 = 4 * stride;
  }
  return first;
}

/// The class check of a block from the OR and AND of its weight words: non-zero when a vertex does
/// not belong to class K (K = 0: weights other than (255, 0, 0, 0); K = 1..3: a non-zero weight
/// past influence K - 1), and its outputs are then wrong.
template <int K>
OSSA_SOA_TARGET OSSA_SOA_INLINE uint32_t outside_class(uint32_t any, uint32_t all) {
  if constexpr (K == 0) return (any ^ 255u) | (all ^ 255u);
  else if constexpr (K < 4) return any >> (8 * K);
  else return 0;
}

template <int K, bool kWideSlots, bool kPacked, bool kPositions, bool kNormals, bool kFused, bool kTail>
OSSA_SOA_TARGET OSSA_SOA_INLINE uint32_t block(Cursor<kPacked> at, uint32_t last, const Layout& l, float* position_out,
                                               float* normal_out, Pending& pending) {
  __m256 a[8], c[8];  // blended columns 0-1 / 2-3 of vertices 0-7
  __m256i A[4];       // words of vertex pairs (0, 4), (1, 5), (2, 6), (3, 7), one per lane
  uint32_t any = 0, all = ~0u;
#pragma GCC unroll 4
  for (uint32_t v = 0; v < 4; ++v) {
    size_t d4;
    const Cursor<kPacked> u = vertex_of<kPacked, kTail>(at, v, last, l.stride, d4);
    blend<K, kWideSlots>(u.joints, u.weights(), l, a[v], c[v]);
    blend<K, kWideSlots>(u.joints + d4, u.weights() + d4, l, a[v + 4], c[v + 4]);
    // Named first: Clang's _mm256_inserti128_si256 is a macro, and the template's comma would split
    // its arguments.
    const __m128i lo = words_of<kNormals, kFused>(u.position, u.normal);
    const __m128i hi = words_of<kNormals, kFused>(u.position + d4, u.normal + d4);
    A[v] = _mm256_inserti128_si256(_mm256_castsi128_si256(lo), hi, 1);
    uint32_t w0, w4;
    std::memcpy(&w0, u.weights(), 4);
    std::memcpy(&w4, u.weights() + d4, 4);
    any |= w0 | w4;
    if constexpr (K == 0) all &= w0 & w4;
  }
  __m256 c01[6], c23[6];  // c0.xyz, c1.xyz / c2.xyz, c3.xyz, eight vertices each
  transpose_columns(a, c01);
  transpose_columns(c, c23);
  if constexpr (kPositions) {
    __m256 x, y, z;
    positions_of(A, x, y, z);
    flush_positions<false>(pending);
    pending.px = transform_point(c01[0], c01[3], c23[0], c23[3], x, y, z);
    pending.py = transform_point(c01[1], c01[4], c23[1], c23[4], x, y, z);
    pending.pz = transform_point(c01[2], c01[5], c23[2], c23[5], x, y, z);
    pending.position_out = position_out;
  }
  if constexpr (kNormals) {
    __m256 x, y, z;
    normals_of(A, l, x, y, z);
    flush_normals<false>(pending, l);  // the previous block's normals
    pending.x = transform_direction(c01[0], c01[3], c23[0], c23[3], x, y, z);
    pending.y = transform_direction(c01[1], c01[4], c23[1], c23[4], x, y, z);
    pending.z = transform_direction(c01[2], c01[5], c23[2], c23[5], x, y, z);
    pending.out = normal_out;
  }
  return outside_class<K>(any, all);
}

// ---- the AVX-512 copy's blend and transposes ----
//
// With 512-bit registers a vertex's whole blended matrix is one register (one FMA per influence
// where the 256-bit form needs two), and two-source permutes (vpermt2ps) move it to rows in 20
// operations where transpose_columns takes 40 shuffles. The rows come in pairs, (c0 | c1) and
// (c2 | c3) of one component, so each output component is one 16-lane multiply and FMA against
// (x | y) and (z | w), and its halves added: fma(c2, z, c0 * x) + fma(c3, w, c1 * y), rounded as
// transform_point (w = 1) and transform_direction (w = 0) round it. These functions are not
// always_inline (an AVX2 function may not inline them): range_avx512 flattens its calls.
#define OSSA_SOA_TARGET512 OSSA_TARGET("avx2,fma,bmi,bmi2,popcnt,avx512f,avx512vl,avx512bw,avx512dq")

/// The blended matrix of the class-K vertex with slots j and weight bytes w, one 512-bit register
/// (c0 | c1 | c2 | c3), the weights read through `weight` (kWeight). skin_x86.cpp's 512-bit range
/// loops blend through it too.
template <int K, bool kWideSlots>
OSSA_SOA_TARGET512 inline __m512 blend512(const uint8_t* j, const uint8_t* w, const float* palette,
                                          const float* weight) {
  const auto matrix = [&](int k) { return slot_matrix<kWideSlots>(palette, j, k); };
  if constexpr (K == 0) {
    return _mm512_loadu_ps(matrix(0));
  } else {
    __m512 m = _mm512_mul_ps(_mm512_set1_ps(weight[w[0]]), _mm512_loadu_ps(matrix(0)));
#pragma GCC unroll 4
    for (int k = 1; k < K; ++k) m = _mm512_fmadd_ps(_mm512_set1_ps(weight[w[k]]), _mm512_loadu_ps(matrix(k)), m);
    return m;
  }
}

/// Eight blended matrices (m[v]: c0 c1 c2 c3 of vertex v, xyzw each) to rows: r[e] = (c0.e | c1.e),
/// r[3 + e] = (c2.e | c3.e) for e = x, y, z, vertices 0-7 in each half.
OSSA_SOA_TARGET512 inline void rows512(const __m512 (&m)[8], __m512 (&r)[6]) {
  // Pairs of vertices: u = x then y of c0..c3 (vertex v, v + 1 alternating), z = z of c0..c3.
  const __m512i iu = _mm512_setr_epi32(0, 16, 4, 20, 8, 24, 12, 28, 1, 17, 5, 21, 9, 25, 13, 29);
  const __m512i iz = _mm512_setr_epi32(2, 18, 6, 22, 10, 26, 14, 30, 2, 18, 6, 22, 10, 26, 14, 30);
  __m512 u[4], z[4];
#pragma GCC unroll 4
  for (int p = 0; p < 4; ++p) {
    u[p] = _mm512_permutex2var_ps(m[2 * p], iu, m[2 * p + 1]);
    z[p] = _mm512_permutex2var_ps(m[2 * p], iz, m[2 * p + 1]);
  }
  // Quads: one component of c0..c3, four vertices each.
  const __m512i ix = _mm512_setr_epi32(0, 1, 16, 17, 2, 3, 18, 19, 4, 5, 20, 21, 6, 7, 22, 23);
  const __m512i iy = _mm512_setr_epi32(8, 9, 24, 25, 10, 11, 26, 27, 12, 13, 28, 29, 14, 15, 30, 31);
  __m512 q[2][3];
#pragma GCC unroll 4
  for (int h = 0; h < 2; ++h) {
    q[h][0] = _mm512_permutex2var_ps(u[2 * h], ix, u[2 * h + 1]);
    q[h][1] = _mm512_permutex2var_ps(u[2 * h], iy, u[2 * h + 1]);
    q[h][2] = _mm512_permutex2var_ps(z[2 * h], ix, z[2 * h + 1]);
  }
  const __m512i i01 = _mm512_setr_epi32(0, 1, 2, 3, 16, 17, 18, 19, 4, 5, 6, 7, 20, 21, 22, 23);
  const __m512i i23 = _mm512_setr_epi32(8, 9, 10, 11, 24, 25, 26, 27, 12, 13, 14, 15, 28, 29, 30, 31);
#pragma GCC unroll 4
  for (int e = 0; e < 3; ++e) {
    r[e] = _mm512_permutex2var_ps(q[0][e], i01, q[1][e]);
    r[3 + e] = _mm512_permutex2var_ps(q[0][e], i23, q[1][e]);
  }
}

/// positions_of for the AVX-512 copy: (x | y) and (z | 1) as apply512 reads them, x, y and z
/// rounded alike (the same conversion and product per element).
OSSA_SOA_TARGET512 inline void positions512(const __m256i (&A)[4], __m512& xy, __m512& zw) {
  const __m256i t0 = _mm256_unpacklo_epi16(A[0], A[1]), t2 = _mm256_unpacklo_epi16(A[2], A[3]);
  // Words x0..3 y0..3 | x4..7 y4..7, and z0..3 w0..3 | z4..7 w4..7.
  const __m256i w_xy = _mm256_unpacklo_epi32(t0, t2), w_zw = _mm256_unpackhi_epi32(t0, t2);
  const __m512 unit = _mm512_set1_ps(1.0f / 65535.0f);
  xy = _mm512_mul_ps(_mm512_cvtepi32_ps(_mm512_cvtepu16_epi32(_mm256_permute4x64_epi64(w_xy, 0xd8))), unit);
  const __m256 z = _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_unpacklo_epi16(w_zw, _mm256_setzero_si256())),
                                 _mm256_set1_ps(1.0f / 65535.0f));
  zw = _mm512_insertf32x8(_mm512_castps256_ps512(z), _mm256_set1_ps(1.0f), 1);
}

/// normals_of for the AVX-512 copy: (x | y) and (z | 0) as apply512 reads them, each element
/// computed as normals_of computes it.
OSSA_SOA_TARGET512 inline void normals512(const __m256i (&A)[4], const Layout& l, __m512& xy, __m512& zw) {
  const __m256i t1 = _mm256_unpackhi_epi16(A[0], A[1]), t3 = _mm256_unpackhi_epi16(A[2], A[3]);
  const __m256i n = _mm256_unpacklo_epi32(t1, t3);  // nx0..3 ny0..3 | nx4..7 ny4..7
  const __m512 sign_bit = _mm512_set1_ps(-0.0f);
  __m512 v = _mm512_max_ps(_mm512_mul_ps(_mm512_cvtepi32_ps(_mm512_cvtepi16_epi32(_mm256_permute4x64_epi64(n, 0xd8))),
                                         _mm512_set1_ps(1.0f / 32767.0f)),
                           _mm512_set1_ps(-1.0f));
  // unfold_octahedral on both halves at once: |x| + |y| in each half.
  const __m512 a = _mm512_andnot_ps(sign_bit, v);
  const __m512 l1 = _mm512_add_ps(a, _mm512_shuffle_f32x4(a, a, 0x4e));
  const __m256 z = _mm256_sub_ps(_mm256_set1_ps(1.0f), _mm512_castps512_ps256(l1));
  const __m512 fold = _mm512_max_ps(_mm512_sub_ps(l1, _mm512_set1_ps(1.0f)), _mm512_setzero_ps());
  v = _mm512_sub_ps(v, _mm512_or_ps(fold, _mm512_and_ps(sign_bit, v)));
  const __m512 pxy = _mm512_insertf32x8(_mm512_set1_ps(l.prescale[0]), _mm256_set1_ps(l.prescale[1]), 1);
  xy = _mm512_mul_ps(v, pxy);
  zw = _mm512_castps256_ps512(_mm256_mul_ps(z, _mm256_set1_ps(l.prescale[2])));
  zw = _mm512_insertf32x8(zw, _mm256_setzero_ps(), 1);
}

/// The rows applied to eight (x, y, z, w) spread as (x | y) and (z | w): out[e] = fma(c2.e, z, c0.e * x) + fma(c3.e, w,
/// c1.e * y).
OSSA_SOA_TARGET512 inline void apply512(const __m512 (&r)[6], __m512 xy, __m512 zw, __m256 (&out)[3]) {
#pragma GCC unroll 4
  for (int e = 0; e < 3; ++e) {
    const __m512 t = _mm512_fmadd_ps(r[3 + e], zw, _mm512_mul_ps(r[e], xy));
    out[e] = _mm256_add_ps(_mm512_castps512_ps256(t), _mm512_extractf32x8_ps(t, 1));
  }
}

/// block() for the AVX-512 copy: the same reads, outputs and class check, with blend512, rows512
/// and apply512.
template <int K, bool kWideSlots, bool kPacked, bool kPositions, bool kNormals, bool kFused, bool kTail>
OSSA_SOA_TARGET512 inline uint32_t block512(Cursor<kPacked> at, uint32_t last, const Layout& l, float* position_out,
                                            float* normal_out, Pending& pending) {
  __m512 m[8];   // blended matrices of vertices 0-7
  __m256i A[4];  // words of vertex pairs (0, 4), (1, 5), (2, 6), (3, 7), one per lane
  uint32_t any = 0, all = ~0u;
#pragma GCC unroll 4
  for (uint32_t v = 0; v < 4; ++v) {
    size_t d4;
    const Cursor<kPacked> u = vertex_of<kPacked, kTail>(at, v, last, l.stride, d4);
    m[v] = blend512<K, kWideSlots>(u.joints, u.weights(), l.palette, l.weight);
    m[v + 4] = blend512<K, kWideSlots>(u.joints + d4, u.weights() + d4, l.palette, l.weight);
    const __m128i lo = words_of<kNormals, kFused>(u.position, u.normal);
    const __m128i hi = words_of<kNormals, kFused>(u.position + d4, u.normal + d4);
    A[v] = _mm256_inserti128_si256(_mm256_castsi128_si256(lo), hi, 1);
    uint32_t w0, w4;
    std::memcpy(&w0, u.weights(), 4);
    std::memcpy(&w4, u.weights() + d4, 4);
    any |= w0 | w4;
    if constexpr (K == 0) all &= w0 & w4;
  }
  __m512 r[6];
  rows512(m, r);
  if constexpr (kPositions) {
    __m512 xy, zw;
    __m256 out[3];
    positions512(A, xy, zw);
    flush_positions<true>(pending);
    apply512(r, xy, zw, out);
    pending.px = out[0];
    pending.py = out[1];
    pending.pz = out[2];
    pending.position_out = position_out;
  }
  if constexpr (kNormals) {
    __m512 xy, zw;
    __m256 out[3];
    normals512(A, l, xy, zw);
    flush_normals<true>(pending, l);  // the previous block's normals
    apply512(r, xy, zw, out);
    pending.x = out[0];
    pending.y = out[1];
    pending.z = out[2];
    pending.out = normal_out;
  }
  return outside_class<K>(any, all);
}

/// block() or block512().
template <int K, bool kWideSlots, bool kPacked, bool kPositions, bool kNormals, bool kFused, bool kTail, bool kAvx512>
OSSA_SOA_TARGET OSSA_SOA_INLINE uint32_t any_block(Cursor<kPacked> at, uint32_t last, const Layout& l,
                                                   float* position_out, float* normal_out, Pending& pending) {
  if constexpr (kAvx512)
    return block512<K, kWideSlots, kPacked, kPositions, kNormals, kFused, kTail>(at, last, l, position_out, normal_out,
                                                                                 pending);
  else
    return block<K, kWideSlots, kPacked, kPositions, kNormals, kFused, kTail>(at, last, l, position_out, normal_out,
                                                                              pending);
}

/// Class K's vertices [0, n) from vx (outputs at position_out / normal_out, already offset to the
/// first vertex), eight at a time; the tail through a stack buffer. Returns the index of the first
/// vertex of the first block holding a vertex outside the class (its outputs and those after it
/// are not written, or wrong), or n when every vertex belonged.
template <int K, bool kWideSlots, bool kPacked, bool kPositions, bool kNormals, bool kFused, bool kAvx512>
OSSA_SOA_TARGET OSSA_SOA_INLINE uint32_t range_body(Cursor<kPacked> at, uint32_t n, const Layout& layout,
                                                    float* position_out, float* normal_out) {
  const Layout l = layout;  // a local copy: its fields stay in registers (the outputs cannot alias them)
  Pending pending;
  uint32_t i = 0;
  for (; i + 8 <= n; i += 8, at.advance(8 * l.stride)) {
    if (any_block<K, kWideSlots, kPacked, kPositions, kNormals, kFused, false, kAvx512>(
            at, 7, l, kPositions ? position_out + 3 * i : nullptr, kNormals ? normal_out + 3 * i : nullptr, pending) !=
        0) {
      flush<kAvx512>(pending, l);
      return i;
    }
  }
  flush<kAvx512>(pending, l);
  if (i < n) {
    alignas(32) float p[24], q[24];
    const uint32_t outside =
        any_block<K, kWideSlots, kPacked, kPositions, kNormals, kFused, true, kAvx512>(at, n - i - 1, l, p, q, pending);
    flush<kAvx512>(pending, l);
    if (outside != 0) return i;
    if constexpr (kPositions) std::memcpy(position_out + 3 * i, p, 12 * (n - i));
    if constexpr (kNormals) std::memcpy(normal_out + 3 * i, q, 12 * (n - i));
  }
  return n;
}

/// range_body compiled for AVX2 + FMA with block(), and for AVX-512 (F/VL/BW/DQ) with block512().
/// (block() compiled for AVX-512, its 32 vector registers sparing the AVX2 copy's stack spills,
/// measured ~11% faster than in the AVX2 copy and ~25% slower than block512, Zen 5: the spills
/// are not most of what the AVX2 copy pays.)
template <int K, bool kWideSlots, bool kPacked, bool kPositions, bool kNormals, bool kFused>
OSSA_SOA_TARGET uint32_t range_avx2(Cursor<kPacked> at, uint32_t n, const Layout& l, float* position_out,
                                    float* normal_out) {
  return range_body<K, kWideSlots, kPacked, kPositions, kNormals, kFused, false>(at, n, l, position_out, normal_out);
}
template <int K, bool kWideSlots, bool kPacked, bool kPositions, bool kNormals, bool kFused>
OSSA_TARGET("avx2,fma,bmi,bmi2,popcnt,avx512f,avx512vl,avx512bw,avx512dq")
OSSA_SOA_FLATTEN uint32_t
    range_avx512(Cursor<kPacked> at, uint32_t n, const Layout& l, float* position_out, float* normal_out) {
  return range_body<K, kWideSlots, kPacked, kPositions, kNormals, kFused, true>(at, n, l, position_out, normal_out);
}

}  // namespace ossa::soa
