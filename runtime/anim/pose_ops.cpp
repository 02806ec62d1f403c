// pose_ops.cpp — blend, blend_n, blend_layered, joint masks and additive layers over SoA poses
// (pose_ops.h).
//
// Loop shape. Every per-joint loop is an outer loop over blocks of kPoseLanes (8) lanes and an
// inner loop over the 8 lanes of a block. The inner loop has a fixed trip count that is a
// multiple of every vector width, so GCC's -O2 vectorizer (cost model "very cheap": no peeling,
// no epilogue, no run-time alias checks) turns it into 4-wide SSE code, and into 8-wide AVX code
// in the avx2 copy that OSSA_VECTOR_DISPATCH compiles; the baseline copy runs on any x86-64.
// `#pragma GCC ivdep` states what the API promises: an output is either a different pose or the
// very same pose as an input (same lane, same component), never a shifted copy of it, so lanes do
// not depend on each other. Check with -fopt-info-vec: every inner lane loop reports
// "loop vectorized" twice (16-byte and 32-byte vectors).
//
// Work is split by component rather than done joint-at-a-time: translations and scales are
// element-wise over the pose's contiguous tx|ty|tz and sx|sy|sz ranges (or per component where
// the weight varies per joint), rotations get a loop of their own (hemisphere test, weighted sum),
// and normalization yet another. That keeps each loop's live pointers within x86-64's registers
// (one pointer per pose plus the component offsets), and keeps loop bodies short: the rotation
// chain (dot product, sign, sum, inverse square root) in one body is long enough that the
// out-of-order core ran out of room to overlap iterations; split, it overlaps them freely. For a
// 3-way blend of 67 joints that is ~30% of the time.
//
// Whole lanes, padding included, are processed. Padding lanes are identity in every input and
// each formula maps identity inputs to identity exactly (lerp written a + t * (b - a), an inverse
// square root that returns exactly 1 for 1); blend_n, whose normalized weights need not sum to
// exactly 1 in float, rewrites its padding afterwards.
//
// Quaternions are normalized with rsqrt() below rather than 1 / std::sqrt: with the default
// -fmath-errno GCC does not vectorize std::sqrt (it keeps a scalar errno path), and the library
// must not depend on per-file flags. Two Newton steps and one correction step from the bit-trick
// estimate give <= 1.7 ulp. Only IEEE add/sub/mul/div are used, never FMA, so both clones produce
// bit-identical results.
#include <algorithm>
#include <bit>
#include <cassert>
#include <cstddef>

#include <ossa/anim/pose_ops.h>
#include "internal/float_env.h"
#include "internal/vector_clones.h"

// No-alias promise for GCC's vectorizer (see the comment above). Clang gets none: its loop hint
// forces vectorization and warns where it cannot (sanitizer builds), and its vectorizer adds its
// own run-time alias checks anyway.
#if defined(__clang__)
#define OSSA_IVDEP
#elif defined(__GNUC__)
#define OSSA_IVDEP _Pragma("GCC ivdep")
#else
#define OSSA_IVDEP
#endif

