// cloth_kernels.cpp — cloth_kernels.h: edges, tethers, the world's carry, the prediction and the
// colliders eight at a time, in AVX2 intrinsics (x86-64 ELF builds with GCC or Clang, as the
// per-joint loops' AVX2 copy).
//
// Eight particles are eight vec4 rows (xyz, inverse mass); they are loaded as 16-byte rows and
// transposed in registers into x, y, z and w vectors (two rows per 256-bit register, then the
// 4 x 4 transpose in each 128-bit half) rather than gathered (gathers are slow on Zen). An edge or
// tether is 8 bytes, so eight of them are two 256-bit loads and one shuffle lines their lengths
// up; the lanes then run in that shuffle's order (kLane). The arithmetic repeats cloth_solve.cpp's
// scalar expressions operation for operation (no FMA, the same association), and lanes the scalar
// loop would skip keep their old values through blends, so the results are the scalar loop's bits.
#include "anim/cloth_kernels.h"

#include "internal/cpu.h"
#include "internal/vector_clones.h"

#if OSSA_HAVE_VECTOR_CLONES
#include <immintrin.h>
#endif

namespace ossa::detail {

#if OSSA_HAVE_VECTOR_CLONES

bool cloth_kernels_selected() { return vector_avx2_selected(); }

namespace {

#define OSSA_CLOTH_TARGET OSSA_TARGET("avx2")
// The GNU spelling: it follows OSSA_CLOTH_TARGET's __attribute__, after which Clang takes no [[...]].
#define OSSA_CLOTH_INLINE __attribute__((always_inline)) inline

struct Rows8 {
  __m256 x, y, z, w;
};

OSSA_CLOTH_TARGET OSSA_CLOTH_INLINE Rows8 transpose_in(__m128 r0, __m128 r1, __m128 r2, __m128 r3, __m128 r4, __m128 r5,
                                                       __m128 r6, __m128 r7) {
  const __m256 t0 = _mm256_insertf128_ps(_mm256_castps128_ps256(r0), r4, 1);
  const __m256 t1 = _mm256_insertf128_ps(_mm256_castps128_ps256(r1), r5, 1);
  const __m256 t2 = _mm256_insertf128_ps(_mm256_castps128_ps256(r2), r6, 1);
  const __m256 t3 = _mm256_insertf128_ps(_mm256_castps128_ps256(r3), r7, 1);
  const __m256 u0 = _mm256_unpacklo_ps(t0, t1), u1 = _mm256_unpackhi_ps(t0, t1);
  const __m256 u2 = _mm256_unpacklo_ps(t2, t3), u3 = _mm256_unpackhi_ps(t2, t3);
  return {_mm256_shuffle_ps(u0, u2, _MM_SHUFFLE(1, 0, 1, 0)), _mm256_shuffle_ps(u0, u2, _MM_SHUFFLE(3, 2, 3, 2)),
          _mm256_shuffle_ps(u1, u3, _MM_SHUFFLE(1, 0, 1, 0)), _mm256_shuffle_ps(u1, u3, _MM_SHUFFLE(3, 2, 3, 2))};
}

OSSA_CLOTH_TARGET OSSA_CLOTH_INLINE float* row(glm::vec4* x, uint32_t i) { return &x[i].x; }

/// The eight edges' lanes run in the order 0, 1, 4, 5, 2, 3, 6, 7: the order in which one shuffle
/// of two 256-bit loads of the edges (8 bytes each: a, b, rest) lines their rest lengths up.
constexpr int kLane[8] = {0, 1, 4, 5, 2, 3, 6, 7};

/// Eight floats in edge order into kLane order, and back.
OSSA_CLOTH_TARGET OSSA_CLOTH_INLINE __m256 lane_order(__m256 v) {
  return _mm256_castpd_ps(_mm256_permute4x64_pd(_mm256_castps_pd(v), _MM_SHUFFLE(3, 1, 2, 0)));
}

template <bool kB>
OSSA_CLOTH_TARGET OSSA_CLOTH_INLINE uint32_t end_of(const fb::ClothEdge* e, int lane) {
  return kB ? e[kLane[lane]].b() : e[kLane[lane]].a();
}
template <bool kB>
OSSA_CLOTH_TARGET OSSA_CLOTH_INLINE uint32_t end_of(const fb::ClothTether* t, int lane) {
  return kB ? t[kLane[lane]].anchor() : t[kLane[lane]].particle();
}

template <bool kB, typename Pair>
OSSA_CLOTH_TARGET OSSA_CLOTH_INLINE Rows8 load_ends(glm::vec4* x, const Pair* e) {
  return transpose_in(_mm_loadu_ps(row(x, end_of<kB>(e, 0))), _mm_loadu_ps(row(x, end_of<kB>(e, 1))),
                      _mm_loadu_ps(row(x, end_of<kB>(e, 2))), _mm_loadu_ps(row(x, end_of<kB>(e, 3))),
                      _mm_loadu_ps(row(x, end_of<kB>(e, 4))), _mm_loadu_ps(row(x, end_of<kB>(e, 5))),
                      _mm_loadu_ps(row(x, end_of<kB>(e, 6))), _mm_loadu_ps(row(x, end_of<kB>(e, 7))));
}

/// Eight rows back where they came from; the pairs of a run share no particle, so no store overlaps.
OSSA_CLOTH_TARGET OSSA_CLOTH_INLINE void transpose_out(const Rows8& r, __m128* rows) {
  const __m256 u0 = _mm256_unpacklo_ps(r.x, r.y), u1 = _mm256_unpackhi_ps(r.x, r.y);
  const __m256 u2 = _mm256_unpacklo_ps(r.z, r.w), u3 = _mm256_unpackhi_ps(r.z, r.w);
  const __m256 t0 = _mm256_shuffle_ps(u0, u2, _MM_SHUFFLE(1, 0, 1, 0));  // rows 0 | 4
  const __m256 t1 = _mm256_shuffle_ps(u0, u2, _MM_SHUFFLE(3, 2, 3, 2));  // rows 1 | 5
  const __m256 t2 = _mm256_shuffle_ps(u1, u3, _MM_SHUFFLE(1, 0, 1, 0));  // rows 2 | 6
  const __m256 t3 = _mm256_shuffle_ps(u1, u3, _MM_SHUFFLE(3, 2, 3, 2));  // rows 3 | 7
  rows[0] = _mm256_castps256_ps128(t0);
  rows[1] = _mm256_castps256_ps128(t1);
  rows[2] = _mm256_castps256_ps128(t2);
  rows[3] = _mm256_castps256_ps128(t3);
  rows[4] = _mm256_extractf128_ps(t0, 1);
  rows[5] = _mm256_extractf128_ps(t1, 1);
  rows[6] = _mm256_extractf128_ps(t2, 1);
  rows[7] = _mm256_extractf128_ps(t3, 1);
}

OSSA_CLOTH_TARGET OSSA_CLOTH_INLINE Rows8 load_block(const glm::vec4* x) {
  const float* p = &x->x;
  return transpose_in(_mm_loadu_ps(p), _mm_loadu_ps(p + 4), _mm_loadu_ps(p + 8), _mm_loadu_ps(p + 12),
                      _mm_loadu_ps(p + 16), _mm_loadu_ps(p + 20), _mm_loadu_ps(p + 24), _mm_loadu_ps(p + 28));
}

OSSA_CLOTH_TARGET OSSA_CLOTH_INLINE void store_block(glm::vec4* x, const Rows8& r) {
  __m128 rows[8];
  transpose_out(r, rows);
  for (size_t l = 0; l < 8; ++l) _mm_storeu_ps(&x[l].x, rows[l]);
}

template <bool kB, typename Pair>
OSSA_CLOTH_TARGET OSSA_CLOTH_INLINE void store_ends(glm::vec4* x, const Pair* e, const Rows8& r) {
  __m128 rows[8];
  transpose_out(r, rows);
  for (int l = 0; l < 8; ++l) _mm_storeu_ps(row(x, end_of<kB>(e, l)), rows[l]);
}

OSSA_CLOTH_TARGET OSSA_CLOTH_INLINE __m256 splat(float v) { return _mm256_set1_ps(v); }
/// x0 * x1 + y0 * y1 + z0 * z1 in glm::dot's order.
OSSA_CLOTH_TARGET OSSA_CLOTH_INLINE __m256 dot3(__m256 x0, __m256 y0, __m256 z0, __m256 x1, __m256 y1, __m256 z1) {
  return _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(x0, x1), _mm256_mul_ps(y0, y1)), _mm256_mul_ps(z0, z1));
}

