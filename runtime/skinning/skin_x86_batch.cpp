// skin_x86_batch.cpp — the batch-level steps of skin_cpu's x86 fast paths (skin_x86.cpp): listing
// a batch's vertices by influence class, decoding its octahedral normals and tangents, and
// renormalizing the directions it wrote. Each runs once per batch of kBatch vertices.
//
// Why it is shaped so: these steps are structure-of-arrays over a whole batch, unlike the
// per-vertex loops, and are called once per batch, so they stand apart from the loops without a
// cost per vertex. Classification loads each vertex's four weight bytes as one word and derives
// the classes of 8 (AVX2) or 16 (AVX-512) vertices with vector compares, left-packing the vertex
// indices of each class into its list (a permute table on AVX2, vpcompressd on AVX-512): this is
// where AVX-512 pays. Scalar word loads rather than gathers: measured faster on Zen 4.
#include <array>
#include <cstdint>
#include <cstring>

#include "skinning/skin_internal.h"

#if OSSA_SKIN_X86
#include "skinning/soa_kernel.h"

namespace ossa::skin_detail {

// ---- classification ----

namespace {

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

}  // namespace

OSSA_TARGET_AVX2 void classify_avx2(const FastMesh& m, Batch& b) {
  alignas(32) uint32_t words[kBatch];
  load_weight_words(m, b, words);
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256i zero = _mm256_setzero_si256();
  uint32_t count[kClasses] = {0, 0, 0, 0, 0};  // locals: list stores cannot alias them
  for (uint32_t c = 0; c < b.n; c += 8) {
    const uint32_t valid = b.n - c >= 8 ? 0xffu : (1u << (b.n - c)) - 1u;
    const __m256i g = _mm256_load_si256(reinterpret_cast<const __m256i*>(words + c));
    const uint32_t z24 = static_cast<uint32_t>(
        _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(_mm256_srli_epi32(g, 24), zero))));
    const uint32_t z16 = static_cast<uint32_t>(
        _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(_mm256_srli_epi32(g, 16), zero))));
    const uint32_t z8 = static_cast<uint32_t>(
        _mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(_mm256_srli_epi32(g, 8), zero))));
    const uint32_t rigid =
        static_cast<uint32_t>(_mm256_movemask_ps(_mm256_castsi256_ps(_mm256_cmpeq_epi32(g, _mm256_set1_epi32(255))))) &
        valid;
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

namespace {

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

}  // namespace

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
  const __m256 sx = _mm256_set1_ps(m.prescale[0]), sy = _mm256_set1_ps(m.prescale[1]),
               sz = _mm256_set1_ps(m.prescale[2]);
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
      const __m256 sign =
          _mm256_or_ps(_mm256_set1_ps(1.0f),
                       _mm256_castsi256_ps(_mm256_and_si256(_mm256_slli_epi32(gs, 16), _mm256_set1_epi32(INT32_MIN))));
      store_aos4(_mm256_mul_ps(tx, sx), _mm256_mul_ps(ty, sy), _mm256_mul_ps(tz, sz), sign, b.tangent + c);
    }
  }
}

template void decode_directions<false>(const FastMesh& m, Batch& b);
template void decode_directions<true>(const FastMesh& m, Batch& b);

// ---- renormalization of the batch's outputs ----

namespace {

using soa::inverse_length;

/// Normalizes 8 packed xyz vectors in place (rsqrt + one Newton step, as soa_kernel.h does).
OSSA_TARGET_AVX2 inline void normalize_xyz8(float* p) {
  const __m256 a = _mm256_loadu_ps(p), b = _mm256_loadu_ps(p + 8), c = _mm256_loadu_ps(p + 16);
  const __m256 qa = _mm256_mul_ps(a, a), qb = _mm256_mul_ps(b, b), qc = _mm256_mul_ps(c, c);
  // a = x0 y0 z0 x1 y1 z1 x2 y2 | b = z2 x3 y3 z3 x4 y4 z4 x5 | c = y5 z5 x6 y6 z6 x7 y7 z7
  const __m256 xx =
      _mm256_blend_ps(_mm256_blend_ps(_mm256_permutevar8x32_ps(qa, _mm256_setr_epi32(0, 3, 6, 0, 0, 0, 0, 0)),
                                      _mm256_permutevar8x32_ps(qb, _mm256_setr_epi32(0, 0, 0, 1, 4, 7, 0, 0)), 0x38),
                      _mm256_permutevar8x32_ps(qc, _mm256_setr_epi32(0, 0, 0, 0, 0, 0, 2, 5)), 0xc0);
  const __m256 yy =
      _mm256_blend_ps(_mm256_blend_ps(_mm256_permutevar8x32_ps(qa, _mm256_setr_epi32(1, 4, 7, 0, 0, 0, 0, 0)),
                                      _mm256_permutevar8x32_ps(qb, _mm256_setr_epi32(0, 0, 0, 2, 5, 0, 0, 0)), 0x18),
                      _mm256_permutevar8x32_ps(qc, _mm256_setr_epi32(0, 0, 0, 0, 0, 0, 3, 6)), 0xe0);
  const __m256 zz =
      _mm256_blend_ps(_mm256_blend_ps(_mm256_permutevar8x32_ps(qa, _mm256_setr_epi32(2, 5, 0, 0, 0, 0, 0, 0)),
                                      _mm256_permutevar8x32_ps(qb, _mm256_setr_epi32(0, 0, 0, 3, 6, 0, 0, 0)), 0x1c),
                      _mm256_permutevar8x32_ps(qc, _mm256_setr_epi32(0, 0, 0, 0, 0, 1, 4, 7)), 0xe0);
  const __m256 inv = inverse_length(_mm256_add_ps(_mm256_add_ps(xx, yy), zz));
  _mm256_storeu_ps(p, _mm256_mul_ps(a, _mm256_permutevar8x32_ps(inv, _mm256_setr_epi32(0, 0, 0, 1, 1, 1, 2, 2))));
  _mm256_storeu_ps(p + 8, _mm256_mul_ps(b, _mm256_permutevar8x32_ps(inv, _mm256_setr_epi32(2, 3, 3, 3, 4, 4, 4, 5))));
  _mm256_storeu_ps(p + 16, _mm256_mul_ps(c, _mm256_permutevar8x32_ps(inv, _mm256_setr_epi32(5, 5, 6, 6, 6, 7, 7, 7))));
}

}  // namespace

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

}  // namespace ossa::skin_detail

#endif  // OSSA_SKIN_X86
