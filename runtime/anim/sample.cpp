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
//      dense run's pair is the frame itself, and a sparse one counts the keys up to the frame in
//      its seek index's bitmap, so a seek costs the same in a long clip) and decodes
//      (anim/sample_decode.h: clip_codec.h's decoding specialized; a run's segmented channels
//      decode after its plain ones, in a loop of their own, each key after its segment's header).
//      A frame more than kSeekFrames from the last sample's (a seek, a loop's wrap, the first
//      sample) skips the range tests: every run takes its pair from its index and decodes both
//      keys of each channel (seek_all), its branches taking the same way run after run. Outside
//      a seek, a run moved to one of its keys' own frames decodes only that key (settle);
//   2. one loop over all joints (SoA, 8-lane blocks): lerp T and S, nlerp R with the shortest-arc
//      sign fix, write the pose (anim/sample_interpolate.cpp: vector code, on x86-64 compiled
//      for AVX2 and the SSE2 baseline, picked per call, so the default build runs on any x86-64).
//      A block with no animated channel of a kind copies that kind's fixed values instead of
//      interpolating them; a block a joint filter keeps no joint of is skipped.
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
// Cost: make_sampling_cache O(joints + animated channels + keys of sparse runs), a few allocations
// (a seek index of 16 bytes per 64 frames per sparse run, shared with a prototype); sample
// O(joints + runs), no branch per key passed, no allocation; reset O(runs).
// advance_time is advance_time.cpp.
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
#include "anim/sample_decode.h"
#include "internal/float_env.h"
#include "internal/memory.h"
#include "internal/sample_lanes.h"

