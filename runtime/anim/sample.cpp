// sample.cpp — compressed clip + time -> local pose (sample.h), with per-instance key caching.
//
// Shape. A SamplingCache::State holds, for every joint and every pose component, the two values
// the interpolation runs between (k0, k1) and, per channel kind (translation, rotation, scale), the
// frame the pair starts at and 1 / its length in frames. Absent channels hold the bind value and
// constants their value in both keys with a zero 1/length, so their blend weight is always 0;
// those entries are written once, when the cache is made. Animated channels overwrite their
// joint's entries whenever playback crosses one of their keys. A sample is then two passes:
//   1. unless the frame lies where every run's cached pair still holds (one compare against the
//      intersection of their ranges, kept with the cursors), per key run (the animated channels
//      sharing one key-frame list: the cooker shares a run between channels with equal frames,
//      and then one test and one cursor serve them all), one compare of the frame position
//      against the range its cached key pair covers; only a run that left its range moves its
//      cursor (forward by one: keep k1 as the new k0 and decode one key per channel; otherwise a
//      short walk or a binary search on key_frames) and decodes (ossa/format/clip_codec.h);
//   2. one loop over all joints (SoA, 8-lane blocks): lerp T and S, nlerp R with the shortest-arc
//      sign fix, write the pose. It is written with vector extensions, and on x86-64 compiled
//      twice (AVX2 and the SSE2 baseline, picked per call: internal/vector_clones.h), so the
//      default build still runs on any x86-64. A block with no animated channel of a kind copies that
//      kind's fixed values instead of interpolating them; a block a joint filter keeps no joint of
//      is skipped.
// Rotations are stored with one component >= 0 (clip_codec.h drops it), so two neighbouring keys
// may lie in opposite hemispheres; the sign fix in pass 2 (flip b when dot(a, b) < 0) keeps the
// blend on the short arc. It is done per sample rather than at decode time so that a cached pair
// and a freshly decoded pair give bit-identical poses.
//
// Time. The sampler works in frame positions (time * sample_rate), because keys are addressed by
// frame. A position within 1e-5 frames of a whole frame snaps to it, so sampling at a frame's
// time returns that frame's decoded keys exactly instead of a blend one ulp away.
//
// Trust. Everything read here was proven by validate_clip.cpp (key ranges, bit ranges, sorted frames
// from 0 to frame_count - 1, finite ranges, bounded rotation components, dropped component 0..3)
// and the cache was made for this clip and a skeleton with its hash and joint count
// (check_clip_binding), so no check is repeated per sample.
//
// Cost: make_sampling_cache O(joints + animated channels), a few allocations; sample O(joints +
// runs) + O(keys passed), no allocation; reset O(runs). advance_time is advance_time.cpp.
#include <ossa/anim/sample.h>

#include <algorithm>
#include <cassert>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <new>
#include <span>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include <ossa/format/clip_codec.h>
#include "internal/float_env.h"
#include "internal/memory.h"
#include "internal/vector_clones.h"

