// clip_compress_internal.h — what the files of the clip compressor share (internal to
// cooker/clip/): the channel plan, the error metric and levers, and the stage functions that
// clip_compress.cpp (classification order, compensation, verification) calls in
// clip_compress_levers.cpp (step 2: levers), clip_compress_channel.cpp (steps 4-5 for one
// channel: classification, keys and bits), clip_compress_share.cpp (step 7) and
// clip_compress_pack.cpp (the bytes). The design is in clip_compress.cpp's header; the stages
// are files of their own so each stays readable on its own.
#pragma once

#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "cooker/clip/clip_compress.h"
#include "cooker/clip/clip_error.h"

namespace ossa::cook::compress_detail {

enum class Kind : uint8_t { Bind, Constant, Animated };

// ---------------------------------------------------------------------------------------------
// Step 2 (clip_compress_levers.cpp)

/// Per joint: which of its channels are fitted to compensate their parent's decoded error.
constexpr uint8_t kCompensatesRotation = 1, kCompensatesTranslation = 2;

struct Lever {
  double translation = 0.0;  // model displacement per unit of local translation error
  double rotation = 0.0;     // ... per unit of 2 sin(angle / 2), or of relative scale error
  double compensated = 0.0;  // rotation, when the joints in `compensates` absorb it (step 4)
};

/// Levers from the reference poses, maximised over frames (`compensated`: under the assumption
/// that the joints in `compensates` absorb a rotation error). O(frames * joints * depth).
std::vector<Lever> compute_levers(const SourceSkeleton& skeleton, const ClipSamples& ref, double probe,
                                  const std::vector<uint8_t>& compensates);

// ---------------------------------------------------------------------------------------------
// Steps 4-5 for one channel (clip_compress_channel.cpp)

struct Metric {
  uint32_t channel = kTranslation;
  double lever = 1.0;
};

/// One key as stored: three quantized components, or three raw float bit patterns (widths of 32).
using Code = std::array<uint32_t, 3>;

struct ChannelPlan {
  Kind kind = Kind::Bind;
  glm::vec4 constant{0.0f};
  uint32_t bits = 0;             // animated: 1..kMaxQuantBits or 32, the widest component's width
  KeyWidths widths;              // animated: each stored component's (key_widths(bits, range_extent))
  uint32_t dropped = 0;          // animated rotation: the component not stored (0..3)
  std::vector<uint16_t> frames;  // animated: kept key frames
  std::vector<Code> codes;       // animated: every frame's key as it would be stored
  float range_min[3] = {0, 0, 0}, range_extent[3] = {0, 0, 0};
};

bool all_equal(const glm::vec4* v, uint32_t n, const glm::vec4& value);
/// The stored widths for a channel quantized at `bits` (1..kMaxQuantBits) whose stored components
/// span `extent`: the widest component takes `bits`, each other one the fewest bits (at least 1)
/// whose step, extent / (2^w - 1), is no coarser than the widest one's; raw floats (32) stay 32
/// for all three. A channel's budget is then still checked on its keys as stored (step 5).
KeyWidths key_widths(uint32_t bits, const float extent[3]);
/// A channel cooked losslessly: bind, constant, or raw floats at every frame.
ChannelPlan plan_lossless(uint32_t channel, const glm::vec4* ref, uint32_t n, const glm::vec4& bind);
/// Step 4: bind or constant when the source (`ref`) allows it within `tolerance`; otherwise a plan
/// of kind Animated, still to be encoded.
ChannelPlan classify_channel(const Metric& m, const glm::vec4* ref, uint32_t n, const glm::vec4& bind,
                             double tolerance);
/// Step 5: keys and bits of an animated channel fitted to `target` (per frame) within tolerance.
ChannelPlan encode_animated(const Metric& m, const glm::vec4* target, uint32_t n, double tolerance);
/// One channel as key removal sees it: its metric, its target at every position between frames
/// (target_positions), its candidate key value at every frame, and its budget.
struct KeyFit {
  Metric metric;
  const glm::vec4* positions = nullptr;
  const glm::vec4* decoded = nullptr;
  double tolerance = 0.0;
};
/// Greedy key removal: the key frames (first 0, last n - 1) from which linear interpolation keeps
/// every channel of `fits` within its budget at every position. One list for all of them: the
/// list a group of channels shares (step 7) is made by the same function as each channel's own.
std::vector<uint16_t> reduce_keys(std::span<const KeyFit> fits, uint32_t n);
/// A channel's target at every position of kErrorSubdivisions per frame, as a runtime plays it.
std::vector<glm::vec4> target_positions(uint32_t channel, const glm::vec4* target, uint32_t n);
/// An animated plan's key at every frame (plan.codes), decoded.
std::vector<glm::vec4> decode_codes(const ChannelPlan& plan, uint32_t channel, uint32_t n);
/// An animated channel fitted to `target` with the bit count and key frames given (a list it
/// shares), quantized at every frame as encode_animated does; the caller verifies the bound.
ChannelPlan refit_animated(const Metric& m, const glm::vec4* target, uint32_t n, double tolerance, uint32_t bits,
                           std::vector<uint16_t> frames);
/// Every frame of a planned channel, decoded exactly as decode_clip decodes the packed bytes.
void decode_plan(const ChannelPlan& plan, uint32_t channel, uint32_t n, const glm::vec4& bind, glm::vec4* out);

// ---------------------------------------------------------------------------------------------
// Step 7 (clip_compress_share.cpp)

/// What key-list sharing needs of one animated channel: its metric and budget as last encoded
/// and the target it was fitted to (every frame). `share` false: the channel keeps its own list.
struct ShareInput {
  bool share = false;
  Metric metric;
  double tolerance = 0.0;
  const std::vector<glm::vec4>* target = nullptr;
};

/// Step 7: groups animated channels (plans[i], i = joint * 3 + channel) whose key lists can become
/// one shared list, each channel within its own budget at every position, merging the pair of
/// groups that saves the most bits first, while a merge saves bits. Rewrites the members' frames
/// to their group's list and returns, per plan, whether it now shares its list with another.
/// Deterministic. O(groups^2) key removals over the groups' channels; more than 512 groups: none.
std::vector<bool> share_key_lists(std::vector<ChannelPlan>& plans, std::span<const ShareInput> inputs, uint32_t frames);

// ---------------------------------------------------------------------------------------------
// Packing (clip_compress_pack.cpp)

/// The plans (plans[joint * 3 + channel]) as the bytes a file holds, into out's constants,
/// animated channels, key frames and key values (cooked_bytes set): identical key-frame lists
/// share one run, channels keyed at every frame store none, and each of those is segmented where
/// that takes fewer bits (ossa/format/clip_codec.h). An error past 4 Gbit of keys. O(keys).
Status pack(const std::vector<ChannelPlan>& plans, uint32_t joints, uint32_t frames, CompressedClip& out);

}  // namespace ossa::cook::compress_detail
