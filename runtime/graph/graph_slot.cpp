// graph_slot.cpp — the slot node: where montages show (graph.h, format/ossa.fbs SlotNode).
//
// The slot evaluates its input, then puts the montages of its group that have a track for it over
// that pose. Override: the montages' poses are blended together by their weights (older first, each
// later one over them, so an interrupting montage blending in covers the one blending out), and the
// result replaces the input on the slot's joints by the weights' sum (at most 1); without a mask and
// at full weight the input is not evaluated at all (it would not be seen), as any graph input with
// no weight. Additive: each montage adds its track's change from the track's first frame, by its
// weight. With no montage weight the input passes through untouched, bit for bit.
//
// An inertialized blend (a curve of Inertialize) switches weights at once; in the update where that
// happens the slot evaluates the pose it would have had with the weights from before the switch,
// and the difference to the new pose becomes an offset that decays to zero over the blend time along
// the quintic the state machines use (graph_machine.cpp), starting with the velocity of the slot's
// own last outputs: no pop, no lag. Only slots of a group with an inertializing montage keep that
// history.
//
// What nobody will see is not computed, where that keeps every seen bit: a masked slot samples its
// montages' clips for the joints it shows only (a filtered sampling cache, slot_shown_joints), and
// while a masked override at full weight evaluates its input, State::hidden names its mask, so what
// that input computes is the lanes the slot shows: a layer whose mask the slot covers blends only
// those (graph_eval.cpp), a clip or blend space samples a cache filtered to them, and a machine of
// pure states evaluates them and replays its history whole when a capture needs it
// (graph_machine.cpp). Only nodes reached with nothing on the way that keeps poses (another
// machine's history, a slot's, spring and foot lock state) or reads model space (procedural nodes)
// are marked (mark_reach, Impl::node_hidden). bind_slots decodes the slot nodes for the definition.
#include <algorithm>
#include <cmath>
#include <cstring>

#include "graph/graph_internal.h"
#include <ossa/anim/morph.h>
#include <ossa/anim/pose_ops.h>