namespace ossa {
namespace {

constexpr uint32_t kNoCursor = std::numeric_limits<uint32_t>::max();
constexpr float kInf = std::numeric_limits<float>::infinity();

/// Per 8-joint block flags (State::block_kinds): an animated channel of a kind, or no kept joint.
constexpr uint8_t kAnimatedT = 1, kAnimatedR = 2, kAnimatedS = 4, kSkipped = 8;

/// Components of each channel kind in a pose (pose.h order: T xyz, R xyzw, S xyz).
constexpr uint32_t kFirstComponent[3] = {kTx, kRx, kSx};

/// A float block aligned for 8-lane loads, from the installable Allocator (allocator.h).
struct AlignedFloats {
  float* data = nullptr;
  size_t count = 0;
  AlignedFloats() = default;
  explicit AlignedFloats(size_t n) : data(static_cast<float*>(detail::allocate(n * sizeof(float), 32))), count(n) {
    if (data == nullptr && n != 0) throw std::bad_alloc();
  }
  AlignedFloats(AlignedFloats&& o) noexcept : data(std::exchange(o.data, nullptr)), count(std::exchange(o.count, 0)) {}
  AlignedFloats& operator=(AlignedFloats&& o) noexcept {
    std::swap(data, o.data);
    std::swap(count, o.count);
    return *this;
  }
  AlignedFloats(const AlignedFloats&) = delete;
  ~AlignedFloats() { detail::deallocate(data, count * sizeof(float), 32); }
};

/// How to decode one animated channel and where its values go, gathered from the FlatBuffer at
/// cache creation so the hot path reads one flat record.
struct Track {
  uint64_t bit_offset = 0;
  uint32_t bits = 0;           // 1..19, or 32 (raw floats)
  float qmax = 0.0f;           // 2^bits - 1
  float lo[4] = {0, 0, 0, 0};  // 4 wide (the 4th unused) for one SSE load
  float extent[4] = {0, 0, 0, 0};
  bool rotation = false;
  uint32_t offset[4] = {0, 0, 0, 0};  // where components go in k0 / k1 (offset[3]: a rotation's rebuilt one)
  uint32_t weight_index = 0;          // kind * stride + joint, into start / inv_length
};

/// Animated channels sharing one key-frame list, and the cursor they share: the pair (cursor,
/// cursor + 1) is valid while enter <= frame < leave (leave is +inf for the last pair, which also
/// covers the last frame).
struct Run {
  const uint16_t* frames = nullptr;
  uint32_t key_count = 0;
  uint32_t cursor = kNoCursor;
  float enter = kInf;
  float leave = -kInf;
  uint32_t first_track = 0;  // its channels are tracks[first_track, first_track + track_count)
  uint32_t track_count = 0;
};

}  // namespace

struct SamplingCache::State {
  const fb::Clip* clip = nullptr;   // the clip this cache was made for
  const uint8_t* stream = nullptr;  // its key_values
  uint32_t joint_count = 0;
  uint32_t stride = 0;      // pose_stride(joint_count)
  float last_frame = 0.0f;  // frame_count - 1

  // One block: k0[10 * stride], k1[10 * stride], start[3 * stride], inv_length[3 * stride].
  AlignedFloats block;
  float* k0 = nullptr;
  float* k1 = nullptr;
  // Source of the fixed (never re-decoded) blocks: k0, or a prototype cache's k0 shared by every
  // instance playing the clip, so crowds read those values from one hot copy.
  const float* fixed = nullptr;
  float* start = nullptr;       // per kind: frame of k0
  float* inv_length = nullptr;  // per kind: 1 / (frame of k1 - frame of k0); 0 for fixed channels
  // Per 8-joint block: bit `kind` set when some joint of the block has an animated channel of
  // that kind. Pass 2 interpolates only those; the rest never change and are copied. kSkipped: a
  // joint filter keeps none of the block's joints, and pass 2 leaves it alone.
  std::vector<uint8_t> block_kinds;
  const uint8_t* kinds = nullptr;  // block_kinds, or a prototype's

