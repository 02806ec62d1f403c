// retarget_pose.cpp — a rig's retarget pose and body frame (retarget.h, make_retarget_pose).
//
// The body frame comes from the bind pose: up from the hips towards the head, left from the right
// leg and arm towards the left ones, each snapped onto the model axis it is within 20 degrees of
// (rigs are authored upright along an axis; snapping keeps a forward-leaning posture or a wide
// stance from tilting the frame, which would tilt every retargeted pose by the difference).
//
// Straightening turns one bone at a time, parents first, by the shortest rotation taking its
// direction (towards the next profile joint) onto the profile's: +x / -x for the left / right upper
// arm, forearm and hand, -y for thighs and shins; a foot turns about up only, to face forward, so
// its sole keeps the pitch it has in its own rest. An IK rig's foot (hanging from the root, not the
// shin) is carried along with the shin at its bind offset. Rotations are taken from the joints'
// local rotations alone, so a rig with non-uniform scales on its limb joints is straightened
// approximately (no sample has one).
#include <ossa/retarget/retarget.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "internal/rotation.h"

namespace ossa {
namespace {

using B = HumanoidBone;

glm::mat4 trs(const Transform& t) {
  glm::mat4 m = glm::mat4_cast(t.rotation);
  m[0] *= t.scale.x;
  m[1] *= t.scale.y;
  m[2] *= t.scale.z;
  m[3] = glm::vec4(t.translation, 1.0f);
  return m;
}

struct Fk {
  std::vector<glm::mat4> model;
  std::vector<glm::quat> rotation;
  glm::vec3 position(int j) const { return glm::vec3(model[static_cast<size_t>(j)][3]); }
};

void forward(std::span<const int16_t> parents, const std::vector<Transform>& local, Fk& fk) {
  fk.model.resize(local.size());
  fk.rotation.resize(local.size());
  for (size_t j = 0; j < local.size(); ++j) {
    const int p = parents[j];
    const glm::mat4 m = trs(local[j]);
    fk.model[j] = p >= 0 ? fk.model[static_cast<size_t>(p)] * m : m;
    fk.rotation[j] =
        p >= 0 ? glm::normalize(fk.rotation[static_cast<size_t>(p)] * local[j].rotation) : local[j].rotation;
  }
}

bool below(std::span<const int16_t> parents, int ancestor, int joint) {
  if (ancestor < 0 || joint < 0) return false;
  for (int j = parents[static_cast<size_t>(joint)]; j >= 0; j = parents[static_cast<size_t>(j)])
    if (j == ancestor) return true;
  return false;
}

/// v snapped onto the model axis within 20 degrees of it, else v (unit in, unit out).
glm::vec3 snap(const glm::vec3& v) {
  int axis = 0;
  for (int a = 1; a < 3; ++a)
    if (std::fabs(v[a]) > std::fabs(v[axis])) axis = a;
  if (std::fabs(v[axis]) < std::cos(glm::radians(20.0f))) return v;
  glm::vec3 s(0.0f);
  s[axis] = v[axis] > 0.0f ? 1.0f : -1.0f;
  return s;
}

/// The point a bone points at in its rest: the next profile joint, else its farthest child.
bool bone_end(const RetargetRig& rig, const Fk& fk, B bone, glm::vec3* end) {
  const HumanoidMap& h = rig.humanoid;
  auto at = [&](B b) { return fk.position(h[b]); };
  const bool left =
      static_cast<int>(bone) <= static_cast<int>(B::LeftHand) || (bone >= B::LeftUpperLeg && bone <= B::LeftToes);
  switch (bone) {
    case B::LeftUpperArm:
    case B::RightUpperArm: *end = at(left ? B::LeftLowerArm : B::RightLowerArm); return true;
    case B::LeftLowerArm:
    case B::RightLowerArm: *end = at(left ? B::LeftHand : B::RightHand); return true;
    case B::LeftUpperLeg:
    case B::RightUpperLeg: *end = at(left ? B::LeftLowerLeg : B::RightLowerLeg); return true;
    case B::LeftLowerLeg:
    case B::RightLowerLeg: *end = at(left ? B::LeftFoot : B::RightFoot); return true;
    case B::LeftFoot:
    case B::RightFoot:
      if (h.has(left ? B::LeftToes : B::RightToes)) {
        *end = at(left ? B::LeftToes : B::RightToes);
        return true;
      }
      break;
    case B::LeftHand:
    case B::RightHand: {
      const B middle = left ? B::LeftMiddleProximal : B::RightMiddleProximal;
      if (h.has(middle)) {
        *end = at(middle);
        return true;
      }
      glm::vec3 sum(0.0f);
      int n = 0;
      for (B f : {B::LeftIndexProximal, B::LeftRingProximal, B::LeftLittleProximal}) {
        const B b = static_cast<B>(static_cast<size_t>(f) + (left ? 0 : 15));
        if (h.has(b)) sum += at(b), ++n;
      }
      if (n > 0) {
        *end = sum / static_cast<float>(n);
        return true;
      }
      break;
    }
    default: return false;
  }
  // No profile joint beyond it: its farthest child.
  const int j = h[bone];
  float best = 1e-6f;
  bool found = false;
  for (size_t c = static_cast<size_t>(j) + 1; c < rig.parents.size(); ++c) {
    if (rig.parents[c] != j) continue;
    const float d = glm::length(fk.position(static_cast<int>(c)) - fk.position(j));
    if (d > best) best = d, *end = fk.position(static_cast<int>(c)), found = true;
  }
  return found;
}

/// Turns joint j in model space by q (about its own origin): its local rotation absorbs it.
void turn(std::span<const int16_t> parents, std::vector<Transform>& local, const Fk& fk, int j, const glm::quat& q) {
  const int p = parents[static_cast<size_t>(j)];
  const glm::quat parent = p >= 0 ? fk.rotation[static_cast<size_t>(p)] : glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
  local[static_cast<size_t>(j)].rotation =
      glm::normalize(glm::inverse(parent) * q * fk.rotation[static_cast<size_t>(j)]);
}

}  // namespace

Result<RetargetPose> make_retarget_pose(const RetargetRig& rig) {
  const std::string who(rig.name);
  const size_t n = rig.parents.size();
  if (rig.bind.size() != n)
    return Error{who + ": bind pose has " + std::to_string(rig.bind.size()) + " joints, not " + std::to_string(n)};
  if (Status st = check_humanoid(rig.humanoid, rig.parents, rig.name); !st) return st.error();
  const HumanoidMap& h = rig.humanoid;
  RetargetPose pose;
  pose.local.assign(rig.bind.begin(), rig.bind.end());
  Fk fk;
  forward(rig.parents, pose.local, fk);

  // Body frame.
  const glm::vec3 hips = fk.position(h[B::Hips]);
  glm::vec3 up = fk.position(h[B::Head]) - hips;
  glm::vec3 left = (fk.position(h[B::LeftUpperLeg]) - fk.position(h[B::RightUpperLeg])) +
                   (fk.position(h[B::LeftUpperArm]) - fk.position(h[B::RightUpperArm]));
  if (!(glm::length(up) > 1e-9f) || !std::isfinite(glm::length(up)))
    return Error{who + ": the head is at the hips in the bind pose: no up direction"};
  up = snap(glm::normalize(up));
  left -= glm::dot(left, up) * up;
  if (!(glm::length(left) > 1e-9f) || !std::isfinite(glm::length(left)))
    return Error{who + ": the left and right limbs coincide in the bind pose: no left direction"};
  left = glm::normalize(left);
  const glm::vec3 snapped = snap(left);
  if (std::fabs(glm::dot(snapped, up)) < 1e-6f) left = snapped;
  const glm::vec3 forward_axis = glm::cross(left, up);
  pose.up = up;
  pose.frame = glm::normalize(glm::quat_cast(glm::transpose(glm::mat3(left, up, forward_axis))));

  // An IK rig's feet hang elsewhere: keep their bind offset from the shin.
  std::array<glm::mat4, 2> foot_offset{};
  for (int s = 0; s < 2; ++s) {
    const int shin = h[s == 0 ? B::LeftLowerLeg : B::RightLowerLeg], foot = h[s == 0 ? B::LeftFoot : B::RightFoot];
    foot_offset[static_cast<size_t>(s)] =
        glm::inverse(fk.model[static_cast<size_t>(shin)]) * fk.model[static_cast<size_t>(foot)];
  }
  auto reanchor_feet = [&] {
    for (int s = 0; s < 2; ++s) {
      const int shin = h[s == 0 ? B::LeftLowerLeg : B::RightLowerLeg], foot = h[s == 0 ? B::LeftFoot : B::RightFoot];
      if (below(rig.parents, shin, foot)) continue;
      const int p = rig.parents[static_cast<size_t>(foot)];
      const glm::mat4 want = fk.model[static_cast<size_t>(shin)] * foot_offset[static_cast<size_t>(s)];
      const glm::mat4 local = p >= 0 ? glm::inverse(fk.model[static_cast<size_t>(p)]) * want : want;
      pose.local[static_cast<size_t>(foot)].translation = glm::vec3(local[3]);
      pose.local[static_cast<size_t>(foot)].rotation = detail::orientation(local);
      forward(rig.parents, pose.local, fk);
    }
  };

  if (rig.rest == RestPose::Straighten) {
    const B order[] = {B::LeftUpperArm, B::LeftLowerArm, B::LeftHand, B::RightUpperArm, B::RightLowerArm, B::RightHand,
                       B::LeftUpperLeg, B::LeftLowerLeg, B::LeftFoot, B::RightUpperLeg, B::RightLowerLeg, B::RightFoot};
    for (B bone : order) {
      glm::vec3 end;
      if (!bone_end(rig, fk, bone, &end)) continue;
      const int j = h[bone];
      glm::vec3 dir = end - fk.position(j);
      const bool foot = bone == B::LeftFoot || bone == B::RightFoot;
      const bool arm = bone <= B::RightHand;
      const bool left_side = bone <= B::LeftHand || (bone >= B::LeftUpperLeg && bone <= B::LeftToes);
      glm::vec3 want = arm ? (left_side ? left : -left) : -up;
      if (foot) {
        dir -= glm::dot(dir, up) * up;  // yaw only
        want = forward_axis;
      }
      if (!(glm::length(dir) > 1e-9f)) continue;
      turn(rig.parents, pose.local, fk, j, detail::from_to(glm::normalize(dir), want));
      forward(rig.parents, pose.local, fk);
      if (bone == B::LeftLowerLeg || bone == B::RightLowerLeg || bone == B::LeftUpperLeg || bone == B::RightUpperLeg)
        reanchor_feet();
    }
  }
  for (const RestRotation& r : rig.rest_rotations) {
    if (r.joint < 0 || static_cast<size_t>(r.joint) >= n)
      return Error{who + ": rest rotation for a joint out of range"};
    pose.local[static_cast<size_t>(r.joint)].rotation = glm::normalize(r.rotation);
  }
  forward(rig.parents, pose.local, fk);

  // Floor: the lowest point of the feet and everything below them.
  float floor = 3.4e38f;
  for (B foot : {B::LeftFoot, B::RightFoot}) {
    const int f = h[foot];
    for (size_t j = 0; j < n; ++j)
      if (static_cast<int>(j) == f || below(rig.parents, f, static_cast<int>(j)))
        floor = std::min(floor, glm::dot(fk.position(static_cast<int>(j)), up));
  }
  pose.pelvis = 0.5f * (fk.position(h[B::LeftUpperLeg]) + fk.position(h[B::RightUpperLeg]));
  const float ankles = 0.5f * (glm::dot(fk.position(h[B::LeftFoot]), up) + glm::dot(fk.position(h[B::RightFoot]), up));
  pose.ankle_height = ankles - floor;
  pose.hips_height = glm::dot(pose.pelvis, up) - ankles;
  if (!(pose.hips_height > 1e-6f * std::max(1.0f, glm::length(pose.pelvis))) || !std::isfinite(pose.hips_height))
    return Error{who + ": the hips are not above the feet in the retarget pose"};
  pose.origin = pose.pelvis - pose.hips_height * up;
  pose.model = std::move(fk.model);
  return pose;
}

}  // namespace ossa
