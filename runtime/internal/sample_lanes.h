// sample_lanes.h — pass 2 of ossa::sample (anim/sample.cpp): the per-joint interpolation between
// a sampling cache's key pairs, kept in its own file (anim/sample_interpolate.cpp) because it is
// 8-lane vector code over joints, where pass 1 (cursors, seeks, key decodes: anim/sample_keys.cpp)
// works per run and channel. Both are compiled twice (internal/vector_clones.h). Internal to runtime/.
#pragma once

#include <cmath>
#include <cstdint>

namespace ossa::detail {

/// Per 8-joint block flags (a cache's block_kinds): an animated channel of a kind, or no kept joint.
constexpr uint8_t kAnimatedT = 1, kAnimatedR = 2, kAnimatedS = 4, kSkipped = 8;

/// What pass 2 reads and writes, all SoA with `stride` lanes per pose component (pose.h order).
struct SampleLanes {
  const float* k0;          // the earlier key of each joint's pair
  const float* fixed;       // where blocks without an animated channel of a kind are copied from
  const float* k1;          // the later key
  const float* start;       // per channel kind: the frame of k0
  const float* inv_length;  // per channel kind: 1 / frames from k0 to k1 (0: fixed)
  const uint8_t* block_kinds;
  float* out;
  uint32_t stride;
};

/// Writes the pose at frame position `frame`: T and S lerped, R nlerped on the short arc, every
/// block a filter keeps. O(stride), no allocation; the AVX2 or baseline copy, picked per call.
void interpolate_nlerp(const SampleLanes& l, float frame);

/// As interpolate_nlerp, with rotations at constant angular velocity (slerp) where keys differ.
void interpolate_slerp(const SampleLanes& l, float frame);

/// Scales a quaternion to unit length (it must not be zero).
inline void normalize4(float* q) {
  const float n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  for (int c = 0; c < 4; ++c) q[c] /= n;
}

}  // namespace ossa::detail