template <bool kLambda>
OSSA_CLOTH_TARGET void edges8(glm::vec4* x, const fb::ClothEdge* e, size_t count, float alpha, float* lambda) {
  const __m256 va = _mm256_set1_ps(alpha), zero = _mm256_setzero_ps(), tiny = _mm256_set1_ps(1e-24f),
               sign = _mm256_set1_ps(-0.0f);
  static_assert(sizeof(fb::ClothEdge) == 8, "an edge is a, b (16 bits each) and rest (32 bits)");
  for (size_t k = 0; k < count; k += 8) {
    const fb::ClothEdge* eight = e + k;
    const __m256 lo = _mm256_loadu_ps(reinterpret_cast<const float*>(eight));
    const __m256 hi = _mm256_loadu_ps(reinterpret_cast<const float*>(eight + 4));
    const __m256 rest = _mm256_shuffle_ps(lo, hi, _MM_SHUFFLE(3, 1, 3, 1));  // lanes in kLane order
    Rows8 a = load_ends<false>(x, eight), b = load_ends<true>(x, eight);
    const __m256 wsum = _mm256_add_ps(a.w, b.w);
    const __m256 dx = _mm256_sub_ps(b.x, a.x), dy = _mm256_sub_ps(b.y, a.y), dz = _mm256_sub_ps(b.z, a.z);
    const __m256 len2 = dot3(dx, dy, dz, dx, dy, dz);
    const __m256 ok = _mm256_and_ps(_mm256_cmp_ps(len2, tiny, _CMP_GT_OQ), _mm256_cmp_ps(wsum, zero, _CMP_NEQ_UQ));
    if (_mm256_testz_ps(ok, ok)) continue;
    const __m256 len = _mm256_sqrt_ps(len2);
    const __m256 neg_violation = _mm256_xor_ps(_mm256_sub_ps(len, rest), sign);
    __m256 s;
    if constexpr (kLambda) {
      // Pairs of multipliers into kLane order and back (the swap of the middle pairs undoes itself).
      const __m256 lam = lane_order(_mm256_loadu_ps(lambda + k));
      const __m256 dl = _mm256_div_ps(_mm256_sub_ps(neg_violation, _mm256_mul_ps(va, lam)), _mm256_add_ps(wsum, va));
      _mm256_storeu_ps(lambda + k, lane_order(_mm256_blendv_ps(lam, _mm256_add_ps(lam, dl), ok)));
      s = _mm256_div_ps(dl, len);
    } else {
      s = _mm256_div_ps(neg_violation, _mm256_mul_ps(_mm256_add_ps(wsum, va), len));
    }
    const __m256 cx = _mm256_mul_ps(dx, s), cy = _mm256_mul_ps(dy, s), cz = _mm256_mul_ps(dz, s);
    a.x = _mm256_blendv_ps(a.x, _mm256_sub_ps(a.x, _mm256_mul_ps(a.w, cx)), ok);
    a.y = _mm256_blendv_ps(a.y, _mm256_sub_ps(a.y, _mm256_mul_ps(a.w, cy)), ok);
    a.z = _mm256_blendv_ps(a.z, _mm256_sub_ps(a.z, _mm256_mul_ps(a.w, cz)), ok);
    b.x = _mm256_blendv_ps(b.x, _mm256_add_ps(b.x, _mm256_mul_ps(b.w, cx)), ok);
    b.y = _mm256_blendv_ps(b.y, _mm256_add_ps(b.y, _mm256_mul_ps(b.w, cy)), ok);
    b.z = _mm256_blendv_ps(b.z, _mm256_add_ps(b.z, _mm256_mul_ps(b.w, cz)), ok);
    store_ends<false>(x, eight, a);
    store_ends<true>(x, eight, b);
  }
}

