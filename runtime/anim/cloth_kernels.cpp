// cloth_kernels.cpp — cloth_kernels.h: edges, tethers, the world's carry, the prediction and the
// colliders eight at a time, in AVX2 intrinsics (x86-64 ELF builds with GCC or Clang, as the
// per-joint loops' AVX2 copy).
//
// The particles are planes (ClothParticles: x[], y[], z[], w[]), so eight consecutive particles
// are one plain load per coordinate. A constraint group's ends are read by its kind (WideKind:
// two blocks of consecutive particles, or sixteen consecutive ones in pairs, one in-lane shuffle
// per coordinate and end; the general kind gathers and stores lane by lane), and its rest lengths
// and inverse masses are per lane, in the lanes' order, in the wide list. The arithmetic repeats
// cloth_solve.cpp's scalar expressions operation for operation (no FMA, the same association),
// and lanes the scalar loop would skip keep their old values through blends, so the results are
// the scalar loop's bits.
#include "anim/cloth_kernels.h"

#include <cmath>

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

/// Eight particles' planes from `first`: the current position and inverse mass, or (`before`)
/// the previous position (w unused).
OSSA_CLOTH_TARGET OSSA_CLOTH_INLINE Rows8 load8(const ClothParticles& p, size_t first, bool before = false) {
  if (before)
    return {_mm256_loadu_ps(p.px.data() + first), _mm256_loadu_ps(p.py.data() + first),
            _mm256_loadu_ps(p.pz.data() + first), _mm256_setzero_ps()};
  return {_mm256_loadu_ps(p.x.data() + first), _mm256_loadu_ps(p.y.data() + first), _mm256_loadu_ps(p.z.data() + first),
          _mm256_loadu_ps(p.w.data() + first)};
}

OSSA_CLOTH_TARGET OSSA_CLOTH_INLINE void store8(ClothParticles& p, size_t first, const Rows8& r, bool before = false) {
  _mm256_storeu_ps((before ? p.px : p.x).data() + first, r.x);
  _mm256_storeu_ps((before ? p.py : p.y).data() + first, r.y);
  _mm256_storeu_ps((before ? p.pz : p.z).data() + first, r.z);
}

OSSA_CLOTH_TARGET OSSA_CLOTH_INLINE __m256 splat(float v) { return _mm256_set1_ps(v); }
/// x0 * x1 + y0 * y1 + z0 * z1 in glm::dot's order.
OSSA_CLOTH_TARGET OSSA_CLOTH_INLINE __m256 dot3(__m256 x0, __m256 y0, __m256 z0, __m256 x1, __m256 y1, __m256 z1) {
  return _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(x0, x1), _mm256_mul_ps(y0, y1)), _mm256_mul_ps(z0, z1));
}

/// One end's coordinate for a group's eight lanes from its plane p (kind: WideKind), and back.
template <int kKind>
OSSA_CLOTH_TARGET OSSA_CLOTH_INLINE void load_plane(const float* p, const uint32_t* ia, const uint32_t* ib, __m256& a,
                                                    __m256& b) {
  if constexpr (kKind == kBlocks) {
    a = _mm256_loadu_ps(p + ia[0]);
    b = _mm256_loadu_ps(p + ib[0]);
  } else if constexpr (kKind == kGather) {
    a = _mm256_i32gather_ps(p, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(ia)), 4);
    b = _mm256_i32gather_ps(p, _mm256_loadu_si256(reinterpret_cast<const __m256i*>(ib)), 4);
  } else {
    // Sixteen particles: a's lanes 0, 2, 8, 10, 4, 6, 12, 14 and b = a + 1 (kPairs1), or a's
    // 0, 1, 8, 9, 4, 5, 12, 13 and b = a + 2 (kPairs2): one in-lane shuffle of the two halves each.
    const __m256 lo = _mm256_loadu_ps(p + ia[0]), hi = _mm256_loadu_ps(p + ia[0] + 8);
    a = kKind == kPairs1 ? _mm256_shuffle_ps(lo, hi, _MM_SHUFFLE(2, 0, 2, 0))
                         : _mm256_shuffle_ps(lo, hi, _MM_SHUFFLE(1, 0, 1, 0));
    b = kKind == kPairs1 ? _mm256_shuffle_ps(lo, hi, _MM_SHUFFLE(3, 1, 3, 1))
                         : _mm256_shuffle_ps(lo, hi, _MM_SHUFFLE(3, 2, 3, 2));
  }
}

