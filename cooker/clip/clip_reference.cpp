// clip_reference.cpp — a source clip sampled on its frame grid (clip_reference.h).
#include "cooker/clip/clip_reference.h"

#include "cooker/import/tiny_values.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include <glm/gtc/quaternion.hpp>

namespace ossa::cook {
namespace {

// A grid time this close (in frames) to a source key takes the key's value exactly.
constexpr double kSnapFrames = 1e-3;

glm::vec4 to_vec4(const glm::vec3& v) { return glm::vec4(v, 0.0f); }
glm::vec4 to_vec4(const glm::quat& q) { return glm::vec4(q.x, q.y, q.z, q.w); }

glm::vec4 interpolate_source(const glm::vec3& a, const glm::vec3& b, double f) {
  return to_vec4(glm::vec3(glm::mix(glm::dvec3(a), glm::dvec3(b), f)));
}
glm::vec4 interpolate_source(const glm::quat& a, const glm::quat& b, double f) {
  glm::dquat qa(a), qb(b);
  if (glm::dot(qa, qb) < 0.0) qb = -qb;
  return to_vec4(glm::quat(glm::normalize(glm::slerp(qa, qb, f))));
}

/// Samples one source channel at every grid frame; false when it has no keys.
template <class V>
bool sample_channel(const std::vector<float>& times, const std::vector<V>& values, const FrameGrid& grid,
                    glm::vec4* out) {
  const size_t n = std::min(times.size(), values.size());
  if (n == 0) return false;
  const double rate = grid.sample_rate;
  size_t i = 0;  // first key with time > t (times increase, frames increase)
  for (uint32_t f = 0; f < grid.frame_count; ++f) {
    const double t = static_cast<double>(f) / rate;
    while (i < n && static_cast<double>(times[i]) <= t) ++i;
    // The nearest key, when the grid time is on it.
    const size_t near =
        (i < n && (i == 0 || static_cast<double>(times[i]) - t < t - static_cast<double>(times[i - 1]))) ? i : i - 1;
    if (std::abs(static_cast<double>(times[near]) - t) * rate <= kSnapFrames) {
      out[f] = to_vec4(values[near]);
    } else if (i == 0) {
      out[f] = to_vec4(values[0]);
    } else if (i == n) {
      out[f] = to_vec4(values[n - 1]);
    } else {
      const double t0 = times[i - 1], t1 = times[i];
      out[f] = interpolate_source(values[i - 1], values[i], (t - t0) / (t1 - t0));
    }
  }
  return true;
}

}  // namespace

ClipSamples reference_samples(const SourceClip& clip, const SourceSkeleton& skeleton, const FrameGrid& grid) {
  ClipSamples ref;
  const auto joints = static_cast<uint32_t>(skeleton.joints.size());
  ref.resize(joints, grid.frame_count);
  std::vector<bool> has(static_cast<size_t>(joints) * kChannelsPerJoint, false);
  for (const SourceTrack& t : clip.tracks) {
    has[t.joint * 3 + kTranslation] =
        sample_channel(t.translation_times, t.translations, grid, ref.channel(t.joint, kTranslation));
    has[t.joint * 3 + kRotation] = sample_channel(t.rotation_times, t.rotations, grid, ref.channel(t.joint, kRotation));
    has[t.joint * 3 + kScale] = sample_channel(t.scale_times, t.scales, grid, ref.channel(t.joint, kScale));
  }
  for (uint32_t j = 0; j < joints; ++j) {
    for (uint32_t ch = 0; ch < kChannelsPerJoint; ++ch) {
      if (has[j * 3 + ch]) continue;
      const glm::vec4 bind = bind_value(skeleton.joints[j], ch);
      std::fill_n(ref.channel(j, ch), grid.frame_count, bind);
    }
  }
  flush_tiny_values(ref.values);  // interpolated across zero: 1e-21 where 0 is meant (tiny_values.h)
  return ref;
}

}  // namespace ossa::cook
