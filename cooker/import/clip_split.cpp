// clip_split.cpp — see clip_split.h.
#include "cooker/import/clip_split.h"

#include <algorithm>
#include <cmath>
#include <cstdio>

#include <glm/gtc/quaternion.hpp>

#include "cooker/model/clip_grid.h"

namespace ossa::cook {
namespace {

float mix_value(float a, float b, float t) { return a + (b - a) * t; }
glm::vec3 mix_value(const glm::vec3& a, const glm::vec3& b, float t) { return a + (b - a) * t; }
glm::quat mix_value(const glm::quat& a, const glm::quat& b, float t) {
  const glm::quat bb = glm::dot(a, b) < 0.0f ? -b : b;  // the short way, as the compressor blends
  return glm::normalize(
      glm::quat(a.w + (bb.w - a.w) * t, a.x + (bb.x - a.x) * t, a.y + (bb.y - a.y) * t, a.z + (bb.z - a.z) * t));
}

/// The channel's value at `time`: its keys interpolated, held before the first and after the last.
template <class T>
T value_at(const std::vector<float>& times, const std::vector<T>& values, float time) {
  if (time <= times.front()) return values.front();
  if (time >= times.back()) return values.back();
  const size_t hi = static_cast<size_t>(std::upper_bound(times.begin(), times.end(), time) - times.begin());
  const size_t lo = hi - 1;
  const float span = times[hi] - times[lo];
  return mix_value(values[lo], values[hi], span > 0.0f ? (time - times[lo]) / span : 0.0f);
}

/// Keys of one channel within [t0, t1], shifted to start at 0, with exact values at both ends.
template <class T>
void cut_channel(const std::vector<float>& times, const std::vector<T>& values, float t0, float t1,
                 std::vector<float>* out_times, std::vector<T>* out_values) {
  if (times.empty()) return;
  out_times->push_back(0.0f);
  out_values->push_back(value_at(times, values, t0));
  for (size_t k = 0; k < times.size(); ++k) {
    if (times[k] <= t0 || times[k] >= t1) continue;
    out_times->push_back(times[k] - t0);
    out_values->push_back(values[k]);
  }
  if (t1 > t0) {
    out_times->push_back(t1 - t0);
    out_values->push_back(value_at(times, values, t1));
  }
}

}  // namespace

std::string split_long_clip(SourceClip clip, std::vector<SourceClip>* out) {
  const FrameGrid grid = frame_grid(clip);
  if (grid.frame_count <= kMaxFrames) {
    out->push_back(std::move(clip));
    return {};
  }
  const uint32_t step = kMaxFrames - 1;  // parts share their boundary frame
  const uint32_t parts = (grid.frame_count - 1 + step - 1) / step;
  std::string described;
  for (uint32_t p = 0; p < parts; ++p) {
    const uint32_t first = p * step, last = std::min(first + step, grid.frame_count - 1);
    const float t0 = grid.time(first), t1 = grid.time(last);
    SourceClip part;
    part.name = clip.name + ".part" + std::to_string(p + 1);
    part.source_name = clip.source_name.empty() ? clip.name : clip.source_name;
    part.sample_rate = grid.sample_rate;
    part.duration = t1 - t0;
    for (const SourceTrack& track : clip.tracks) {
      SourceTrack cut;
      cut.joint = track.joint;
      cut_channel(track.translation_times, track.translations, t0, t1, &cut.translation_times, &cut.translations);
      cut_channel(track.rotation_times, track.rotations, t0, t1, &cut.rotation_times, &cut.rotations);
      cut_channel(track.scale_times, track.scales, t0, t1, &cut.scale_times, &cut.scales);
      part.tracks.push_back(std::move(cut));
    }
    for (const SourceMorphTrack& track : clip.morph_weights) {
      SourceMorphTrack cut;
      cut.name = track.name;
      cut_channel(track.times, track.weights, t0, t1, &cut.times, &cut.weights);
      part.morph_weights.push_back(std::move(cut));
    }
    char range[96];
    std::snprintf(range, sizeof range, " (%.3f-%.3f s)", static_cast<double>(t0), static_cast<double>(t1));
    described += (p == 0 ? "'" : ", '") + part.name + "'" + range;
    out->push_back(std::move(part));
  }
  char head[160];
  std::snprintf(head, sizeof head,
                "%u frames at %g frames/s, more than the %u one clip holds: cooked as %u consecutive clips ",
                grid.frame_count, static_cast<double>(grid.sample_rate), kMaxFrames, parts);
  return "clip '" + clip.name + "' has " + head + described;
}

}  // namespace ossa::cook
