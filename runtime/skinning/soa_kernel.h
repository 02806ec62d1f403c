// soa_kernel.h — skin_cpu's structure-of-arrays kernel: eight vertices of one influence class at a
// time, for positions with normals, or normals alone (the cooker's quantized layout, class-ordered
// ranges, no tangents). Internal to runtime/skinning (skin_x86*.cpp include it after <immintrin.h>).
//
// Why it is shaped so:
// - Blending stays array-of-structures, one vertex at a time (two 8-wide FMAs per influence,
//   columns 0-1 and 2-3): a structure-of-arrays blend would need 12 gathers per influence, and
//   gathers are slow on Zen. What goes structure-of-arrays is everything after it: the eight
//   blended matrices are transposed once (an 8x8 transpose of each column pair, the w row
//   dropped), and each output component of eight vertices is then a few FMAs.
// - The per-vertex kernel (skin_x86.cpp) spreads (x, y, z, 1) over the columns and adds the
//   halves, per vertex and stream; it also decodes the normals to memory first and renormalizes
//   in a second pass over the output. Here the normals are decoded eight at a time in registers
//   (from the same 16-byte load as the position when the normal follows it, the cooker's layout),
//   transformed with the matrices already transposed for the positions, and renormalized in
//   registers (rsqrt + one Newton step). On Pab's arnaud (Zen 5 VM) positions + normals went from
//   ~3.4 to ~2.9 ns a vertex, ~3.0 to ~2.5 without renormalizing.
// - Positions alone stay with the per-vertex kernel: this one measured ~30% slower for them (the
//   transposes cost about what the per-vertex spreading does, and its long per-block dependency
//   chains overlap worse), so it is used only where normals pay for the transposes.
// - Every value is rounded as the per-vertex kernel rounds it (the same operations, in the same
//   order, FMA contraction blocked), so what skin_cpu writes does not depend on which streams
//   were asked for (skinning_test checks it bit for bit).
// - Outputs go out as three packed 256-bit stores per stream (24 floats: eight xyz), made with
//   in-lane shuffles: the lane-crossing variable permute (vpermps) measured several times slower
//   here. A block of fewer than eight vertices (a range's tail) repeats its last vertex in the
//   missing lanes and writes through a stack buffer, so the tail runs the same arithmetic.
// - Slots and weights are read byte by byte and the pointers walk by the stride: fewer registers
//   live than shifting a 64-bit word apart, which mattered (the AVX2 copy spilled otherwise).
// - Compiled twice (range_avx2, range_avx512): the AVX-512 copy is the same 256-bit code with 32
//   vector registers, ~8% faster with normals.
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
#else
#define OSSA_SOA_INLINE __forceinline
#endif

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
  const auto matrix = [&](int k) {
    uint32_t s;
    if constexpr (kWideSlots) {
      uint16_t q;
      std::memcpy(&q, j + 2 * k, 2);
      s = q;
    } else {
      s = j[k];
    }
    return l.palette + 16 * static_cast<size_t>(s);
  };
  const float* p = matrix(0);
  if constexpr (K == 0) {
    a01 = _mm256_loadu_ps(p);
    a23 = _mm256_loadu_ps(p + 8);
  } else {
    __m256 wk = _mm256_broadcast_ss(l.weight + w[0]);
    a01 = _mm256_mul_ps(wk, _mm256_loadu_ps(p));
    a23 = _mm256_mul_ps(wk, _mm256_loadu_ps(p + 8));
    for (int k = 1; k < K; ++k) {
      p = matrix(k);
      wk = _mm256_broadcast_ss(l.weight + w[k]);
      a01 = _mm256_fmadd_ps(wk, _mm256_loadu_ps(p), a01);
      a23 = _mm256_fmadd_ps(wk, _mm256_loadu_ps(p + 8), a23);
    }
  }
}

