// pose.h — a skeleton's local-space pose, stored structure-of-arrays.
//
// Sampling, blending and additive layering do the same arithmetic on every joint, so a pose keeps
// each scalar component in its own array (tx[], ty[], ..., sz[]), padded to a multiple of
// kPoseLanes joints and 32-byte aligned: the per-joint loops then compile to 8-wide vector code
// with no shuffles, which is how ossa beats an array-of-transforms layout (and matches ozz's SoA
// design without its hand-written SIMD types). Padding lanes hold the identity transform so
// whole-lane loops stay finite.
//
// Functions take spans (PoseSpan / ConstPoseSpan) and never allocate; a Pose owns the storage.
#pragma once
#include <cstddef>
#include <cstdint>
#include <span>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include <ossa/loader/asset.h>

namespace ossa {

inline constexpr uint32_t kPoseLanes = 8;

/// Component arrays, in this order, each `stride` floats apart in one block.
enum PoseComponent : uint32_t { kTx, kTy, kTz, kRx, kRy, kRz, kRw, kSx, kSy, kSz, kPoseComponents };

/// Rounds a joint count up to whole lanes.
constexpr uint32_t pose_stride(uint32_t joint_count) {
  return (joint_count + kPoseLanes - 1) / kPoseLanes * kPoseLanes;
}

/// Mutable view of a pose: component k of joint j is base[k * stride + j].
struct PoseSpan {
  float* base = nullptr;
  uint32_t joint_count = 0;
  uint32_t stride = 0;  // pose_stride(joint_count)
  float* operator[](PoseComponent k) const { return base + size_t(k) * stride; }
};

/// Read-only view of a pose.
struct ConstPoseSpan {
  const float* base = nullptr;
  uint32_t joint_count = 0;
  uint32_t stride = 0;
  ConstPoseSpan() = default;
  ConstPoseSpan(const float* b, uint32_t n, uint32_t s) : base(b), joint_count(n), stride(s) {}
  ConstPoseSpan(PoseSpan p) : base(p.base), joint_count(p.joint_count), stride(p.stride) {}
  const float* operator[](PoseComponent k) const { return base + size_t(k) * stride; }
};

/// One joint's transform, for code that works joint by joint (tests, tools, IK).
struct Transform {
  glm::vec3 translation{0.0f};
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};
  glm::vec3 scale{1.0f};
};

/// Owns a pose's storage (10 * stride floats, 32-byte aligned), initialized to identity.
/// Allocation happens here, once, never in the per-frame functions.
class Pose {
 public:
  Pose() = default;
  explicit Pose(uint32_t joint_count);
  Pose(Pose&& other) noexcept;
  Pose& operator=(Pose&& other) noexcept;
  Pose(const Pose&) = delete;
  Pose& operator=(const Pose&) = delete;
  ~Pose();

  uint32_t joint_count() const { return joint_count_; }
  PoseSpan span() { return {data_, joint_count_, pose_stride(joint_count_)}; }
  ConstPoseSpan span() const { return {data_, joint_count_, pose_stride(joint_count_)}; }
  operator PoseSpan() { return span(); }
  operator ConstPoseSpan() const { return span(); }

 private:
  float* data_ = nullptr;
  uint32_t joint_count_ = 0;
};

/// Every joint (and padding lane) to the identity transform. O(stride).
void set_identity(PoseSpan out);
/// The skeleton's bind pose. out.joint_count == skeleton joint count. O(joints).
void set_bind_pose(const SkeletonView& skeleton, PoseSpan out);
/// Copies a pose. O(stride).
void copy_pose(ConstPoseSpan in, PoseSpan out);

Transform get_transform(ConstPoseSpan pose, uint32_t joint);
void set_transform(PoseSpan pose, uint32_t joint, const Transform& t);

}  // namespace ossa
