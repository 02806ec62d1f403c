// sample_interpolate.cpp — pass 2 of ossa::sample (internal/sample_lanes.h): one loop over all
// joints in 8-lane blocks that lerps T and S and nlerps R between each joint's cached key pair.
//
// Written with GCC/Clang vector extensions over 8-lane blocks (stride is a multiple of kPoseLanes)
// rather than left to the auto-vectorizer: at -O2 GCC will not vectorize a loop that calls sqrt
// (it must keep errno) or that has selects it cannot if-convert under trapping math, and both are
// in an nlerp. The same source compiles to one 256-bit op per line in the AVX2 clone and to two
// SSE2 ops in the baseline clone (vector_clones.h picks per call), or to scalar code elsewhere.
#include <cstdint>
#include <cstring>

#include <ossa/anim/pose.h>
#include "internal/sample_lanes.h"
#include "internal/vector_clones.h"

namespace ossa::detail {
namespace {

// The helpers take and return 32-byte vectors by value, which GCC warns changes the ABI between
// AVX and non-AVX callers; they are always inlined into this file's kernels, so no ABI is involved.
// (Clang honours the GCC spelling.)
#if defined(__GNUC__)
#pragma GCC diagnostic ignored "-Wpsabi"
#endif

using F8 = float __attribute__((vector_size(32)));
using I8 = int32_t __attribute__((vector_size(32)));

OSSA_INLINE F8 load8(const float* p) {
  F8 v;
  std::memcpy(&v, p, sizeof v);  // one unaligned vector load
  return v;
}
OSSA_INLINE void store8(float* p, const F8& v) { std::memcpy(p, &v, sizeof v); }
OSSA_INLINE F8 splat8(float x) { return F8{x, x, x, x, x, x, x, x}; }
OSSA_INLINE F8 select8(const I8& mask, const F8& a, const F8& b) {  // mask lanes are 0 or -1
  I8 ai, bi;
  std::memcpy(&ai, &a, sizeof ai);
  std::memcpy(&bi, &b, sizeof bi);
  const I8 r = (ai & mask) | (bi & ~mask);
  F8 out;
  std::memcpy(&out, &r, sizeof out);
  return out;
}
OSSA_INLINE F8 clamp01(const F8& x) {
  const F8 zero = splat8(0.0f), one = splat8(1.0f);
  const F8 w = select8(x < zero, zero, x);
  return select8(w > one, one, w);
}
/// 1 / sqrt(x) for x >= ~1/2 in plain IEEE float arithmetic (pose_ops.cpp's rsqrt, eight lanes):
/// a bit-trick estimate, two Newton steps and a correction step, <= 1.7 ulp, exact for x == 1.
/// Replaces one / sqrt8(x), whose square roots and division sat on the nlerp's critical path
/// (~40% of the kernel's samples on Zen 5); no FMA, so both compiled copies agree bit for bit.
OSSA_INLINE F8 rsqrt8(const F8& x) {
  I8 bits;
  std::memcpy(&bits, &x, sizeof bits);
  bits = 0x5f375a86 - (bits >> 1);  // x > 0: the arithmetic shift is the logical one
  F8 y;
  std::memcpy(&y, &bits, sizeof y);
  const F8 half = x * 0.5f;
  y = y * (1.5f - half * y * y);
  y = y * (1.5f - half * y * y);
  y = y + y * (0.5f - half * y * y);
  return y;
}

// The kernel below is compiled for AVX2 and the baseline and picked per call
// (internal/vector_clones.h: OSSA_VECTOR_DISPATCH; ossa/anim/vector_isa.h selects).

OSSA_INLINE static void interpolate_nlerp_body(const SampleLanes& l, float frame) {
  const size_t n = l.stride;
  const float* k0 = l.k0;
  const float* k1 = l.k1;
  const float* start = l.start;
  const float* inv = l.inv_length;
  float* out = l.out;
  const F8 f = splat8(frame), one = splat8(1.0f), zero = splat8(0.0f);
  for (size_t j = 0, b = 0; j < n; j += kPoseLanes, ++b) {
    // A block whose joints have no animated channel of a kind holds fixed values (k0 == k1) for
    // it: copy them. Real rigs have few animated translations and scales, and runs of joints
    // (fingers, props) that a clip leaves alone.
    const uint8_t kinds = l.block_kinds[b];
    if (kinds & kSkipped) continue;  // a joint filter keeps no joint of this block
    const auto copy = [&](size_t c) { store8(out + c * n + j, load8(l.fixed + c * n + j)); };
    const auto lerp = [&](size_t c, const F8& wa, const F8& wb) {
      // a * (1 - w) + b * w is exact at both ends (w = 0 gives a, w = 1 gives b).
      store8(out + c * n + j, load8(k0 + c * n + j) * wa + load8(k1 + c * n + j) * wb);
    };
    // T (kind 0) and S (kind 2): a lerp by the kind's weight, or the fixed values.
    const auto three = [&](uint8_t animated, size_t kind, size_t first) {
      if (kinds & animated) {
        const F8 w = clamp01((f - load8(start + kind * n + j)) * load8(inv + kind * n + j));
        const F8 a = one - w;
        lerp(first, a, w);
        lerp(first + 1, a, w);
        lerp(first + 2, a, w);
      } else {
        copy(first);
        copy(first + 1);
        copy(first + 2);
      }
    };
    three(kAnimatedT, 0, kTx);
    three(kAnimatedS, 2, kSx);
    if (!(kinds & kAnimatedR)) {
      copy(kRx);
      copy(kRy);
      copy(kRz);
      copy(kRw);
      continue;
    }
    const F8 wr = clamp01((f - load8(start + n + j)) * load8(inv + n + j));
    const F8 ax = load8(k0 + kRx * n + j), ay = load8(k0 + kRy * n + j), az = load8(k0 + kRz * n + j),
             aw = load8(k0 + kRw * n + j);
    const F8 bx = load8(k1 + kRx * n + j), by = load8(k1 + kRy * n + j), bz = load8(k1 + kRz * n + j),
             bw = load8(k1 + kRw * n + j);
    // Shortest arc: b's weight takes dot(a, b)'s sign (keys are stored with one component >= 0).
    const F8 dot = ax * bx + ay * by + az * bz + aw * bw;
    const F8 wb = select8(dot < zero, -wr, wr);
    const F8 wa = one - wr;
    const F8 rx = ax * wa + bx * wb, ry = ay * wa + by * wb, rz = az * wa + bz * wb, rw = aw * wa + bw * wb;
    // Both keys are unit (up to quantization) and on one hemisphere, so |r|^2 >= ~1/2.
    const F8 scale = rsqrt8(rx * rx + ry * ry + rz * rz + rw * rw);
    store8(out + kRx * n + j, rx * scale);
    store8(out + kRy * n + j, ry * scale);
    store8(out + kRz * n + j, rz * scale);
    store8(out + kRw * n + j, rw * scale);
  }
}

}  // namespace

OSSA_VECTOR_DISPATCH(interpolate_nlerp, (const SampleLanes& l, float frame), (l, frame))

/// Slerp variant (an option, not the hot path): translations and scales as above, rotations at
/// constant angular velocity, falling back to nlerp where the keys are nearly equal.
void interpolate_slerp(const SampleLanes& l, float frame) {
  interpolate_nlerp(l, frame);  // T, S, and an nlerp R the loop below replaces
  const uint32_t stride = l.stride;
  for (uint32_t j = 0; j < stride; ++j) {
    if (l.block_kinds[j / kPoseLanes] & kSkipped) continue;
    float w = (frame - l.start[stride + j]) * l.inv_length[stride + j];
    w = w < 0.0f ? 0.0f : (w > 1.0f ? 1.0f : w);
    // At weight 0 the nlerp above gives the first key and reads nothing of the second, which the
    // sampler may leave undecoded there (sample_keys.cpp, settle); a slerp would read it.
    if (w == 0.0f) continue;
    float a[4], b[4];
    for (uint32_t c = 0; c < 4; ++c) {
      a[c] = l.k0[(kRx + c) * stride + j];
      b[c] = l.k1[(kRx + c) * stride + j];
    }
    float d = a[0] * b[0] + a[1] * b[1] + a[2] * b[2] + a[3] * b[3];
    if (d < 0.0f) {
      d = -d;
      for (float& v : b) v = -v;
    }
    if (d > 0.9995f) continue;  // nearly parallel: the nlerp above is as exact and stable
    const float theta = std::acos(d);
    const float inv_sin = 1.0f / std::sin(theta);
    const float wa = std::sin((1.0f - w) * theta) * inv_sin, wb = std::sin(w * theta) * inv_sin;
    float r[4];
    for (uint32_t c = 0; c < 4; ++c) r[c] = a[c] * wa + b[c] * wb;
    normalize4(r);  // keys are unit only up to quantization
    for (uint32_t c = 0; c < 4; ++c) l.out[(kRx + c) * stride + j] = r[c];
  }
}

}  // namespace ossa::detail
