// retarget_map.cpp — deciding, once, how every target joint is driven (retarget.h, make_retarget_map).
//
// Per target joint, in an order where parents (and an IK foot's shin) come first:
//   - the hips: Hips; a limb, head, shoulder or toe bone the source also has: Rotate from it; one
//     the source lacks: Rotate from the source's nearest mapped ancestor in the profile (a missing
//     shoulder moves with the chest, missing toes with the foot);
//   - the trunk (every joint between the hips and the head, labelled or not) and each finger:
//     Blend, by normalized length along the chain (the trunk cut at the neck when both rigs have
//     one, so necks map onto necks), each finger by joint count;
//   - anything else: Copy from a same-named joint under a same-named parent (when the option is
//     on), else Keep.
#include <ossa/retarget/retarget.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <string>

namespace ossa {
namespace {

using B = HumanoidBone;
using Step = RetargetMap::Step;

bool below(std::span<const int16_t> parents, int ancestor, int joint) {
  if (ancestor < 0 || joint < 0) return false;
  for (int j = parents[static_cast<size_t>(joint)]; j >= 0; j = parents[static_cast<size_t>(j)])
    if (j == ancestor) return true;
  return false;
}

glm::vec3 position(const RetargetPose& pose, int j) { return glm::vec3(pose.model[static_cast<size_t>(j)][3]); }

/// Joints strictly between `from` and `to` (an ancestor of to), top down.
std::vector<int> path_between(std::span<const int16_t> parents, int from, int to) {
  std::vector<int> path;
  for (int j = parents[static_cast<size_t>(to)]; j >= 0 && j != from; j = parents[static_cast<size_t>(j)])
    path.insert(path.begin(), j);
  return path;
}

/// A chain's joints with their normalized position along it: the start joint at 0, the end at 1.
struct Chain {
  std::vector<int> joints;
  std::vector<float> at;
};

Chain make_chain(std::span<const int16_t> parents, const RetargetPose& pose, int start, int end) {
  Chain c;
  c.joints.push_back(start);
  for (int j : path_between(parents, start, end)) c.joints.push_back(j);
  c.joints.push_back(end);
  c.at.assign(c.joints.size(), 0.0f);
  float total = 0.0f;
  std::vector<float> length(c.joints.size(), 0.0f);
  for (size_t k = 1; k < c.joints.size(); ++k) {
    length[k] = glm::length(position(pose, c.joints[k]) - position(pose, c.joints[k - 1]));
    total += length[k];
  }
  // Joints at one place (a zero-length bone) still get increasing positions, so each keeps its
  // own partner in a chain of the same shape (a rig retargeted onto itself maps joint to joint).
  const float least = 1e-3f * total;
  total = 0.0f;
  for (size_t k = 1; k < c.joints.size(); ++k) {
    total += std::max(length[k], least);
    c.at[k] = total;
  }
  for (size_t k = 1; k < c.joints.size(); ++k)
    c.at[k] = total > 0.0f ? c.at[k] / total : static_cast<float>(k) / static_cast<float>(c.joints.size() - 1);
  c.at.back() = 1.0f;
  return c;
}

/// The source joints and weight around normalized position u of a source chain.
void sample_chain(const Chain& source, float u, Step& step) {
  for (size_t k = 0; k < source.joints.size(); ++k) {
    if (std::fabs(source.at[k] - u) < 1e-5f) {
      step.kind = RetargetStep::Rotate;
      step.source_a = static_cast<int16_t>(source.joints[k]);
      return;
    }
  }
  size_t k = 0;
  while (k + 2 < source.joints.size() && source.at[k + 1] < u) ++k;
  const float span = source.at[k + 1] - source.at[k];
  step.kind = RetargetStep::Blend;
  step.source_a = static_cast<int16_t>(source.joints[k]);
  step.source_b = static_cast<int16_t>(source.joints[k + 1]);
  step.weight = span > 0.0f ? std::clamp((u - source.at[k]) / span, 0.0f, 1.0f) : 0.0f;
}

int nearest_mapped(const HumanoidMap& map, B bone) {
  for (B b = bone; b != B::Count; b = humanoid_bone_parent(b))
    if (map.has(b)) return map[b];
  return -1;
}

}  // namespace

glm::vec3 RetargetMap::map_point(const glm::vec3& p, float floor) const {
  return target_pose.origin + scale * (rotation * (p - source_pose.origin - floor * source_pose.up));
}

Result<RetargetMap> make_retarget_map(const RetargetRig& source, const RetargetRig& target,
                                      const RetargetOptions& options) {
  auto source_pose = make_retarget_pose(source);
  if (!source_pose) return source_pose.error();
  auto target_pose = make_retarget_pose(target);
  if (!target_pose) return target_pose.error();
  if (source.parents.size() > 32767 || target.parents.size() > 32767)
    return Error{std::string(source.name) + ": too many joints to retarget"};
  RetargetMap map;
  map.source_joint_count = static_cast<uint32_t>(source.parents.size());
  map.target_joint_count = static_cast<uint32_t>(target.parents.size());
  map.source_parents.assign(source.parents.begin(), source.parents.end());
  map.target_parents.assign(target.parents.begin(), target.parents.end());
  map.source_humanoid = source.humanoid;
  map.target_humanoid = target.humanoid;
  map.source_bind.assign(source.bind.begin(), source.bind.end());
  map.target_bind.assign(target.bind.begin(), target.bind.end());
  map.source_pose = std::move(*source_pose);
  map.target_pose = std::move(*target_pose);
  map.rotation = glm::normalize(glm::inverse(map.target_pose.frame) * map.source_pose.frame);
  map.scale = map.target_pose.hips_height / map.source_pose.hips_height;
  const RetargetPose& sp = map.source_pose;
  const RetargetPose& tp = map.target_pose;
  map.source_rest_inverse.resize(map.source_joint_count);
  {  // model rotations of the source's retarget pose
    std::vector<glm::quat> rot(map.source_joint_count);
    for (size_t j = 0; j < rot.size(); ++j) {
      const int p = source.parents[j];
      rot[j] = p >= 0 ? glm::normalize(rot[static_cast<size_t>(p)] * sp.local[j].rotation) : sp.local[j].rotation;
      map.source_rest_inverse[j] = glm::inverse(rot[j]);
    }
  }
  std::vector<glm::quat> target_rest(map.target_joint_count);
  for (size_t j = 0; j < target_rest.size(); ++j) {
    const int p = target.parents[j];
    target_rest[j] =
        p >= 0 ? glm::normalize(target_rest[static_cast<size_t>(p)] * tp.local[j].rotation) : tp.local[j].rotation;
  }
  map.target_rest_inverse.resize(target_rest.size());
  for (size_t j = 0; j < target_rest.size(); ++j) map.target_rest_inverse[j] = glm::inverse(target_rest[j]);
  const glm::quat r_inverse = glm::inverse(map.rotation);
  map.target_hips_rest_inverse = map.target_rest_inverse[static_cast<size_t>(target.humanoid[HumanoidBone::Hips])];
  map.target_forward = glm::inverse(tp.frame) * glm::vec3(0.0f, 0.0f, 1.0f);

  const HumanoidMap& sh = source.humanoid;
  const HumanoidMap& th = target.humanoid;
  std::vector<Step> steps(map.target_joint_count);
  for (size_t j = 0; j < steps.size(); ++j) {
    steps[j].joint = static_cast<int16_t>(j);
    steps[j].rest = glm::normalize(r_inverse * target_rest[j]);
  }
  auto drive = [&](int j, int source_joint) {
    Step& s = steps[static_cast<size_t>(j)];
    s.kind = RetargetStep::Rotate;
    s.source_a = static_cast<int16_t>(source_joint);
  };

  // Limbs, head, shoulders, toes: one to one (or the source's nearest mapped ancestor).
  for (size_t b = 0; b < static_cast<size_t>(B::LeftThumbMetacarpal); ++b) {
    const auto bone = static_cast<B>(b);
    if (!th.has(bone) || bone == B::Spine || bone == B::Chest || bone == B::UpperChest || bone == B::Neck) continue;
    drive(th[bone], nearest_mapped(sh, bone));
  }
  {
    Step& hips = steps[static_cast<size_t>(th[B::Hips])];
    hips.kind = RetargetStep::Hips;
    hips.offset = map.target_rest_inverse[static_cast<size_t>(th[B::Hips])] * (position(tp, th[B::Hips]) - tp.pelvis);
    map.source_hips_offset = position(sp, sh[B::Hips]) - sp.pelvis;
  }

  // Trunk: hips .. head, cut at the neck when both rigs have one.
  auto trunk = [&](int t_from, int t_to, int s_from, int s_to) {
    const Chain s = make_chain(source.parents, sp, s_from, s_to);
    const Chain t = make_chain(target.parents, tp, t_from, t_to);
    for (size_t k = 1; k + 1 < t.joints.size(); ++k) sample_chain(s, t.at[k], steps[static_cast<size_t>(t.joints[k])]);
  };
  if (sh.has(B::Neck) && th.has(B::Neck)) {
    trunk(th[B::Hips], th[B::Neck], sh[B::Hips], sh[B::Neck]);
    drive(th[B::Neck], sh[B::Neck]);
    trunk(th[B::Neck], th[B::Head], sh[B::Neck], sh[B::Head]);
  } else {
    trunk(th[B::Hips], th[B::Head], sh[B::Hips], sh[B::Head]);
  }

  // Fingers: by joint count along each finger; a finger the source lacks moves with its hand.
  for (size_t f = 0; f < 10; ++f) {
    const size_t first = static_cast<size_t>(B::LeftThumbMetacarpal) + f * 3;
    const B hand = f < 5 ? B::LeftHand : B::RightHand;
    std::vector<int> s_joints, t_joints;
    for (size_t k = 0; k < 3; ++k) {
      if (sh.joints[first + k] >= 0) s_joints.push_back(sh.joints[first + k]);
      if (th.joints[first + k] >= 0) t_joints.push_back(th.joints[first + k]);
    }
    for (size_t k = 0; k < t_joints.size(); ++k) {
      if (s_joints.empty()) {
        drive(t_joints[k], sh[hand]);
        continue;
      }
      Chain s;
      s.joints = s_joints;
      for (size_t i = 0; i < s_joints.size(); ++i)
        s.at.push_back(static_cast<float>(i) / static_cast<float>(s_joints.size()));
      if (s.joints.size() == 1) {
        drive(t_joints[k], s.joints[0]);
        continue;
      }
      s.at.back() = static_cast<float>(s_joints.size() - 1) / static_cast<float>(s_joints.size());
      const float u = static_cast<float>(k) / static_cast<float>(t_joints.size());
      sample_chain(s, std::min(u, s.at.back()), steps[static_cast<size_t>(t_joints[k])]);
    }
  }

  // Feet hanging elsewhere (IK rigs) follow their shin.
  for (int side = 0; side < 2; ++side) {
    const int shin = th[side == 0 ? B::LeftLowerLeg : B::RightLowerLeg],
              foot = th[side == 0 ? B::LeftFoot : B::RightFoot];
    RetargetMap::Leg& leg = map.legs[static_cast<size_t>(side)];
    leg.upper = th[side == 0 ? B::LeftUpperLeg : B::RightUpperLeg];
    leg.lower = static_cast<int16_t>(shin);
    leg.foot = static_cast<int16_t>(foot);
    leg.source_foot = sh[side == 0 ? B::LeftFoot : B::RightFoot];
    leg.source_lower = sh[side == 0 ? B::LeftLowerLeg : B::RightLowerLeg];
    leg.source_offset = glm::vec3(glm::inverse(sp.model[static_cast<size_t>(leg.source_lower)]) *
                                  sp.model[static_cast<size_t>(leg.source_foot)][3]);
    if (below(target.parents, shin, foot)) continue;
    Step& s = steps[static_cast<size_t>(foot)];
    s.kind = RetargetStep::Anchored;
    s.anchor = static_cast<int16_t>(shin);
    s.offset = glm::vec3(glm::inverse(tp.model[static_cast<size_t>(shin)]) * tp.model[static_cast<size_t>(foot)][3]);
  }

  // Joints outside the profile: a same-named source joint under a same-named parent drives them.
  if (options.match_extra_joints && source.names.size() == source.parents.size() &&
      target.names.size() == target.parents.size()) {
    std::vector<bool> source_profile(map.source_joint_count, false);
    for (int16_t j : sh.joints)
      if (j >= 0) source_profile[static_cast<size_t>(j)] = true;
    std::map<std::string_view, int> by_name;
    for (size_t j = 0; j < source.names.size(); ++j) by_name.emplace(source.names[j], static_cast<int>(j));
    for (size_t j = 0; j < steps.size(); ++j) {
      if (steps[j].kind != RetargetStep::Keep) continue;
      const auto it = by_name.find(target.names[j]);
      if (it == by_name.end() || source_profile[static_cast<size_t>(it->second)]) continue;
      const int sp_parent = source.parents[static_cast<size_t>(it->second)], tp_parent = target.parents[j];
      if ((sp_parent < 0) != (tp_parent < 0)) continue;
      if (sp_parent >= 0 &&
          source.names[static_cast<size_t>(sp_parent)] != target.names[static_cast<size_t>(tp_parent)])
        continue;
      Step& s = steps[j];
      s.kind = RetargetStep::Copy;
      s.source_a = static_cast<int16_t>(it->second);
      s.rest = tp.local[j].rotation;
      s.source_rest_local_inverse = glm::inverse(sp.local[static_cast<size_t>(it->second)].rotation);
    }
  }

  // One-to-one joints that are the same joint on both rigs (name and parent's name).
  if (source.names.size() == source.parents.size() && target.names.size() == target.parents.size()) {
    for (Step& s : steps) {
      if (s.kind != RetargetStep::Rotate && s.kind != RetargetStep::Hips && s.kind != RetargetStep::Anchored) continue;
      const auto a = static_cast<size_t>(s.source_a), j = static_cast<size_t>(s.joint);
      const int pa = source.parents[a], pj = target.parents[j];
      s.same_joint = source.names[a] == target.names[j] && (pa < 0) == (pj < 0) &&
                     (pa < 0 || source.names[static_cast<size_t>(pa)] == target.names[static_cast<size_t>(pj)]);
    }
  }

  // Evaluation order: parents first, anchored feet after their shins (Kahn's algorithm, lowest
  // index first, so the order is the joint order whenever no foot is anchored).
  const size_t n = steps.size();
  std::vector<std::vector<int>> after(n);
  std::vector<int> waiting(n, 0);
  for (size_t j = 0; j < n; ++j) {
    for (int dep : {static_cast<int>(target.parents[j]), static_cast<int>(steps[j].anchor)}) {
      if (dep < 0) continue;
      after[static_cast<size_t>(dep)].push_back(static_cast<int>(j));
      ++waiting[j];
    }
  }
  std::vector<int> ready;
  for (size_t j = 0; j < n; ++j)
    if (waiting[j] == 0) ready.push_back(static_cast<int>(j));
  while (!ready.empty()) {
    const auto lowest = std::min_element(ready.begin(), ready.end());
    const int j = *lowest;
    ready.erase(lowest);
    map.steps.push_back(steps[static_cast<size_t>(j)]);
    for (int k : after[static_cast<size_t>(j)])
      if (--waiting[static_cast<size_t>(k)] == 0) ready.push_back(k);
  }
  if (map.steps.size() != n) return Error{std::string(target.name) + ": an IK foot hangs below its own shin's chain"};
  return map;
}

}  // namespace ossa