namespace ossa::graph_detail {
namespace {

using State = GraphInstance::State;

struct Entry {
  MontagePlay* play = nullptr;
  const TrackInfo* track = nullptr;
};

/// Copies the masked joints (ranges of joints) of `from` into `to`; the others keep their bits.
void copy_ranges(const std::vector<std::pair<uint32_t, uint32_t>>& ranges, ConstPoseSpan from, PoseSpan to) {
  for (uint32_t k = 0; k < kPoseComponents; ++k)
    for (const auto& [first, last] : ranges)
      std::memcpy(to[PoseComponent(k)] + first, from[PoseComponent(k)] + first, sizeof(float) * (last - first));
}

/// Puts the entries' poses, at weight `now` or `before`, over `out` (and their morph weights over ow).
void combine(State& s, const SlotInfo& slot, const Entry* entries, uint32_t count, bool before, float weight,
             PoseSpan out, std::span<float> ow, uint32_t depth) {
  const GraphDefinition::Impl& d = *s.def;
  PoseSpan sum = s.scratch->poses[depth].span(), tmp = s.scratch->poses[depth + 1].span();
  const std::span<float> tw = scratch_weights(s, depth + 1);
  // With a mask the result is made aside and only the masked joints are copied in: a blend at
  // weight 0 renormalizes rotations, which would change unmasked joints' last bits.
  const bool masked = slot.mask >= 0;
  if (slot.additive && masked) copy_pose(out, sum);
  PoseSpan added = masked ? sum : out;
  bool any = false;
  float acc = 0.0f;
  for (uint32_t k = 0; k < count; ++k) {
    MontagePlay& p = *entries[k].play;
    const float w = before ? p.weight_before : p.weight;
    if (!(w > 0.0f)) continue;
    const bool first = acc == 0.0f;
    uint16_t clip = 0;
    float time = 0.0f;
    PoseSpan target = slot.additive || !first ? tmp : sum;
    sample_track(s, *entries[k].track, p.position, target, &clip, &time);
    if (!before) p.slot_weight = std::max(p.slot_weight, weight * std::min(w, 1.0f));
    if (!ow.empty()) {  // the channels the montage's clip drives move towards its weights
      std::copy(ow.begin(), ow.end(), tw.begin());
      sample_morph_weights(d.clips[clip], time, d.clip_channels[clip], tw);
      blend_morph_weights(ow, tw, std::min(w, 1.0f), ow);
    }
    if (slot.additive) {
      make_additive(tmp, d.track_reference[static_cast<size_t>(entries[k].track - d.tracks.data())], tmp);
      add(added, tmp, w, added);
      any = true;
      continue;
    }
    acc += w;
    if (!first) blend(sum, tmp, w / acc, sum);
  }
  if (slot.additive) {
    if (masked && any) copy_ranges(d.slot_ranges[static_cast<size_t>(slot.mask)], sum, out);
    return;
  }
  if (!(acc > 0.0f)) return;
  const float t = std::min(acc, 1.0f);
  if (masked && t >= 1.0f) {  // at full weight the masked joints are the montages' pose: no blend
    const auto& ranges = d.slot_ranges[static_cast<size_t>(slot.mask)];
    if (!slot.mesh_space) return copy_ranges(ranges, sum, out);
    // In mesh space the mask roots take the montages' model rotation under the input's parents.
    const LayerJoints& lj = d.slot_joints[static_cast<size_t>(slot.mask)];
    const auto parents = d.skeleton.parents();
    GraphScratch::Buffers& b = *s.scratch;
    for (const uint16_t j : lj.chain) {
      const int p = parents[j];
      const glm::quat qb = rotation_at(out, j), ql = rotation_at(sum, j);
      b.model_base[j] = p >= 0 ? b.model_base[static_cast<size_t>(p)] * qb : qb;
      b.model_layer[j] = p >= 0 ? b.model_layer[static_cast<size_t>(p)] * ql : ql;
    }
    copy_ranges(ranges, sum, out);
    for (size_t k = 0; k < lj.chain.size(); ++k) {
      if (!lj.root[k]) continue;
      const uint16_t j = lj.chain[k];
      const int p = parents[j];
      const glm::quat parent = p >= 0 ? b.model_base[static_cast<size_t>(p)] : glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
      set_rotation(out, j, glm::normalize(glm::conjugate(parent) * glm::normalize(b.model_layer[j])));
    }
    return;
  }
  if (masked) {
    const std::vector<float>& mask = d.slot_masks[static_cast<size_t>(slot.mask)];
    if (slot.mesh_space) {
      copy_pose(out, tmp);
      blend_mesh_space(s, d.slot_joints[static_cast<size_t>(slot.mask)], mask, t, sum, tmp);
    } else {
      blend_layered(out, sum, mask, t, tmp);
    }
    copy_ranges(d.slot_ranges[static_cast<size_t>(slot.mask)], tmp, out);
  } else if (t >= 1.0f) {
    copy_pose(sum, out);
  } else {
    blend(out, sum, t, out);
  }
}

/// Starts the offset that carries `before` (the pose without the switch) into `after`, with the
/// velocity of the slot's last two outputs when they are from the two updates before this one.
void capture(const State& s, MachineState& m, ConstPoseSpan before, ConstPoseSpan after, float duration) {
  const bool velocity = m.last_update != 0 && m.last_update + 1 == s.update_counter &&
                        m.before_last_update + 1 == m.last_update && m.last_dt > 0.0f;
  const float inv_dt = velocity ? 1.0f / m.last_dt : 0.0f;
  const ConstPoseSpan last = m.last.span(), older = m.before_last.span();
  for (uint32_t j = 0; j < s.def->joints; ++j) {
    glm::vec3 vt(0.0f), vr(0.0f);
    if (velocity) {
      vt = glm::vec3(last[kTx][j] - older[kTx][j], last[kTy][j] - older[kTy][j], last[kTz][j] - older[kTz][j]) * inv_dt;
      vr = rotation_vector(rotation_at(last, j) * glm::conjugate(rotation_at(older, j))) * inv_dt;
    }
    const glm::vec3 offset(before[kTx][j] - after[kTx][j], before[kTy][j] - after[kTy][j],
                           before[kTz][j] - after[kTz][j]);
    init_channel(m.translation[j], offset, vt, duration);
    init_channel(m.rotation[j], rotation_vector(rotation_at(before, j) * glm::conjugate(rotation_at(after, j))), vr,
                 duration);
  }
  m.inertial = true;
  m.inertial_elapsed = 0.0f;
  m.inertial_duration = duration;
}

}  // namespace

void evaluate_slot(State& s, uint16_t n, const Advance& advance, float weight, bool dominant, PoseSpan out,
                   std::span<float> ow, uint32_t depth) {
  const GraphDefinition::Impl& d = *s.def;
  const SlotInfo& slot = d.slots[d.nodes[n].aux];
  if (!s.montages_active && slot.inertia < 0)  // nothing plays and nothing to remember: the input as it is
    return evaluate(s, slot.input, advance, weight, dominant, out, ow, depth);
  Entry entries[kMaxMontagePlays];
  uint32_t count = 0;
  float total = 0.0f, total_before = 0.0f, switch_time = 0.0f;
  for (MontagePlay& p : s.plays) {
    if (p.montage < 0 || (!(p.weight > 0.0f) && !(p.weight_before > 0.0f))) continue;
    const MontageInfo& mi = d.montages[static_cast<size_t>(p.montage)];
    if (mi.group != slot.group) continue;
    const TrackInfo* track = track_for(d, mi, slot.slot);
    if (!track) continue;
    uint32_t at = count++;  // kept in play order
    for (; at > 0 && entries[at - 1].play->serial > p.serial; --at) entries[at] = entries[at - 1];
    entries[at] = {&p, track};
    total += std::max(p.weight, 0.0f);
    total_before += std::max(p.weight_before, 0.0f);
    if (p.switch_update == s.update_counter) switch_time = std::max(switch_time, p.switch_time);
  }
  MachineState* inertia = slot.inertia >= 0 ? &s.slot_inertia[static_cast<size_t>(slot.inertia)] : nullptr;
  const bool switched = inertia && switch_time > 0.0f;
  const bool replaces_all = !slot.additive && slot.mask < 0;
  const auto input_seen = [&](float t) { return !replaces_all || t < 1.0f; };
  if (input_seen(total) || (switched && input_seen(total_before))) {
    const float shown = replaces_all ? 1.0f - std::min(total, 1.0f) : 1.0f;
    // A masked override at full weight (and no switch, whose pose from before needs the input's
    // masked joints) shows only the input's unmasked joints: the input may skip blending the rest.
    float full = 0.0f;  // the weights summed as combine() sums them
    for (uint32_t k = 0; k < count; ++k)
      if (entries[k].play->weight > 0.0f) full += entries[k].play->weight;
    const int32_t hidden = s.hidden;
    if (!slot.additive && slot.mask >= 0 && full >= 1.0f && !switched) s.hidden = slot.mask;
    evaluate(s, slot.input, advance, weight * shown, dominant && shown >= 0.5f, out, ow, depth);
    s.hidden = hidden;
  } else {
    std::copy(d.default_weights.begin(), d.default_weights.end(), ow.begin());
  }
  if (count == 0 && !inertia) return;  // nothing playing here: the input as it is

  if (switched) {  // the pose without the switch, into the third scratch pose
    PoseSpan before = s.scratch->poses[depth + 2].span();
    const std::span<float> before_weights = scratch_weights(s, depth + 2);
    copy_pose(out, before);
    std::copy(ow.begin(), ow.end(), before_weights.begin());
    combine(s, slot, entries, count, true, weight, before, before_weights, depth);
    combine(s, slot, entries, count, false, weight, out, ow, depth);
    capture(s, *inertia, before, out, switch_time);
  } else if (count > 0) {
    combine(s, slot, entries, count, false, weight, out, ow, depth);
  }
  if (!inertia) return;
  if (inertia->inertial && !switched) {
    inertia->inertial_elapsed += advance.dt;
    if (inertia->inertial_elapsed >= inertia->inertial_duration) inertia->inertial = false;
  }
  if (inertia->inertial) apply_offset(s, *inertia, out);
  // Keep this output for a later capture's velocity: the older buffer becomes the newest.
  std::swap(inertia->last, inertia->before_last);
  inertia->before_last_update = inertia->last_update;
  stream_pose(out, inertia->last);
  inertia->last_update = s.update_counter;
  inertia->last_dt = advance.dt;
}

namespace {

/// Whether everything node `n` reaches is a clip, a blend space or a blend (no node that keeps
/// poses, reads model space or plays another rig): what a machine's states must be for it to leave
/// a covering slot's joints out and still replay its history whole.
bool pure_subtree(const GraphDefinition::Impl& d, uint16_t n, uint32_t depth = 0) {
  if (depth > d.nodes.size()) return false;  // validation proved the graph acyclic; stay bounded anyway
  const NodeInfo& info = d.nodes[n];
  const auto go = [&](uint16_t child) { return pure_subtree(d, child, depth + 1); };
  switch (info.kind) {
    case Kind::Clip:
    case Kind::BlendSpace: return true;
    case Kind::BlendAlpha: {
      const auto* t = static_cast<const fb::BlendAlphaNode*>(info.table);
      return go(t->a()) && go(t->b());
    }
    case Kind::Select:
      for (uint16_t c : *static_cast<const fb::SelectNode*>(info.table)->children())
        if (!go(c)) return false;
      return true;
    case Kind::Layered: {
      const auto* t = static_cast<const fb::LayeredBlendNode*>(info.table);
      if (!go(t->base())) return false;
      for (const fb::Layer* layer : *t->layers())
        if (!go(layer->node())) return false;
      return true;
    }
    case Kind::Additive: {
      const auto* t = static_cast<const fb::AdditiveNode*>(info.table);
      return go(t->base()) && go(t->additive());
    }
    case Kind::Morph: return go(static_cast<const fb::MorphWeightsNode*>(info.table)->input());
    default: return false;
  }
}

/// Whether machine node `n` may evaluate a covering slot's shown lanes only (graph_machine.cpp).
bool hidden_machine(const GraphDefinition::Impl& d, const NodeInfo& info) {
  for (const fb::State* st : *d.machines[info.machine].fb->states())
    if (!pure_subtree(d, st->node())) return false;
  return true;
}

/// Marks what node `n` reaches, itself included: in `open` what it reaches with no node that keeps
/// poses or reads model space on the way (a layer there may leave a covering slot's joints
/// unblended, a clip need not sample them), in `closed` what it reaches through one (it may not:
/// that node needs whole poses). A machine whose states are pure (hidden_machine) keeps the way
/// open: it makes its history whole by replaying it when a capture needs it.
void mark_reach(const GraphDefinition::Impl& d, uint16_t n, bool through, std::vector<uint8_t>& open,
                std::vector<uint8_t>& closed) {
  std::vector<uint8_t>& seen = through ? closed : open;
  if (seen[n]) return;
  seen[n] = 1;
  const NodeInfo& info = d.nodes[n];
  const auto go = [&](uint16_t child, bool memory) { mark_reach(d, child, through || memory, open, closed); };
  switch (info.kind) {
    case Kind::Clip:
    case Kind::Retarget:
    case Kind::BlendSpace: return;
    case Kind::BlendAlpha: {
      const auto* t = static_cast<const fb::BlendAlphaNode*>(info.table);
      go(t->a(), false);
      go(t->b(), false);
      return;
    }
    case Kind::Select:
      for (uint16_t c : *static_cast<const fb::SelectNode*>(info.table)->children()) go(c, false);
      return;
    case Kind::Layered: {
      const auto* t = static_cast<const fb::LayeredBlendNode*>(info.table);
      go(t->base(), false);
      for (const fb::Layer* layer : *t->layers()) go(layer->node(), false);
      return;
    }
    case Kind::Additive: {
      const auto* t = static_cast<const fb::AdditiveNode*>(info.table);
      go(t->base(), false);
      go(t->additive(), false);
      return;
    }
    case Kind::Morph: return go(static_cast<const fb::MorphWeightsNode*>(info.table)->input(), false);
    case Kind::Machine: {
      const bool keeps = !hidden_machine(d, info);
      for (const fb::State* st : *d.machines[info.machine].fb->states()) go(st->node(), keeps);
      return;
    }
    case Kind::Slot: return go(static_cast<const fb::SlotNode*>(info.table)->input(), true);
    case Kind::TwoBoneIk:
    case Kind::Aim:
    case Kind::FootPlacement:
    case Kind::FootLock:
    case Kind::Spring: return go(procedural_input(info), true);
  }
}

}  // namespace

void bind_slots(GraphDefinition::Impl& d) {
  const auto parents = d.skeleton.parents();
  for (NodeInfo& info : d.nodes) {
    if (info.kind != Kind::Slot) continue;
    const auto* t = static_cast<const fb::SlotNode*>(info.table);
    SlotInfo slot;
    slot.input = t->input();
    slot.slot = intern_name(d.slot_names, flatbuffers::GetStringView(t->slot()));
    slot.group = intern_name(d.groups, flatbuffers::GetStringView(t->group()));
    slot.additive = t->additive();
    if (t->mask() && t->mask()->size() > 0) {
      std::vector<float> mask(d.joints, 0.0f);
      for (const fb::MaskEntry* e : *t->mask()) build_joint_mask(parents, e->joint(), e->depth(), mask);
      LayerJoints lj;  // mask roots and their ancestors, as a layer's (graph_definition.cpp)
      std::vector<uint8_t> on_chain(d.joints, 0), is_root(d.joints, 0);
      for (uint32_t j = 0; j < d.joints; ++j) {
        const int p = parents[j];
        if (!(mask[j] > 0.0f) || (p >= 0 && mask[static_cast<size_t>(p)] > 0.0f)) continue;
        is_root[j] = 1;
        for (int a = static_cast<int>(j); a >= 0 && !on_chain[static_cast<size_t>(a)];
             a = parents[static_cast<size_t>(a)])
          on_chain[static_cast<size_t>(a)] = 1;
      }
      for (uint32_t j = 0; j < d.joints; ++j) {
        if (!on_chain[j]) continue;
        lj.chain.push_back(static_cast<uint16_t>(j));
        lj.root.push_back(is_root[j]);
      }
      std::vector<std::pair<uint32_t, uint32_t>> ranges;
      for (uint32_t j = 0; j < d.joints; ++j) {
        if (!(mask[j] > 0.0f)) continue;
        if (!ranges.empty() && ranges.back().second == j) ranges.back().second = j + 1;
        else ranges.emplace_back(j, j + 1);
      }
      std::vector<std::pair<uint32_t, uint32_t>> shown;  // blocks with an unmasked joint
      for (uint32_t j = 0; j < d.joints; j += kPoseLanes) {
        bool any = false;
        for (uint32_t k = j; k < std::min(j + kPoseLanes, d.joints); ++k) any |= !(mask[k] > 0.0f);
        if (!any) continue;
        if (!shown.empty() && shown.back().second == j) shown.back().second = j + kPoseLanes;
        else shown.emplace_back(j, j + kPoseLanes);
      }
      std::vector<uint8_t> visible(d.joints, 0);
      for (uint32_t j = 0; j < d.joints; ++j) visible[j] = mask[j] > 0.0f ? 0 : 1;
      slot.mask = static_cast<int32_t>(d.slot_masks.size());
      slot.mesh_space = t->mesh_space_rotation() && !slot.additive;
      d.slot_visible.push_back(std::move(visible));
      d.slot_shown_lanes.push_back(std::move(shown));
      d.slot_ranges.push_back(std::move(ranges));
      d.slot_masks.push_back(std::move(mask));
      d.slot_joints.push_back(std::move(lj));
    }
    info.aux = static_cast<uint32_t>(d.slots.size());
    d.slots.push_back(slot);
  }
  d.layer_covered.assign(d.masks.size(), std::vector<uint8_t>(d.slot_masks.size(), 0));
  d.node_hidden.assign(d.nodes.size(), -1);
  constexpr int32_t kConflict = -2;  // reached hidden by two masks: by neither
  for (const SlotInfo& slot : d.slots) {
    if (slot.mask < 0) continue;
    std::vector<uint8_t> open(d.nodes.size(), 0), closed(d.nodes.size(), 0);
    mark_reach(d, slot.input, false, open, closed);
    const std::vector<float>& mask = d.slot_masks[static_cast<size_t>(slot.mask)];
    for (size_t n = 0; n < d.nodes.size(); ++n) {
      const NodeInfo& info = d.nodes[n];
      if (!open[n] || closed[n]) continue;
      const bool samples = (info.kind == Kind::Clip && info.held < 0) || info.kind == Kind::BlendSpace;
      if (!slot.additive && (samples || info.kind == Kind::Machine)) {
        int32_t& h = d.node_hidden[n];
        h = h == -1 || h == slot.mask ? slot.mask : kConflict;
      }
      if (info.kind != Kind::Layered) continue;
      const auto* t = static_cast<const fb::LayeredBlendNode*>(info.table);
      for (uint32_t k = 0; k < t->layers()->size(); ++k) {
        const std::vector<float>& layer = d.masks[info.aux + k];
        bool covered = true;
        for (uint32_t j = 0; j < d.joints && covered; ++j) covered = !(layer[j] > 0.0f) || mask[j] > 0.0f;
        d.layer_covered[info.aux + k][static_cast<size_t>(slot.mask)] = covered ? 1 : 0;
      }
    }
  }
  // Filtered prototypes for the clips sampled hidden: one mask per clip (a node whose clip has
  // another mask's prototype is not sampled hidden, it samples whole).
  d.hidden_prototypes.resize(d.clips.size());
  d.hidden_prototype_mask.assign(d.clips.size(), -1);
  for (size_t n = 0; n < d.nodes.size(); ++n) {
    int32_t& h = d.node_hidden[n];
    if (h == kConflict) h = -1;
    const NodeInfo& info = d.nodes[n];
    if (h < 0 || info.kind == Kind::Machine) continue;
    const std::vector<uint16_t> clips = sampled_clips(info);
    for (const uint16_t c : clips)
      if (d.hidden_prototype_mask[c] != -1 && d.hidden_prototype_mask[c] != h) h = -1;
    if (h < 0) continue;
    for (const uint16_t c : clips) {
      if (d.hidden_prototype_mask[c] == h) continue;
      auto prototype = make_sampling_cache(d.clips[c], d.skeleton, nullptr, d.slot_visible[static_cast<size_t>(h)]);
      if (!prototype) {  // the clip was bound to this rig with these very checks: cannot happen
        h = -1;
        break;
      }
      d.hidden_prototypes[c] = std::move(*prototype);
      d.hidden_prototype_mask[c] = h;
    }
  }
}

std::vector<uint16_t> sampled_clips(const NodeInfo& info) {
  if (info.kind == Kind::Clip) return {static_cast<const fb::ClipNode*>(info.table)->clip()};
  std::vector<uint16_t> clips;
  if (info.kind == Kind::BlendSpace)
    for (const fb::BlendSample* smp : *static_cast<const fb::BlendSpaceNode*>(info.table)->samples())
      clips.push_back(smp->clip());
  return clips;
}

/// The joints the slot nodes named `slot` read from a montage's pose: their masks and the chains a
/// mesh-space rotation walks (1 each); empty (every joint) when one of them has no mask.
std::vector<uint8_t> slot_shown_joints(const GraphDefinition::Impl& d, uint16_t slot) {
  std::vector<uint8_t> shown(d.joints, 0);
  for (const SlotInfo& info : d.slots) {
    if (info.slot != slot) continue;
    if (info.mask < 0) return {};
    const auto mask = static_cast<size_t>(info.mask);
    for (const auto& [first, last] : d.slot_ranges[mask]) std::fill(shown.begin() + first, shown.begin() + last, 1);
    for (const uint16_t j : d.slot_joints[mask].chain) shown[j] = 1;
  }
  return shown;
}

}  // namespace ossa::graph_detail
