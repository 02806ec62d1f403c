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

glm::quat read_rotation(ConstPoseSpan p, uint32_t j) {
  return glm::quat(p[kRw][j], p[kRx][j], p[kRy][j], p[kRz][j]);
}
glm::vec3 read3(ConstPoseSpan p, PoseComponent first, uint32_t j) {
  return {p[first][j], p[PoseComponent(first + 1)][j], p[PoseComponent(first + 2)][j]};
}

void write(PoseSpan out, uint32_t j, const glm::vec3& t, const glm::quat& r, const glm::vec3& s) {
  out[kTx][j] = t.x, out[kTy][j] = t.y, out[kTz][j] = t.z;
  out[kRx][j] = r.x, out[kRy][j] = r.y, out[kRz][j] = r.z, out[kRw][j] = r.w;
  out[kSx][j] = s.x, out[kSy][j] = s.y, out[kSz][j] = s.z;
}

/// Shortest-arc slerp (the deltas of neighbouring chain joints are close; nlerp would do too, but
/// slerp keeps a 50 % blend exactly halfway).
glm::quat blend(const glm::quat& a, glm::quat b, float w) {
  if (glm::dot(a, b) < 0.0f) b = -b;
  return glm::normalize(glm::slerp(a, b, w));
}

glm::quat delta(const RetargetMap& map, const RetargetScratch& s, int source_joint) {
  return s.source_rotation[static_cast<size_t>(source_joint)] * map.source_rest_inverse[static_cast<size_t>(source_joint)];
}

/// Target local and model space from the steps. With `pinned` (after IK), the pose already in
/// `out` is read instead of recomputed for rotating joints, except that each leg's foot takes the
/// model rotation kept in scratch.foot_rotation.
void evaluate(const RetargetMap& map, const RetargetInput& in, RetargetScratch& s, PoseSpan out, bool pinned,
              const std::array<bool, 2>& legs, const glm::vec3& hips_shift) {
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
        const glm::vec3 ss = read3(in.source, kSx, a);
        sc = bind.scale * glm::vec3(sb.scale.x != 0.0f ? ss.x / sb.scale.x : 1.0f, sb.scale.y != 0.0f ? ss.y / sb.scale.y : 1.0f,
                                    sb.scale.z != 0.0f ? ss.z / sb.scale.z : 1.0f);
        break;
      }
      default: {
        glm::quat model;
        bool foot = false;
        for (size_t leg = 0; leg < 2; ++leg)
          if (pinned && legs[leg] && step.joint == map.legs[leg].foot) model = s.foot_rotation[leg], foot = true;
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
        if (step.kind == RetargetStep::Hips) {
          const HumanoidMap& sh = map.source_humanoid;
          const glm::vec3 pelvis = 0.5f * (glm::vec3(s.source_model[static_cast<size_t>(sh[HumanoidBone::LeftUpperLeg])][3]) +
                                           glm::vec3(s.source_model[static_cast<size_t>(sh[HumanoidBone::RightUpperLeg])][3]));
          const glm::vec3 p = map.map_point(pelvis, in.source_floor) + hips_shift + model * step.offset;
          t = parent >= 0 ? glm::vec3(glm::inverse(parent_model) * glm::vec4(p, 1.0f)) : p;
        } else if (step.kind == RetargetStep::Anchored) {
          const glm::vec3 p(s.target_model[static_cast<size_t>(step.anchor)] * glm::vec4(step.offset, 1.0f));
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
    const glm::quat r = glm::normalize(read_rotation(source, j));
    s.source_rotation[j] = p >= 0 ? glm::normalize(s.source_rotation[static_cast<size_t>(p)] * r) : r;
  }
  return true;
}

bool retarget(const RetargetMap& map, const RetargetInput& in, RetargetScratch& s, PoseSpan out) {
  if (out.base == nullptr || out.joint_count != map.target_joint_count) return false;
  if (in.target_base.base != nullptr && in.target_base.joint_count != map.target_joint_count) return false;
  if (!in.contacts.empty() && in.contacts.size() != 2) return false;
  if (!pose_source(map, in.source, s)) return false;
  std::array<bool, 2> legs{false, false};
  evaluate(map, in, s, out, false, legs, glm::vec3(0.0f));
  if (in.contacts.empty()) return true;

  // Where each planted foot should be, and how much of that the pelvis takes across the ground.
  const glm::vec3 up = map.target_pose.up;
  std::array<glm::vec3, 2> goal{};
  glm::vec3 shift(0.0f);
  float weights = 0.0f;
  for (size_t leg = 0; leg < 2; ++leg) {
    const FootContact& c = in.contacts[leg];
    const RetargetMap::Leg& l = map.legs[leg];
    if (!(c.weight > 0.0f) || l.upper < 0 || l.lower < 0 || l.foot < 0) continue;
    const glm::vec3 ankle(s.target_model[static_cast<size_t>(l.foot)][3]);
    const glm::vec3 error = c.weight >= 1.0f ? map.map_point(c.position, in.source_floor) - ankle
                                             : std::min(c.weight, 1.0f) * map.scale * (map.rotation * c.shift);
    if (!std::isfinite(error.x + error.y + error.z)) continue;
    goal[leg] = ankle + error;
    shift += error - glm::dot(error, up) * up;
    weights += std::min(c.weight, 1.0f);
    legs[leg] = true;
  }
  if (!legs[0] && !legs[1]) return true;
  shift /= std::max(1.0f, weights);
  evaluate(map, in, s, out, false, {false, false}, shift);

  for (size_t leg = 0; leg < 2; ++leg) {
    if (!legs[leg]) continue;
    const RetargetMap::Leg& l = map.legs[leg];
    TwoBoneIkInput ik;
    ik.start = s.target_model[static_cast<size_t>(l.upper)];
    ik.mid = s.target_model[static_cast<size_t>(l.lower)];
    ik.end = s.target_model[static_cast<size_t>(l.foot)];
    ik.target = goal[leg];
    // Bend the way the knee already bends; a straight leg bends towards the body's forward.
    const glm::vec3 hip(ik.start[3]), knee(ik.mid[3]), ankle(ik.end[3]);
    const glm::vec3 axis = ankle - hip;
    const float len2 = glm::dot(axis, axis);
    glm::vec3 pole = knee - hip - (len2 > 0.0f ? glm::dot(knee - hip, axis) / len2 : 0.0f) * axis;
    if (glm::dot(pole, pole) < 1e-6f * len2) {
      const auto hips = static_cast<size_t>(map.target_humanoid[HumanoidBone::Hips]);
      pole = s.target_rotation[hips] * (map.target_hips_rest_inverse * map.target_forward);
    }
    ik.pole = pole;
    TwoBoneIkOutput result;
    if (!two_bone_ik(ik, &result)) {
      legs[leg] = false;
      continue;
    }
    s.foot_rotation[leg] = s.target_rotation[static_cast<size_t>(l.foot)];
    const auto upper = static_cast<uint32_t>(l.upper), lower = static_cast<uint32_t>(l.lower);
    const glm::quat ru = glm::normalize(read_rotation(out, upper) * result.start_correction);
    const glm::quat rl = glm::normalize(read_rotation(out, lower) * result.mid_correction);
    out[kRx][upper] = ru.x, out[kRy][upper] = ru.y, out[kRz][upper] = ru.z, out[kRw][upper] = ru.w;
    out[kRx][lower] = rl.x, out[kRy][lower] = rl.y, out[kRz][lower] = rl.z, out[kRw][lower] = rl.w;
  }
  evaluate(map, in, s, out, true, legs, shift);
  return true;
}

}  // namespace ossa
