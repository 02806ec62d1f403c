// pose.cpp — Pose storage and the joint-by-joint accessors (pose.h).
//
// The storage is one block of kPoseComponents * stride floats, 32-byte aligned, so that every
// component array starts on a 32-byte boundary (stride is a multiple of 8 floats) and an 8-lane
// AVX load of any lane block is aligned. Nothing here is per-frame hot: set_identity / copy_pose
// are straight fills and copies the compiler turns into vector stores, set_bind_pose runs at
// instantiation or reset.
#include <ossa/anim/pose.h>

#include <algorithm>
#include <cassert>
#include <cstdlib>
#include <cstring>
#include <new>
#include <utility>

#include "internal/memory.h"

namespace ossa {

namespace {

constexpr size_t kPoseAlignment = 32;

size_t pose_floats(uint32_t joint_count) { return size_t(kPoseComponents) * pose_stride(joint_count); }

// Identity on lanes [first, stride): tx..rz = 0, rw = 1, sx..sz = 1.
void set_identity_lanes(PoseSpan out, uint32_t first) {
  if (first >= out.stride) return;
  const size_t count = out.stride - first;
  for (uint32_t k = kTx; k <= kRz; ++k) std::fill_n(out[PoseComponent(k)] + first, count, 0.0f);
  std::fill_n(out[kRw] + first, count, 1.0f);
  for (uint32_t k = kSx; k <= kSz; ++k) std::fill_n(out[PoseComponent(k)] + first, count, 1.0f);
}

}  // namespace

Pose::Pose(uint32_t joint_count) : joint_count_(joint_count) {
  const size_t bytes = pose_floats(joint_count) * sizeof(float);
  if (bytes == 0) return;
  // Through the installable Allocator (allocator.h); its default is aligned operator new, which,
  // unlike std::aligned_alloc, exists with MinGW and MSVC.
  data_ = static_cast<float*>(detail::allocate(bytes, kPoseAlignment));
  if (data_ == nullptr) throw std::bad_alloc();  // allocation failure is not an animation error
  set_identity(span());
}

Pose::Pose(Pose&& other) noexcept
    : data_(std::exchange(other.data_, nullptr)), joint_count_(std::exchange(other.joint_count_, 0)) {}

Pose& Pose::operator=(Pose&& other) noexcept {
  if (this != &other) {
    detail::deallocate(data_, pose_floats(joint_count_) * sizeof(float), kPoseAlignment);
    data_ = std::exchange(other.data_, nullptr);
    joint_count_ = std::exchange(other.joint_count_, 0);
  }
  return *this;
}

Pose::~Pose() { detail::deallocate(data_, pose_floats(joint_count_) * sizeof(float), kPoseAlignment); }

void set_identity(PoseSpan out) { set_identity_lanes(out, 0); }

void set_bind_pose(const SkeletonView& skeleton, PoseSpan out) {
  assert(skeleton.joint_count() == out.joint_count);
  // A mismatched skeleton fills what both have; the rest (and the padding) stays identity, so a
  // caller's mistake yields a wrong pose, never a read past the skeleton's arrays.
  const std::span<const fb::Vec3> t = skeleton.bind_translations();
  const std::span<const fb::Quat> r = skeleton.bind_rotations();
  const std::span<const fb::Vec3> s = skeleton.bind_scales();
  const uint32_t n = uint32_t(std::min<size_t>({out.joint_count, t.size(), r.size(), s.size()}));
  float* tx = out[kTx];
  float* ty = out[kTy];
  float* tz = out[kTz];
  float* rx = out[kRx];
  float* ry = out[kRy];
  float* rz = out[kRz];
  float* rw = out[kRw];
  float* sx = out[kSx];
  float* sy = out[kSy];
  float* sz = out[kSz];
  for (uint32_t j = 0; j < n; ++j) {
    tx[j] = t[j].x();
    ty[j] = t[j].y();
    tz[j] = t[j].z();
    rx[j] = r[j].x();
    ry[j] = r[j].y();
    rz[j] = r[j].z();
    rw[j] = r[j].w();
    sx[j] = s[j].x();
    sy[j] = s[j].y();
    sz[j] = s[j].z();
  }
  set_identity_lanes(out, n);
}

void copy_pose(ConstPoseSpan in, PoseSpan out) {
  assert(in.joint_count == out.joint_count);
  if (in.base == out.base) return;
  if (in.joint_count == out.joint_count && in.stride == out.stride) {
    std::memcpy(out.base, in.base, pose_floats(out.joint_count) * sizeof(float));
    return;
  }
  // Different joint counts: copy the joints both have, identity elsewhere (never read past `in`).
  const uint32_t n = std::min(in.joint_count, out.joint_count);
  for (uint32_t k = 0; k < kPoseComponents; ++k)
    std::memcpy(out[PoseComponent(k)], in[PoseComponent(k)], n * sizeof(float));
  set_identity_lanes(out, n);
}

Transform get_transform(ConstPoseSpan pose, uint32_t joint) {
  assert(joint < pose.stride);
  Transform t;
  t.translation = {pose[kTx][joint], pose[kTy][joint], pose[kTz][joint]};
  t.rotation = glm::quat(pose[kRw][joint], pose[kRx][joint], pose[kRy][joint], pose[kRz][joint]);
  t.scale = {pose[kSx][joint], pose[kSy][joint], pose[kSz][joint]};
  return t;
}

void set_transform(PoseSpan pose, uint32_t joint, const Transform& t) {
  assert(joint < pose.joint_count);
  pose[kTx][joint] = t.translation.x;
  pose[kTy][joint] = t.translation.y;
  pose[kTz][joint] = t.translation.z;
  pose[kRx][joint] = t.rotation.x;
  pose[kRy][joint] = t.rotation.y;
  pose[kRz][joint] = t.rotation.z;
  pose[kRw][joint] = t.rotation.w;
  pose[kSx][joint] = t.scale.x;
  pose[kSy][joint] = t.scale.y;
  pose[kSz][joint] = t.scale.z;
}

}  // namespace ossa