OSSA_CLOTH_TARGET void tethers8(glm::vec4* x, const fb::ClothTether* t, size_t count, float scale) {
  static_assert(sizeof(fb::ClothTether) == 8, "a tether is particle, anchor (16 bits each) and length (32 bits)");
  for (size_t k = 0; k < count; k += 8) {
    const fb::ClothTether* eight = t + k;
    const __m256 lo = _mm256_loadu_ps(reinterpret_cast<const float*>(eight));
    const __m256 hi = _mm256_loadu_ps(reinterpret_cast<const float*>(eight + 4));
    const __m256 limit = _mm256_mul_ps(_mm256_shuffle_ps(lo, hi, _MM_SHUFFLE(3, 1, 3, 1)), _mm256_set1_ps(scale));
    Rows8 p = load_ends<false>(x, eight);
    const Rows8 a = load_ends<true>(x, eight);
    const __m256 dx = _mm256_sub_ps(p.x, a.x), dy = _mm256_sub_ps(p.y, a.y), dz = _mm256_sub_ps(p.z, a.z);
    const __m256 len2 = dot3(dx, dy, dz, dx, dy, dz);
    const __m256 over = _mm256_and_ps(_mm256_cmp_ps(p.w, _mm256_setzero_ps(), _CMP_NEQ_UQ),
                                      _mm256_cmp_ps(len2, _mm256_mul_ps(limit, limit), _CMP_NLE_UQ));
    if (_mm256_testz_ps(over, over)) continue;
    const __m256 s = _mm256_div_ps(limit, _mm256_sqrt_ps(len2));
    p.x = _mm256_blendv_ps(p.x, _mm256_add_ps(a.x, _mm256_mul_ps(dx, s)), over);
    p.y = _mm256_blendv_ps(p.y, _mm256_add_ps(a.y, _mm256_mul_ps(dy, s)), over);
    p.z = _mm256_blendv_ps(p.z, _mm256_add_ps(a.z, _mm256_mul_ps(dz, s)), over);
    store_ends<false>(x, eight, p);
  }
}

