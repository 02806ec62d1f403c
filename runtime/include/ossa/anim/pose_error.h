// pose_error.h — how far one pose moves a skeleton from another, measured the way the cooker's
// clip compression bounds its error, so tools that judge cooked output (ossa-diff, tests) report
// the same figure the cooker promised, without linking the cooker.
//
// The measure (ACL's "virtual vertices", ozz's error at a distance): around every joint sit six
// probe points at ±probe along each of the joint's three axes. Both poses carry them into model
// space through the joint's whole parent chain, so an error high in the hierarchy shows up at
// every joint below it as a skinned vertex would see it, and the joint's error is the largest
// displacement among its six points; a pose's error is the largest over its joints. Six points,
// not three: with a translation error d and a rotation error r a point moves by |d + r·p|, which
// is largest on whichever side r·p points along d. The points sit `probe` from the joint in model
// space, placed by the reference pose: along axis k the local point is ±probe / |reference axis k|,
// so a rig whose armature carries a ×100 scale (Blender exports) is measured 10 cm from its joints
// like any other, not 10 m; the test pose carries the same local points, so a scale error still
// moves them.
// Model space is built in double from the float poses, so the measurement reflects the data and
// not rounding in the measurement; cooker/clip/clip_error.cpp uses these same definitions. Cost: per
// joint one quaternion-to-matrix conversion, one 3x3 product and six 3-vector lengths, all in
// double; pose_error on a 67-joint rig (both poses to model space, then compared) measured about
// 11 microseconds per pose pair on this repository's 2-core VM. That is a tool's and a test's
// budget, not a per-frame one, so the functions write into caller-owned spans and allocate
// nothing, but make no attempt at SIMD.
#pragma once
#include <cstdint>
#include <span>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include <ossa/anim/pose.h>

namespace ossa {

/// Where a clip's error is measured: at every frame and at the points 1/4, 2/4 and 3/4 of the way to
/// the next frame, because a runtime plays between frames too (the cooker bounds its error there,
/// ossa-diff and ossa-bench-acl sample there, so all three report one figure).
inline constexpr uint32_t kClipErrorSubdivisions = 4;

/// A joint's model-space transform in double: x -> linear * x + origin.
struct ModelAffine {
  glm::dmat3 linear{1.0};
  glm::dvec3 origin{0.0};
};

/// Local TRS -> affine: translate * rotate * scale. The rotation is normalized first (decoded and
/// blended quaternions are unit only up to float rounding); a zero quaternion counts as identity.
ModelAffine affine_from_trs(const glm::vec3& translation, const glm::quat& rotation, const glm::vec3& scale);

/// Model space of every joint of a local SoA pose: out[i] = out[parent] * TRS(local_i), parents
/// first (parents[i] < i; an index outside [0, i) counts as a root). Writes min(local.joint_count,
/// parents.size(), out.size()) transforms. O(joints).
void local_to_model_affine(std::span<const int16_t> parents, ConstPoseSpan local, std::span<ModelAffine> out);

/// The largest displacement of the six probe points between two model-space transforms of one
/// joint: the local points ±(probe / |reference.linear[k]|) e_k, that is `probe` from the joint
/// along each of its axes in the reference's model space (a zero-length reference axis puts its two
/// points on the joint). In the transforms' units. O(1).
double probe_error(const ModelAffine& reference, const ModelAffine& test, double probe);

struct PoseError {
  double max = 0.0;  // the largest probe displacement over the joints compared, in pose units
  int joint = -1;    // the first joint where it occurs; -1 when no joint was compared
};

/// Largest probe error between two model-space poses of one skeleton (joint i against joint i,
/// over min(reference.size(), test.size()) joints). O(joints).
PoseError model_pose_error(std::span<const ModelAffine> reference, std::span<const ModelAffine> test, double probe);

/// Largest probe error between two local poses of one skeleton: both go to model space through
/// `parents` (into `scratch`, which holds at least 2 * joint count transforms), then as
/// model_pose_error. The poses have the same joint count. O(joints), allocation-free.
PoseError pose_error(std::span<const int16_t> parents, ConstPoseSpan reference, ConstPoseSpan test, double probe,
                     std::span<ModelAffine> scratch);

}  // namespace ossa