/// Stores a's lanes (and b's, with kB) back into the plane.
template <int kKind, bool kB>
OSSA_CLOTH_TARGET OSSA_CLOTH_INLINE void store_plane(float* p, const uint32_t* ia, const uint32_t* ib, __m256 a,
                                                     __m256 b) {
  if constexpr (kKind == kBlocks) {
    _mm256_storeu_ps(p + ia[0], a);
    if (kB) _mm256_storeu_ps(p + ib[0], b);
  } else if constexpr (kKind == kGather) {
    alignas(32) float out[2][8];
    _mm256_store_ps(out[0], a);
    _mm256_store_ps(out[1], b);
    for (size_t l = 0; l < 8; ++l) {
      p[ia[l]] = out[0][l];
      if (kB) p[ib[l]] = out[1][l];
    }
  } else {
    static_assert(kB, "the pair kinds are edges'");
    _mm256_storeu_ps(p + ia[0], kKind == kPairs1 ? _mm256_unpacklo_ps(a, b) : _mm256_shuffle_ps(a, b, 0x44));
    _mm256_storeu_ps(p + ia[0] + 8, kKind == kPairs1 ? _mm256_unpackhi_ps(a, b) : _mm256_shuffle_ps(a, b, 0xEE));
  }
}

/// The current positions' planes.
struct Planes {
  float *x, *y, *z;
};

template <int kKind, bool kLambda>
OSSA_CLOTH_TARGET OSSA_CLOTH_INLINE void edge_group(const Planes& p, const ClothWideList& l, size_t k, __m256 va,
                                                    float* lambda) {
  const __m256 zero = _mm256_setzero_ps(), tiny = _mm256_set1_ps(1e-24f), sign = _mm256_set1_ps(-0.0f);
  const uint32_t *ia = l.a.data() + k, *ib = l.b.data() + k;
  __m256 ax, ay, az, bx, by, bz;
  load_plane<kKind>(p.x, ia, ib, ax, bx);
  load_plane<kKind>(p.y, ia, ib, ay, by);
  load_plane<kKind>(p.z, ia, ib, az, bz);
  const __m256 wa = _mm256_loadu_ps(l.wa.data() + k), wb = _mm256_loadu_ps(l.wb.data() + k);
  const __m256 wsum = _mm256_add_ps(wa, wb);
  const __m256 dx = _mm256_sub_ps(bx, ax), dy = _mm256_sub_ps(by, ay), dz = _mm256_sub_ps(bz, az);
  const __m256 len2 = dot3(dx, dy, dz, dx, dy, dz);
  const __m256 ok = _mm256_and_ps(_mm256_cmp_ps(len2, tiny, _CMP_GT_OQ), _mm256_cmp_ps(wsum, zero, _CMP_NEQ_UQ));
  if (_mm256_testz_ps(ok, ok)) return;
  const __m256 len = _mm256_sqrt_ps(len2);
  const __m256 neg_violation = _mm256_xor_ps(_mm256_sub_ps(len, _mm256_loadu_ps(l.rest.data() + k)), sign);
  __m256 s;
  if constexpr (kLambda) {
    const __m256 lam = _mm256_loadu_ps(lambda + k);
    const __m256 dl = _mm256_div_ps(_mm256_sub_ps(neg_violation, _mm256_mul_ps(va, lam)), _mm256_add_ps(wsum, va));
    _mm256_storeu_ps(lambda + k, _mm256_blendv_ps(lam, _mm256_add_ps(lam, dl), ok));
    s = _mm256_div_ps(dl, len);
  } else {
    s = _mm256_div_ps(neg_violation, _mm256_mul_ps(_mm256_add_ps(wsum, va), len));
  }
  const __m256 cx = _mm256_mul_ps(dx, s), cy = _mm256_mul_ps(dy, s), cz = _mm256_mul_ps(dz, s);
  ax = _mm256_blendv_ps(ax, _mm256_sub_ps(ax, _mm256_mul_ps(wa, cx)), ok);
  ay = _mm256_blendv_ps(ay, _mm256_sub_ps(ay, _mm256_mul_ps(wa, cy)), ok);
  az = _mm256_blendv_ps(az, _mm256_sub_ps(az, _mm256_mul_ps(wa, cz)), ok);
  bx = _mm256_blendv_ps(bx, _mm256_add_ps(bx, _mm256_mul_ps(wb, cx)), ok);
  by = _mm256_blendv_ps(by, _mm256_add_ps(by, _mm256_mul_ps(wb, cy)), ok);
  bz = _mm256_blendv_ps(bz, _mm256_add_ps(bz, _mm256_mul_ps(wb, cz)), ok);
  store_plane<kKind, true>(p.x, ia, ib, ax, bx);
  store_plane<kKind, true>(p.y, ia, ib, ay, by);
  store_plane<kKind, true>(p.z, ia, ib, az, bz);
}

