// sample_cache.h — a sampling cache's state (SamplingCache::State) and its key runs, shared by the
// sampler's two files: sample.cpp makes caches and runs a sample's two passes; sample_keys.cpp is
// pass 1 (cursors, seeks, key decodes), compiled for AVX2 and the baseline as the per-joint kernels
// are (internal/vector_clones.h), because that pass is most of a seek. Internal to runtime/anim.
#pragma once
#include <cstddef>
#include <cstdint>
#include <limits>
#include <new>
#include <span>
#include <utility>
#include <vector>

#include <ossa/anim/sample.h>
#include "anim/sample_decode.h"
#include "internal/memory.h"

namespace ossa {
namespace sample_detail {

constexpr uint32_t kNoCursor = std::numeric_limits<uint32_t>::max();
constexpr float kInf = std::numeric_limits<float>::infinity();

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

}  // namespace sample_detail

struct SamplingCache::State {
  const fb::Clip* clip = nullptr;   // the clip this cache was made for
  const uint8_t* stream = nullptr;  // its key_values
  uint32_t joint_count = 0;
  uint32_t stride = 0;      // pose_stride(joint_count)
  float last_frame = 0.0f;  // frame_count - 1
  float duration = 0.0f;    // the clip's, read once here: sample() needs both on every call
  float sample_rate = 0.0f;

  // One block: k0[10 * stride], k1[10 * stride], start[3 * stride], inv_length[3 * stride].
  sample_detail::AlignedFloats block;
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
  sample_detail::Run* runs = nullptr;
  uint32_t run_count = 0;
  // The intersection of every run's range (largest enter, smallest leave): a frame inside moves no
  // run, so pass 1 is one compare (a slow clip, updates faster than keys). Empty when forgotten.
  float all_enter = sample_detail::kInf, all_leave = -sample_detail::kInf;
  float last = sample_detail::kInf;          // the frame position of the last sample (kInf when forgotten)
  std::vector<sample_detail::Track> tracks;  // grouped by run
  // What settle and seek_all read: tracks, or a prototype's (identical: they depend on the clip, rig and filter only).
  const sample_detail::Track* track_data = nullptr;
  // Per track (track_data's order), the segment it last decoded; empty when no track is segmented.
  std::vector<sample_detail::SegmentCursor> segments;
  // The sparse runs' seek indexes, one after another (Run::seek points into this or a prototype's).
  std::vector<sample_detail::SeekBlock> seek_index;
  // The joint filter the cache was made with (empty: every joint), compared with a prototype's.
  std::span<const uint8_t> filter;
};

namespace sample_detail {

/// Pass 1 of a sample at frame position `frame` (in [0, last frame]) that some run's cached pair no
/// longer covers, or a seek (`seek`: more than kSeekFrames from the last sample): brings the key
/// pairs to the frame (sample_keys.cpp). O(runs + keys decoded), O(runs + tracks) for a seek; no
/// allocation. The AVX2 or the baseline copy, picked per call (ossa/anim/vector_isa.h).
void update_keys(SamplingCache::State& s, float frame, bool seek);

}  // namespace sample_detail
}  // namespace ossa