namespace ossa {
namespace {

using detail::kSkipped;
using detail::normalize4;
using sample_detail::decode;
using sample_detail::decode_pair;
using sample_detail::decode_two;
using sample_detail::KeySource;
using sample_detail::SegmentCursor;
using sample_detail::Track;

constexpr uint32_t kNoCursor = std::numeric_limits<uint32_t>::max();
constexpr float kInf = std::numeric_limits<float>::infinity();

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

/// 64 frames of a sparse run's seek index (Run::seek): bit i of `keys` is set when the run has a
/// key at frame 64 b + i, and `before` counts its keys before frame 64 b. The pair around a frame
/// is then `before` plus the keys set up to it, minus one: a population count, with no branch per
/// key, where walking the keys from an entry per 8 frames (at most 7) mispredicted at each walk's
/// end (Pab's atlas, 40 runs: ~20 % of a random seek, Zen 5). 2 bits per frame, as that index.
struct SeekBlock {
  uint64_t keys = 0;
  uint32_t before = 0;
  uint32_t unused = 0;
};

/// Set bits of x (SWAR: the SSE2 baseline has no POPCNT, and std::popcount there calls libgcc).
inline uint32_t popcount64(uint64_t x) {
  x = x - ((x >> 1) & 0x5555555555555555ull);
  x = (x & 0x3333333333333333ull) + ((x >> 2) & 0x3333333333333333ull);
  x = (x + (x >> 4)) & 0x0f0f0f0f0f0f0f0full;
  return static_cast<uint32_t>((x * 0x0101010101010101ull) >> 56);
}

/// Animated channels sharing one key-frame list, and the cursor they share: the pair (cursor,
/// cursor + 1) is valid while enter <= frame < leave (leave is +inf for the last pair, which also
/// covers the last frame).
struct Run {
  const uint16_t* frames = nullptr;  // null for a dense run (the file stores no frames for it)
  // Sparse runs: the keys of frames 64 b .. 64 b + 63 (make_seek_index). Null for a dense run, a
  // key on every frame (key_count == frame_count), whose pair is the frame itself.
  const SeekBlock* seek = nullptr;
  uint32_t key_count = 0;
  uint32_t cursor = kNoCursor;
  float enter = kInf;
  float leave = -kInf;
  uint32_t first_track = 0;  // its channels are tracks[first_track, first_track + track_count)
  uint32_t track_count = 0;
  uint32_t segmented = 0;  // its last `segmented` tracks are segmented channels, the others plain
  // Only the pair's first key is decoded (k1 holds older keys): moved to at that key's own frame,
  // where the second key's weight is 0. The range is then that frame alone (leave == enter).
  uint32_t half = 0;
};

/// A sample more than this many frames from the last one is a seek (seek_all).
constexpr float kSeekFrames = 2.0f;

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
  float last = kInf;          // the frame position of the last sample (kInf when forgotten)
  std::vector<Track> tracks;  // grouped by run
  // What settle and seek_all read: tracks, or a prototype's (identical: they depend on the clip, rig and filter only).
  const Track* track_data = nullptr;
  // Per track (track_data's order), the segment it last decoded; empty when no track is segmented.
  std::vector<SegmentCursor> segments;
  // The sparse runs' seek indexes, one after another (Run::seek points into this or a prototype's).
  std::vector<SeekBlock> seek_index;
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
    r.half = 0;
  }
  s.all_enter = kInf;
  s.all_leave = -kInf;
  s.last = kInf;
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

Track make_track(const fb::AnimatedChannel& ch, uint32_t stride) {
  Track t;
  t.bit_offset = ch.bit_offset();
  const KeyWidths w = widths_of(ch);
  t.key_bits = static_cast<uint32_t>(w.total());
  t.raw = w.raw();
  t.offset_bits = ch.segment_offset_bits();  // validation proved it 0 for raw keys
  t.widths = w;
  t.header_bits = t.raw ? 0u : static_cast<uint32_t>(segment_header_bits(w, t.offset_bits));
  for (uint32_t c = 0; c < 3 && !t.raw; ++c) {
    t.shift[c] = static_cast<uint8_t>(w.shift(c));
    t.mask[c] = quant_max(w.c[c]);
    t.qmax[c] = static_cast<float>(t.mask[c]);
  }
  t.lo[0] = ch.range_min().x() + 0.0f, t.lo[1] = ch.range_min().y() + 0.0f, t.lo[2] = ch.range_min().z() + 0.0f;
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

/// Where a sparse run's keys are: the last key at or before frame `whole` (its seek index's keys
/// up to it, counted; frames[0] == 0, so at least one), not yet clamped to the last pair.
inline uint32_t indexed_key(const Run& r, uint32_t whole) {
  const SeekBlock& b = r.seek[whole >> 6];
  return b.before + popcount64(b.keys & (~0ull >> (63 - (whole & 63)))) - 1;
}

/// The frames of pair k's two keys (a dense run stores none: its key k is at frame k).
struct PairFrames {
  uint32_t first, second;
};
inline PairFrames pair_frames(const Run& r, uint32_t k) {
  return r.frames ? PairFrames{r.frames[k], r.frames[k + 1]} : PairFrames{k, k + 1};
}

/// The key pair of a run around `frame` (in [0, last frame]): k with frames[k] <= frame <
/// frames[k + 1], or the last pair at the last frame (or the first before a first key past 0). A
/// dense run's pair is the frame's whole part. A sparse run takes the next pair when playback moved
/// forward into it (the common case: one compare, the index untouched); otherwise its seek index
/// gives the last key at or before the frame's whole part (frames are whole, so that key's pair
/// holds the frame) in O(1) whatever the clip's length, where a binary search over a long clip's
/// keys would cost a dozen mispredicted branches. (A half pair's leave is its enter, not its second
/// key's frame: it always asks the index.)
inline uint32_t find_pair(const Run& r, float frame) {
  const uint32_t n = r.key_count;
  const auto whole = static_cast<uint32_t>(frame);
  uint32_t k;
  if (!r.seek) {
    k = whole;  // frames[k] == k
  } else {
    k = r.cursor != kNoCursor && !r.half && frame >= r.leave ? r.cursor + 1 : 0;
    if (k + 2 < n && frame >= static_cast<float>(r.frames[k + 1])) k = indexed_key(r, whole);  // past that pair
  }
  return k > n - 2 ? n - 2 : k;
}

/// Appends a sparse run's seek index to `index`: for each 64-frame block of the clip's
/// `frame_count` frames, its keys as bits and the keys before it. O(keys + blocks); 16 bytes per 64
/// frames.
void make_seek_index(const uint16_t* frames, uint32_t key_count, uint32_t frame_count, std::vector<SeekBlock>& index) {
  const size_t first = index.size();
  index.resize(first + ((frame_count + 63) >> 6));
  for (uint32_t k = 0; k < key_count; ++k) index[first + (frames[k] >> 6)].keys |= 1ull << (frames[k] & 63);
  uint32_t before = 0;
  for (size_t b = first; b < index.size(); ++b) {
    index[b].before = before;
    before += popcount64(index[b].keys);
  }
}

/// Decodes both keys of pair k (frames f0 and f0 + 1 / inv) of tracks [t, end) of a run.
/// kSegments: the tracks are segmented. The helpers here are always inlined: each caller's loop is
/// then compiled for its case (a call per run cost Pab's three-clip frame a tenth, Zen 5).
template <bool kSegments>
[[gnu::always_inline]] inline void decode_pairs(State& s, const Track* t, const Track* end, uint32_t k, float f0,
                                                float inv) {
  const KeySource src{s.stream, s.track_data, s.segments.data()};
  float* k0 = s.k0;
  float* k1 = s.k1;
  for (; t != end; ++t) {
    decode_pair<kSegments>(*t, src, k, k0, k1);
    s.start[t->weight_index] = f0;
    s.inv_length[t->weight_index] = inv;
  }
}

/// Both keys of pair k of every track of run r: its plain tracks, then its segmented ones (after
/// them), each in a loop compiled for its layout (measured: the segmented decode in the plain
/// keys' loop slowed their seeks by a quarter).
[[gnu::always_inline]] inline void decode_run_pairs(State& s, const Run& r, uint32_t k, float f0, float inv) {
  const Track* t = s.track_data + r.first_track;
  const Track* end = t + r.track_count;
  decode_pairs<false>(s, t, end - r.segmented, k, f0, inv);
  if (r.segmented != 0) decode_pairs<true>(s, end - r.segmented, end, k, f0, inv);
}

/// Decodes key `key` of tracks [t, end) into `keys` (k0 or k1), two tracks at a time (one square
/// root for two rotations).
template <bool kSegments>
[[gnu::always_inline]] inline void decode_keys(State& s, const Track* t, const Track* end, uint32_t key, float* keys) {
  const KeySource src{s.stream, s.track_data, s.segments.data()};
  for (; end - t >= 2; t += 2) decode_two<kSegments>(t[0], t[1], src, key, keys);
  if (t != end) decode<kSegments>(*t, src, key, keys);
}

/// Playback moved forward by one pair (to k): each track's k1 becomes its k0 and key k + 1 is
/// decoded into k1.
template <bool kSegments>
[[gnu::always_inline]] inline void shift_tracks(State& s, const Track* t, const Track* end, uint32_t k, float f0,
                                                float inv) {
  const KeySource src{s.stream, s.track_data, s.segments.data()};
  float* k0 = s.k0;
  float* k1 = s.k1;
  const auto shift = [&](const Track& x) {  // k1 becomes k0
    k0[x.offset[0]] = k1[x.offset[0]];
    k0[x.offset[1]] = k1[x.offset[1]];
    k0[x.offset[2]] = k1[x.offset[2]];
    if (x.rotation) k0[x.offset[3]] = k1[x.offset[3]];
    s.start[x.weight_index] = f0;
    s.inv_length[x.weight_index] = inv;
  };
  for (; end - t >= 2; t += 2) {
    shift(t[0]);
    shift(t[1]);
    decode_two<kSegments>(t[0], t[1], src, k + 1, k1);
  }
  if (t != end) {
    shift(*t);
    decode<kSegments>(*t, src, k + 1, k1);
  }
}

/// Brings run r's tracks to pair k for a sample at `frame`, decoding only what they lack, and
/// sets its cursor and range. Plain and segmented tracks in loops of their own, as in
/// decode_run_pairs:
///   - the next pair: shift (one key per track);
///   - the same pair: nothing, or its second keys if only the first were decoded and the frame
///     left the first key's;
///   - at key k's own frame: its first keys only (half). The second key's weight is 0 there, and
///     no key decodes to -0 (clip_codec.h), so the lerps and nlerps give the first key whatever k1
///     holds: bit for bit the pose of the whole pair, for one key per track instead of two
///     (mocap at 120 frames per second played at 60 Hz steps two keys, every sample at a key);
///   - otherwise both keys.
void settle(State& s, Run& r, uint32_t k, float frame) {
  const Track* t = s.track_data + r.first_track;
  const Track* end = t + r.track_count;
  const Track* seg = end - r.segmented;
  const PairFrames frames = pair_frames(r, k);
  const auto f0 = static_cast<float>(frames.first);
  const float inv = inverse_gap(frames.first, frames.second);
  if (k == r.cursor + 1 && r.cursor != kNoCursor && !r.half) {
    shift_tracks<false>(s, t, seg, k, f0, inv);
    if (seg != end) shift_tracks<true>(s, seg, end, k, f0, inv);
  } else if (k == r.cursor) {
    if (r.half && frame != f0) {
      decode_keys<false>(s, t, seg, k + 1, s.k1);
      if (seg != end) decode_keys<true>(s, seg, end, k + 1, s.k1);
      r.half = 0;
    }
  } else if (frame == f0) {
    decode_keys<false>(s, t, seg, k, s.k0);
    if (seg != end) decode_keys<true>(s, seg, end, k, s.k0);
    for (const Track* x = t; x != end; ++x) {
      s.start[x->weight_index] = f0;
      s.inv_length[x->weight_index] = inv;
    }
    r.half = 1;
  } else {
    decode_run_pairs(s, r, k, f0, inv);
    r.half = 0;
  }
  r.cursor = k;
  r.enter = f0;
  r.leave = r.half ? f0 : k + 2 == r.key_count ? kInf : static_cast<float>(frames.second);
}

/// A seek: every run to the pair around `frame`, from its seek index (the pair find_pair would
/// find), both keys decoded unless the run already holds that whole pair. A random seek moves
/// nearly every run; testing each run's range first mispredicted, and its outcome then broke the
/// prediction of the short track loops after it (a long clip has dozens of sparse runs of one to
/// three tracks). Here the branches take the same way run after run, so settle's cases stay out
/// (they cost Pab's atlas 5% of a seek, Zen 5). O(runs + tracks).
void seek_all(State& s, float frame) {
  const auto whole = static_cast<uint32_t>(frame);
  float all_enter = -kInf, all_leave = kInf;
  for (Run& r : std::span<Run>(s.runs, s.run_count)) {
    uint32_t k = r.seek ? indexed_key(r, whole) : whole;  // a dense run: frames[k] == k
    k = k > r.key_count - 2 ? r.key_count - 2 : k;
    const PairFrames frames = pair_frames(r, k);
    const auto f0 = static_cast<float>(frames.first);
    if (k != r.cursor || r.half) decode_run_pairs(s, r, k, f0, inverse_gap(frames.first, frames.second));
    r.half = 0;
    r.cursor = k;
    r.enter = f0;
    r.leave = k + 2 == r.key_count ? kInf : static_cast<float>(frames.second);
    all_enter = std::max(all_enter, r.enter);
    all_leave = std::min(all_leave, r.leave);
  }
  s.all_enter = all_enter;
  s.all_leave = all_leave;
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
      if (!keyed_every_frame(a.key_count(), clip.frame_count())) r.frames = clip.key_frames().data() + a.first_key();
      r.key_count = a.key_count();
      runs.push_back(r);
    }
    run_index[i] = it->second;
    ++runs[it->second].track_count;
    if (a.segment_offset_bits() != 0) ++runs[it->second].segmented;
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
    float v[4];
    constant_value(c, v);
    const auto kind = static_cast<uint32_t>(c.channel());
    if (kind == 1) normalize4(v);  // validation proved rotation constants normalizable
    set_fixed(*s, c.joint(), kind, v);
  }