/// Lane k alone: cloth_solve.cpp's project_edge operation for operation.
template <bool kLambda>
OSSA_CLOTH_TARGET OSSA_CLOTH_INLINE void edge_one(const Planes& p, const ClothWideList& l, size_t k, float alpha,
                                                  float* lambda) {
  const uint32_t a = l.a[k], b = l.b[k];
  const float wa = l.wa[k], wb = l.wb[k], wsum = wa + wb;
  const float dx = p.x[b] - p.x[a], dy = p.y[b] - p.y[a], dz = p.z[b] - p.z[a];
  const float len2 = dx * dx + dy * dy + dz * dz;
  if (!(len2 > 1e-24f) || wsum == 0.0f) return;
  const float len = std::sqrt(len2);
  const float violation = len - l.rest[k];
  float s;
  if constexpr (kLambda) {
    const float dl = (-violation - alpha * lambda[k]) / (wsum + alpha);
    lambda[k] += dl;
    s = dl / len;
  } else {
    s = -violation / ((wsum + alpha) * len);
  }
  const float cx = dx * s, cy = dy * s, cz = dz * s;
  p.x[a] -= wa * cx;
  p.y[a] -= wa * cy;
  p.z[a] -= wa * cz;
  p.x[b] += wb * cx;
  p.y[b] += wb * cy;
  p.z[b] += wb * cz;
}

