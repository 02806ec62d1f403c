// sample_keys.cpp — pass 1 of ossa::sample (anim/sample.cpp): brings a sampling cache's key pairs
// to the sampled frame, decoding what the pose will read.
//
// Unless the frame lies where every run's cached pair still holds (one compare against the
// intersection of their ranges, kept with the cursors; sample.cpp makes it before calling here),
// per key run (the animated channels sharing one key-frame list: the cooker shares a run between
// channels with equal frames, and then one test and one cursor serve them all) one compare of the
// frame position against the range its cached key pair covers; only a run that left its range
// moves its cursor (forward by one: keep k1 as the new k0 and decode one key per channel;
// otherwise a dense run's pair is the frame itself, and a sparse one counts the keys up to the
// frame in its seek index's bitmap, so a seek costs the same in a long clip) and decodes
// (anim/sample_decode.h: clip_codec.h's decoding specialized; a run's segmented channels decode
// after its plain ones, in a loop of their own, each key after its segment's header). A frame more
// than kSeekFrames from the last sample's (a seek, a loop's wrap, the first sample) skips the range
// tests: every run takes its pair from its index and decodes both keys of each channel (seek_all),
// its branches taking the same way run after run. Outside a seek, a run moved to one of its keys'
// own frames decodes only that key (settle).
//
// Compiled twice (internal/vector_clones.h), for AVX2 and the x86-64 baseline, with every helper
// inlined into each copy: the decode is SSE code either way, but the VEX encoding's three-operand
// forms drop the register copies that are a good part of a key's ~100 instructions (a seek on CMU
// 01_03 12 % faster, on Pab's atlas 15 %, Zen 5). No FMA in either copy, so both give the same bits.
//
// Trust: sample.cpp's (validate_clip.cpp proved every read; the cache was made for this clip).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>

#include <ossa/format/clip_codec.h>
#include "anim/sample_cache.h"
#include "anim/sample_decode.h"
#include "internal/vector_clones.h"

namespace ossa::sample_detail {
namespace {

using State = SamplingCache::State;

/// 1 / gap for the key gaps real clips have (a few frames), so moving a cursor costs no division.
struct Reciprocals {
  float r[64];
  constexpr Reciprocals() : r() {
    for (int i = 1; i < 64; ++i) r[i] = 1.0f / static_cast<float>(i);
  }
};
constexpr Reciprocals kReciprocals;
OSSA_INLINE float inverse_gap(uint32_t f0, uint32_t f1) {
  const uint32_t gap = f1 - f0;  // >= 1: frames strictly increase
  return gap < 64 ? kReciprocals.r[gap] : 1.0f / static_cast<float>(gap);
}

/// Where a sparse run's keys are: the last key at or before frame `whole` (its seek index's keys
/// up to it, counted; frames[0] == 0, so at least one), not yet clamped to the last pair.
OSSA_INLINE uint32_t indexed_key(const Run& r, uint32_t whole) {
  const SeekBlock& b = r.seek[whole >> 6];
  return b.before + popcount64(b.keys & (~0ull >> (63 - (whole & 63)))) - 1;
}

/// The frames of pair k's two keys (a dense run stores none: its key k is at frame k).
struct PairFrames {
  uint32_t first, second;
};
OSSA_INLINE PairFrames pair_frames(const Run& r, uint32_t k) {
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
OSSA_INLINE uint32_t find_pair(const Run& r, float frame) {
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

/// Decodes both keys of pair k (frames f0 and f0 + 1 / inv) of tracks [t, end) of a run.
/// kSegments: the tracks are segmented. The helpers here are always inlined: each caller's loop is
/// then compiled for its case (a call per run cost Pab's three-clip frame a tenth, Zen 5).
template <bool kSegments>
OSSA_INLINE void decode_pairs(State& s, const Track* t, const Track* end, uint32_t k, float f0, float inv) {
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
OSSA_INLINE void decode_run_pairs(State& s, const Run& r, uint32_t k, float f0, float inv) {
  const Track* t = s.track_data + r.first_track;
  const Track* end = t + r.track_count;
  decode_pairs<false>(s, t, end - r.segmented, k, f0, inv);
  if (r.segmented != 0) decode_pairs<true>(s, end - r.segmented, end, k, f0, inv);
}

/// Decodes key `key` of tracks [t, end) into `keys` (k0 or k1), two tracks at a time (one square
/// root for two rotations).
template <bool kSegments>
OSSA_INLINE void decode_keys(State& s, const Track* t, const Track* end, uint32_t key, float* keys) {
  const KeySource src{s.stream, s.track_data, s.segments.data()};
  for (; end - t >= 2; t += 2) decode_two<kSegments>(t[0], t[1], src, key, keys);
  if (t != end) decode<kSegments>(*t, src, key, keys);
}

/// Playback moved forward by one pair (to k): each track's k1 becomes its k0 and key k + 1 is
/// decoded into k1.
template <bool kSegments>
OSSA_INLINE void shift_tracks(State& s, const Track* t, const Track* end, uint32_t k, float f0, float inv) {
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
OSSA_INLINE void settle(State& s, Run& r, uint32_t k, float frame) {
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
OSSA_INLINE void seek_all(State& s, float frame) {
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

/// Pass 1: a seek (`seek`) moves every run; otherwise the runs whose range no longer holds the frame.
OSSA_INLINE void update_keys_body(State& s, float frame, bool seek) {
  if (seek) {
    seek_all(s, frame);
    return;
  }
  float all_enter = -kInf, all_leave = kInf;
  for (Run& r : std::span<Run>(s.runs, s.run_count)) {
    if (!(frame >= r.enter && frame < r.leave)) settle(s, r, find_pair(r, frame), frame);
    all_enter = std::max(all_enter, r.enter);
    all_leave = std::min(all_leave, r.leave);
  }
  s.all_enter = all_enter;
  s.all_leave = all_leave;
}

}  // namespace

OSSA_VECTOR_DISPATCH(update_keys, (State & s, float frame, bool seek), (s, frame, seek))

}  // namespace ossa::sample_detail