  // The runs live at the end of `block` (after the floats): one allocation holds everything a
  // sample touches per instance, so a crowd pays one cache miss per clip instead of three.
  Run* runs = nullptr;
  uint32_t run_count = 0;
  // The intersection of every run's range (largest enter, smallest leave): a frame inside moves no
  // run, so pass 1 is one compare (a slow clip, updates faster than keys). Empty when forgotten.
  float all_enter = kInf, all_leave = -kInf;
  std::vector<Track> tracks;  // grouped by run
  // What move_run reads: tracks, or a prototype's (identical: they depend on the clip, rig and filter only).
  const Track* track_data = nullptr;
  // The joint filter the cache was made with (empty: every joint), compared with a prototype's.
  std::span<const uint8_t> filter;
};

SamplingCache::SamplingCache() = default;
SamplingCache::SamplingCache(SamplingCache&&) noexcept = default;
SamplingCache& SamplingCache::operator=(SamplingCache&&) noexcept = default;
SamplingCache::~SamplingCache() = default;
SamplingCache::SamplingCache(std::unique_ptr<State> s) : state_(std::move(s)) {}

namespace {

using State = SamplingCache::State;

void forget_cursors(State& s) {
  // An empty range: the next sample's range test fails for every run, whatever the frame.
  for (Run& r : std::span<Run>(s.runs, s.run_count)) {
    r.cursor = kNoCursor;
    r.enter = kInf;
    r.leave = -kInf;
  }
  s.all_enter = kInf;
  s.all_leave = -kInf;
}

/// Writes a fixed value (bind or constant) into both keys of one joint's channel.
void set_fixed(State& s, uint32_t joint, uint32_t kind, const float* value) {
  const uint32_t n = kind == 1 ? 4 : 3;
  for (uint32_t c = 0; c < n; ++c) {
    s.k0[(kFirstComponent[kind] + c) * s.stride + joint] = value[c];
    s.k1[(kFirstComponent[kind] + c) * s.stride + joint] = value[c];
  }
  s.start[kind * s.stride + joint] = 0.0f;
  s.inv_length[kind * s.stride + joint] = 0.0f;
}

void normalize4(float* q) {
  const float n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  for (int c = 0; c < 4; ++c) q[c] /= n;
}

Track make_track(const fb::AnimatedChannel& ch, uint32_t stride) {
  Track t;
  t.bit_offset = ch.bit_offset();
  t.bits = ch.bits();
  t.qmax = t.bits == kRawFloatBits ? 0.0f : static_cast<float>(quant_max(t.bits));
  t.lo[0] = ch.range_min().x(), t.lo[1] = ch.range_min().y(), t.lo[2] = ch.range_min().z();
  t.extent[0] = ch.range_extent().x(), t.extent[1] = ch.range_extent().y(), t.extent[2] = ch.range_extent().z();
  const auto kind = static_cast<uint32_t>(ch.channel());
  t.rotation = kind == 1;
  // Stored component i goes to the i-th pose component that is not the dropped one (x, y, z, w
  // order); a rotation's rebuilt component goes to the dropped one (ossa/format/clip_codec.h).
  const uint32_t dropped = t.rotation ? ch.dropped() : 3;  // validation proved dropped <= 3
  for (uint32_t c = 0, i = 0; c < 4; ++c) {
    const uint32_t at = (kFirstComponent[kind] + c) * stride + ch.joint();
    if (c == dropped) t.offset[3] = at;
    else if (i < 3) t.offset[i++] = at;
  }
  t.weight_index = kind * stride + ch.joint();
  return t;
}

/// Decodes key `key` of a track into the k0 or k1 array: ossa/format/clip_codec.h's decode_key and
/// rotation_from_stored, specialized to the precomputed record. On x86-64 the three components
/// are dequantized in one SSE register (one division instead of three); each lane performs the
/// same IEEE operations as the scalar code (lo + extent * (q / qmax)), so results are identical.
inline void decode(const Track& t, const uint8_t* stream, uint32_t key, float* keys) {
  float v[4];
  if (t.bits == kRawFloatBits) {
    std::memcpy(v, stream + (t.bit_offset >> 3) + 12ull * key, 12);
  } else {
    const uint64_t packed = read_bits(stream, t.bit_offset + key_bits(t.bits) * key, 3 * t.bits);
    const auto mask = static_cast<uint32_t>(quant_max(t.bits));
    const auto q0 = static_cast<uint32_t>(packed) & mask;
    const auto q1 = static_cast<uint32_t>(packed >> t.bits) & mask;
    const auto q2 = static_cast<uint32_t>(packed >> (2 * t.bits)) & mask;
#if defined(__SSE2__)
    // q < 2^19 fits a signed 32-bit lane, so the signed conversion is exact.
    const __m128 q =
        _mm_cvtepi32_ps(_mm_setr_epi32(static_cast<int>(q0), static_cast<int>(q1), static_cast<int>(q2), 0));
    const __m128 r =
        _mm_add_ps(_mm_loadu_ps(t.lo), _mm_mul_ps(_mm_loadu_ps(t.extent), _mm_div_ps(q, _mm_set1_ps(t.qmax))));
    _mm_storeu_ps(v, r);
#else
    const uint32_t q[3] = {q0, q1, q2};
    for (uint32_t c = 0; c < 3; ++c) v[c] = t.lo[c] + t.extent[c] * (static_cast<float>(q[c]) / t.qmax);
#endif
  }
  keys[t.offset[0]] = v[0];
  keys[t.offset[1]] = v[1];
  keys[t.offset[2]] = v[2];
  if (t.rotation) keys[t.offset[3]] = rotation_w(v);
}

/// 1 / gap for the key gaps real clips have (a few frames), so moving a cursor costs no division.
struct Reciprocals {
  float r[64];
  constexpr Reciprocals() : r() {
    for (int i = 1; i < 64; ++i) r[i] = 1.0f / static_cast<float>(i);
  }
};
constexpr Reciprocals kReciprocals;
inline float inverse_gap(uint32_t f0, uint32_t f1) {
  const uint32_t gap = f1 - f0;  // >= 1: frames strictly increase
  return gap < 64 ? kReciprocals.r[gap] : 1.0f / static_cast<float>(gap);
}

/// The key pair of a run around `frame`: forward by one key (the common case in forward
/// playback) or a few keys by walking, anything else (a seek, a loop, reverse play) by binary
/// search. Returns k with frames[k] <= frame < frames[k + 1], or the last pair at the last frame.
inline uint32_t find_pair(const Run& r, float frame) {
  const uint16_t* frames = r.frames;
  const uint32_t n = r.key_count;
  const auto after = [](float f, uint16_t key_frame) { return f < static_cast<float>(key_frame); };
  uint32_t k;
  if (r.cursor != kNoCursor && frame >= r.leave) {
    k = r.cursor + 1;
    for (int step = 0; step < 4 && k + 2 < n && frame >= static_cast<float>(frames[k + 1]); ++step) ++k;
    if (k + 2 < n && frame >= static_cast<float>(frames[k + 1]))
      k = static_cast<uint32_t>(std::upper_bound(frames + k, frames + n, frame, after) - frames) - 1;
  } else {
    const uint16_t* hit = std::upper_bound(frames, frames + n, frame, after);
    k = hit == frames ? 0 : static_cast<uint32_t>(hit - frames) - 1;
  }
  return k > n - 2 ? n - 2 : k;
}

/// Moves a run that left its key pair to the pair around `frame`, decoding what changed: one key
/// per channel when it moved forward by one (k1 becomes k0), both keys otherwise.
void move_run(State& s, Run& r, float frame) {
  const uint32_t k = find_pair(r, frame);
  const Track* t = s.track_data + r.first_track;
  const Track* end = t + r.track_count;
  const uint8_t* stream = s.stream;
  float* k0 = s.k0;
  float* k1 = s.k1;
  const auto f0 = static_cast<float>(r.frames[k]);
  const float inv = inverse_gap(r.frames[k], r.frames[k + 1]);
  if (r.cursor != kNoCursor && k == r.cursor + 1) {
    for (; t != end; ++t) {
      k0[t->offset[0]] = k1[t->offset[0]];
      k0[t->offset[1]] = k1[t->offset[1]];
      k0[t->offset[2]] = k1[t->offset[2]];
      if (t->rotation) k0[t->offset[3]] = k1[t->offset[3]];
      decode(*t, stream, k + 1, k1);
      s.start[t->weight_index] = f0;
      s.inv_length[t->weight_index] = inv;
    }
  } else if (k != r.cursor) {
    for (; t != end; ++t) {
      decode(*t, stream, k, k0);
      decode(*t, stream, k + 1, k1);
      s.start[t->weight_index] = f0;
      s.inv_length[t->weight_index] = inv;
    }
  }
  r.cursor = k;
  r.enter = f0;
  r.leave = k + 2 == r.key_count ? kInf : static_cast<float>(r.frames[k + 1]);
}

// ---- pass 2: the per-joint interpolation -------------------------------------------------------
//
// Written with GCC/Clang vector extensions over 8-lane blocks (stride is a multiple of kPoseLanes)
// rather than left to the auto-vectorizer: at -O2 GCC will not vectorize a loop that calls sqrt
// (it must keep errno) or that has selects it cannot if-convert under trapping math, and both are
// in an nlerp. The same source compiles to one 256-bit op per line in the AVX2 clone and to two
// SSE2 ops in the baseline clone (vector_clones.h picks per call), or to scalar code elsewhere.

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

struct Lanes {
  const float* k0;
  const float* fixed;  // where blocks without an animated channel of a kind are copied from
  const float* k1;
  const float* start;
  const float* inv_length;
  const uint8_t* block_kinds;
  float* out;
  uint32_t stride;
};

OSSA_INLINE static void interpolate_nlerp_body(const Lanes& l, float frame) {
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
    if (kinds & kAnimatedT) {
      const F8 wt = clamp01((f - load8(start + j)) * load8(inv + j));
      const F8 at = one - wt;
      lerp(kTx, at, wt);
      lerp(kTy, at, wt);
      lerp(kTz, at, wt);
    } else {
      copy(kTx);
      copy(kTy);
      copy(kTz);
    }
    if (kinds & kAnimatedS) {
      const F8 ws = clamp01((f - load8(start + 2 * n + j)) * load8(inv + 2 * n + j));
      const F8 as = one - ws;
      lerp(kSx, as, ws);
      lerp(kSy, as, ws);
      lerp(kSz, as, ws);
    } else {
      copy(kSx);
      copy(kSy);
      copy(kSz);
    }
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

OSSA_VECTOR_DISPATCH(interpolate_nlerp, (const Lanes& l, float frame), (l, frame))

/// Slerp variant (an option, not the hot path): translations and scales as above, rotations at
/// constant angular velocity, falling back to nlerp where the keys are nearly equal.
void interpolate_slerp(const Lanes& l, float frame) {
  interpolate_nlerp(l, frame);  // T, S, and an nlerp R the loop below replaces
  const uint32_t stride = l.stride;
  for (uint32_t j = 0; j < stride; ++j) {
    if (l.block_kinds[j / kPoseLanes] & kSkipped) continue;
    float w = (frame - l.start[stride + j]) * l.inv_length[stride + j];
    w = w < 0.0f ? 0.0f : (w > 1.0f ? 1.0f : w);
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

}  // namespace

// ---- public API --------------------------------------------------------------------------------

Result<SamplingCache> make_sampling_cache(const ClipView& clip, const SkeletonView& skeleton,
                                          const SamplingCache* prototype, std::span<const uint8_t> joints) {
  if (Status st = check_clip_binding(clip, skeleton, "make_sampling_cache"); !st) return st.error();
  if (!joints.empty() && joints.size() != skeleton.joint_count())
    return Error{"make_sampling_cache: a joint filter of " + std::to_string(joints.size()) + " entries for " +
                 std::to_string(skeleton.joint_count()) + " joints"};
  auto s = std::make_unique<State>();
  s->filter = joints;
  s->clip = clip.fb;
  s->stream = clip.key_values().data();
  s->joint_count = static_cast<uint32_t>(skeleton.joint_count());
  s->stride = pose_stride(s->joint_count);
  s->last_frame = static_cast<float>(clip.frame_count() - 1);
  const size_t stride = s->stride;
  // Runs: channels that address the same key-frame range share one, in order of first use;
  // tracks are grouped by run. A filter drops the channels of the joints it leaves out (and runs
  // left without a channel), but not the kinds of blocks it keeps a joint of: pass 2 then treats
  // every lane of those as the unfiltered cache does, which keeps the kept joints' bits. A block it
  // keeps no joint of is left out of pass 2 (kSkipped): a filter pays for the blocks it shows only.
  s->block_kinds.assign(s->stride / kPoseLanes, joints.empty() ? 0 : kSkipped);
  for (uint32_t j = 0; j < joints.size(); ++j) s->block_kinds[j / kPoseLanes] &= joints[j] != 0 ? 0 : 0xff;
  std::vector<Run> runs;
  std::vector<const fb::AnimatedChannel*> animated;
  for (const fb::AnimatedChannel& a : clip.animated()) {
    s->block_kinds[a.joint() / kPoseLanes] |= static_cast<uint8_t>(1u << static_cast<uint32_t>(a.channel()));
    if (joints.empty() || joints[a.joint()] != 0) animated.push_back(&a);
  }
  std::map<std::pair<uint32_t, uint32_t>, uint32_t> run_of;  // (first_key, key_count) -> run
  std::vector<uint32_t> run_index(animated.size());
  for (size_t i = 0; i < animated.size(); ++i) {
    const fb::AnimatedChannel& a = *animated[i];
    const auto [it, added] =
        run_of.emplace(std::make_pair(a.first_key(), a.key_count()), static_cast<uint32_t>(runs.size()));
    if (added) {
      Run r;
      r.frames = clip.key_frames().data() + a.first_key();
      r.key_count = a.key_count();
      runs.push_back(r);
    }
    run_index[i] = it->second;
    ++runs[it->second].track_count;
  }
  // Floats first (a multiple of 8 floats: the runs start 32-byte aligned), then the runs.
  const size_t floats = (2 * kPoseComponents + 6) * stride;
  s->block = AlignedFloats(floats + (runs.size() * sizeof(Run) + sizeof(float) - 1) / sizeof(float));
  s->k0 = s->block.data;
  s->k1 = s->k0 + kPoseComponents * stride;
  s->start = s->k1 + kPoseComponents * stride;
  s->inv_length = s->start + 3 * stride;

  // Every lane starts as identity (padding lanes stay so, keeping whole-lane loops finite).
  static constexpr float kIdentity[3][4] = {{0, 0, 0, 0}, {0, 0, 0, 1}, {1, 1, 1, 0}};
  for (uint32_t j = 0; j < s->stride; ++j)
    for (uint32_t kind = 0; kind < 3; ++kind) set_fixed(*s, j, kind, kIdentity[kind]);
  // Bind values for channels the clip leaves out.
  const auto bt = skeleton.bind_translations();
  const auto br = skeleton.bind_rotations();
  const auto bs = skeleton.bind_scales();
  for (uint32_t j = 0; j < s->joint_count; ++j) {
    const float t[3] = {bt[j].x(), bt[j].y(), bt[j].z()};
    float r[4] = {br[j].x(), br[j].y(), br[j].z(), br[j].w()};
    normalize4(r);  // validation proved bind rotations normalizable
    const float sc[3] = {bs[j].x(), bs[j].y(), bs[j].z()};
    set_fixed(*s, j, 0, t);
    set_fixed(*s, j, 1, r);
    set_fixed(*s, j, 2, sc);
  }
  for (const fb::ConstantChannel& c : clip.constants()) {
    float v[4] = {c.value().x(), c.value().y(), c.value().z(), c.value().w()};
    const auto kind = static_cast<uint32_t>(c.channel());
    if (kind == 1) normalize4(v);  // validation proved rotation constants normalizable
    set_fixed(*s, c.joint(), kind, v);
  }

  uint32_t next = 0;
  for (Run& r : runs) {
    r.first_track = next;
    next += r.track_count;
  }
  static_assert(std::is_trivially_copyable_v<Run>);
  s->runs = reinterpret_cast<Run*>(s->block.data + floats);
  s->run_count = static_cast<uint32_t>(runs.size());
  if (!runs.empty()) std::memcpy(static_cast<void*>(s->runs), runs.data(), runs.size() * sizeof(Run));
  s->tracks.resize(animated.size());
  std::vector<uint32_t> filled(runs.size(), 0);
  for (size_t i = 0; i < animated.size(); ++i) {
    const Run& r = runs[run_index[i]];
    s->tracks[r.first_track + filled[run_index[i]]++] = make_track(*animated[i], s->stride);
  }
  forget_cursors(*s);
  s->fixed = s->k0;
  s->track_data = s->tracks.data();
  s->kinds = s->block_kinds.data();
  if (prototype && prototype->state() && prototype->state()->clip == s->clip &&
      prototype->state()->joint_count == s->joint_count && prototype->state()->filter.data() == joints.data() &&
      prototype->state()->filter.size() == joints.size()) {
    // Same clip, rig and filter: identical fixed blocks and decode records. Only the cursors and
    // the decoded key pairs stay per instance.
    s->fixed = prototype->state()->fixed;
    s->track_data = prototype->state()->track_data;
    s->kinds = prototype->state()->kinds;
    s->tracks.clear();
    s->tracks.shrink_to_fit();
    s->block_kinds.clear();
    s->block_kinds.shrink_to_fit();
  }
  return SamplingCache(std::move(s));
}

void reset(SamplingCache& cache) {
  if (State* s = cache.state()) forget_cursors(*s);
}

void sample(const ClipView& clip, float time, const SampleOptions& options, SamplingCache& cache, PoseSpan out) {
  const detail::FlushDenormals flush;  // a rest value like 1e-33 squared must not cost an assist
  State& s = *cache.state();
  assert(clip.fb == s.clip && "a SamplingCache plays the clip it was made for");
  assert(out.joint_count == s.joint_count && out.stride == s.stride);
  (void)out;

  // Time -> frame position in [0, last_frame]. The common case (a time already inside the clip)
  // skips fmod, a library call.
  const float duration = clip.duration();
  float t = time;
  if (!(t >= 0.0f && t < duration)) {
    if (!std::isfinite(t)) t = 0.0f;
    if (options.loop) {
      if (duration > 0.0f) {
        t = std::fmod(t, duration);
        if (t < 0.0f) t += duration;
        if (t >= duration) t = 0.0f;  // -tiny + duration rounds up to duration
      } else {
        t = 0.0f;
      }
    } else {
      t = t < 0.0f ? 0.0f : (t > duration ? duration : t);
    }
  }
  float frame = t * clip.sample_rate();
  frame = frame > s.last_frame ? s.last_frame : frame;
  // frame is in [0, 65535]: adding 0.5 and truncating rounds to nearest without a libm call.
  const auto nearest = static_cast<float>(static_cast<int32_t>(frame + 0.5f));
  if (std::fabs(frame - nearest) <= 1e-5f * (1.0f + nearest)) frame = nearest;

  // Pass 1: runs whose cached pair no longer covers the frame (none while inside every run's range).
  if (!(frame >= s.all_enter && frame < s.all_leave)) {
    float all_enter = -kInf, all_leave = kInf;
    for (Run& r : std::span<Run>(s.runs, s.run_count)) {
      if (!(frame >= r.enter && frame < r.leave)) move_run(s, r, frame);
      all_enter = std::max(all_enter, r.enter);
      all_leave = std::min(all_leave, r.leave);
    }
    s.all_enter = all_enter;
    s.all_leave = all_leave;
  }

  // Pass 2: every joint (of the blocks a joint filter keeps).
  const Lanes lanes{s.k0, s.fixed, s.k1, s.start, s.inv_length, s.kinds, out.base, s.stride};
  if (options.rotation == RotationInterpolation::Slerp) interpolate_slerp(lanes, frame);
  else interpolate_nlerp(lanes, frame);
}

}  // namespace ossa
