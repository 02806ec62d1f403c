// graph_procedural.cpp — the graph's procedural nodes: two-bone IK, aim, foot placement, foot
// locking and spring chains (graph.h, format/ossa.fbs "Procedural pose").
//
// Each node evaluates its input into `out`, then works on that pose's model matrices: it builds
// them once (local_to_model into the scratch's `model`), runs the runtime's jobs on them
// (ossa/anim/ik.h, ossa/anim/spring.h) and writes the corrections back into the local pose. A
// correction moves a subtree; refresh_below recomputes only that subtree's matrices (parents come
// first, so one forward sweep finds it), so a node with several legs pays one full local-to-model
// and a few short sweeps. Everything lives in preallocated scratch and instance state: nothing
// allocates, and the same inputs give the same bits.
//
// Spaces: the pose is in model space; the host's Vector parameters are in model or world space
// (converted through the character's transform), foot locks remember world positions and spring
// chains simulate in world space, so a character that turns or runs drags its hair and keeps a
// planted foot where it is in the world while its model space moves under it.
#include <algorithm>
#include <cmath>
#include <iterator>

#include "graph/graph_internal.h"
#include "internal/rotation.h"
#include <ossa/anim/ik.h>
#include <ossa/anim/pose_ops.h>

namespace ossa::graph_detail {
namespace {

using detail::from_to;
using detail::orientation;

using State = GraphInstance::State;

float clamp01(float v) { return v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f; }

glm::vec3 vec_or(const fb::Vec3* v, const glm::vec3& fallback) {
  if (!v) return fallback;
  const glm::vec3 r(v->x(), v->y(), v->z());
  return glm::dot(r, r) > 0.0f ? r : fallback;
}

/// The node's weight: weight * (weight parameter's value), in [0, 1].
float node_weight_of(const State& s, const NodeInfo& info) {
  return clamp01(info.weight *
                 (info.weight_parameter >= 0 ? s.params[static_cast<size_t>(info.weight_parameter)] : 1.0f));
}

/// A Vector parameter as a model-space point / direction.
glm::vec3 model_point(const State& s, int parameter) {
  const glm::vec3 v = s.vectors[static_cast<size_t>(parameter)];
  const auto* p = s.def->graph->parameters()->Get(static_cast<flatbuffers::uoffset_t>(parameter));
  return p->space() == fb::ParameterSpace::World ? glm::vec3(s.inverse_transform * glm::vec4(v, 1.0f)) : v;
}
glm::vec3 model_direction(const State& s, int parameter) {
  const glm::vec3 v = s.vectors[static_cast<size_t>(parameter)];
  const auto* p = s.def->graph->parameters()->Get(static_cast<flatbuffers::uoffset_t>(parameter));
  return p->space() == fb::ParameterSpace::World ? glm::vec3(s.inverse_transform * glm::vec4(v, 0.0f)) : v;
}

glm::mat4 local_matrix(ConstPoseSpan p, uint32_t j) {
  const glm::quat q(p[kRw][j], p[kRx][j], p[kRy][j], p[kRz][j]);
  glm::mat4 m = glm::mat4_cast(q);
  m[0] *= p[kSx][j];
  m[1] *= p[kSy][j];
  m[2] *= p[kSz][j];
  m[3] = glm::vec4(p[kTx][j], p[kTy][j], p[kTz][j], 1.0f);
  return m;
}

/// Calls visit(j, parent) for `joint` and each of its descendants, parents first: one forward
/// sweep over the joints after it (parents come first), marking the subtree in the scratch.
/// O(joints after `joint`).
template <typename Visit>
void for_subtree(State& s, uint32_t joint, Visit&& visit) {
  const auto parents = s.def->skeleton.parents();
  std::vector<uint8_t>& moved = s.scratch->moved;
  const uint32_t n = s.def->joints;
  std::fill(moved.begin() + joint, moved.begin() + n, uint8_t{0});
  for (uint32_t j = joint; j < n; ++j) {
    const int p = parents[j];
    if (j != joint && (p < static_cast<int>(joint) || !moved[static_cast<size_t>(p)])) continue;
    moved[j] = 1;
    visit(j, p);
  }
}

/// Recomputes the model matrices of `joint` and its descendants from the local pose.
void refresh_below(State& s, ConstPoseSpan pose, uint32_t joint) {
  std::vector<glm::mat4>& model = s.scratch->model;
  for_subtree(s, joint, [&](uint32_t j, int p) {
    model[j] = p >= 0 ? model[static_cast<size_t>(p)] * local_matrix(pose, j) : local_matrix(pose, j);
  });
}

/// Adds a model-space offset to the translation of `joint` and every descendant: what moving
/// `joint` by that offset does to their model matrices (a pure translation of the subtree), at a
/// fraction of refresh_below's cost.
void translate_below(State& s, uint32_t joint, const glm::vec3& offset) {
  std::vector<glm::mat4>& model = s.scratch->model;
  for_subtree(s, joint, [&](uint32_t j, int) { model[j][3] += glm::vec4(offset, 0.0f); });
}

/// Recomputes the model matrices on the path from `from` (included) down to its descendant `to`
/// only: an aim chain needs its own joints, not the arms hanging off the neck. Leaves the other
/// descendants stale (the node then marks the matrices unusable for the next node). The path is
/// marked in the scratch's joint flags (free outside for_subtree) walking up from `to`, then
/// refreshed in index order, which is parents first: no bound on the rig's depth, no allocation.
/// O(depth + to - from).
void refresh_path(State& s, ConstPoseSpan pose, uint32_t from, uint32_t to) {
  const auto parents = s.def->skeleton.parents();
  std::vector<glm::mat4>& model = s.scratch->model;
  std::vector<uint8_t>& on_path = s.scratch->moved;
  for (int j = static_cast<int>(to); j >= 0; j = parents[static_cast<size_t>(j)]) {
    on_path[static_cast<size_t>(j)] = 1;
    if (static_cast<uint32_t>(j) == from) break;
  }
  for (uint32_t j = from; j <= to; ++j) {
    if (!on_path[j]) continue;
    on_path[j] = 0;
    const int p = parents[j];
    model[j] = p >= 0 ? model[static_cast<size_t>(p)] * local_matrix(pose, j) : local_matrix(pose, j);
  }
}

/// The pose's model matrices in the scratch, for a procedural node whose input was just
/// evaluated into `out`. When that input is itself a procedural node that left the matrices
/// matching `out` (Buffers::model_pose), they are reused instead of rebuilt: a look-at over foot
/// placement over foot locking pays one local-to-model, not three. O(joints) or O(1).
void model_of(State& s, PoseSpan out) {
  if (s.scratch->model_pose != out.base) local_to_model(s.def->skeleton.parents(), out, s.scratch->model);
  s.scratch->model_pose = out.base;
}

bool is_procedural(Kind k) {
  return k == Kind::TwoBoneIk || k == Kind::Aim || k == Kind::FootPlacement || k == Kind::FootLock || k == Kind::Spring;
}

void rotate_local(PoseSpan pose, uint32_t j, const glm::quat& correction) {
  set_rotation(pose, j, glm::normalize(rotation_at(pose, j) * correction));
}

/// Runs two_bone_ik on (start, mid, end) towards `target` and applies it; returns whether reached.
bool solve_two_bone(State& s, PoseSpan out, uint32_t start, uint32_t mid, uint32_t end, const glm::vec3& target,
                    const glm::vec3& pole, const glm::vec3& mid_axis, float twist, float soften, float weight) {
  const std::vector<glm::mat4>& model = s.scratch->model;
  TwoBoneIkInput in;
  in.start = model[start];
  in.mid = model[mid];
  in.end = model[end];
  in.target = target;
  in.pole = pole;
  in.mid_axis = mid_axis;
  in.twist = twist;
  in.soften = soften;
  in.weight = weight;
  TwoBoneIkOutput o;
  if (!two_bone_ik(in, &o)) return false;
  rotate_local(out, start, o.start_correction);
  rotate_local(out, mid, o.mid_correction);
  refresh_below(s, out, start);
  return o.reached;
}

/// What an IK or aim node does first: its weight, and its `reached` flag cleared. Null when the
/// weight is 0: the node then passes its input through, and writes the flag only if it was set
/// (a crowd with the node off writes nothing). Otherwise the pose's model matrices are built.
float* begin_reaching(State& s, const NodeInfo& info, PoseSpan out, float& weight) {
  weight = node_weight_of(s, info);
  float& reached = s.floats[info.floats];
  if (!(weight > 0.0f)) {
    if (reached != 0.0f) reached = 0.0f;
    return nullptr;
  }
  reached = 0.0f;
  model_of(s, out);
  return &reached;
}

// ---- two-bone IK ----

void two_bone(State& s, const NodeInfo& info, PoseSpan out) {
  const auto& t = *static_cast<const fb::TwoBoneIkNode*>(info.table);
  float w = 0.0f;
  float* reached = begin_reaching(s, info, out, w);
  if (reached == nullptr) return;
  const glm::vec3 start(s.scratch->model[t.start()][3]);
  const glm::vec3 pole =
      t.pole_parameter() >= 0 ? model_point(s, t.pole_parameter()) - start : vec_or(t.pole(), glm::vec3(0.0f));
  const bool ok = solve_two_bone(s, out, t.start(), t.mid(), t.end(), model_point(s, t.target_parameter()), pole,
                                 vec_or(t.mid_axis(), glm::vec3(0.0f, 0.0f, 1.0f)), t.twist(), t.soften(), w);
  *reached = ok && w >= 1.0f ? 1.0f : 0.0f;
}

// ---- aim ----

void aim(State& s, const NodeInfo& info, PoseSpan out) {
  const auto& a = *static_cast<const fb::AimNode*>(info.table);
  float w = 0.0f;
  float* reached = begin_reaching(s, info, out, w);
  if (reached == nullptr) return;
  std::vector<glm::mat4>& model = s.scratch->model;
  const glm::vec3 target = model_point(s, a.target_parameter());
  const glm::vec3 forward = vec_or(a.forward(), glm::vec3(0.0f, 0.0f, 1.0f));
  const glm::vec3 up = vec_or(a.up(), glm::vec3(0.0f, 1.0f, 0.0f));
  const glm::vec3 pole = vec_or(a.pole(), glm::vec3(0.0f));
  const auto& chain = *a.chain();
  const uint32_t last = chain.Get(chain.size() - 1)->joint();
  bool last_reached = false;
  for (flatbuffers::uoffset_t k = 0; k < chain.size(); ++k) {
    const fb::AimJoint& joint = *chain.Get(k);
    const uint32_t j = joint.joint();
    // The last joint's axes, seen from this joint: each joint of the chain turns the head's
    // facing (not its own) towards the target, so the turn is shared along the chain.
    const glm::quat to_joint = glm::conjugate(orientation(model[j])) * orientation(model[last]);
    AimIkInput in;
    in.joint = model[j];
    in.target = target;
    in.forward = to_joint * forward;
    in.up = to_joint * up;
    in.pole = pole;
    in.max_angle = joint.max_angle();
    in.weight = clamp01(joint.weight()) * w;
    AimIkOutput o;
    if (!aim_ik(in, &o)) continue;
    rotate_local(out, j, o.correction);
    refresh_path(s, out, j, last);
    if (j == last) last_reached = o.reached;
  }
  s.scratch->model_pose = nullptr;  // only the chain's own matrices are current
  *reached = last_reached && w >= 1.0f ? 1.0f : 0.0f;
}

// ---- foot placement ----

struct LegTarget {
  glm::vec3 target{0.0f};
  glm::vec3 normal{0.0f, 1.0f, 0.0f};
  glm::quat animated{1.0f, 0.0f, 0.0f, 0.0f};  // the ankle's model rotation before any correction
};

void foot_placement(State& s, const NodeInfo& info, PoseSpan out) {
  const auto& f = *static_cast<const fb::FootPlacementNode*>(info.table);
  const float w = node_weight_of(s, info);
  if (!(w > 0.0f)) return;
  std::vector<glm::mat4>& model = s.scratch->model;
  const auto parents = s.def->skeleton.parents();
  model_of(s, out);
  const glm::vec3 up = glm::normalize(vec_or(f.up(), glm::vec3(0.0f, 1.0f, 0.0f)));
  const auto& legs = *f.legs();
  // Each ankle's target: its spot on the ground the parameters give, at the clearance it had
  // above the flat ground the clip was made on, measured along the new ground's normal.
  LegTarget targets[kMaxFootLegs];  // validation bounds the legs
  float drop = 0.0f;
  for (flatbuffers::uoffset_t i = 0; i < legs.size(); ++i) {
    const fb::FootLeg& leg = *legs.Get(i);
    const glm::vec3 ankle(model[leg.ankle()][3]);
    const float height = leg.ground_parameter() >= 0 ? s.params[static_cast<size_t>(leg.ground_parameter())] : 0.0f;
    glm::vec3 normal = leg.normal_parameter() >= 0 ? model_direction(s, leg.normal_parameter()) : up;
    const float nl = glm::length(normal);
    normal = nl > 1e-6f && glm::dot(normal, up) > 0.05f * nl ? normal / nl : up;  // a wall is no ground
    const float clearance = glm::dot(ankle, up);
    const glm::vec3 ground = ankle + up * (height - clearance);
    targets[i].target = ground + normal * clearance;
    targets[i].normal = normal;
    targets[i].animated = orientation(model[leg.ankle()]);
    // The pelvis drop that lets this leg reach (at 99.5% of its length, so it keeps a bend, or as
    // far as the clip itself stretches it): |target - (hip + up * drop)| <= reach, solved for the
    // highest drop <= 0. Flat ground under the clip's own feet asks for no drop.
    const glm::vec3 hip(model[leg.hip()][3]), knee(model[leg.knee()][3]);
    const float reach =
        std::max(0.995f * (glm::length(knee - hip) + glm::length(ankle - knee)), glm::length(ankle - hip));
    const glm::vec3 d = targets[i].target - hip;
    const float dv = glm::dot(d, up);
    const float dh2 = std::max(0.0f, glm::dot(d, d) - dv * dv);
    if (reach * reach > dh2) drop = std::min(drop, dv + std::sqrt(reach * reach - dh2));
  }
  drop = std::max(drop, -std::fabs(f.max_pelvis_drop()));
  if (drop < 0.0f) {
    const uint32_t pelvis = f.pelvis();
    const int p = parents[pelvis];
    const glm::vec3 model_offset = up * (drop * w);
    const glm::vec3 offset =
        p >= 0 ? glm::vec3(glm::inverse(model[static_cast<size_t>(p)]) * glm::vec4(model_offset, 0.0f)) : model_offset;
    out[kTx][pelvis] += offset.x;
    out[kTy][pelvis] += offset.y;
    out[kTz][pelvis] += offset.z;
    translate_below(s, pelvis, model_offset);
  }
  const float align = clamp01(f.align()) * w;
  for (flatbuffers::uoffset_t i = 0; i < legs.size(); ++i) {
    const fb::FootLeg& leg = *legs.Get(i);
    solve_two_bone(s, out, leg.hip(), leg.knee(), leg.ankle(), targets[i].target, glm::vec3(0.0f),
                   glm::vec3(0.0f, 0.0f, 1.0f), 0.0f, f.soften(), w);
    // The ankle turns with the slope: its animated model rotation gains the turn from up to the
    // normal (the legs' IK turned it with the shin; the foot keeps the clip's own angle instead).
    const uint32_t ankle = leg.ankle();
    const int p = parents[ankle];
    const glm::quat slope = glm::slerp(glm::quat(1.0f, 0.0f, 0.0f, 0.0f), from_to(up, targets[i].normal), align);
    const glm::quat model_rotation = slope * targets[i].animated;
    const glm::quat parent = p >= 0 ? orientation(model[static_cast<size_t>(p)]) : glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
    set_rotation(out, ankle, glm::normalize(glm::conjugate(parent) * model_rotation));
    refresh_below(s, out, ankle);
  }
}

// ---- foot locking ----

/// In State::floats: an "any state" flag, then per leg: locked, blend, planted (from events), the
/// locked world point (3) and the last model-space target (3).
constexpr uint32_t kLockFloats = 9;

void foot_lock(State& s, const NodeInfo& info, const Advance& advance, PoseSpan out) {
  const auto& f = *static_cast<const fb::FootLockNode*>(info.table);
  const float w = node_weight_of(s, info);
  const auto& legs = *f.legs();
  float& active = s.floats[info.floats];  // any leg state set: cleared once when the node goes off
  if (!(w > 0.0f)) {
    // Off: nothing locked, nothing to blend out, nothing tracked (a crowd with the node off reads
    // one float). Turned on mid-stride, a leg driven by events locks from its next plant event.
    if (active != 0.0f) std::fill_n(&s.floats[info.floats], 1 + legs.size() * kLockFloats, 0.0f);
    return;
  }
  active = 1.0f;
  // Planted from events: the last plant / lift event crossed so far (events of this update from
  // the input subtree are already in s.events, in the order they were reached).
  for (flatbuffers::uoffset_t i = 0; i < legs.size(); ++i) {
    float* st = &s.floats[info.floats + 1 + i * kLockFloats];
    const std::string_view plant = s.def->leg_events[info.aux + 2 * i], lift = s.def->leg_events[info.aux + 2 * i + 1];
    for (const GraphEvent& e : s.events) {
      if (!plant.empty() && e.name == plant) st[2] = 1.0f;
      if (!lift.empty() && e.name == lift) st[2] = 0.0f;
    }
  }
  std::vector<glm::mat4>& model = s.scratch->model;
  model_of(s, out);
  const float radius = f.release_radius();
  for (flatbuffers::uoffset_t i = 0; i < legs.size(); ++i) {
    const fb::FootLeg& leg = *legs.Get(i);
    float* st = &s.floats[info.floats + 1 + i * kLockFloats];
    const bool planted =
        leg.planted_parameter() >= 0 ? s.params[static_cast<size_t>(leg.planted_parameter())] > 0.5f : st[2] > 0.5f;
    const glm::vec3 ankle(model[leg.ankle()][3]);
    if (planted && st[0] == 0.0f && st[1] <= 0.0f) {  // lands: remember where, in the world
      const glm::vec3 world(s.transform * glm::vec4(ankle, 1.0f));
      st[0] = 1.0f;
      st[3] = world.x, st[4] = world.y, st[5] = world.z;
    }
    if (st[0] != 0.0f) {
      const glm::vec3 target(s.inverse_transform * glm::vec4(st[3], st[4], st[5], 1.0f));
      if (!planted || glm::length(target - ankle) > radius) {
        st[0] = 0.0f;  // lifts or strays: release, blending out from the last target
      } else {
        st[6] = target.x, st[7] = target.y, st[8] = target.z;
      }
    }
    const float goal = st[0] != 0.0f ? 1.0f : 0.0f;
    st[1] = f.blend_time() > 0.0f ? (goal > st[1] ? std::min(goal, st[1] + advance.dt / f.blend_time())
                                                  : std::max(goal, st[1] - advance.dt / f.blend_time()))
                                  : goal;
    const float lw = st[1] * w;
    if (!(lw > 0.0f)) continue;
    solve_two_bone(s, out, leg.hip(), leg.knee(), leg.ankle(), glm::vec3(st[6], st[7], st[8]), glm::vec3(0.0f),
                   glm::vec3(0.0f, 0.0f, 1.0f), 0.0f, 1.0f, lw);
  }
}

// ---- spring chains ----

void springs(State& s, const NodeInfo& info, const Advance& advance, PoseSpan out) {
  const auto& sp = *static_cast<const fb::SpringNode*>(info.table);
  const float w = node_weight_of(s, info);
  std::vector<glm::mat4>& model = s.scratch->model;
  const auto parents = s.def->skeleton.parents();
  model_of(s, out);
  s.scratch->model_pose = nullptr;  // made world-space below, and partly updated
  // World space: the chains trail the character's own motion through the world.
  for (uint32_t j = 0; j < s.def->joints; ++j) model[j] = s.transform * model[j];
  const std::span<const SpringCollider> colliders = s.def->colliders[info.samples];
  const uint32_t chains = sp.chains()->size();
  for (uint32_t k = 0; k < chains; ++k) {
    SpringChain& chain = s.springs[info.aux + k];
    if (w >= 1.0f) {
      update_spring_chain(chain, advance.dt, parents, out, model, colliders);
      continue;
    }
    // Partial or no weight: the simulation runs as at full weight (its state stays continuous,
    // so raising the weight later does not start from rest), and the result is blended with, or
    // replaced by, the animated rotations.
    glm::quat animated[kMaxSpringJoints];
    const size_t count = chain.joints.size();  // <= kMaxSpringJoints (validation)
    for (size_t i = 0; i < count; ++i) animated[i] = rotation_at(out, chain.joints[i]);
    update_spring_chain(chain, advance.dt, parents, out, model, colliders);
    if (!(w > 0.0f)) {
      for (size_t i = 0; i < count; ++i) set_rotation(out, chain.joints[i], animated[i]);
      continue;
    }
    for (size_t i = 0; i < count; ++i) {
      glm::quat q = rotation_at(out, chain.joints[i]);
      if (glm::dot(q, animated[i]) < 0.0f) q = -q;
      set_rotation(out, chain.joints[i], glm::normalize(animated[i] * (1.0f - w) + q * w));
    }
  }
}

}  // namespace

uint16_t procedural_input(const NodeInfo& info) { return info.input; }

void evaluate_procedural(State& s, uint16_t n, const Advance& advance, float weight, bool dominant, PoseSpan out,
                         std::span<float> ow, uint32_t depth) {
  const NodeInfo& info = s.def->nodes[n];
  const uint16_t input = procedural_input(info);
  evaluate(s, input, advance, weight, dominant, out, ow, depth);
  // model_pose is trusted only as a procedural input left it (a node that returns without
  // touching the pose passes it on); any other input wrote `out` after it was last set.
  if (!is_procedural(s.def->nodes[input].kind)) s.scratch->model_pose = nullptr;
  switch (info.kind) {
    case Kind::TwoBoneIk: return two_bone(s, info, out);
    case Kind::Aim: return aim(s, info, out);
    case Kind::FootPlacement: return foot_placement(s, info, out);
    case Kind::FootLock: return foot_lock(s, info, advance, out);
    case Kind::Spring: return springs(s, info, advance, out);
    default: return;
  }
}

void restart_procedural(State& s, uint16_t n) {
  const NodeInfo& info = s.def->nodes[n];
  restart(s, procedural_input(info));
  if (info.kind == Kind::FootLock) {
    const uint32_t legs = static_cast<const fb::FootLockNode*>(info.table)->legs()->size();
    std::fill_n(&s.floats[info.floats], 1 + legs * kLockFloats, 0.0f);
  } else if (info.kind == Kind::Spring) {
    const uint32_t chains = static_cast<const fb::SpringNode*>(info.table)->chains()->size();
    for (uint32_t k = 0; k < chains; ++k) {
      s.springs[info.aux + k].started = false;  // the next update resets it to the pose
      s.springs[info.aux + k].banked = 0.0f;
    }
  } else if (info.kind == Kind::TwoBoneIk || info.kind == Kind::Aim) {
    s.floats[info.floats] = 0.0f;  // reached
  }
}

}  // namespace ossa::graph_detail