/// Row `row` of r * p + t for eight points (glm's mat3 * vec3 order: column 0's term, plus column
/// 1's, plus column 2's; then t).
OSSA_CLOTH_TARGET OSSA_CLOTH_INLINE __m256 transformed(const Rows8& p, const glm::mat3& r, const glm::vec3& t,
                                                       int row) {
  return _mm256_add_ps(_mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(_mm256_set1_ps(r[0][row]), p.x),
                                                   _mm256_mul_ps(_mm256_set1_ps(r[1][row]), p.y)),
                                     _mm256_mul_ps(_mm256_set1_ps(r[2][row]), p.z)),
                       _mm256_set1_ps(t[row]));
}

OSSA_CLOTH_TARGET OSSA_CLOTH_INLINE void transform(Rows8& p, const glm::mat3& r, const glm::vec3& t) {
  const __m256 x = transformed(p, r, t, 0), y = transformed(p, r, t, 1), z = transformed(p, r, t, 2);
  p.x = x;
  p.y = y;
  p.z = z;
}

OSSA_CLOTH_TARGET void carry8(glm::vec4* x, glm::vec4* previous, size_t count, const glm::mat3& r, const glm::vec3& t) {
  for (size_t i = 0; i < count; i += 8) {
    Rows8 a = load_block(x + i), b = load_block(previous + i);
    transform(a, r, t);
    transform(b, r, t);
    store_block(x + i, a);
    store_block(previous + i, b);
  }
}