template <int kKind>
OSSA_CLOTH_TARGET OSSA_CLOTH_INLINE void tether_group(const Planes& p, const ClothWideList& l, size_t k, float scale) {
  const uint32_t *ia = l.a.data() + k, *ib = l.b.data() + k;
  __m256 px, py, pz, qx, qy, qz;
  load_plane<kKind>(p.x, ia, ib, px, qx);
  load_plane<kKind>(p.y, ia, ib, py, qy);
  load_plane<kKind>(p.z, ia, ib, pz, qz);
  const __m256 limit = _mm256_mul_ps(_mm256_loadu_ps(l.rest.data() + k), _mm256_set1_ps(scale));
  const __m256 dx = _mm256_sub_ps(px, qx), dy = _mm256_sub_ps(py, qy), dz = _mm256_sub_ps(pz, qz);
  const __m256 len2 = dot3(dx, dy, dz, dx, dy, dz);
  const __m256 over = _mm256_and_ps(_mm256_cmp_ps(_mm256_loadu_ps(l.wa.data() + k), _mm256_setzero_ps(), _CMP_NEQ_UQ),
                                    _mm256_cmp_ps(len2, _mm256_mul_ps(limit, limit), _CMP_NLE_UQ));
  if (_mm256_testz_ps(over, over)) return;
  const __m256 s = _mm256_div_ps(limit, _mm256_sqrt_ps(len2));
  px = _mm256_blendv_ps(px, _mm256_add_ps(qx, _mm256_mul_ps(dx, s)), over);
  py = _mm256_blendv_ps(py, _mm256_add_ps(qy, _mm256_mul_ps(dy, s)), over);
  pz = _mm256_blendv_ps(pz, _mm256_add_ps(qz, _mm256_mul_ps(dz, s)), over);
  store_plane<kKind, false>(p.x, ia, ib, px, qx);
  store_plane<kKind, false>(p.y, ia, ib, py, qy);
  store_plane<kKind, false>(p.z, ia, ib, pz, qz);
}

/// Lane k alone: cloth_solve.cpp's project_tether (hold_within) operation for operation.
OSSA_CLOTH_TARGET OSSA_CLOTH_INLINE void tether_one(const Planes& p, const ClothWideList& l, size_t k, float scale) {
  if (l.wa[k] == 0.0f) return;
  const uint32_t a = l.a[k], b = l.b[k];
  const float limit = l.rest[k] * scale;
  const float dx = p.x[a] - p.x[b], dy = p.y[a] - p.y[b], dz = p.z[a] - p.z[b];
  const float len2 = dx * dx + dy * dy + dz * dz;
  if (len2 <= limit * limit) return;
  const float s = limit / std::sqrt(len2);
  p.x[a] = p.x[b] + dx * s;
  p.y[a] = p.y[b] + dy * s;
  p.z[a] = p.z[b] + dz * s;
}

template <bool kLambda>
OSSA_CLOTH_TARGET void wide_edges(const Planes& p, const ClothWideList& l, float alpha, float* lambda) {
  const __m256 va = _mm256_set1_ps(alpha);
  size_t k = 0, group = 0;
  for (size_t r = 0; r + 1 < l.runs.size(); r += 2) {
    for (; k < l.runs[r]; k += 8, ++group) {
      switch (l.kinds[group]) {
        case kBlocks: edge_group<kBlocks, kLambda>(p, l, k, va, lambda); break;
        case kPairs1: edge_group<kPairs1, kLambda>(p, l, k, va, lambda); break;
        case kPairs2: edge_group<kPairs2, kLambda>(p, l, k, va, lambda); break;
        default: edge_group<kGather, kLambda>(p, l, k, va, lambda); break;
      }
    }
    for (; k < l.runs[r + 1]; ++k) edge_one<kLambda>(p, l, k, alpha, lambda);
  }
}

