// pose_ops.h — what an animation graph does to poses: blend, layer, add, and go to model space.
//
// All functions take spans in and a span out (which may alias an input where noted), run over
// SoA lanes (pose.h) and never allocate. Rotations blend by normalized lerp on the shortest arc
// (the sign of each weighted quaternion follows the first contributing pose's hemisphere),
// translations and scales linearly. Costs are per joint; the loops are 8-wide vectorizable.
#pragma once
#include <cstdint>
#include <span>

#include <glm/glm.hpp>

#include <ossa/loader/asset.h>
#include <ossa/anim/pose.h>

namespace ossa {

/// out = a * (1 - alpha) + b * alpha. alpha outside [0, 1] is clamped. out may alias a or b.
void blend(ConstPoseSpan a, ConstPoseSpan b, float alpha, PoseSpan out);

/// Weighted blend of N poses; weights are normalized (their sum must be > 0; otherwise out = the
/// first pose). Poses with weight 0 are skipped and do not affect the result. out must not alias
/// an input. O(N * joints).
void blend_n(std::span<const ConstPoseSpan> poses, std::span<const float> weights, PoseSpan out);

/// Per-joint layered blend: out_j = blend(base_j, layer_j, weight * joint_weights[j]).
/// joint_weights has one entry per joint (see build_joint_mask). out may alias base.
void blend_layered(ConstPoseSpan base, ConstPoseSpan layer, std::span<const float> joint_weights, float weight,
                   PoseSpan out);

/// blend_layered on the lanes [first, last) only (multiples of kPoseLanes, last <= the stride):
/// those lanes get exactly the bits blend_layered gives them, the others are not touched (a layer
/// under a slot that covers the rest of the pose blends only what the slot shows).
void blend_layered_lanes(ConstPoseSpan base, ConstPoseSpan layer, std::span<const float> joint_weights, float weight,
                         PoseSpan out, uint32_t first, uint32_t last);

/// A joint + depth mask: weight 1 on `joint` and its descendants up to `depth` levels below it
/// (depth < 0: all), 0 elsewhere; entries are max-combined into `out` so several calls build one
/// mask. Start from a zeroed span (entries must be >= 0). O(joints).
void build_joint_mask(std::span<const int16_t> parents, int joint, int depth, std::span<float> out);

/// additive = reference^-1 * pose, per joint (translation difference, rotation conj(ref) * rot,
/// scale ratio): turns a clip's pose into a delta against a reference pose. O(joints).
void make_additive(ConstPoseSpan pose, ConstPoseSpan reference, PoseSpan out_additive);

/// out = base + weight * additive (rotation: base * nlerp(identity, delta, weight); translation:
/// base + weight * delta; scale: base * lerp(1, delta, weight)). out may alias base.
void add(ConstPoseSpan base, ConstPoseSpan additive, float weight, PoseSpan out);

/// Local -> model matrices, parents first (parents[i] < i, -1 for roots). out[i] = out[parent] *
/// TRS(local_i); a parent index outside [0, i) is treated as a root. Writes min(joint count,
/// parents.size(), out_model.size()) matrices. O(joints), one pass.
void local_to_model(std::span<const int16_t> parents, ConstPoseSpan local, std::span<glm::mat4> out_model);

}  // namespace ossa
