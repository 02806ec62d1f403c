// graph_machine.cpp — the state machine node: transition rules, crossfades, inertialization
// (graph.h describes the behaviour; this file is how).
//
// Per update: (1) transitions are checked in priority order against the parameters as the host set
// them and the source's normalized time as of the last update; at most one fires, consuming its
// triggers; (2) the playing states are advanced and evaluated (both sides of a crossfade);
// (3) a pending inertialization captures its offset from the last output and this frame's pose;
// a running one is applied; (4) the output is kept for the next capture.
//
// Inertialization follows Bollo (GDC 2018): per joint, the offset's magnitude x (a translation
// length, a rotation angle about a fixed axis) follows the quintic with x(0) = x0, x'(0) = v0 (the
// source's velocity along the offset, from the last two outputs, clamped so it never grows) and
// x = x' = x'' = 0 at t1 = min(duration, -5 x0 / v0). Scales are not inertialized (they switch).
//
// Under a slot showing its montages over some joints at full weight, a machine whose states hold
// only clips, blend spaces and blends evaluates just the lanes the slot shows; its history then
// lacks the rest, so each such update is journaled (the instance's scalars, a few hundred bytes for
// Pab, and the machine's clock), and a capture that needs that history first replays those updates
// on every joint (replay_history).
#include <algorithm>
#include <cmath>

#include "graph/graph_internal.h"
#include <ossa/anim/morph.h>
#include <ossa/anim/pose_ops.h>

