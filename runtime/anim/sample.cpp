// sample.cpp — compressed clip + time -> local pose (sample.h), with per-instance key caching.
//
// Shape. A SamplingCache::State (anim/sample_cache.h) holds, for every joint and every pose
// component, the two values the interpolation runs between (k0, k1) and, per channel kind
// (translation, rotation, scale), the frame the pair starts at and 1 / its length in frames.
// Absent channels hold the bind value and constants their value in both keys with a zero
// 1/length, so their blend weight is always 0; those entries are written once, when the cache is
// made. Animated channels overwrite their joint's entries whenever playback crosses one of their
// keys. A sample is then two passes:
//   1. unless the frame lies where every run's cached pair still holds (one compare against the
//      intersection of their ranges), the runs that left their range move and decode their keys,
//      or on a seek every run does (anim/sample_keys.cpp);
//   2. one loop over all joints (SoA, 8-lane blocks): lerp T and S, nlerp R with the shortest-arc
//      sign fix, write the pose (anim/sample_interpolate.cpp).
//      A block with no animated channel of a kind copies that kind's fixed values instead of
//      interpolating them; a block a joint filter keeps no joint of is skipped.
// Both passes are vector code compiled for AVX2 and the SSE2 baseline, picked per call
// (internal/vector_clones.h), so the default build runs on any x86-64.
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
#include <map>
#include <memory>
#include <span>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <ossa/format/clip_codec.h>
#include "anim/sample_cache.h"
#include "anim/sample_decode.h"
#include "internal/float_env.h"
#include "internal/sample_lanes.h"

namespace ossa {
namespace {

using detail::kSkipped;
using detail::normalize4;
using sample_detail::AlignedFloats;
using sample_detail::kInf;
using sample_detail::kNoCursor;
using sample_detail::kSeekFrames;
using sample_detail::popcount64;
using sample_detail::Run;
using sample_detail::SeekBlock;
using sample_detail::Track;

/// Components of each channel kind in a pose (pose.h order: T xyz, R xyzw, S xyz).
constexpr uint32_t kFirstComponent[3] = {kTx, kRx, kSx};

}  // namespace

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
  s->duration = clip.duration();
  s->sample_rate = clip.sample_rate();
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
  (void)clip;
  (void)out;

  // Time -> frame position in [0, last_frame]. The common case (a time already inside the clip)
  // skips fmod, a library call.
  const float duration = s.duration;
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
  float frame = t * s.sample_rate;
  frame = frame > s.last_frame ? s.last_frame : frame;
  // frame is in [0, 65535]: adding 0.5 and truncating rounds to nearest without a libm call.
  const auto nearest = static_cast<float>(static_cast<int32_t>(frame + 0.5f));
  if (std::fabs(frame - nearest) <= 1e-5f * (1.0f + nearest)) frame = nearest;

  // Pass 1: a seek (a frame more than kSeekFrames from the last sample's, or the first sample)
  // decodes every track's pair; otherwise only runs whose cached pair no longer covers the frame
  // move (none while inside every run's range).
  const bool seek = !(std::fabs(frame - s.last) <= kSeekFrames);
  s.last = frame;
  if (seek || !(frame >= s.all_enter && frame < s.all_leave)) sample_detail::update_keys(s, frame, seek);

  // Pass 2: every joint (of the blocks a joint filter keeps).
  const detail::SampleLanes lanes{s.k0, s.fixed, s.k1, s.start, s.inv_length, s.kinds, out.base, s.stride};
  if (options.rotation == RotationInterpolation::Slerp) detail::interpolate_slerp(lanes, frame);
  else detail::interpolate_nlerp(lanes, frame);
}

}  // namespace ossa