OSSA_CLOTH_TARGET uint32_t predict8(glm::vec4* x, glm::vec4* previous, size_t first, float keep,
                                    const glm::vec3& gravity, float max_step) {
  Rows8 at = load_block(x + first), p = load_block(previous + first);
  const __m256 fixed = _mm256_cmp_ps(at.w, _mm256_setzero_ps(), _CMP_EQ_OQ);
  const __m256 k = _mm256_set1_ps(keep);
  __m256 vx = _mm256_add_ps(_mm256_mul_ps(_mm256_sub_ps(at.x, p.x), k), _mm256_set1_ps(gravity.x));
  __m256 vy = _mm256_add_ps(_mm256_mul_ps(_mm256_sub_ps(at.y, p.y), k), _mm256_set1_ps(gravity.y));
  __m256 vz = _mm256_add_ps(_mm256_mul_ps(_mm256_sub_ps(at.z, p.z), k), _mm256_set1_ps(gravity.z));
  const float max2 = max_step * max_step;
  if (max2 > 0.0f) {
    const __m256 l2 = dot3(vx, vy, vz, vx, vy, vz);
    const __m256 fast = _mm256_cmp_ps(l2, _mm256_set1_ps(max2), _CMP_GT_OQ);
    if (!_mm256_testz_ps(fast, fast)) {
      const __m256 s = _mm256_div_ps(_mm256_set1_ps(max_step), _mm256_sqrt_ps(l2));
      vx = _mm256_blendv_ps(vx, _mm256_mul_ps(vx, s), fast);
      vy = _mm256_blendv_ps(vy, _mm256_mul_ps(vy, s), fast);
      vz = _mm256_blendv_ps(vz, _mm256_mul_ps(vz, s), fast);
    }
  }
  // Free lanes: previous = at, current = at + v; fixed lanes are left to the caller.
  const Rows8 moved{_mm256_blendv_ps(_mm256_add_ps(at.x, vx), at.x, fixed),
                    _mm256_blendv_ps(_mm256_add_ps(at.y, vy), at.y, fixed),
                    _mm256_blendv_ps(_mm256_add_ps(at.z, vz), at.z, fixed), at.w};
  const Rows8 was{_mm256_blendv_ps(at.x, p.x, fixed), _mm256_blendv_ps(at.y, p.y, fixed),
                  _mm256_blendv_ps(at.z, p.z, fixed), p.w};
  store_block(x + first, moved);
  store_block(previous + first, was);
  return static_cast<uint32_t>(_mm256_movemask_ps(fixed));
}