/// Eight vertices of class K from at (kTail: only vertices 0..last exist, the missing ones repeat
/// the last). Writes 24 floats per requested stream. Returns non-zero when a vertex does not
/// belong to the class (K = 0: weights other than (255, 0, 0, 0); K = 1..3: a non-zero weight
/// past influence K - 1), and its outputs are then wrong.
template <int K, bool kWideSlots, bool kPacked, bool kPositions, bool kNormals, bool kFused, bool kTail>
OSSA_SOA_TARGET OSSA_SOA_INLINE uint32_t block(Cursor<kPacked> at, uint32_t last, const Layout& l, float* position_out,
                                               float* normal_out) {
  __m256 a[8], c[8];  // blended columns 0-1 / 2-3 of vertices 0-7
  __m256i A[4];       // words of vertex pairs (0, 4), (1, 5), (2, 6), (3, 7), one per lane
  uint32_t any = 0, all = ~0u;
  const Cursor<kPacked> first = at;
  const size_t s4 = 4 * l.stride;
#pragma GCC unroll 4
  for (uint32_t v = 0; v < 4; ++v) {
    // Vertex v at at, vertex v + 4 at at + d4 (a tail block repeats its last vertex).
    size_t d4 = s4;
    if constexpr (kTail) {
      at = first;
      at.advance((v < last ? v : last) * l.stride);
      d4 = ((v + 4 < last ? v + 4 : last) - (v < last ? v : last)) * l.stride;
    }
    blend<K, kWideSlots>(at.joints, at.weights(), l, a[v], c[v]);
    blend<K, kWideSlots>(at.joints + d4, at.weights() + d4, l, a[v + 4], c[v + 4]);
    // Named first: Clang's _mm256_inserti128_si256 is a macro, and the template's comma would split
    // its arguments.
    const __m128i lo = words_of<kNormals, kFused>(at.position, at.normal);
    const __m128i hi = words_of<kNormals, kFused>(at.position + d4, at.normal + d4);
    A[v] = _mm256_inserti128_si256(_mm256_castsi128_si256(lo), hi, 1);
    uint32_t w0, w4;
    std::memcpy(&w0, at.weights(), 4);
    std::memcpy(&w4, at.weights() + d4, 4);
    any |= w0 | w4;
    if constexpr (K == 0) all &= w0 & w4;
    if constexpr (!kTail) at.advance(l.stride);
  }
  __m256 c01[6], c23[6];  // c0.xyz, c1.xyz / c2.xyz, c3.xyz, eight vertices each
  transpose_columns(a, c01);
  transpose_columns(c, c23);

  // (x0 x1 y0 y1 z0 z1 w0 w1 | x4 x5 ...), (x2 x3 ... | x6 x7 ...) -> x of 0-3 | 4-7.
  const __m256i zero = _mm256_setzero_si256();
  if constexpr (kPositions) {
    const __m256i t0 = _mm256_unpacklo_epi16(A[0], A[1]), t2 = _mm256_unpacklo_epi16(A[2], A[3]);
    const __m256i xy = _mm256_unpacklo_epi32(t0, t2), zw = _mm256_unpackhi_epi32(t0, t2);
    const __m256 unit = _mm256_set1_ps(1.0f / 65535.0f);
    const __m256 x = _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_unpacklo_epi16(xy, zero)), unit);
    const __m256 y = _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_unpackhi_epi16(xy, zero)), unit);
    const __m256 z = _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_unpacklo_epi16(zw, zero)), unit);
    store_xyz8(position_out, transform_point(c01[0], c01[3], c23[0], c23[3], x, y, z),
               transform_point(c01[1], c01[4], c23[1], c23[4], x, y, z),
               transform_point(c01[2], c01[5], c23[2], c23[5], x, y, z));
  }
  if constexpr (kNormals) {
    const __m256i t1 = _mm256_unpackhi_epi16(A[0], A[1]), t3 = _mm256_unpackhi_epi16(A[2], A[3]);
    const __m256i n = _mm256_unpacklo_epi32(t1, t3);  // nx0..3 ny0..3 | nx4..7 ny4..7
    // Snorm16 as OpenGL decodes it: max(v / 32767, -1); the word moved to the top, shifted down.
    const __m256 unit = _mm256_set1_ps(1.0f / 32767.0f), minus_one = _mm256_set1_ps(-1.0f);
    __m256 x = _mm256_max_ps(
        _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_srai_epi32(_mm256_unpacklo_epi16(zero, n), 16)), unit), minus_one);
    __m256 y = _mm256_max_ps(
        _mm256_mul_ps(_mm256_cvtepi32_ps(_mm256_srai_epi32(_mm256_unpackhi_epi16(zero, n), 16)), unit), minus_one);
    __m256 z;
    unfold_octahedral(x, y, z);
    x = _mm256_mul_ps(x, _mm256_set1_ps(l.prescale[0]));
    y = _mm256_mul_ps(y, _mm256_set1_ps(l.prescale[1]));
    z = _mm256_mul_ps(z, _mm256_set1_ps(l.prescale[2]));
    __m256 nx = transform_direction(c01[0], c01[3], c23[0], c23[3], x, y, z);
    __m256 ny = transform_direction(c01[1], c01[4], c23[1], c23[4], x, y, z);
    __m256 nz = transform_direction(c01[2], c01[5], c23[2], c23[5], x, y, z);
    if (l.renormalize) {
      const __m256 inv =
          inverse_length(_mm256_add_ps(_mm256_add_ps(rounded(_mm256_mul_ps(nx, nx)), rounded(_mm256_mul_ps(ny, ny))),
                                       rounded(_mm256_mul_ps(nz, nz))));
      nx = _mm256_mul_ps(nx, inv);
      ny = _mm256_mul_ps(ny, inv);
      nz = _mm256_mul_ps(nz, inv);
    }
    store_xyz8(normal_out, nx, ny, nz);
  }
  if constexpr (K == 0) return (any ^ 255u) | (all ^ 255u);
  else if constexpr (K < 4) return any >> (8 * K);
  else return 0;
}

