// guard_reference.h — plain scalar references for ossa-bench-guard's sample, frame and skin rows:
// the work a game would write first, over plain float arrays, in code that calls nothing of the
// runtime per frame.
//
// Why a reference of its own. A guard that times ossa's sampler against ossa's sampler (forward
// playback / a reset cache) moves with it: when Pab's rest pose started carrying 1e-33 values and
// sampling became 2x slower on Intel, both sides of that row slowed alike and it passed. These
// references are written once, here; their data are decoded from the cooked files once, at setup
// (through the runtime: only the timing must not depend on it), and the guard runs them with
// flush-to-zero set, so no value in the data can slow them. A ratio ossa / reference then moves
// only when ossa's own cost per frame moves, whatever the cause: code, cooked data, or a value
// that reaches the runtime's arithmetic.
//
//   PlainClip      a clip as dense per-frame keys (every joint, every frame, T R S as floats);
//   plain_sample   one time -> local transforms: per joint, the two frames around it, lerp T and
//                  S, nlerp R with the shortest-arc sign, 1 / sqrt;
//   plain_blend    weighted sum of N local poses, rotations on the first pose's hemisphere;
//   plain_model    local transforms -> model matrices (quaternion -> 3x3, parent product);
//   plain_palette  model[joint[s]] * bind[s] per slot;
//   PlainMesh / plain_skin   positions and normals as floats, four influences per vertex,
//                  blended matrix times position and normal, normals renormalized.
// O(joints) per sample, blend and model pass; O(vertices) per skin. No allocation per call.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include <ossa/loader/asset.h>

namespace ossa::bench {

struct PlainTransform {
  float t[3], r[4], s[3];  // translation, rotation (x y z w), scale
};

struct PlainClip {
  uint32_t joints = 0, frames = 0;
  float sample_rate = 0.0f, duration = 0.0f;
  std::vector<PlainTransform> keys;  // frames x joints, frame-major
};

/// The clip sampled by the runtime at each of its frames (setup only).
PlainClip plain_clip(const ClipView& clip, const SkeletonView& skeleton);

/// Local transforms at `time` (seconds, looping), into out[0, joints).
void plain_sample(const PlainClip& clip, float time, PlainTransform* out);

/// out = normalized sum of weights[k] * poses[k], rotations flipped onto poses[0]'s hemisphere.
void plain_blend(std::span<const PlainTransform* const> poses, std::span<const float> weights, uint32_t joints,
                 PlainTransform* out);

/// Model matrices from local transforms (parents[i] < i, or < 0 for a root).
void plain_model(std::span<const int16_t> parents, const PlainTransform* local, glm::mat4* out);

/// palette[s] = model[joints[s]] * bind[s].
void plain_palette(std::span<const uint16_t> joints, std::span<const glm::mat4> bind, const glm::mat4* model,
                   glm::mat4* palette);

struct PlainMesh {
  uint32_t vertices = 0;
  std::vector<float> positions, normals;  // 3 per vertex: positions as stored (the palette dequantizes)
  std::vector<uint16_t> slots;            // 4 per vertex
  std::vector<float> weights;             // 4 per vertex
};

/// A skinned mesh's positions, normals and influences as floats (setup only).
PlainMesh plain_mesh(const MeshView& mesh);

/// Linear blend skinning of every vertex: positions and unit normals, 3 floats each.
void plain_skin(const PlainMesh& mesh, const glm::mat4* palette, float* positions, float* normals);

}  // namespace ossa::bench