OSSA_CLOTH_TARGET void wide_tethers(const Planes& p, const ClothWideList& l, float scale) {
  size_t k = 0, group = 0;
  for (size_t r = 0; r + 1 < l.runs.size(); r += 2) {
    for (; k < l.runs[r]; k += 8, ++group) {
      if (l.kinds[group] == kBlocks) tether_group<kBlocks>(p, l, k, scale);
      else tether_group<kGather>(p, l, k, scale);
    }
    for (; k < l.runs[r + 1]; ++k) tether_one(p, l, k, scale);
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

OSSA_CLOTH_TARGET void carry8(ClothParticles& p, size_t count, const glm::mat3& r, const glm::vec3& t) {
  for (size_t i = 0; i < count; i += 8)
    for (const bool before : {false, true}) {
      Rows8 a = load8(p, i, before);
      transform(a, r, t);
      store8(p, i, a, before);
    }
}

OSSA_CLOTH_TARGET uint32_t predict8(ClothParticles& c, size_t first, float keep, const glm::vec3& gravity,
                                    float max_step, const glm::mat3* r, const glm::vec3& t) {
  Rows8 at = load8(c, first), p = load8(c, first, true);
  if (r) {  // carry8's operations
    transform(at, *r, t);
    transform(p, *r, t);
  }
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
  store8(
      c, first,
      {_mm256_blendv_ps(_mm256_add_ps(at.x, vx), at.x, fixed), _mm256_blendv_ps(_mm256_add_ps(at.y, vy), at.y, fixed),
       _mm256_blendv_ps(_mm256_add_ps(at.z, vz), at.z, fixed), at.w});
  store8(
      c, first,
      {_mm256_blendv_ps(at.x, p.x, fixed), _mm256_blendv_ps(at.y, p.y, fixed), _mm256_blendv_ps(at.z, p.z, fixed), p.w},
      true);
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

OSSA_CLOTH_TARGET void push4(ClothParticles& c, size_t first, const glm::vec4* step, size_t count) {
  Rows8 r = load8(c, first);
  const Rows8 side = load8(c, first, true);
  const __m256 free = _mm256_cmp_ps(r.w, _mm256_setzero_ps(), _CMP_NEQ_UQ);
  const __m256 moved = push_out8(r.x, r.y, r.z, side.x, side.y, side.z, free, step, count);
  if (!_mm256_testz_ps(moved, moved)) store8(c, first, r);  // lanes not moved keep their bits
}

OSSA_CLOTH_TARGET void push3(glm::vec3* p, const ClothParticles& state, size_t first, const glm::vec4* step,
                             size_t count) {
  alignas(32) float in[3][8];
  for (size_t l = 0; l < 8; ++l) {
    in[0][l] = p[first + l].x;
    in[1][l] = p[first + l].y;
    in[2][l] = p[first + l].z;
  }
  __m256 px = _mm256_load_ps(in[0]), py = _mm256_load_ps(in[1]), pz = _mm256_load_ps(in[2]);
  const Rows8 side = load8(state, first);
  const __m256 free = _mm256_cmp_ps(side.w, _mm256_setzero_ps(), _CMP_NEQ_UQ);
  const __m256 moved = push_out8(px, py, pz, side.x, side.y, side.z, free, step, count);
  if (_mm256_testz_ps(moved, moved)) return;
  _mm256_store_ps(in[0], px);
  _mm256_store_ps(in[1], py);
  _mm256_store_ps(in[2], pz);
  const int mask = _mm256_movemask_ps(moved);
  for (size_t l = 0; l < 8; ++l)
    if (mask & (1 << l)) p[first + l] = glm::vec3(in[0][l], in[1][l], in[2][l]);
}

}  // namespace

void project_wide(ClothParticles& p, const ClothWideList& list, bool tethers, float alpha, float tether_scale,
                  float* lambda) {
  const Planes planes{p.x.data(), p.y.data(), p.z.data()};
  if (tethers) wide_tethers(planes, list, tether_scale);
  else if (lambda) wide_edges<true>(planes, list, alpha, lambda);
  else wide_edges<false>(planes, list, alpha, nullptr);
}

void carry_particles8(ClothParticles& p, size_t count, const glm::mat3& r, const glm::vec3& t) {
  carry8(p, count, r, t);
}

uint32_t predict_particles8(ClothParticles& p, size_t first, float keep, const glm::vec3& gravity, float max_step,
                            const glm::mat3* r, const glm::vec3& t) {
  return predict8(p, first, keep, gravity, max_step, r, t);
}

void push_out_colliders8(ClothParticles& p, size_t first, const glm::vec4* step, size_t count) {
  push4(p, first, step, count);
}

void push_out_colliders8(glm::vec3* out, const ClothParticles& state, size_t first, const glm::vec4* step,
                         size_t count) {
  push3(out, state, first, step, count);
}

#else

bool cloth_kernels_selected() { return false; }

#endif

}  // namespace ossa::detail