/// Eight points (p; `side`: where one exactly on a collider's axis goes out towards; `free`: the
/// lanes that move) pushed out of each collider of `step` in turn, as cloth_solve.cpp's push_out
/// pushes one: a collider whose bounding sphere and capsule hold none of the lanes costs a few
/// operations. Returns the lanes moved.
OSSA_CLOTH_TARGET OSSA_CLOTH_INLINE __m256 push_out8(__m256& px, __m256& py, __m256& pz, __m256 sx, __m256 sy,
                                                     __m256 sz, __m256 free, const glm::vec4* step, size_t count) {
  const __m256 zero = _mm256_setzero_ps(), one = splat(1.0f), tiny = splat(1e-12f);
  __m256 moved = zero;
  for (size_t k = 0; k < count; ++k) {
    const glm::vec4& ea = step[3 * k];
    const glm::vec4& eb = step[3 * k + 1];
    const glm::vec4& bound = step[3 * k + 2];
    const __m256 dcx = _mm256_sub_ps(px, splat(bound.x)), dcy = _mm256_sub_ps(py, splat(bound.y)),
                 dcz = _mm256_sub_ps(pz, splat(bound.z));
    const __m256 d2 = dot3(dcx, dcy, dcz, dcx, dcy, dcz);
    const __m256 near = _mm256_and_ps(free, _mm256_cmp_ps(d2, splat(bound.w), _CMP_NGE_UQ));
    if (_mm256_testz_ps(near, near)) continue;
    // closest_on_segment: a + ab * clamp(dot(p - a, ab) / |ab|^2, 0, 1), or a when |ab| = 0.
    const glm::vec3 a(ea), ab = glm::vec3(eb) - a;
    const float len2 = glm::dot(ab, ab);
    __m256 qx = splat(a.x), qy = splat(a.y), qz = splat(a.z);
    if (len2 > 0.0f) {
      __m256 t = _mm256_div_ps(dot3(_mm256_sub_ps(px, qx), _mm256_sub_ps(py, qy), _mm256_sub_ps(pz, qz), splat(ab.x),
                                    splat(ab.y), splat(ab.z)),
                               splat(len2));
      t = _mm256_blendv_ps(t, zero, _mm256_cmp_ps(t, zero, _CMP_LT_OQ));  // std::clamp's order: below, then above
      t = _mm256_blendv_ps(t, one, _mm256_cmp_ps(one, t, _CMP_LT_OQ));
      qx = _mm256_add_ps(qx, _mm256_mul_ps(splat(ab.x), t));
      qy = _mm256_add_ps(qy, _mm256_mul_ps(splat(ab.y), t));
      qz = _mm256_add_ps(qz, _mm256_mul_ps(splat(ab.z), t));
    }
    const __m256 ax = _mm256_sub_ps(px, qx), ay = _mm256_sub_ps(py, qy), az = _mm256_sub_ps(pz, qz);
    const __m256 dist2 = dot3(ax, ay, az, ax, ay, az);
    const __m256 hit = _mm256_and_ps(near, _mm256_cmp_ps(dist2, splat(ea.w * ea.w), _CMP_NGE_UQ));
    if (_mm256_testz_ps(hit, hit)) continue;
    const __m256 dist = _mm256_sqrt_ps(dist2);
    const __m256 off_axis = _mm256_cmp_ps(dist, tiny, _CMP_GT_OQ);
    __m256 dx = _mm256_blendv_ps(_mm256_sub_ps(sx, qx), _mm256_div_ps(ax, dist), off_axis);
    __m256 dy = _mm256_blendv_ps(_mm256_sub_ps(sy, qy), _mm256_div_ps(ay, dist), off_axis);
    __m256 dz = _mm256_blendv_ps(_mm256_sub_ps(sz, qz), _mm256_div_ps(az, dist), off_axis);
    const __m256 dl = _mm256_sqrt_ps(dot3(dx, dy, dz, dx, dy, dz));
    const __m256 usable = _mm256_cmp_ps(dl, tiny, _CMP_GT_OQ);
    dx = _mm256_blendv_ps(zero, _mm256_div_ps(dx, dl), usable);
    dy = _mm256_blendv_ps(one, _mm256_div_ps(dy, dl), usable);
    dz = _mm256_blendv_ps(zero, _mm256_div_ps(dz, dl), usable);
    const __m256 reach = splat(ea.w);
    px = _mm256_blendv_ps(px, _mm256_add_ps(qx, _mm256_mul_ps(dx, reach)), hit);
    py = _mm256_blendv_ps(py, _mm256_add_ps(qy, _mm256_mul_ps(dy, reach)), hit);
    pz = _mm256_blendv_ps(pz, _mm256_add_ps(qz, _mm256_mul_ps(dz, reach)), hit);
    moved = _mm256_or_ps(moved, hit);
  }
  return moved;
}

