// clip_grid.h — the uniform frame grid a clip is cooked on.
//
// Compressed clips address keys by frame index (format/ossa.fbs, Clip), so every stage that
// resamples a clip (compression, root-motion extraction, glTF sampler conversion) must agree on
// the grid: this is that one definition.
#pragma once
#include <cmath>
#include <cstdint>

#include "cooker/model/source_scene.h"

namespace ossa::cook {

/// Frames per second used when a source does not say (e.g. a single-key clip).
inline constexpr float kDefaultSampleRate = 30.0f;
/// Frame indices are stored as uint16.
inline constexpr uint32_t kMaxFrames = 65536;

struct FrameGrid {
  float sample_rate = kDefaultSampleRate;
  uint32_t frame_count = 1;  // frames 0 .. frame_count - 1
  float time(uint32_t frame) const { return static_cast<float>(frame) / sample_rate; }
  float duration() const { return static_cast<float>(frame_count - 1) / sample_rate; }
};

/// The clip's source rate (or kDefaultSampleRate when unknown) and enough frames to reach its
/// duration: frame_count = round(duration * rate) + 1. The cooked duration is grid.duration().
inline FrameGrid frame_grid(const SourceClip& clip) {
  FrameGrid g;
  g.sample_rate = clip.sample_rate > 0.0f ? clip.sample_rate : kDefaultSampleRate;
  const double frames = std::round(static_cast<double>(clip.duration) * g.sample_rate);
  g.frame_count = static_cast<uint32_t>(frames < 0.0 ? 0.0 : frames) + 1u;
  return g;
}

}  // namespace ossa::cook