  uint32_t next = 0;
  for (Run& r : runs) {
    r.first_track = next;
    next += r.track_count;
  }
  // Same clip, rig and filter as the prototype: identical fixed blocks, decode records and seek
  // indexes, read from it. Only the cursors and the decoded key pairs stay per instance.
  const State* shared = prototype && prototype->state() && prototype->state()->clip == s->clip &&
                                prototype->state()->joint_count == s->joint_count &&
                                prototype->state()->filter.data() == joints.data() &&
                                prototype->state()->filter.size() == joints.size()
                            ? prototype->state()
                            : nullptr;
  // Seek indexes for the sparse runs; a dense run (a key on every frame) needs none.
  std::vector<size_t> seek_at(runs.size(), 0);
  for (size_t i = 0; i < runs.size() && !shared; ++i) {
    if (runs[i].key_count == clip.frame_count()) continue;
    seek_at[i] = s->seek_index.size();
    make_seek_index(runs[i].frames, runs[i].key_count, clip.frame_count(), s->seek_index);
  }
  for (size_t i = 0; i < runs.size(); ++i) {
    if (shared) runs[i].seek = shared->runs[i].seek;
    else if (runs[i].key_count != clip.frame_count()) runs[i].seek = s->seek_index.data() + seek_at[i];
  }
  static_assert(std::is_trivially_copyable_v<Run>);
  s->runs = reinterpret_cast<Run*>(s->block.data + floats);
  s->run_count = static_cast<uint32_t>(runs.size());
  if (!runs.empty()) std::memcpy(static_cast<void*>(s->runs), runs.data(), runs.size() * sizeof(Run));
  s->tracks.resize(animated.size());
  // Within a run, plain tracks first, then the segmented ones (decode_run_pairs's two loops).
  std::vector<uint32_t> plain(runs.size(), 0), segmented(runs.size(), 0);
  for (size_t i = 0; i < animated.size(); ++i) {
    const Run& r = runs[run_index[i]];
    const uint32_t at = animated[i]->segment_offset_bits() != 0
                            ? r.track_count - r.segmented + segmented[run_index[i]]++
                            : plain[run_index[i]]++;
    s->tracks[r.first_track + at] = make_track(*animated[i], s->stride);
  }
  if (std::any_of(animated.begin(), animated.end(),
                  [](const fb::AnimatedChannel* a) { return a->segment_offset_bits() != 0; }))
    s->segments.resize(animated.size());
  forget_cursors(*s);
  s->fixed = s->k0;
  s->track_data = s->tracks.data();
  s->kinds = s->block_kinds.data();
  if (shared) {
    s->fixed = shared->fixed;
    s->track_data = shared->track_data;
    s->kinds = shared->kinds;
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

  // Pass 1: a seek (a frame more than kSeekFrames from the last sample's, or the first sample)
  // decodes every track's pair; otherwise only runs whose cached pair no longer covers the frame
  // move (none while inside every run's range).
  const float last = s.last;
  s.last = frame;
  if (!(std::fabs(frame - last) <= kSeekFrames)) {
    seek_all(s, frame);
  } else if (!(frame >= s.all_enter && frame < s.all_leave)) {
    float all_enter = -kInf, all_leave = kInf;
    for (Run& r : std::span<Run>(s.runs, s.run_count)) {
      if (!(frame >= r.enter && frame < r.leave)) settle(s, r, find_pair(r, frame), frame);
      all_enter = std::max(all_enter, r.enter);
      all_leave = std::min(all_leave, r.leave);
    }
    s.all_enter = all_enter;
    s.all_leave = all_leave;
  }

  // Pass 2: every joint (of the blocks a joint filter keeps).
  const detail::SampleLanes lanes{s.k0, s.fixed, s.k1, s.start, s.inv_length, s.kinds, out.base, s.stride};
  if (options.rotation == RotationInterpolation::Slerp) detail::interpolate_slerp(lanes, frame);
  else detail::interpolate_nlerp(lanes, frame);
}

}  // namespace ossa