/// Class K's vertices [0, n) from vx (outputs at position_out / normal_out, already offset to the
/// first vertex), eight at a time; the tail through a stack buffer. Returns the index of the first
/// vertex of the first block holding a vertex outside the class (its outputs and those after it
/// are not written, or wrong), or n when every vertex belonged.
template <int K, bool kWideSlots, bool kPacked, bool kPositions, bool kNormals, bool kFused>
OSSA_SOA_TARGET OSSA_SOA_INLINE uint32_t range_body(Cursor<kPacked> at, uint32_t n, const Layout& layout,
                                                    float* position_out, float* normal_out) {
  const Layout l = layout;  // a local copy: its fields stay in registers (the outputs cannot alias them)
  uint32_t i = 0;
  for (; i + 8 <= n; i += 8, at.advance(8 * l.stride)) {
    if (block<K, kWideSlots, kPacked, kPositions, kNormals, kFused, false>(
            at, 7, l, kPositions ? position_out + 3 * i : nullptr, kNormals ? normal_out + 3 * i : nullptr) != 0)
      return i;
  }
  if (i < n) {
    alignas(32) float p[24], q[24];
    if (block<K, kWideSlots, kPacked, kPositions, kNormals, kFused, true>(at, n - i - 1, l, p, q) != 0) return i;
    if constexpr (kPositions) std::memcpy(position_out + 3 * i, p, 12 * (n - i));
    if constexpr (kNormals) std::memcpy(normal_out + 3 * i, q, 12 * (n - i));
  }
  return n;
}

/// range_body compiled for AVX2 + FMA, and for AVX-512 (F/VL/BW/DQ: the same 256-bit code, with
/// 32 vector registers instead of 16).
template <int K, bool kWideSlots, bool kPacked, bool kPositions, bool kNormals, bool kFused>
OSSA_SOA_TARGET uint32_t range_avx2(Cursor<kPacked> at, uint32_t n, const Layout& l, float* position_out,
                                    float* normal_out) {
  return range_body<K, kWideSlots, kPacked, kPositions, kNormals, kFused>(at, n, l, position_out, normal_out);
}
template <int K, bool kWideSlots, bool kPacked, bool kPositions, bool kNormals, bool kFused>
OSSA_TARGET("avx2,fma,bmi,bmi2,popcnt,avx512f,avx512vl,avx512bw,avx512dq")
uint32_t range_avx512(Cursor<kPacked> at, uint32_t n, const Layout& l, float* position_out, float* normal_out) {
  return range_body<K, kWideSlots, kPacked, kPositions, kNormals, kFused>(at, n, l, position_out, normal_out);
}

}  // namespace ossa::soa
