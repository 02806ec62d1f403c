// clip_compress.h — SourceClip -> compressed channels with a stated, measured error bound.
//
// Each channel is resampled on the clip's frame grid (clip_grid.h), classified as bind (equal to
// the skeleton's bind value within tolerance: stored as nothing), constant (one value) or animated;
// animated channels lose the keys that linear interpolation can rebuild, then get the fewest bits
// per component (range-reduced, ossa/format/clip_codec.h) that keep the model-space error of every joint
// under the tolerance. The error is measured, as the animation-compression literature does, as the
// displacement of probe points at a fixed distance from each joint along its three axes, in model
// space, accumulated down the hierarchy, over every joint at every frame; the compressor verifies
// the final result against the source and tightens until the bound holds.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "cooker/model/clip_grid.h"
#include "cooker/model/cook_options.h"
#include "cooker/clip/morph_weights.h"
#include "cooker/model/source_scene.h"
#include <ossa/format/clip_codec.h>
#include <ossa/format/result.h>

namespace ossa::cook {

struct CompressedConstant {
  uint16_t joint = 0;
  uint8_t channel = 0;            // fb::Channel
  uint8_t dropped = 0;            // rotations: the component not stored (fb::ConstantChannel)
  float value[4] = {0, 0, 0, 0};  // as a reader decodes it (a rotation rebuilt from the three stored)
};

struct CompressedAnimated {
  uint16_t joint = 0;
  uint8_t channel = 0;
  KeyWidths bits;                   // per stored component: 1..kMaxQuantBits (19) each, or all 32
  uint8_t dropped = 3;              // rotations: the component not stored (ossa/format/clip_codec.h)
  uint8_t segment_offset_bits = 0;  // 0: plain keys; 1..32: segmented (ossa/format/clip_codec.h)
  uint32_t first_key = 0;
  uint32_t key_count = 0;
  uint32_t bit_offset = 0;
  float range_min[3] = {0, 0, 0};
  float range_extent[3] = {0, 0, 0};
};

/// A clip as the writer serializes it (format/ossa.fbs, Clip).
struct CompressedClip {
  std::string name;
  FrameGrid grid;
  std::vector<CompressedConstant> constants;  // sorted by (joint, channel)
  std::vector<CompressedAnimated> animated;   // sorted by (joint, channel)
  std::vector<uint16_t> key_frames;           // none for channels keyed at every frame
  std::vector<uint8_t> key_values;            // padded (ossa/format/clip_codec.h)
  // What was measured, in source units.
  float tolerance = 0.0f, probe_distance = 0.0f, max_error = 0.0f, mean_error = 0.0f;
  uint16_t worst_joint = 0;
  uint32_t raw_bytes = 0;     // 10 floats * joints * frames
  uint32_t cooked_bytes = 0;  // the clip's vectors as stored: constants, animated,
                              // key_frames, key_values (padding included); tables'
                              // overhead excluded
  bool has_root_motion = false;
  SourceRootMotion root_motion;
  std::vector<SourceEvent> events;                  // copied from the source clip
  std::vector<CompressedMorphTrack> morph_weights;  // sorted by name (format v5)
};

/// Compresses one clip of `skeleton`. metres_per_unit converts the tolerances to source units.
/// Errors name the clip (e.g. more frames than kMaxFrames). Deterministic.
/// Cost: O(frames * joints * iterations) for the error verification.
Result<CompressedClip> compress_clip(const SourceClip& clip, const SourceSkeleton& skeleton, float metres_per_unit,
                                     const ClipCompressionOptions& options);

}  // namespace ossa::cook
