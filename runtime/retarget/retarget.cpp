// retarget.cpp — the per-frame job (retarget.h): source local pose -> source model space ->
// per-joint deltas -> target local pose, then the feet held by two-bone IK where planted.
//
// One pass over the map's steps builds the target's local pose and model space together (a step's
// local rotation needs its parent's model rotation). Model rotations are kept as quaternion
// products beside the matrices, so a local rotation is inverse(parent) * model without a matrix
// decomposition; positions (the hips, an IK rig's anchored foot) come from the matrices.
//
// The IK pass solves both legs on that model space (the legs are separate branches), multiplies
// the corrections into the thighs' and shins' local rotations, and runs the pass again reading
// the pose it wrote, giving each corrected foot back the model rotation it had before (so the sole
// keeps its angle) and re-placing anchored feet at their shins.
#include <ossa/retarget/retarget.h>

#include "retarget/retarget_internal.h"

#include <ossa/anim/ik.h>
#include <ossa/anim/pose_ops.h>

#include <algorithm>
#include <cmath>

namespace ossa {
namespace {

using Step = RetargetMap::Step;

glm::mat4 trs(const glm::vec3& t, const glm::quat& r, const glm::vec3& s) {
  glm::mat4 m = glm::mat4_cast(r);
  m[0] *= s.x;
  m[1] *= s.y;
  m[2] *= s.z;
  m[3] = glm::vec4(t, 1.0f);
  return m;
}

/// Shortest-arc slerp (the deltas of neighbouring chain joints are close; nlerp would do too, but
/// slerp keeps a 50 % blend exactly halfway).
glm::quat blend(const glm::quat& a, glm::quat b, float w) {
  if (glm::dot(a, b) < 0.0f) b = -b;
  return glm::normalize(glm::slerp(a, b, w));
}

/// a / b per axis (1 where b is 0).
glm::vec3 ratio(const glm::vec3& a, const glm::vec3& b) {
  return {b.x != 0.0f ? a.x / b.x : 1.0f, b.y != 0.0f ? a.y / b.y : 1.0f, b.z != 0.0f ? a.z / b.z : 1.0f};
}

glm::quat delta(const RetargetMap& map, const RetargetScratch& s, int source_joint) {
  return s.source_rotation[static_cast<size_t>(source_joint)] *
         map.source_rest_inverse[static_cast<size_t>(source_joint)];
}

}  // namespace

namespace detail {

void evaluate(const RetargetMap& map, const RetargetInput& in, RetargetScratch& s, PoseSpan out, bool pinned,
              std::span<const Kept> kept, const glm::vec3& hips_shift) {
  const float scale = map.scale;
  for (const Step& step : map.steps) {
    const auto j = static_cast<uint32_t>(step.joint);
    const int parent = map.target_parents[j];
    const glm::mat4 parent_model = parent >= 0 ? s.target_model[static_cast<size_t>(parent)] : glm::mat4(1.0f);
    const glm::quat parent_rotation =
        parent >= 0 ? s.target_rotation[static_cast<size_t>(parent)] : glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
    const Transform& bind = map.target_bind[j];
    glm::vec3 t = bind.translation, sc = bind.scale;
    glm::quat r = bind.rotation;
    switch (step.kind) {
      case RetargetStep::Keep:
        if (in.target_base.base != nullptr) {
          t = read3(in.target_base, kTx, j);
          r = read_rotation(in.target_base, j);
          sc = read3(in.target_base, kSx, j);
        }
        break;
      case RetargetStep::Copy: {
        const auto a = static_cast<uint32_t>(step.source_a);
        const Transform& sb = map.source_bind[a];
        r = glm::normalize(step.rest * (step.source_rest_local_inverse * read_rotation(in.source, a)));
        t = bind.translation + scale * (read3(in.source, kTx, a) - sb.translation);
        sc = bind.scale * ratio(read3(in.source, kSx, a), sb.scale);
        break;
      }
      default: {
        glm::quat model;
        bool foot = false;
        for (const Kept& k : kept)
          if (pinned && k.joint == step.joint) model = k.model, foot = true;
        if (pinned && !foot) {
          r = read_rotation(out, j);
          model = glm::normalize(parent_rotation * r);
        } else if (!foot) {
          const glm::quat d = step.kind == RetargetStep::Blend
                                  ? blend(delta(map, s, step.source_a), delta(map, s, step.source_b), step.weight)
                                  : delta(map, s, step.source_a);
          model = glm::normalize(map.rotation * d * step.rest);
        }
        if (!pinned || foot) r = glm::normalize(glm::inverse(parent_rotation) * model);
        if (step.same_joint) {
          // The same joint's squash and stretch: the source's scale as a ratio of its bind's.
          sc *= ratio(read3(in.source, kSx, static_cast<uint32_t>(step.source_a)),
                      map.source_bind[static_cast<size_t>(step.source_a)].scale);
        }
        if (step.same_joint && step.kind == RetargetStep::Rotate) {
          // The same joint's translation away from its bind (a stretch, or keys that differ from the
          // skin's bind) rides along, carried through model space.
          const auto a = static_cast<uint32_t>(step.source_a);
          const glm::vec3 moved = read3(in.source, kTx, a) - map.source_bind[a].translation;
          const int sp = map.source_parents[a];
          if (moved != glm::vec3(0.0f)) {
            const glm::quat source_parent =
                sp >= 0 ? s.source_rotation[static_cast<size_t>(sp)] : glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
            t += glm::inverse(parent_rotation) * (map.scale * (map.rotation * (source_parent * moved)));
          }
        }
        if (step.kind == RetargetStep::Hips) {
          const HumanoidMap& sh = map.source_humanoid;
          const glm::vec3 pelvis =
              0.5f * (glm::vec3(s.source_model[static_cast<size_t>(sh[HumanoidBone::LeftUpperLeg])][3]) +
                      glm::vec3(s.source_model[static_cast<size_t>(sh[HumanoidBone::RightUpperLeg])][3]));
          // What the source's hips move against its own legs (an animated leg root) rides along.
          const auto sj = static_cast<size_t>(step.source_a);
          const glm::vec3 own = step.same_joint
                                    ? glm::vec3(s.source_model[sj][3]) - pelvis -
                                          s.source_rotation[sj] * (map.source_rest_inverse[sj] * map.source_hips_offset)
                                    : glm::vec3(0.0f);
          const glm::vec3 p = map.map_point(pelvis, in.source_floor) + hips_shift + model * step.offset +
                              map.scale * (map.rotation * own);
          t = parent >= 0 ? glm::vec3(glm::inverse(parent_model) * glm::vec4(p, 1.0f)) : p;
        } else if (step.kind == RetargetStep::Anchored) {
          const RetargetMap::Leg& leg = map.legs[step.joint == map.legs[0].foot ? 0 : 1];
          const glm::vec3 own = step.same_joint ? glm::vec3(s.source_model[static_cast<size_t>(leg.source_foot)][3]) -
                                                      glm::vec3(s.source_model[static_cast<size_t>(leg.source_lower)] *
                                                                glm::vec4(leg.source_offset, 1.0f))
                                                : glm::vec3(0.0f);
          const glm::vec3 p =
              glm::vec3(s.target_model[static_cast<size_t>(step.anchor)] * glm::vec4(step.offset, 1.0f)) +
              map.scale * (map.rotation * own);
          t = parent >= 0 ? glm::vec3(glm::inverse(parent_model) * glm::vec4(p, 1.0f)) : p;
        }
        break;
      }
    }
    write(out, j, t, r, sc);
    s.target_model[j] = parent_model * trs(t, r, sc);
    s.target_rotation[j] = glm::normalize(parent_rotation * r);
  }
}

}  // namespace detail

namespace {

bool fits(const RetargetMap& map, const RetargetScratch& s) {
  return s.source_model.size() == map.source_joint_count && s.source_rotation.size() == map.source_joint_count &&
         s.target_model.size() == map.target_joint_count && s.target_rotation.size() == map.target_joint_count &&
         map.source_parents.size() == map.source_joint_count;
}

}  // namespace

RetargetScratch make_retarget_scratch(const RetargetMap& map) {
  RetargetScratch s;
  s.source_model.resize(map.source_joint_count);
  s.source_rotation.resize(map.source_joint_count);
  s.target_model.resize(map.target_joint_count);
  s.target_rotation.resize(map.target_joint_count);
  return s;
}

bool pose_source(const RetargetMap& map, ConstPoseSpan source, RetargetScratch& s) {
  if (!fits(map, s) || source.base == nullptr || source.joint_count != map.source_joint_count) return false;
  local_to_model(map.source_parents, source, s.source_model);
  for (uint32_t j = 0; j < map.source_joint_count; ++j) {
    const int p = map.source_parents[j];
    const glm::quat r = glm::normalize(detail::read_rotation(source, j));
    s.source_rotation[j] = p >= 0 ? glm::normalize(s.source_rotation[static_cast<size_t>(p)] * r) : r;
  }
  return true;
}

glm::vec3 held_ankle(const RetargetMap& map, const RetargetScratch& s, int foot, const FootContact& contact,
                     float source_floor) {
  const auto j = static_cast<size_t>(map.legs[foot == 0 ? 0 : 1].source_foot);
  return map.map_point(glm::vec3(s.source_model[j][3]) + contact.offset, source_floor);
}

bool retarget(const RetargetMap& map, const RetargetInput& in, RetargetScratch& s, PoseSpan out) {
  if (out.base == nullptr || out.joint_count != map.target_joint_count) return false;
  if (in.target_base.base != nullptr && in.target_base.joint_count != map.target_joint_count) return false;
  if (!in.contacts.empty() && in.contacts.size() != 2) return false;
  if (!pose_source(map, in.source, s)) return false;
  s.adjusted = 0;
  detail::evaluate(map, in, s, out, false, {}, glm::vec3(0.0f));
  detail::guard_mid_plane(map, in, s, out);
  if (!in.contacts.empty()) detail::hold_contacts(map, in, s, out);
  return true;
}

}  // namespace ossa
