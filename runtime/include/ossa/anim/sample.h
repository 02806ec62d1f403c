// sample.h — a compressed clip at a time -> a local-space pose.
//
// The seed blog's idea, done for compressed data: each animated channel keeps a cursor (the key
// pair around the last sampled time) and the two keys already decoded, in a SamplingCache. Forward
// playback then only decodes a key when time passes it, and each channel's keys are read in
// memory order; a seek, a loop or reverse play moves the cursor (to the frame itself where a
// channel has a key on every frame, else a count of the keys up to the frame in a seek index of
// one 64-bit key bitmap per 64 frames) and stays exact. Per frame the work left is one
// interpolation per joint over SoA arrays: constants and bind-pose channels sit in the cache as
// key pairs that never change, so the interpolation loop has no per-channel branches.
//
// sample() never allocates and touches only the cache and the output; one cache per (clip,
// playing instance). Caches are made for one clip + skeleton and checked against the clip's
// skeleton hash.
#pragma once
#include <cstdint>
#include <memory>
#include <span>

#include <ossa/format/result.h>
#include <ossa/loader/asset.h>
#include <ossa/anim/pose.h>

namespace ossa {

enum class RotationInterpolation : uint8_t {
  Nlerp,  // normalized lerp on the shortest arc: the default, what the cooker's error bound assumes
  Slerp,  // constant angular velocity between keys
};

struct SampleOptions {
  bool loop = true;  // wrap time into [0, duration); otherwise clamp to [0, duration]
  RotationInterpolation rotation = RotationInterpolation::Nlerp;
};

/// Per-instance sampling state for one clip. Opaque; made by make_sampling_cache.
class SamplingCache {
 public:
  SamplingCache();
  SamplingCache(SamplingCache&&) noexcept;
  SamplingCache& operator=(SamplingCache&&) noexcept;
  ~SamplingCache();
  struct State;
  State* state() const { return state_.get(); }
  explicit SamplingCache(std::unique_ptr<State> s);

 private:
  std::unique_ptr<State> state_;
};

/// Allocates and primes a cache for playing `clip` on `skeleton` (bind values for channels the
/// clip leaves out). Error when the clip's skeleton hash or joint count is not the skeleton's.
/// `prototype` (optional): a cache of the same clip and rig, never used for sampling, that must
/// outlive this one; what never changes (constant and bind channels, and each animated channel's
/// decode record) is then read from it, so many characters playing one clip share it in cache and
/// each cache keeps only its cursors and decoded key pairs (and the seek index: 16 bytes per 64
/// frames per run of channels with fewer keys than frames). O(joints + animated channels + keys).
/// `joints` (optional, one entry per joint): decode only the animated channels of the joints with
/// a non-zero entry (a masked slot, which shows some joints of a clip, pays for their keys only).
/// Every kept joint samples bit for bit as without the filter. sample() leaves the output's lanes
/// of an 8-joint block (kPoseLanes) with no kept joint as they were; in a block with one, a dropped
/// joint's animated channels hold their bind values. So a filter showing a few joints of a large rig
/// costs their blocks only. It must outlive the cache, and a prototype must have the very same span.
Result<SamplingCache> make_sampling_cache(const ClipView& clip, const SkeletonView& skeleton,
                                          const SamplingCache* prototype = nullptr,
                                          std::span<const uint8_t> joints = {});

/// Forgets the cursors (the next sample searches from scratch). O(animated channels).
void reset(SamplingCache& cache);

/// Samples `clip` at `time` seconds into `out` (out.joint_count == the skeleton's). Forward
/// playback: O(joints) + O(keys passed); a seek: O(joints + animated channels). Allocation-free.
/// Like every float kernel of the runtime it runs with x86's flush-to-zero and denormals-are-zero
/// set and gives the caller its MXCSR back: two MXCSR writes a call (3-5 ns on a Zen 5, a tenth of
/// a 10-joint clip's sample) unless the calling thread has both bits set already, as many engines
/// do for their game threads; then it only reads it.
void sample(const ClipView& clip, float time, const SampleOptions& options, SamplingCache& cache, PoseSpan out);

/// Time after advancing by dt * rate (rate may be negative), wrapped into [0, duration) when
/// looping or clamped otherwise. *loops (optional) receives the signed number of wraps.
float advance_time(float time, float dt, float rate, float duration, bool loop, int* loops = nullptr);

}  // namespace ossa
