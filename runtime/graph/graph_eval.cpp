// graph_eval.cpp — evaluating the graph's nodes: advance their time, sample, blend (graph.h).
//
// One recursive walk from the root. A node writes its pose into `out` and takes scratch poses
// from State::scratch starting at `depth` (the definition sized the pool with scratch_needed, which
// mirrors the choices made here). Inputs with zero weight are skipped entirely: not advanced, not
// sampled, so a graph costs what its active branches cost. The state machine node lives in
// graph_machine.cpp.
#include <algorithm>
#include <cmath>

#include "graph/graph_internal.h"
#include <ossa/anim/morph.h>
#include <ossa/anim/pose_ops.h>

namespace ossa::graph_detail {
namespace {

using State = GraphInstance::State;

float clamp01(float v) { return v > 0.0f ? (v < 1.0f ? v : 1.0f) : 0.0f; }

/// Moves `current` towards `target` by dt / blend_time (at once when blend_time is 0).
float ease(float current, float target, float dt, float blend_time) {
  if (!(blend_time > 0.0f)) return target;
  const float step = dt / blend_time;
  return current < target ? std::min(target, current + step) : std::max(target, current - step);
}

void push_event(State& s, const fb::ClipEvent& e, uint16_t clip, uint16_t node) {
  if (s.events.size() < s.event_capacity) {
    s.events.push_back(GraphEvent{std::string_view(e.name()->c_str(), e.name()->size()), clip, node, e.time()});
  } else {
    ++s.dropped;
  }
}

/// Events of `clip` crossed moving from t0 to t1 with `loops` signed wraps (advance_time's count).
/// Forward, the spans [t0, t1) unrolled over the wraps; backward, (t1, t0], the mirror: either
/// way the time playback starts from counts and the time it reaches does not, so consecutive
/// updates report each crossing once. A wrap passes time 0 (= the end of a looping clip); a clamped
/// clip that reaches an end includes an event exactly there.
void collect_events(State& s, const ClipView& clip, uint16_t clip_index, uint16_t node, float t0, float t1, int loops,
                    bool forward, bool loop) {
  const auto* events = clip.fb->events();
  if (!events || events->size() == 0 || (t0 == t1 && loops == 0)) return;
  const float d = clip.duration();
  // Events with lo <= t < hi (or <= hi), in increasing time.
  const auto up = [&](float lo, float hi, bool hi_inclusive) {
    for (const fb::ClipEvent* e : *events) {
      const float t = e->time();
      if (t >= lo && (t < hi || (hi_inclusive && t == hi))) push_event(s, *e, clip_index, node);
    }
  };
  // Events with lo < t <= hi (or lo <= t), in decreasing time.
  const auto down = [&](float lo, float hi, bool lo_inclusive, bool hi_inclusive) {
    for (flatbuffers::uoffset_t k = events->size(); k-- > 0;) {
      const fb::ClipEvent* e = events->Get(k);
      const float t = e->time();
      if ((t > lo || (lo_inclusive && t == lo)) && (t < hi || (hi_inclusive && t == hi)))
        push_event(s, *e, clip_index, node);
    }
  };
  const int whole = std::min(std::abs(loops) - 1, 4);  // a huge dt would only repeat the same events
  if (forward) {
    if (loops <= 0) return up(t0, t1, !loop && t1 >= d && t0 < d);
    up(t0, d, false);
    for (int k = 0; k < whole; ++k) up(0.0f, d, false);
    return up(0.0f, t1, false);
  }
  if (loops >= 0) return down(t1, t0, !loop && t1 <= 0.0f && t0 > 0.0f, true);
  down(0.0f, t0, true, true);
  for (int k = 0; k < whole; ++k) down(0.0f, d, true, false);
  down(t1, d, false, false);
}

/// The cache node `n` samples with: filtered to what the covering slot shows while it hides the
/// rest from this node (Impl::node_hidden), else the whole one.
SamplingCache& cache_of(State& s, uint16_t n, uint32_t index) {
  return s.hidden >= 0 && s.def->node_hidden[n] == s.hidden ? s.hidden_caches[index] : s.caches[index];
}

float param_or(const State& s, int16_t parameter, float fallback) {
  return parameter >= 0 ? s.params[static_cast<size_t>(parameter)] : fallback;
}

/// Products of a node's factor and a parameter a host may set anywhere in the parameter's range
/// are kept where float arithmetic stays finite (validation bounds the factors themselves).
constexpr float kMaxScaledRate = 1000.0f, kMaxScaledWeight = 100.0f, kMaxCoordinate = 1e6f;

// ---- clip ----

float clip_rate(const State& s, const fb::ClipNode& c) {
  return std::clamp(c.rate() * param_or(s, c.rate_parameter(), 1.0f), -kMaxScaledRate, kMaxScaledRate);
}

/// A clip's morph weights at `time`: the channels it has tracks for, the defaults elsewhere.
void clip_weights(const State& s, uint16_t clip, float time, std::span<float> ow) {
  if (ow.empty()) return;
  std::copy(s.def->default_weights.begin(), s.def->default_weights.end(), ow.begin());
  sample_morph_weights(s.def->clips[clip], time, s.def->clip_channels[clip], ow);
}

void evaluate_clip(State& s, uint16_t n, const NodeInfo& info, const Advance& advance, bool dominant, PoseSpan out,
                   std::span<float> ow) {
  const auto& c = *static_cast<const fb::ClipNode*>(info.table);
  if (info.held >= 0) {  // time never moves
    clip_weights(s, c.clip(), std::clamp(c.start_offset(), 0.0f, s.def->clips[c.clip()].duration()), ow);
    return copy_pose(s.def->held[static_cast<size_t>(info.held)], out);
  }
  const ClipView& clip = s.def->clips[c.clip()];
  float& time = s.floats[info.floats];
  const float duration = clip.duration();
  const float rate = clip_rate(s, c);
  const float t0 = time;
  int loops = 0;
  if (advance.synced)
    time = advance_time(time, advance.phase * duration, rate < 0.0f ? -1.0f : 1.0f, duration, c.loop(), &loops);
  else time = advance_time(time, advance.dt, rate, duration, c.loop(), &loops);
  if (dominant) collect_events(s, clip, c.clip(), n, t0, time, loops, rate >= 0.0f, c.loop());
  SampleOptions options;
  options.loop = c.loop();
  sample(clip, time, options, cache_of(s, n, info.caches), out);
  clip_weights(s, c.clip(), time, ow);
}

// ---- blend space ----

/// Fills the sample weights (floats after the phase) from the parameters; returns the sample count.
uint32_t blend_space_weights(State& s, const NodeInfo& info) {
  const auto& b = *static_cast<const fb::BlendSpaceNode*>(info.table);
  const uint32_t count = b.samples()->size();
  const std::span<float> w(&s.floats[info.floats + 1], count);
  const float x = std::clamp(s.params[b.x_parameter()], -kMaxCoordinate, kMaxCoordinate);
  if (b.y_parameter() < 0) {
    blend_space_1d_weights(std::span<const float>(&s.def->sample_x[info.samples], count), x, w);
  } else {
    const float y = std::clamp(s.params[static_cast<size_t>(b.y_parameter())], -kMaxCoordinate, kMaxCoordinate);
    blend_space_2d_weights(s.def->spaces[info.aux], glm::vec2(x, y), w);
  }
  return count;
}

/// The blended cycle: the synchronized duration of the sample clips at their weights, over |rate|.
float blend_space_duration(const State& s, const NodeInfo& info) {
  const auto& b = *static_cast<const fb::BlendSpaceNode*>(info.table);
  const uint32_t count = b.samples()->size();
  const float d = synchronized_duration(std::span<const float>(&s.def->sample_duration[info.samples], count),
                                        std::span<const float>(&s.floats[info.floats + 1], count));
  const float rate = std::fabs(b.rate());
  return rate > 1e-6f ? d / rate : d * 1e6f;
}

void evaluate_blend_space(State& s, uint16_t n, const NodeInfo& info, const Advance& advance, bool dominant,
                          PoseSpan out, std::span<float> ow, uint32_t depth) {
  const auto& b = *static_cast<const fb::BlendSpaceNode*>(info.table);
  const uint32_t count = blend_space_weights(s, info);
  const float* w = &s.floats[info.floats + 1];
  float& phase = s.floats[info.floats];
  const float p0 = phase;
  float p1 = p0;
  if (advance.synced) {
    p1 = p0 + advance.phase * (b.rate() < 0.0f ? -1.0f : 1.0f);
  } else {
    const float d = blend_space_duration(s, info);
    p1 = d > 0.0f ? p0 + advance.dt * (b.rate() < 0.0f ? -1.0f : 1.0f) / d : p0;
  }
  int loops = 0;
  if (b.loop()) {
    const float fl = std::floor(p1);
    loops = static_cast<int>(fl);
    p1 -= fl;
    if (p1 >= 1.0f) p1 = 0.0f;  // rounding of a value just below an integer
  } else {
    p1 = clamp01(p1);
  }
  phase = p1;

  // Active samples (weight > 0), at most three (a triangle) or two (a segment).
  ConstPoseSpan poses[3];
  float weights[3];
  uint32_t active = 0, leader = 0;
  float best = -1.0f;
  uint32_t indices[3];
  for (uint32_t i = 0; i < count && active < 3; ++i) {
    if (!(w[i] > 0.0f)) continue;
    indices[active] = i;
    weights[active] = w[i];
    if (w[i] >= best) {
      best = w[i];
      leader = active;
    }
    ++active;
  }
  SampleOptions options;
  options.loop = b.loop();
  for (uint32_t k = 0; k < active; ++k) {
    const fb::BlendSample& smp = *b.samples()->Get(indices[k]);
    const ClipView& clip = s.def->clips[smp.clip()];
    const float d = clip.duration();
    const float t0 = p0 * d, t1 = p1 * d;
    if (dominant && k == leader) collect_events(s, clip, smp.clip(), n, t0, t1, loops, b.rate() >= 0.0f, b.loop());
    PoseSpan target = active == 1 ? out : s.scratch->poses[depth + k].span();
    sample(clip, t1, options, cache_of(s, n, info.caches + indices[k]), target);
    poses[k] = target;
    // Weights: the first sample's into ow, the others added in with their share.
    if (!ow.empty()) {
      std::span<float> tw = k == 0 ? ow : scratch_weights(s, depth + k);
      clip_weights(s, smp.clip(), t1, tw);
      float sum = 0.0f;
      for (uint32_t i = 0; i <= k; ++i) sum += weights[i];
      if (k > 0) blend_morph_weights(ow, tw, weights[k] / sum, ow);
    }
  }
  if (active > 1) blend_n(std::span<const ConstPoseSpan>(poses, active), std::span<const float>(weights, active), out);
}

// ---- select (blend by bool / int / enum) ----

uint32_t selection(const State& s, const fb::SelectNode& sel) {
  const float v = s.params[sel.parameter()];
  const uint32_t n = sel.children()->size();
  if (!(v > 0.0f)) return 0;
  const auto i = static_cast<uint32_t>(v);
  return i < n ? i : n - 1;
}

/// The child with the most weight (ties: the later one).
uint32_t select_leader(const State& s, const NodeInfo& info, uint32_t n) {
  const float* w = &s.floats[info.floats];
  uint32_t leader = 0;
  for (uint32_t i = 1; i < n; ++i)
    if (w[i] >= w[leader]) leader = i;
  return leader;
}

void evaluate_select(State& s, const NodeInfo& info, const Advance& advance, float weight, bool dominant, PoseSpan out,
                     std::span<float> ow, uint32_t depth) {
  const auto& sel = *static_cast<const fb::SelectNode*>(info.table);
  const uint32_t n = sel.children()->size();
  float* w = &s.floats[info.floats];
  const uint32_t selected = selection(s, sel);
  float total = 0.0f;
  for (uint32_t i = 0; i < n; ++i) {
    w[i] = ease(w[i], i == selected ? 1.0f : 0.0f, advance.dt, sel.blend_time());
    total += w[i];
  }
  if (!(total > 0.0f)) {  // cannot happen after ease (the selected child only grows), but stay safe
    w[selected] = total = 1.0f;
  }
  const uint32_t leader = select_leader(s, info, n);
  // The first active child writes out; each further one is blended in with its share of the
  // weight accumulated so far, which gives the normalized weighted blend.
  float accumulated = 0.0f;
  for (uint32_t i = 0; i < n; ++i) {
    if (!(w[i] > 0.0f)) continue;
    const uint16_t child = sel.children()->Get(i);
    const float share = w[i] / total;
    if (accumulated == 0.0f) {
      evaluate(s, child, advance, weight * share, dominant && i == leader, out, ow, depth);
    } else {
      PoseSpan tmp = s.scratch->poses[depth].span();
      const std::span<float> tw = scratch_weights(s, depth);
      evaluate(s, child, advance, weight * share, dominant && i == leader, tmp, tw, depth + 1);
      blend(out, tmp, w[i] / (accumulated + w[i]), out);
      blend_morph_weights(ow, tw, w[i] / (accumulated + w[i]), ow);
    }
    accumulated += w[i];
  }
}

// ---- layered blend per joint ----

glm::quat nlerp(const glm::quat& a, glm::quat b, float t) {
  if (glm::dot(a, b) < 0.0f) b = -b;
  return glm::normalize(a * (1.0f - t) + b * t);
}

}  // namespace

/// A layer whose rotations blend in model space at the mask roots: the masked subtree is blended
/// locally (vectorized, like any layer), then each mask root gets the local rotation that puts its
/// model rotation at nlerp(base model, layer model, w) under its unmasked parent. At full weight
/// the masked chain therefore has the layer's model-space orientation whatever the base did above
/// it (the spine keeps facing where the layer faces while the hips swing); below the roots, where
/// parents agree, local and model blends coincide, so the cost is the two ancestor chains only.
void blend_mesh_space(State& s, const LayerJoints& lj, std::span<const float> mask, float w, ConstPoseSpan layer,
                      PoseSpan out) {
  const auto parents = s.def->skeleton.parents();
  GraphScratch::Buffers& b = *s.scratch;
  // Base model rotations along the chain, and the roots' base local rotations, before blending.
  for (size_t k = 0; k < lj.chain.size(); ++k) {
    const uint16_t j = lj.chain[k];
    const int p = parents[j];
    const glm::quat qb = rotation_at(out, j), ql = rotation_at(layer, j);
    b.model_base[j] = p >= 0 ? b.model_base[p] * qb : qb;
    b.model_layer[j] = p >= 0 ? b.model_layer[p] * ql : ql;
  }
  blend_layered(out, layer, mask, w, out);
  const glm::quat identity(1.0f, 0.0f, 0.0f, 0.0f);
  for (size_t k = 0; k < lj.chain.size(); ++k) {
    if (!lj.root[k]) continue;
    const uint16_t j = lj.chain[k];
    const int p = parents[j];
    const glm::quat parent = p >= 0 ? b.model_base[p] : identity;  // unmasked: the base's
    const glm::quat model = nlerp(b.model_base[j], b.model_layer[j], clamp01(w * mask[j]));
    set_rotation(out, j, glm::normalize(glm::conjugate(parent) * model));
  }
}

namespace {

void evaluate_layered(State& s, const NodeInfo& info, const Advance& advance, float weight, bool dominant, PoseSpan out,
                      std::span<float> ow, uint32_t depth) {
  const auto& l = *static_cast<const fb::LayeredBlendNode*>(info.table);
  evaluate(s, l.base(), advance, weight, dominant, out, ow, depth);
  const auto& layers = *l.layers();
  for (uint32_t k = 0; k < layers.size(); ++k) {
    const fb::Layer& layer = *layers.Get(k);
    float& current = s.floats[info.floats + k];
    const float target = clamp01(layer.weight() * param_or(s, layer.weight_parameter(), 1.0f));
    current = ease(current, target, advance.dt, layer.blend_time());
    if (!(current > 0.0f)) continue;
    PoseSpan tmp = s.scratch->poses[depth].span();
    const std::span<float> tw = scratch_weights(s, depth);
    evaluate(s, layer.node(), advance, weight * current, dominant && current >= 0.5f, tmp, tw, depth + 1);
    // Morph weights: the layer blends the channels its own clips drive (a face layer over a body),
    // and leaves the others to the base (an upper-body layer does not reset the face).
    const std::vector<float>& morph_mask = s.def->layer_morphs[info.aux + k];
    for (size_t c = 0; c < ow.size(); ++c) ow[c] += (tw[c] - ow[c]) * (current * morph_mask[c]);
    const std::vector<float>& mask = s.def->masks[info.aux + k];
    if (s.hidden >= 0 && s.def->layer_covered[info.aux + k][static_cast<size_t>(s.hidden)]) {
      // Under a slot that covers every joint this layer weighs: only the slot's shown lanes are
      // seen, and there the blend leaves the base (its weight is 0) but for its renormalization,
      // which is kept bit for bit. A mesh-space blend turns only mask roots: all covered.
      for (const auto& [first, last] : s.def->slot_shown_lanes[static_cast<size_t>(s.hidden)])
        blend_layered_lanes(out, tmp, mask, current, out, first, last);
      continue;
    }
    if (layer.mesh_space_rotation()) blend_mesh_space(s, s.def->layer_joints[info.aux + k], mask, current, tmp, out);
    else blend_layered(out, tmp, mask, current, out);
  }
}

// ---- blend by alpha, additive ----

void evaluate_alpha(State& s, const NodeInfo& info, const Advance& advance, float weight, bool dominant, PoseSpan out,
                    std::span<float> ow, uint32_t depth) {
  const auto& a = *static_cast<const fb::BlendAlphaNode*>(info.table);
  const float alpha = clamp01(s.params[a.alpha_parameter()]);
  if (alpha <= 0.0f) return evaluate(s, a.a(), advance, weight, dominant, out, ow, depth);
  if (alpha >= 1.0f) return evaluate(s, a.b(), advance, weight, dominant, out, ow, depth);
  evaluate(s, a.a(), advance, weight * (1.0f - alpha), dominant && alpha < 0.5f, out, ow, depth);
  PoseSpan tmp = s.scratch->poses[depth].span();
  const std::span<float> tw = scratch_weights(s, depth);
  evaluate(s, a.b(), advance, weight * alpha, dominant && alpha >= 0.5f, tmp, tw, depth + 1);
  blend(out, tmp, alpha, out);
  blend_morph_weights(ow, tw, alpha, ow);
}

void evaluate_additive(State& s, const NodeInfo& info, const Advance& advance, float weight, bool dominant,
                       PoseSpan out, std::span<float> ow, uint32_t depth) {
  const auto& a = *static_cast<const fb::AdditiveNode*>(info.table);
  evaluate(s, a.base(), advance, weight, dominant, out, ow, depth);
  const float w = std::clamp(a.weight() * param_or(s, a.weight_parameter(), 1.0f), -kMaxScaledWeight, kMaxScaledWeight);
  if (w == 0.0f) return;
  PoseSpan tmp = s.scratch->poses[depth].span();
  const std::span<float> tw = scratch_weights(s, depth);
  evaluate(s, a.additive(), advance, weight * std::fabs(w), dominant && std::fabs(w) >= 0.5f, tmp, tw, depth + 1);
  make_additive(tmp, s.def->bind, tmp);
  add(out, tmp, w, out);
  // Weights add their difference from the defaults (the additive's reference is the bind pose,
  // whose weights are the defaults).
  for (size_t c = 0; c < ow.size(); ++c) ow[c] += w * (tw[c] - s.def->default_weights[c]);
}

// ---- morph weights from parameters ----

void evaluate_morph(State& s, const NodeInfo& info, const Advance& advance, float weight, bool dominant, PoseSpan out,
                    std::span<float> ow, uint32_t depth) {
  const auto& m = *static_cast<const fb::MorphWeightsNode*>(info.table);
  evaluate(s, m.input(), advance, weight, dominant, out, ow, depth);
  for (uint32_t k = 0; k < m.drives()->size(); ++k) {
    const int32_t c = s.def->drive_channels[info.aux + k];
    if (c < 0) continue;  // a target this character lacks
    const fb::MorphDrive& d = *m.drives()->Get(k);
    ow[static_cast<size_t>(c)] = std::clamp(d.scale() * s.params[d.parameter()], -kMaxScaledWeight, kMaxScaledWeight);
  }
}

}  // namespace

void evaluate(State& s, uint16_t n, const Advance& advance, float weight, bool dominant, PoseSpan out,
              std::span<float> ow, uint32_t depth) {
  const NodeInfo& info = s.def->nodes[n];
  s.node_weights[n] = weight;
  switch (info.kind) {
    case Kind::Clip: return evaluate_clip(s, n, info, advance, dominant, out, ow);
    case Kind::Retarget: return evaluate_retarget(s, n, advance, out, ow);
    case Kind::BlendSpace: return evaluate_blend_space(s, n, info, advance, dominant, out, ow, depth);
    case Kind::Select: return evaluate_select(s, info, advance, weight, dominant, out, ow, depth);
    case Kind::Layered: return evaluate_layered(s, info, advance, weight, dominant, out, ow, depth);
    case Kind::BlendAlpha: return evaluate_alpha(s, info, advance, weight, dominant, out, ow, depth);
    case Kind::Additive: return evaluate_additive(s, info, advance, weight, dominant, out, ow, depth);
    case Kind::Machine: return evaluate_machine(s, n, advance, weight, dominant, out, ow, depth);
    case Kind::Morph: return evaluate_morph(s, info, advance, weight, dominant, out, ow, depth);
    case Kind::TwoBoneIk:
    case Kind::Aim:
    case Kind::FootPlacement:
    case Kind::FootLock:
    case Kind::Spring: return evaluate_procedural(s, n, advance, weight, dominant, out, ow, depth);
    case Kind::Slot: return evaluate_slot(s, n, advance, weight, dominant, out, ow, depth);
  }
}

void restart(State& s, uint16_t n) {
  const NodeInfo& info = s.def->nodes[n];
  switch (info.kind) {
    case Kind::Clip: {
      const auto& c = *static_cast<const fb::ClipNode*>(info.table);
      s.floats[info.floats] = std::clamp(c.start_offset(), 0.0f, s.def->clips[c.clip()].duration());
      return;
    }
    case Kind::BlendSpace:
      s.floats[info.floats] = 0.0f;
      blend_space_weights(s, info);
      return;
    case Kind::Select: {
      const auto& sel = *static_cast<const fb::SelectNode*>(info.table);
      const uint32_t selected = selection(s, sel);
      for (uint32_t i = 0; i < sel.children()->size(); ++i) {
        s.floats[info.floats + i] = i == selected ? 1.0f : 0.0f;
        restart(s, sel.children()->Get(i));
      }
      return;
    }
    case Kind::Layered: {
      const auto& l = *static_cast<const fb::LayeredBlendNode*>(info.table);
      restart(s, l.base());
      for (uint32_t k = 0; k < l.layers()->size(); ++k) {
        const fb::Layer& layer = *l.layers()->Get(k);
        s.floats[info.floats + k] = clamp01(layer.weight() * param_or(s, layer.weight_parameter(), 1.0f));
        restart(s, layer.node());
      }
      return;
    }
    case Kind::BlendAlpha: {
      const auto& a = *static_cast<const fb::BlendAlphaNode*>(info.table);
      restart(s, a.a());
      restart(s, a.b());
      return;
    }
    case Kind::Additive: {
      const auto& a = *static_cast<const fb::AdditiveNode*>(info.table);
      restart(s, a.base());
      restart(s, a.additive());
      return;
    }
    case Kind::Retarget: return restart_retarget(s, info);
    case Kind::Machine: return restart_machine(s, info.machine);
    case Kind::Morph: return restart(s, static_cast<const fb::MorphWeightsNode*>(info.table)->input());
    case Kind::TwoBoneIk:
    case Kind::Aim:
    case Kind::FootPlacement:
    case Kind::FootLock:
    case Kind::Spring: return restart_procedural(s, n);
    case Kind::Slot: return restart(s, s.def->slots[info.aux].input);
  }
}

Cycle cycle(const State& s, uint16_t n) {
  const NodeInfo& info = s.def->nodes[n];
  switch (info.kind) {
    case Kind::Clip: {
      const auto& c = *static_cast<const fb::ClipNode*>(info.table);
      const float d = s.def->clips[c.clip()].duration();
      const float rate = std::fabs(clip_rate(s, c));
      Cycle out;
      out.duration = d > 0.0f ? (rate > 1e-6f ? d / rate : d * 1e6f) : 1.0f;
      out.phase = d > 0.0f ? s.floats[info.floats] / d : 0.0f;
      out.loop = c.loop();
      return out;
    }
    case Kind::BlendSpace: {
      Cycle out;
      const float d = blend_space_duration(s, info);
      out.duration = d > 0.0f ? d : 1.0f;
      out.phase = s.floats[info.floats];
      out.loop = static_cast<const fb::BlendSpaceNode*>(info.table)->loop();
      return out;
    }
    case Kind::Select: {
      const auto& sel = *static_cast<const fb::SelectNode*>(info.table);
      return cycle(s, sel.children()->Get(select_leader(s, info, sel.children()->size())));
    }
    case Kind::Layered: return cycle(s, static_cast<const fb::LayeredBlendNode*>(info.table)->base());
    case Kind::BlendAlpha: {
      const auto& a = *static_cast<const fb::BlendAlphaNode*>(info.table);
      return cycle(s, s.params[a.alpha_parameter()] < 0.5f ? a.a() : a.b());
    }
    case Kind::Additive: return cycle(s, static_cast<const fb::AdditiveNode*>(info.table)->base());
    case Kind::Retarget: return retarget_cycle(s, info);
    case Kind::Machine: return machine_cycle(s, info.machine);
    case Kind::Morph: return cycle(s, static_cast<const fb::MorphWeightsNode*>(info.table)->input());
    case Kind::TwoBoneIk:
    case Kind::Aim:
    case Kind::FootPlacement:
    case Kind::FootLock:
    case Kind::Spring: return cycle(s, procedural_input(info));
    case Kind::Slot: return cycle(s, s.def->slots[info.aux].input);
  }
  return {};
}

void set_phase(State& s, uint16_t n, float p) {
  const NodeInfo& info = s.def->nodes[n];
  p = clamp01(p);
  switch (info.kind) {
    case Kind::Clip: {
      const auto& c = *static_cast<const fb::ClipNode*>(info.table);
      const float d = s.def->clips[c.clip()].duration();
      s.floats[info.floats] = std::min(p * d, d);
      return;
    }
    case Kind::BlendSpace:
      s.floats[info.floats] = p >= 1.0f && static_cast<const fb::BlendSpaceNode*>(info.table)->loop() ? 0.0f : p;
      return;
    case Kind::Select:
      for (uint16_t c : *static_cast<const fb::SelectNode*>(info.table)->children()) set_phase(s, c, p);
      return;
    case Kind::Layered: {
      const auto& l = *static_cast<const fb::LayeredBlendNode*>(info.table);
      set_phase(s, l.base(), p);
      for (const fb::Layer* layer : *l.layers()) set_phase(s, layer->node(), p);
      return;
    }
    case Kind::BlendAlpha: {
      const auto& a = *static_cast<const fb::BlendAlphaNode*>(info.table);
      set_phase(s, a.a(), p);
      set_phase(s, a.b(), p);
      return;
    }
    case Kind::Additive: {
      const auto& a = *static_cast<const fb::AdditiveNode*>(info.table);
      set_phase(s, a.base(), p);
      set_phase(s, a.additive(), p);
      return;
    }
    case Kind::Retarget: return set_retarget_phase(s, info, p);
    case Kind::Machine: return set_machine_phase(s, info.machine, p);
    case Kind::Morph: return set_phase(s, static_cast<const fb::MorphWeightsNode*>(info.table)->input(), p);
    case Kind::TwoBoneIk:
    case Kind::Aim:
    case Kind::FootPlacement:
    case Kind::FootLock:
    case Kind::Spring: return set_phase(s, procedural_input(info), p);
    case Kind::Slot: return set_phase(s, s.def->slots[info.aux].input, p);
  }
}

}  // namespace ossa::graph_detail
