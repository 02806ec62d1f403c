// ozz_side.h — the workloads of bench_vs_ozz.cpp as ozz-animation runs them, behind a plain C-style
// interface.
//
// ozz_side.cpp is compiled twice, against two builds of ozz-animation (its default -O3, and -O3
// -mavx2 -mfma), each in a namespace of its own (-Dozz=ozz_avx2 for the second), so both builds
// and ossa run in one process on the same minutes. Nothing here names a standard-library template
// or an ozz type: whatever one copy instantiates with AVX2 code cannot be picked by the linker for
// the other copy or for ossa's side.
#pragma once
#include <cstdint>

namespace ossa::bench {

/// The workloads, in the order bench_vs_ozz prints them.
enum AnchorWorkload : uint32_t {
  kSampleForward,  // walk, forward 60 Hz playback through one sampling context / cache
  kSampleSeek,     // walk, a random time per call (seek_fraction)
  kBlend3,         // three perturbed rest poses, weights 0.5 / 0.3 / 0.2
  kLocalToModel,   // a perturbed rest pose to model space
  kFrame,          // walk, jog, run at the walk's 60 Hz phase + blend (0.2, 0.5, 0.3) + model + palette
  kSkinPositions,  // the arnaud mesh, positions, a palette of rotations nudged from the rest pose
  kSkinNormals,    // the same, positions and normals
  kAnchorWorkloads
};

/// A number in [-1, 1] from (seed, joint, draw), the same on both sides (no library RNG).
inline float nudge_draw(uint32_t seed, uint32_t joint, uint32_t draw) {
  uint32_t h = seed * 0x9E3779B1u ^ (joint + 1) * 0x85EBCA77u ^ (draw + 1) * 0xC2B2AE3Du;
  h ^= h >> 15, h *= 0x2C1B3C6Du, h ^= h >> 12, h *= 0x297A2D39u, h ^= h >> 15;
  return static_cast<float>(h >> 8) * (2.0f / 16777215.0f) - 1.0f;
}

/// The random-seek workload's i-th time, as a fraction of the clip's duration, in [0, 1).
inline float seek_fraction(uint32_t i) {
  const float f = 0.5f * (nudge_draw(42, i, 0) + 1.0f);
  return f < 1.0f ? f : 0.0f;
}

/// The perturbation both sides give joint `joint` of their rest pose for the pose workloads (so
/// blend inputs differ from joint to joint as sampled poses do): rotation by `angle` radians (up
/// to 0.1) about `axis` (not normalized), translation by `move` x 1% of (1 + |t|), scale x (1 +
/// 2% `scale`). Rotation-only when a palette for skinning is made.
struct Nudge {
  float axis[3], angle, move[3], scale;
};
inline Nudge nudge(uint32_t seed, uint32_t joint) {
  Nudge n;
  for (uint32_t k = 0; k < 3; ++k) n.axis[k] = nudge_draw(seed, joint, k) + (k == 2 ? 1e-3f : 0.0f);
  n.angle = 0.1f * nudge_draw(seed, joint, 3);
  for (uint32_t k = 0; k < 3; ++k) n.move[k] = nudge_draw(seed, joint, 4 + k);
  n.scale = nudge_draw(seed, joint, 7);
  return n;
}

/// One workload: `fn(state)` runs it once.
struct AnchorCall {
  void (*fn)(void* state) = nullptr;
  void* state = nullptr;
};

struct AnchorSide {
  uint32_t joints = 0;    // skeleton joints
  uint32_t vertices = 0;  // skinned vertices (all parts)
  uint32_t palette = 0;   // skinning matrices
  AnchorCall run[kAnchorWorkloads];
  char error[512] = {};  // set when the media could not be loaded
};

/// ozz-animation as built with its default flags (-O3); `media` is its media/bin folder.
bool ozz_side_o3(const char* media, AnchorSide* out);
/// ozz-animation built with -O3 -mavx2 -mfma; call only where the CPU has AVX2 and FMA.
bool ozz_side_avx2(const char* media, AnchorSide* out);

}  // namespace ossa::bench