namespace ossa::graph_detail {
namespace {

using State = GraphInstance::State;

constexpr int kConditionStack = 16;  // validate_graph.cpp bounds a condition's stack depth by this

bool condition_holds(const State& s, const fb::Transition& t) {
  const auto* cond = t.condition();
  if (!cond || cond->size() == 0) return true;
  bool stack[kConditionStack];
  int sp = 0;
  for (const fb::ConditionInstr* c : *cond) {
    const bool reads = c->op() >= fb::ConditionOp::Less && c->op() <= fb::ConditionOp::Trigger;
    const float v = reads ? s.params[c->parameter()] : 0.0f;
    switch (c->op()) {
      case fb::ConditionOp::True: stack[sp++] = true; break;
      case fb::ConditionOp::Less: stack[sp++] = v < c->value(); break;
      case fb::ConditionOp::LessEqual: stack[sp++] = v <= c->value(); break;
      case fb::ConditionOp::Greater: stack[sp++] = v > c->value(); break;
      case fb::ConditionOp::GreaterEqual: stack[sp++] = v >= c->value(); break;
      case fb::ConditionOp::Equal: stack[sp++] = v == c->value(); break;
      case fb::ConditionOp::NotEqual: stack[sp++] = v != c->value(); break;
      case fb::ConditionOp::Bool:
      case fb::ConditionOp::Trigger: stack[sp++] = v != 0.0f; break;
      case fb::ConditionOp::Not: stack[sp - 1] = !stack[sp - 1]; break;
      case fb::ConditionOp::And:
        --sp;
        stack[sp - 1] = stack[sp - 1] && stack[sp];
        break;
      case fb::ConditionOp::Or:
        --sp;
        stack[sp - 1] = stack[sp - 1] || stack[sp];
        break;
    }
  }
  return sp > 0 && stack[sp - 1];
}

/// Whether the current state's normalized time has reached exit time e: for a looping state and
/// e < 1, in every loop (the fraction is past e, or a wrap crossed it during the last update);
/// otherwise once the unwrapped normalized time is at least e.
bool exit_time_reached(const MachineState& m, float e) {
  if (m.looping && e < 1.0f) {
    const double u0 = m.normalized_before, u1 = m.normalized;
    if (u1 - std::floor(u1) >= e) return true;
    return std::floor(u1 - e) > std::floor(u0 - e);
  }
  return m.normalized >= e;
}

uint16_t state_node(const MachineInfo& mi, int state) {
  return mi.fb->states()->Get(static_cast<flatbuffers::uoffset_t>(state))->node();
}

/// Enters `state`: restarts its subtree when the state says so, and starts its normalized clock
/// at its leader's phase.
void enter_state(State& s, MachineState& m, const MachineInfo& mi, int state) {
  const fb::State& st = *mi.fb->states()->Get(static_cast<flatbuffers::uoffset_t>(state));
  if (st.restart()) restart(s, st.node());
  m.current = state;
  const Cycle c = cycle(s, st.node());
  m.normalized = m.normalized_before = c.phase;
  m.looping = c.loop;
}

/// Whether the last two outputs are from the previous update (so an offset and its velocity can be
/// taken from them).
bool has_last(const State& s, const MachineState& m) {
  return m.last_update != 0 && m.last_update + 1 == s.update_counter;
}

}  // namespace

float quintic(const InertialChannel& c, float t) {
  if (t >= c.t1) return 0.0f;
  return (((((c.k5 * t + c.k4) * t + c.k3) * t + c.k2) * t + c.v0) * t) + c.x0;
}

void init_channel(InertialChannel& c, const glm::vec3& offset, const glm::vec3& velocity, float duration) {
  const float x0 = glm::length(offset);
  if (!(x0 > 1e-9f) || !(duration > 0.0f)) {
    c = InertialChannel{};
    return;
  }
  c.direction = offset / x0;
  c.x0 = x0;
  c.v0 = std::min(0.0f, glm::dot(velocity, c.direction));  // never let the offset grow
  c.t1 = duration;
  if (c.v0 < 0.0f) c.t1 = std::min(duration, -5.0f * x0 / c.v0);
  if (!(c.t1 > 1e-4f)) {  // gone within 0.1 ms (a tiny offset against a fast motion): t1^5 would underflow
    c = InertialChannel{};
    return;
  }
  const float t1 = c.t1;
  const float v0 = c.v0, a0 = std::max(0.0f, (-8.0f * v0 * t1 - 20.0f * x0) / (t1 * t1));
  const float t1_2 = t1 * t1, t1_3 = t1_2 * t1;
  c.k5 = -(a0 * t1_2 + 6.0f * v0 * t1 + 12.0f * x0) / (2.0f * t1_3 * t1_2);
  c.k4 = (3.0f * a0 * t1_2 + 16.0f * v0 * t1 + 30.0f * x0) / (2.0f * t1_3 * t1);
  c.k3 = -(3.0f * a0 * t1_2 + 12.0f * v0 * t1 + 20.0f * x0) / (2.0f * t1_3);
  c.k2 = 0.5f * a0;
}

/// The rotation vector (axis * angle) of q, on the shortest arc.
glm::vec3 rotation_vector(glm::quat q) {
  if (q.w < 0.0f) q = -q;
  const glm::vec3 v(q.x, q.y, q.z);
  const float s = glm::length(v);
  if (!(s > 1e-12f)) return glm::vec3(0.0f);
  return v * (2.0f * std::atan2(s, q.w) / s);
}

namespace {

/// Starts an offset that carries the last output into `now` (this frame's pose before offsets).
void capture_offset(State& s, MachineState& m, ConstPoseSpan now, float duration) {
  const uint32_t joints = s.def->joints;
  const ConstPoseSpan last = m.last.span(), before = m.before_last.span();
  const bool velocity = m.before_last_update != 0 && m.before_last_update + 1 == m.last_update && m.last_dt > 0.0f;
  const float inv_dt = velocity ? 1.0f / m.last_dt : 0.0f;
  for (uint32_t j = 0; j < joints; ++j) {
    const glm::vec3 lt(last[kTx][j], last[kTy][j], last[kTz][j]);
    const glm::vec3 nt(now[kTx][j], now[kTy][j], now[kTz][j]);
    glm::vec3 vt(0.0f), vr(0.0f);
    const glm::quat lq = rotation_at(last, j);
    if (velocity) {
      vt = (lt - glm::vec3(before[kTx][j], before[kTy][j], before[kTz][j])) * inv_dt;
      vr = rotation_vector(lq * glm::conjugate(rotation_at(before, j))) * inv_dt;
    }
    init_channel(m.translation[j], lt - nt, vt, duration);
    init_channel(m.rotation[j], rotation_vector(lq * glm::conjugate(rotation_at(now, j))), vr, duration);
  }
  m.inertial = true;
  m.inertial_elapsed = 0.0f;
  m.inertial_duration = duration;
}

}  // namespace

namespace {

/// Adds the offsets of channels `translation` and `rotation` (one per joint) at time t.
void apply_channels(const State& s, const InertialChannel* translation, const InertialChannel* rotation, float t,
                    PoseSpan out) {
  for (uint32_t j = 0; j < s.def->joints; ++j) {
    const InertialChannel& ct = translation[j];
    if (ct.x0 > 0.0f) {
      const float x = quintic(ct, t);
      out[kTx][j] += ct.direction.x * x;
      out[kTy][j] += ct.direction.y * x;
      out[kTz][j] += ct.direction.z * x;
    }
    const InertialChannel& cr = rotation[j];
    if (cr.x0 > 0.0f) {
      const float x = quintic(cr, t);
      if (x == 0.0f) continue;
      set_rotation(out, j, glm::angleAxis(x, cr.direction) * rotation_at(out, j));
    }
  }
}

}  // namespace

void apply_offset(const State& s, const MachineState& m, PoseSpan out) {
  apply_channels(s, m.translation.data(), m.rotation.data(), m.inertial_elapsed, out);
}

namespace {

/// Checks the transitions; starts the first that holds. Returns whether an offset must be captured
/// this frame (an inertialization or an interrupted crossfade), and its duration in *capture.
bool try_transition(State& s, MachineState& m, const MachineInfo& mi, float* capture) {
  for (size_t k = 0; k < mi.transitions.size(); ++k) {
    const TransitionInfo& ti = mi.transitions[k];
    const fb::Transition& t = *ti.fb;
    if (t.from() >= 0 ? t.from() != m.current : t.to() == m.current) continue;
    if (t.exit_time() >= 0.0f && !exit_time_reached(m, t.exit_time())) continue;
    if (!condition_holds(s, t)) continue;
    for (uint32_t i = 0; i < ti.trigger_count; ++i) s.params[s.def->transition_triggers[ti.first_trigger + i]] = 0.0f;

    const bool crossfading = m.source >= 0;
    const int from = m.current;
    const float duration = t.duration();
    const uint16_t from_node = state_node(mi, from);
    const float from_phase = cycle(s, from_node).phase;
    enter_state(s, m, mi, t.to());
    m.transition = static_cast<int>(k);
    m.mode = t.mode();
    m.elapsed = 0.0f;
    m.duration = duration;
    m.source = -1;
    if (t.mode() == fb::TransitionMode::Inertialize || !(duration > 0.0f)) {
      *capture = duration;
      return duration > 0.0f && has_last(s, m);
    }
    // A crossfade: the old target keeps playing as the source.
    m.source = from;
    if (t.mode() == fb::TransitionMode::SyncCrossfade) {
      set_phase(s, state_node(mi, t.to()), from_phase);
      m.normalized = m.normalized_before = from_phase;
    }
    // Interrupting a crossfade drops its source: an offset keeps the pose the character had.
    *capture = duration;
    return crossfading && has_last(s, m);
  }
  return false;
}

}  // namespace

void restart_machine(State& s, uint16_t machine) {
  MachineState& m = s.machines[machine];
  m.entered = false;
  m.source = -1;
  m.transition = -1;
  m.elapsed = m.duration = 0.0f;
  m.inertial = false;
  m.last_update = m.before_last_update = 0;
  m.last_partial = m.before_last_partial = false;
  m.skipped_joints = 0;
}

Cycle machine_cycle(const State& s, uint16_t machine) {
  const MachineState& m = s.machines[machine];
  const MachineInfo& mi = s.def->machines[machine];
  const int state = m.entered ? m.current : mi.fb->entry();
  if (m.entered && m.source >= 0 && m.duration > 0.0f && m.elapsed < 0.5f * m.duration)
    return cycle(s, state_node(mi, m.source));
  return cycle(s, state_node(mi, state));
}

void set_machine_phase(State& s, uint16_t machine, float p) {
  MachineState& m = s.machines[machine];
  const MachineInfo& mi = s.def->machines[machine];
  if (!m.entered) {
    m.entered = true;
    enter_state(s, m, mi, mi.fb->entry());
  }
  set_phase(s, state_node(mi, m.current), p);
  if (m.source >= 0) set_phase(s, state_node(mi, m.source), p);
  m.normalized = m.normalized_before = p;
}

namespace {

/// Advances the playing states and evaluates them into out (both sides of a crossfade).
void evaluate_states(State& s, MachineState& m, const MachineInfo& mi, const Advance& advance, float weight,
                     bool dominant, PoseSpan out, std::span<float> ow, uint32_t depth) {
  const uint16_t target = state_node(mi, m.current);
  float normalized_step = 0.0f;
  if (m.source >= 0) {
    const uint16_t source = state_node(mi, m.source);
    m.elapsed += advance.dt;
    const float w = m.duration > 0.0f ? std::min(1.0f, m.elapsed / m.duration) : 1.0f;
    Advance both = advance;
    if (m.mode == fb::TransitionMode::SyncCrossfade && !advance.synced) {
      const float blended = (1.0f - w) * cycle(s, source).duration + w * cycle(s, target).duration;
      both.synced = true;
      both.phase = blended > 0.0f ? advance.dt / blended : 0.0f;
    }
    normalized_step = both.synced ? both.phase : advance.dt / cycle(s, target).duration;
    if (w >= 1.0f) {
      m.source = -1;  // done: only the target from now on
      evaluate(s, target, both, weight, dominant, out, ow, depth);
    } else {
      evaluate(s, target, both, weight * w, dominant && w >= 0.5f, out, ow, depth);
      PoseSpan tmp = s.scratch->poses[depth].span();
      const std::span<float> tw = scratch_weights(s, depth);
      evaluate(s, source, both, weight * (1.0f - w), dominant && w < 0.5f, tmp, tw, depth + 1);
      blend(tmp, out, w, out);
      blend_morph_weights(tw, ow, w, ow);
    }
  } else {
    m.elapsed += advance.dt;
    normalized_step = advance.synced ? advance.phase : advance.dt / cycle(s, target).duration;
    evaluate(s, target, advance, weight, dominant, out, ow, depth);
  }
  m.normalized_before = m.normalized;
  m.normalized += normalized_step;
}

/// Makes the history buffers that hold a covering slot's shown lanes only whole again, before a
/// capture reads them: the states are evaluated on every joint once more as they were in those
/// updates (their journals). Exact: the states are pure (hidden_machine in graph_slot.cpp), so
/// their output is a function of the instance's scalars, the clock and the advance, all of them
/// journaled, and a sampling cache samples exactly from any cursor. The offset applied then is
/// the channels of that update (the ones before the last capture for an update before it). No
/// event fires again; everything else is put back as it was.
void replay_history(State& s, MachineState& m, const MachineInfo& mi, uint32_t depth) {
  std::copy(s.values.begin(), s.values.end(), m.replay_values.begin());
  const MachineClock now = m;
  const int32_t hidden = s.hidden;
  s.hidden = -1;
  const auto replay = [&](uint64_t update, Pose& into) {
    const MachineJournal& j = m.journal[update & 1];
    if (j.update != update) return false;
    std::copy(j.values.begin(), j.values.end(), s.values.begin());
    static_cast<MachineClock&>(m) = j.clock;
    Advance a;
    a.dt = j.dt;
    a.phase = j.phase;
    a.synced = j.synced;
    evaluate_states(s, m, mi, a, j.weight, false, into.span(), m.replay_weights, depth);
    if (j.clock.inertial && j.clock.inertial_elapsed + j.dt < j.clock.inertial_duration) {
      const bool older = update < m.capture_update;
      apply_channels(s, (older ? m.prev_translation : m.translation).data(),
                     (older ? m.prev_rotation : m.rotation).data(), j.clock.inertial_elapsed + j.dt, into.span());
    }
    return true;
  };
  if (m.before_last_partial && replay(m.before_last_update, m.before_last)) m.before_last_partial = false;
  if (m.last_partial && replay(m.last_update, m.last)) m.last_partial = false;
  std::copy(m.replay_values.begin(), m.replay_values.end(), s.values.begin());
  static_cast<MachineClock&>(m) = now;
  s.hidden = hidden;
}

}  // namespace

void evaluate_machine(State& s, uint16_t n, const Advance& advance, float weight, bool dominant, PoseSpan out,
                      std::span<float> ow, uint32_t depth) {
  const NodeInfo& info = s.def->nodes[n];
  MachineState& m = s.machines[info.machine];
  const MachineInfo& mi = s.def->machines[info.machine];
  if (!m.entered) {
    m.entered = true;
    enter_state(s, m, mi, mi.fb->entry());
  }

  float capture_duration = 0.0f;
  const bool capture = try_transition(s, m, mi, &capture_duration);
  if (capture && (m.last_partial || m.before_last_partial)) replay_history(s, m, mi, depth);

  // Under a slot that shows its montages over some joints at full weight, a pure machine evaluates
  // only the lanes the slot shows (its clips sample filtered caches), unless it captures an offset
  // now, which needs every joint of this pose; it journals the update to replay it if a later
  // capture needs it whole.
  const int32_t hidden = s.hidden;
  const bool hide = hidden >= 0 && s.def->node_hidden[n] == hidden && !capture;
  if (hide) {
    MachineJournal& j = m.journal[s.update_counter & 1];
    j.update = s.update_counter;
    j.dt = advance.dt;
    j.phase = advance.phase;
    j.synced = advance.synced;
    j.weight = weight;
    j.clock = m;
    std::copy(s.values.begin(), s.values.end(), j.values.begin());
  } else {
    s.hidden = -1;
  }
  evaluate_states(s, m, mi, advance, weight, dominant, out, ow, depth);
  s.hidden = hidden;

  if (capture) {
    if (!m.prev_translation.empty()) {  // a replay of an update before this one applies these
      std::copy(m.translation.begin(), m.translation.end(), m.prev_translation.begin());
      std::copy(m.rotation.begin(), m.rotation.end(), m.prev_rotation.begin());
      m.capture_update = s.update_counter;
    }
    capture_offset(s, m, out, capture_duration);
    // Morph weights: the jump at the switch, decayed linearly over the same duration.
    for (size_t c = 0; c < ow.size(); ++c) m.weight_offset[c] = m.last_weights[c] - ow[c];
  }
  if (m.inertial) {
    m.inertial_elapsed += advance.dt;
    if (m.inertial_elapsed >= m.inertial_duration) {
      m.inertial = false;
    } else {
      apply_offset(s, m, out);
      const float keep = 1.0f - m.inertial_elapsed / m.inertial_duration;
      for (size_t c = 0; c < ow.size(); ++c) ow[c] += m.weight_offset[c] * keep;
    }
  }
  std::copy(ow.begin(), ow.end(), m.last_weights.begin());
  if (m.source < 0 && !m.inertial && m.elapsed >= m.duration) m.transition = -1;

  // Keep this output for a later capture: the older buffer becomes the newest.
  std::swap(m.last, m.before_last);
  std::swap(m.last_partial, m.before_last_partial);
  m.before_last_update = m.last_update;
  if (hide) {
    const auto& lanes = s.def->slot_shown_lanes[static_cast<size_t>(hidden)];
    stream_lanes(out, m.last, lanes);
    uint32_t shown = 0;
    for (const auto& [first, last] : lanes) shown += std::min(last, s.def->joints) - first;
    m.skipped_joints = s.def->joints - shown;
  } else {
    stream_pose(out, m.last);
    m.skipped_joints = 0;
  }
  m.last_partial = hide;
  m.last_update = s.update_counter;
  m.last_dt = advance.dt;
}

}  // namespace ossa::graph_detail

namespace ossa {

MachineStatus GraphInstance::machine_status(size_t machine) const {
  MachineStatus out;
  if (machine >= state_->machines.size()) return out;
  const graph_detail::MachineState& m = state_->machines[machine];
  out.current = m.entered ? m.current : state_->def->machines[machine].fb->entry();
  out.previous = m.source;
  out.weight = m.source >= 0 && m.duration > 0.0f ? std::min(1.0f, m.elapsed / m.duration) : 1.0f;
  out.elapsed = m.elapsed;
  out.duration = m.duration;
  out.transition = m.transition;
  out.inertial_remaining = m.inertial ? m.inertial_duration - m.inertial_elapsed : 0.0f;
  out.skipped_joints = m.skipped_joints;
  return out;
}

}  // namespace ossa