namespace ossa {

namespace {

constexpr size_t kLanes = kPoseLanes;

/// 1 / sqrt(x) for x > 0 in plain float arithmetic (vectorizes; see the header comment). Exact
/// for x == 1, so identity rotations and padding lanes stay exactly identity.
OSSA_INLINE float rsqrt(float x) {
  float y = std::bit_cast<float>(0x5f375a86u - (std::bit_cast<uint32_t>(x) >> 1));
  const float half = 0.5f * x;
  y = y * (1.5f - half * y * y);
  y = y * (1.5f - half * y * y);
  y = y + y * (0.5f - half * y * y);
  return y;
}

inline float clamp01(float t) { return t > 0.0f ? (t < 1.0f ? t : 1.0f) : 0.0f; }  // NaN -> 0

/// Lanes of the poses' common stride: a mismatched caller gets a partial result, never a read or
/// write past a buffer.
uint32_t common_stride(ConstPoseSpan a, ConstPoseSpan b, PoseSpan out) {
  assert(a.stride == out.stride && b.stride == out.stride);
  return std::min({a.stride, b.stride, out.stride});
}

/// Identity on the padding lanes [joint_count, stride).
void reset_padding(PoseSpan out) {
  for (uint32_t j = out.joint_count; j < out.stride; ++j) {
    for (uint32_t k = kTx; k <= kRz; ++k) out[PoseComponent(k)][j] = 0.0f;
    out[kRw][j] = 1.0f;
    for (uint32_t k = kSx; k <= kSz; ++k) out[PoseComponent(k)][j] = 1.0f;
  }
}

// ---------------------------------------------------------------------------------------------
// Lane kernels. `count` is a multiple of kLanes. Rotation kernels take a pointer to the rx array
// of each pose; ry, rz and rw follow at stride, 2 * stride and 3 * stride.

/// Normalizes `count` rotations in place.
OSSA_INLINE void normalize_rotations(float* rx, size_t stride, size_t count) {
  const size_t s1 = stride, s2 = 2 * stride, s3 = 3 * stride;
  for (size_t first = 0; first < count; first += kLanes) {
    float* o = rx + first;
    OSSA_IVDEP
    for (size_t l = 0; l < kLanes; ++l) {
      const float x = o[l], y = o[l + s1], z = o[l + s2], w = o[l + s3];
      const float inv = rsqrt(x * x + y * y + z * z + w * w);
      o[l] = x * inv, o[l + s1] = y * inv, o[l + s2] = z * inv, o[l + s3] = w * inv;
    }
  }
}

/// out = a + t * (b - a), t per lane.
OSSA_INLINE void lerp_lanes(const float* a, const float* b, const float* t, float* out, size_t count) {
  for (size_t first = 0; first < count; first += kLanes) {
    const float *pa = a + first, *pb = b + first, *pt = t + first;
    float* o = out + first;
    OSSA_IVDEP
    for (size_t l = 0; l < kLanes; ++l) o[l] = pa[l] + pt[l] * (pb[l] - pa[l]);
  }
}

/// out = a + t * (b' - a), b' = b on a's hemisphere; not normalized. The weight is t[lane] with
/// kPerLane, else t[0] for every lane.
template <bool kPerLane>
OSSA_INLINE void lerp_rotations(const float* a, const float* b, const float* t, float* out, size_t stride,
                                size_t count) {
  const size_t s1 = stride, s2 = 2 * stride, s3 = 3 * stride;
  const float t0 = t[0];
  for (size_t first = 0; first < count; first += kLanes) {
    const float *pa = a + first, *pb = b + first, *pt = kPerLane ? t + first : t;
    float* o = out + first;
    OSSA_IVDEP
    for (size_t l = 0; l < kLanes; ++l) {
      const float ax = pa[l], ay = pa[l + s1], az = pa[l + s2], aw = pa[l + s3];
      const float bx = pb[l], by = pb[l + s1], bz = pb[l + s2], bw = pb[l + s3];
      const float w = kPerLane ? pt[l] : t0;
      const float tb = ax * bx + ay * by + az * bz + aw * bw < 0.0f ? -w : w;
      o[l] = ax + (tb * bx - w * ax);
      o[l + s1] = ay + (tb * by - w * ay);
      o[l + s2] = az + (tb * bz - w * az);
      o[l + s3] = aw + (tb * bw - w * aw);
    }
  }
}

/// out[i] = f(a[i], b[i]) for i in [0, count).
template <class F>
OSSA_INLINE void elementwise(const float* a, const float* b, float* out, size_t count, F f) {
  for (size_t first = 0; first < count; first += kLanes) {
    const float *pa = a + first, *pb = b + first;
    float* o = out + first;
    OSSA_IVDEP
    for (size_t l = 0; l < kLanes; ++l) o[l] = f(pa[l], pb[l]);
  }
}

/// The loader's bound on every translation and scale it accepts (internal/validator.h's kMaxPoseValue):
/// ratios and products of bounded values are clamped back into it, so they stay finite.
constexpr float kMaxPoseValue = 1e7f;
OSSA_INLINE float clamp_pose_value(float v) { return std::min(std::max(v, -kMaxPoseValue), kMaxPoseValue); }

/// Lanes per chunk of blend_layered: its per-lane weights live in a stack array.
constexpr size_t kChunk = 256;

// blend_n takes its inputs up to three at a time, each group one pass over the pose: the first
// pass writes `out`, later ones add to it, the last one normalizes. One pass reads each input
// once and writes `out` once, where input-at-a-time accumulation would re-read and re-write `out`
// for every input.

/// out[i] (= or +=) sum over k < K of w[k] * in[k][i], for i in [0, count).
template <int K, bool kAccumulate>
OSSA_INLINE void weighted_sum(const float* const (&in)[3], const float (&w)[3], float* out, size_t count) {
  const float wa = w[0], wb = w[1], wc = w[2];
  for (size_t first = 0; first < count; first += kLanes) {
    const float *a = in[0] + first, *b = in[K > 1 ? 1 : 0] + first, *c = in[K > 2 ? 2 : 0] + first;
    float* o = out + first;
    OSSA_IVDEP
    for (size_t l = 0; l < kLanes; ++l) {
      float v = wa * a[l];
      if constexpr (K > 1) v += wb * b[l];
      if constexpr (K > 2) v += wc * c[l];
      o[l] = kAccumulate ? o[l] + v : v;
    }
  }
}

/// The rotations of a blend_n pass: each input flipped where it lies opposite the reference
/// rotation `ref`, weighted and summed; not normalized. With kRefIsFirst, in[0] is the reference
/// and its own (never negative) hemisphere test is skipped.
template <int K, bool kAccumulate, bool kRefIsFirst>
OSSA_INLINE void weighted_rotation_sum(const float* ref, const float* const (&in)[3], const float (&w)[3], float* out,
                                       size_t stride) {
  const size_t s1 = stride, s2 = 2 * stride, s3 = 3 * stride;
  for (size_t first = 0; first < stride; first += kLanes) {
    const float *a = in[0] + first, *b = in[K > 1 ? 1 : 0] + first, *c = in[K > 2 ? 2 : 0] + first;
    const float* f = kRefIsFirst ? a : ref + first;  // one set of loads when they coincide
    float* o = out + first;
    OSSA_IVDEP
    for (size_t l = 0; l < kLanes; ++l) {
      const float fx = f[l], fy = f[l + s1], fz = f[l + s2], fw = f[l + s3];
      // The three inputs written out: GCC -O2 vectorizes this loop only as straight-line code.
      // The first term initializes the sums (adding it to 0.0f would cost an add per component:
      // the compiler may not drop x + 0.0f, which differs from x for x = -0.0f).
      float x, y, z, q;
      {
        const float ax = a[l], ay = a[l + s1], az = a[l + s2], aw = a[l + s3];
        const float wa = kRefIsFirst ? w[0] : (fx * ax + fy * ay + fz * az + fw * aw < 0.0f ? -w[0] : w[0]);
        x = wa * ax, y = wa * ay, z = wa * az, q = wa * aw;
      }
      if constexpr (kAccumulate) x += o[l], y += o[l + s1], z += o[l + s2], q += o[l + s3];
      if constexpr (K > 1) {
        const float bx = b[l], by = b[l + s1], bz = b[l + s2], bw = b[l + s3];
        const float wb = fx * bx + fy * by + fz * bz + fw * bw < 0.0f ? -w[1] : w[1];
        x += wb * bx, y += wb * by, z += wb * bz, q += wb * bw;
      }
      if constexpr (K > 2) {
        const float cx = c[l], cy = c[l + s1], cz = c[l + s2], cw = c[l + s3];
        const float wc = fx * cx + fy * cy + fz * cz + fw * cw < 0.0f ? -w[2] : w[2];
        x += wc * cx, y += wc * cy, z += wc * cz, q += wc * cw;
      }
      o[l] = x, o[l + s1] = y, o[l + s2] = z, o[l + s3] = q;
    }
  }
}

/// One blend_n pass over the whole pose. The reference is the first input of the first pass.
template <int K, bool kAccumulate, bool kNormalize>
OSSA_INLINE void blend_n_pass(ConstPoseSpan ref, const ConstPoseSpan (&in)[3], const float (&w)[3], PoseSpan out,
                              uint32_t stride) {
  const float* t[3] = {in[0].base, in[K > 1 ? 1 : 0].base, in[K > 2 ? 2 : 0].base};
  weighted_sum<K, kAccumulate>(t, w, out.base, 3 * size_t(stride));
  const size_t s = size_t(kSx) * stride;
  const float* sc[3] = {t[0] + s, t[1] + s, t[2] + s};
  weighted_sum<K, kAccumulate>(sc, w, out.base + s, 3 * size_t(stride));
  const size_t r = size_t(kRx) * stride;
  const float* rot[3] = {t[0] + r, t[1] + r, t[2] + r};
  weighted_rotation_sum<K, kAccumulate, !kAccumulate>(ref.base + r, rot, w, out.base + r, stride);
  if constexpr (kNormalize) normalize_rotations(out.base + r, stride, stride);
}

}  // namespace

OSSA_INLINE static void blend_body(ConstPoseSpan a, ConstPoseSpan b, float alpha, PoseSpan out) {
  const detail::FlushDenormals flush;  // internal/float_env.h
  const float t = clamp01(alpha);
  // The ends are copies: exact, and cheaper than blending with a zero weight.
  if (t == 0.0f) return copy_pose(a, out);
  if (t == 1.0f) return copy_pose(b, out);
  const size_t stride = common_stride(a, b, out);
  // Translations and scales: one lerp over each of the contiguous ranges tx|ty|tz and sx|sy|sz.
  const auto lerp = [t](float av, float bv) { return av + t * (bv - av); };
  elementwise(a.base, b.base, out.base, 3 * stride, lerp);
  const size_t s = kSx * stride, r = kRx * stride;
  elementwise(a.base + s, b.base + s, out.base + s, 3 * stride, lerp);
  lerp_rotations<false>(a.base + r, b.base + r, &t, out.base + r, stride, stride);
  normalize_rotations(out.base + r, stride, stride);
}

OSSA_VECTOR_DISPATCH(blend, (ConstPoseSpan a, ConstPoseSpan b, float alpha, PoseSpan out), (a, b, alpha, out))

OSSA_INLINE static void blend_n_body(std::span<const ConstPoseSpan> poses, std::span<const float> weights,
                                     PoseSpan out) {
  const detail::FlushDenormals flush;  // internal/float_env.h
  const size_t count = std::min(poses.size(), weights.size());
  if (count == 0) return set_identity(out);
  // Normalize the weights; a non-positive (or NaN) total has no meaningful blend, so the first
  // pose stands in rather than a pose full of NaNs.
  float total = 0.0f;
  uint32_t stride = out.stride;
  size_t first_weighted = count, last_weighted = 0;
  for (size_t i = 0; i < count; ++i) {
    assert(poses[i].stride == out.stride);
    total += weights[i];
    stride = std::min(stride, poses[i].stride);
    if (weights[i] != 0.0f) {
      first_weighted = std::min(first_weighted, i);
      last_weighted = i;
    }
  }
  if (!(total > 0.0f)) return copy_pose(poses[0], out);
  // One contributing pose: a copy, exact (w * (1 / w) need not be 1 in float).
  if (first_weighted == last_weighted) return copy_pose(poses[first_weighted], out);
  // Zero weights are skipped (common in blend trees), and the rotation hemisphere follows the
  // first pose that contributes: a pose with weight 0 must not change the result.
  const float inv_total = 1.0f / total;
  const ConstPoseSpan ref = poses[first_weighted];
  bool first_pass = true;
  for (size_t i = first_weighted; i <= last_weighted;) {
    ConstPoseSpan group[3] = {};
    float w[3] = {};
    int k = 0;
    for (; k < 3 && i <= last_weighted; ++i)
      if (weights[i] != 0.0f) {
        group[k] = poses[i];
        w[k++] = weights[i] * inv_total;
      }
    const bool last_pass = i > last_weighted;
    // Only the shapes that occur: a group is full unless it is the last one, and the first
    // group has at least two inputs.
    if (first_pass && last_pass) {
      if (k == 2) blend_n_pass<2, false, true>(ref, group, w, out, stride);
      else blend_n_pass<3, false, true>(ref, group, w, out, stride);
    } else if (first_pass) {
      blend_n_pass<3, false, false>(ref, group, w, out, stride);
    } else if (!last_pass) {
      blend_n_pass<3, true, false>(ref, group, w, out, stride);
    } else if (k == 1) {
      blend_n_pass<1, true, true>(ref, group, w, out, stride);
    } else if (k == 2) {
      blend_n_pass<2, true, true>(ref, group, w, out, stride);
    } else {
      blend_n_pass<3, true, true>(ref, group, w, out, stride);
    }
    first_pass = false;
  }
  reset_padding(out);
}

OSSA_VECTOR_DISPATCH(blend_n, (std::span<const ConstPoseSpan> poses, std::span<const float> weights, PoseSpan out),
                     (poses, weights, out))

OSSA_INLINE static void blend_layered_range_body(ConstPoseSpan base, ConstPoseSpan layer,
                                                 std::span<const float> joint_weights, float weight, PoseSpan out,
                                                 size_t lo, size_t hi) {
  const detail::FlushDenormals flush;  // internal/float_env.h
  const size_t stride = common_stride(base, layer, out);
  hi = std::min(hi, stride);
  // Joints past joint_weights (and padding lanes) get weight 0: they keep the base pose.
  const size_t weighted = std::min<size_t>(joint_weights.size(), out.joint_count);
  float ts[kChunk];
  // Every lane's result depends on that lane alone, so a range of whole blocks gives its lanes
  // the bits a whole-pose call gives them.
  for (size_t first = lo; first < hi; first += kChunk) {
    const size_t count = std::min<size_t>(kChunk, hi - first);
    const size_t known = weighted > first ? std::min(weighted - first, count) : 0;
    const float* jw = joint_weights.data() + first;
    size_t l = 0;
    for (; l + kLanes <= known; l += kLanes)  // whole blocks vectorize; the tail is scalar
      for (size_t m = 0; m < kLanes; ++m) ts[l + m] = clamp01(weight * jw[l + m]);
    for (; l < known; ++l) ts[l] = clamp01(weight * jw[l]);
    std::fill(ts + known, ts + count, 0.0f);
    for (uint32_t k : {kTx, kTy, kTz, kSx, kSy, kSz}) {
      const size_t at = k * stride + first;
      lerp_lanes(base.base + at, layer.base + at, ts, out.base + at, count);
    }
    const size_t at = kRx * stride + first;
    lerp_rotations<true>(base.base + at, layer.base + at, ts, out.base + at, stride, count);
    normalize_rotations(out.base + at, stride, count);
  }
}

namespace {
OSSA_VECTOR_DISPATCH(blend_layered_range,
                     (ConstPoseSpan base, ConstPoseSpan layer, std::span<const float> joint_weights, float weight,
                      PoseSpan out, size_t lo, size_t hi),
                     (base, layer, joint_weights, weight, out, lo, hi))
}  // namespace

void blend_layered(ConstPoseSpan base, ConstPoseSpan layer, std::span<const float> joint_weights, float weight,
                   PoseSpan out) {
  blend_layered_range(base, layer, joint_weights, weight, out, 0, out.stride);
}

void blend_layered_lanes(ConstPoseSpan base, ConstPoseSpan layer, std::span<const float> joint_weights, float weight,
                         PoseSpan out, uint32_t first, uint32_t last) {
  assert(first % kPoseLanes == 0 && last % kPoseLanes == 0);
  blend_layered_range(base, layer, joint_weights, weight, out, first, last);
}

void build_joint_mask(std::span<const int16_t> parents, int joint, int depth, std::span<float> out) {
  const size_t n = std::min(parents.size(), out.size());
  if (joint < 0 || size_t(joint) >= n) return;
  // One forward pass, no scratch memory: parents come before children, so a joint is in the
  // masked subtree exactly when its parent is. While the pass runs, a masked joint's entry holds
  // the marker -(level + 1) (level 0 at `joint`); entries are weights >= 0, so markers cannot be
  // confused with them, and every marked joint ends at weight 1 anyway, so nothing is lost by
  // overwriting. Joints below the depth limit are not marked, and neither are their children.
  const size_t j0 = size_t(joint);
  out[j0] = -1.0f;
  for (size_t i = j0 + 1; i < n; ++i) {
    const int p = parents[i];
    if (p < joint || size_t(p) >= i) continue;  // outside the subtree (or an invalid parent)
    const float parent_marker = out[size_t(p)];
    if (parent_marker >= 0.0f) continue;
    const float level = -parent_marker;  // the parent's level + 1
    if (depth >= 0 && level > float(depth)) continue;
    out[i] = parent_marker - 1.0f;
  }
  for (size_t i = j0; i < n; ++i)
    if (out[i] < 0.0f) out[i] = 1.0f;
}

OSSA_INLINE static void make_additive_body(ConstPoseSpan pose, ConstPoseSpan reference, PoseSpan out_additive) {
  const detail::FlushDenormals flush;  // internal/float_env.h
  const size_t stride = common_stride(pose, reference, out_additive);
  const float *p = pose.base, *r = reference.base;
  float* o = out_additive.base;
  // Translation differences and scale ratios: element-wise over tx|ty|tz and sx|sy|sz.
  const size_t s = kSx * stride;
  elementwise(p, r, o, 3 * stride, [](float pv, float rv) { return pv - rv; });
  // A zero reference scale has no ratio; 1 (no scale change) keeps the result finite. A tiny one
  // (a denormal bind scale) has a ratio beyond any pose value: it is clamped to the loader's bound.
  elementwise(p + s, r + s, o + s, 3 * stride,
              [](float pv, float rv) { return rv != 0.0f ? clamp_pose_value(pv / rv) : 1.0f; });
  // conj(r) * q: w = rw qw + rv.qv, v = rw qv - qw rv - rv x qv.
  const size_t rot = kRx * stride, s1 = stride, s2 = 2 * stride, s3 = 3 * stride;
  for (size_t first = 0; first < stride; first += kLanes) {
    const float *pq = p + rot + first, *pr = r + rot + first;
    float* po = o + rot + first;
    OSSA_IVDEP
    for (size_t l = 0; l < kLanes; ++l) {
      const float rx = pr[l], ry = pr[l + s1], rz = pr[l + s2], rw = pr[l + s3];
      const float qx = pq[l], qy = pq[l + s1], qz = pq[l + s2], qw = pq[l + s3];
      po[l + s3] = rw * qw + rx * qx + ry * qy + rz * qz;
      po[l] = rw * qx - qw * rx - (ry * qz - rz * qy);
      po[l + s1] = rw * qy - qw * ry - (rz * qx - rx * qz);
      po[l + s2] = rw * qz - qw * rz - (rx * qy - ry * qx);
    }
  }
}

OSSA_VECTOR_DISPATCH(make_additive, (ConstPoseSpan pose, ConstPoseSpan reference, PoseSpan out_additive),
                     (pose, reference, out_additive))

OSSA_INLINE static void add_body(ConstPoseSpan base, ConstPoseSpan additive, float weight, PoseSpan out) {
  const detail::FlushDenormals flush;  // internal/float_env.h
  const size_t stride = common_stride(base, additive, out);
  const float *b = base.base, *d = additive.base;
  float* o = out.base;
  const float w = weight;
  // Translations add the weighted delta; scales multiply by lerp(1, delta, w). Both are clamped
  // to the loader's bound on pose values, so additive layers stacked as deep as a graph allows
  // (each may multiply a scale by up to 1e7 times its weight) never overflow to infinity.
  const size_t s = kSx * stride;
  elementwise(b, d, o, 3 * stride, [w](float bv, float dv) { return clamp_pose_value(bv + w * dv); });
  elementwise(b + s, d + s, o + s, 3 * stride,
              [w](float bv, float dv) { return clamp_pose_value(bv * (1.0f + w * (dv - 1.0f))); });
  // Rotations: base * nlerp(identity, delta, w). |base * q| = |q| for a unit base, so the
  // product is formed unnormalized and normalized afterwards, in a loop of its own.
  const size_t r = kRx * stride, s1 = stride, s2 = 2 * stride, s3 = 3 * stride;
  for (size_t first = 0; first < stride; first += kLanes) {
    const float *pb = b + r + first, *pd = d + r + first;
    float* po = o + r + first;
    OSSA_IVDEP
    for (size_t l = 0; l < kLanes; ++l) {
      // lerp(identity, delta, w) on the short arc (delta's dot with identity is its w).
      const float dw = pd[l + s3];
      const float ws = dw < 0.0f ? -w : w;
      const float qx = ws * pd[l], qy = ws * pd[l + s1], qz = ws * pd[l + s2];
      const float qw = 1.0f + (ws * dw - w);
      // base * q: w = bw qw - bv.qv, v = bw qv + qw bv + bv x qv.
      const float bx = pb[l], by = pb[l + s1], bz = pb[l + s2], bw = pb[l + s3];
      po[l + s3] = bw * qw - (bx * qx + by * qy + bz * qz);
      po[l] = bw * qx + qw * bx + (by * qz - bz * qy);
      po[l + s1] = bw * qy + qw * by + (bz * qx - bx * qz);
      po[l + s2] = bw * qz + qw * bz + (bx * qy - by * qx);
    }
  }
  normalize_rotations(o + r, stride, stride);
}

OSSA_VECTOR_DISPATCH(add, (ConstPoseSpan base, ConstPoseSpan additive, float weight, PoseSpan out),
                     (base, additive, weight, out))

}  // namespace ossa