OSSA_CLOTH_TARGET void push4(glm::vec4* x, const glm::vec4* previous, size_t first, const glm::vec4* step,
                             size_t count) {
  Rows8 r = load_block(x + first);
  const Rows8 side = load_block(previous + first);
  const __m256 free = _mm256_cmp_ps(r.w, _mm256_setzero_ps(), _CMP_NEQ_UQ);
  const __m256 moved = push_out8(r.x, r.y, r.z, side.x, side.y, side.z, free, step, count);
  if (_mm256_testz_ps(moved, moved)) return;
  alignas(32) float out[3][8];
  _mm256_store_ps(out[0], r.x);
  _mm256_store_ps(out[1], r.y);
  _mm256_store_ps(out[2], r.z);
  const int mask = _mm256_movemask_ps(moved);
  for (size_t l = 0; l < 8; ++l)
    if (mask & (1 << l)) x[first + l] = glm::vec4(out[0][l], out[1][l], out[2][l], x[first + l].w);
}

OSSA_CLOTH_TARGET void push3(glm::vec3* p, const glm::vec4* state, size_t first, const glm::vec4* step, size_t count) {
  alignas(32) float in[7][8];
  for (size_t l = 0; l < 8; ++l) {
    in[0][l] = p[first + l].x;
    in[1][l] = p[first + l].y;
    in[2][l] = p[first + l].z;
    in[3][l] = state[first + l].x;
    in[4][l] = state[first + l].y;
    in[5][l] = state[first + l].z;
    in[6][l] = state[first + l].w;
  }
  __m256 px = _mm256_load_ps(in[0]), py = _mm256_load_ps(in[1]), pz = _mm256_load_ps(in[2]);
  const __m256 free = _mm256_cmp_ps(_mm256_load_ps(in[6]), _mm256_setzero_ps(), _CMP_NEQ_UQ);
  const __m256 moved =
      push_out8(px, py, pz, _mm256_load_ps(in[3]), _mm256_load_ps(in[4]), _mm256_load_ps(in[5]), free, step, count);
  if (_mm256_testz_ps(moved, moved)) return;
  _mm256_store_ps(in[0], px);
  _mm256_store_ps(in[1], py);
  _mm256_store_ps(in[2], pz);
  const int mask = _mm256_movemask_ps(moved);
  for (size_t l = 0; l < 8; ++l)
    if (mask & (1 << l)) p[first + l] = glm::vec3(in[0][l], in[1][l], in[2][l]);
}

}  // namespace

void project_edges8(glm::vec4* x, const fb::ClothEdge* edges, size_t count, float alpha, float* lambda) {
  if (lambda) edges8<true>(x, edges, count, alpha, lambda);
  else edges8<false>(x, edges, count, alpha, nullptr);
}

void project_tethers8(glm::vec4* x, const fb::ClothTether* tethers, size_t count, float scale) {
  tethers8(x, tethers, count, scale);
}

void carry_particles8(glm::vec4* x, glm::vec4* previous, size_t count, const glm::mat3& r, const glm::vec3& t) {
  carry8(x, previous, count, r, t);
}

uint32_t predict_particles8(glm::vec4* x, glm::vec4* previous, size_t first, float keep, const glm::vec3& gravity,
                            float max_step) {
  return predict8(x, previous, first, keep, gravity, max_step);
}

void push_out_colliders8(glm::vec4* x, const glm::vec4* previous, size_t first, const glm::vec4* step, size_t count) {
  push4(x, previous, first, step, count);
}

void push_out_colliders8(glm::vec3* p, const glm::vec4* state, size_t first, const glm::vec4* step, size_t count) {
  push3(p, state, first, step, count);
}

#else

bool cloth_kernels_selected() { return false; }

#endif

}  // namespace ossa::detail
