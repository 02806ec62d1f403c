// graph_definition.cpp — binding a cooked graph to its clips and precomputing what every instance
// shares (graph.h, graph_internal.h). Runs once per graph; allocation is fine here.
//
// The file was validated when it was opened (validate_graph.cpp): indices are in range, the node
// tree is children first and shallow, conditions are well formed. What validation cannot know is
// checked here: that the clips named exist (in this file or the extra clip files) and are bound to
// this rig, and that 2D blend-space points triangulate.
#include <algorithm>
#include <cstdio>

#include <ossa/anim/morph.h>
#include "graph/graph_internal.h"
#include <ossa/anim/pose_ops.h>

namespace ossa {
using namespace graph_detail;

namespace {

const fb::Clip* find_clip(const Asset& asset, std::string_view name) {
  const auto* clips = asset.file().clips();
  if (!clips) return nullptr;
  for (const fb::Clip* c : *clips)
    if (flatbuffers::GetStringView(c->name()) == name) return c;
  return nullptr;
}

/// Whether joint a is b or one of b's ancestors.
bool ancestor_of(std::span<const int16_t> parents, uint32_t a, uint32_t b) {
  for (int j = static_cast<int>(b); j >= 0; j = parents[static_cast<size_t>(j)])
    if (static_cast<uint32_t>(j) == a) return true;
  return false;
}

/// The chain a > b > c (each a strict ancestor of the next), or an error naming the joints.
std::string chain_error(const SkeletonView& skeleton, std::initializer_list<uint32_t> joints) {
  const auto parents = skeleton.parents();
  const uint32_t* prev = nullptr;
  for (const uint32_t& j : joints) {
    if (prev && (*prev == j || !ancestor_of(parents, *prev, j)))
      return "joint '" + std::string(skeleton.joint_name(*prev)) + "' is not an ancestor of '" +
             std::string(skeleton.joint_name(j)) + "'";
    prev = &j;
  }
  return {};
}

}  // namespace

size_t graph_count(const Asset& asset) {
  const auto* graphs = asset.file().graphs();
  return graphs ? graphs->size() : 0;
}

const fb::Graph* find_graph(const Asset& asset, std::string_view name) {
  const auto* graphs = asset.file().graphs();
  if (!graphs) return nullptr;
  for (const fb::Graph* g : *graphs)
    if (flatbuffers::GetStringView(g->name()) == name) return g;
  return nullptr;
}

namespace graph_detail {

uint32_t scratch_needed(const GraphDefinition::Impl& def, uint16_t n) {
  const NodeInfo& info = def.nodes[n];
  switch (info.kind) {
    case Kind::Clip:
    case Kind::Retarget: return 0;
    case Kind::BlendAlpha: {
      const auto* t = static_cast<const fb::BlendAlphaNode*>(info.table);
      return std::max(scratch_needed(def, t->a()), 1 + scratch_needed(def, t->b()));
    }
    case Kind::Select: {
      uint32_t need = 0;
      for (uint16_t c : *static_cast<const fb::SelectNode*>(info.table)->children())
        need = std::max(need, 1 + scratch_needed(def, c));
      return need;
    }
    case Kind::Layered: {
      const auto* t = static_cast<const fb::LayeredBlendNode*>(info.table);
      uint32_t need = scratch_needed(def, t->base());
      for (const fb::Layer* layer : *t->layers()) need = std::max(need, 1 + scratch_needed(def, layer->node()));
      return need;
    }
    case Kind::BlendSpace: {
      const auto* t = static_cast<const fb::BlendSpaceNode*>(info.table);
      return std::min<uint32_t>(t->samples()->size(), t->y_parameter() < 0 ? 2 : 3);
    }
    case Kind::Additive: {
      const auto* t = static_cast<const fb::AdditiveNode*>(info.table);
      return std::max(scratch_needed(def, t->base()), 1 + scratch_needed(def, t->additive()));
    }
    case Kind::Machine: {
      uint32_t need = 0;
      for (const fb::State* st : *def.machines[info.machine].fb->states())
        need = std::max(need, 1 + scratch_needed(def, st->node()));
      return need;
    }
    case Kind::Morph: return scratch_needed(def, static_cast<const fb::MorphWeightsNode*>(info.table)->input());
    case Kind::TwoBoneIk:
    case Kind::Aim:
    case Kind::FootPlacement:
    case Kind::FootLock:
    case Kind::Spring: return scratch_needed(def, procedural_input(info));
    case Kind::Slot: {  // the montages' pose and one more, plus the pose before a switch when inertialized
      const SlotInfo& slot = def.slots[info.aux];
      return std::max(scratch_needed(def, slot.input), slot.inertia >= 0 ? 3u : 2u);
    }
  }
  return 0;
}

}  // namespace graph_detail

GraphDefinition::GraphDefinition(std::unique_ptr<Impl> impl) : impl_(std::move(impl)) {}
GraphDefinition::GraphDefinition(GraphDefinition&&) noexcept = default;
GraphDefinition& GraphDefinition::operator=(GraphDefinition&&) noexcept = default;
GraphDefinition::~GraphDefinition() = default;

namespace {

/// Sets mask[c] = 1 for every channel a clip in node n's subtree has a weight track for.
void mark_driven_channels(const GraphDefinition::Impl& d, uint16_t n, std::vector<float>& mask) {
  const auto mark_clip = [&](uint16_t clip) {
    for (const int32_t c : d.clip_channels[clip])
      if (c >= 0) mask[static_cast<size_t>(c)] = 1.0f;
  };
  const NodeInfo& info = d.nodes[n];
  switch (info.kind) {
    case Kind::Clip: return mark_clip(static_cast<const fb::ClipNode*>(info.table)->clip());
    case Kind::Retarget: return;  // its clip's weight tracks are not played (graph_retarget.cpp)
    case Kind::BlendSpace:
      for (const fb::BlendSample* smp : *static_cast<const fb::BlendSpaceNode*>(info.table)->samples())
        mark_clip(smp->clip());
      return;
    case Kind::Select:
      for (uint16_t c : *static_cast<const fb::SelectNode*>(info.table)->children()) mark_driven_channels(d, c, mask);
      return;
    case Kind::Layered: {
      const auto* t = static_cast<const fb::LayeredBlendNode*>(info.table);
      mark_driven_channels(d, t->base(), mask);
      for (const fb::Layer* layer : *t->layers()) mark_driven_channels(d, layer->node(), mask);
      return;
    }
    case Kind::BlendAlpha: {
      const auto* t = static_cast<const fb::BlendAlphaNode*>(info.table);
      mark_driven_channels(d, t->a(), mask);
      mark_driven_channels(d, t->b(), mask);
      return;
    }
    case Kind::Additive: {
      const auto* t = static_cast<const fb::AdditiveNode*>(info.table);
      mark_driven_channels(d, t->base(), mask);
      mark_driven_channels(d, t->additive(), mask);
      return;
    }
    case Kind::Machine:
      for (const fb::State* st : *d.machines[info.machine].fb->states()) mark_driven_channels(d, st->node(), mask);
      return;
    case Kind::Morph: {
      const auto* t = static_cast<const fb::MorphWeightsNode*>(info.table);
      mark_driven_channels(d, t->input(), mask);
      for (uint32_t k = 0; k < t->drives()->size(); ++k)
        if (const int32_t c = d.drive_channels[info.aux + k]; c >= 0) mask[static_cast<size_t>(c)] = 1.0f;
      return;
    }
    case Kind::TwoBoneIk:
    case Kind::Aim:
    case Kind::FootPlacement:
    case Kind::FootLock:
    case Kind::Spring: return mark_driven_channels(d, procedural_input(info), mask);
    case Kind::Slot: return mark_driven_channels(d, d.slots[info.aux].input, mask);
  }
}

}  // namespace

Result<GraphDefinition> GraphDefinition::create(const Asset& asset, std::string_view graph_name,
                                                std::span<const Asset* const> more_clips) {
  const std::string where = asset.name() + ": graph '" + std::string(graph_name) + "'";
  const fb::Graph* g = find_graph(asset, graph_name);
  if (!g) {
    std::string names;
    if (const auto* graphs = asset.file().graphs())
      for (const fb::Graph* other : *graphs)
        names += (names.empty() ? "" : ", ") + std::string(flatbuffers::GetStringView(other->name()));
    return Error{asset.name() + ": no graph named '" + std::string(graph_name) + "'" +
                 (names.empty() ? " (the file has no graphs)" : " (graphs: " + names + ")")};
  }
  auto impl = std::make_unique<Impl>();
  Impl& d = *impl;
  d.graph = g;
  d.skeleton = asset.skeleton();
  if (d.skeleton.empty()) return Error{where + ": the file has no skeleton to play the graph on"};
  d.joints = static_cast<uint32_t>(d.skeleton.joint_count());
  if (g->skeleton_hash() != d.skeleton.hash() || g->joint_count() != d.joints)
    return Error{where + ": made for another rig (skeleton hash or joint count differs from the file's skeleton)"};

  // Clips by name: this file first, then the extra clip files in order.
  for (const flatbuffers::String* name : *g->clips()) {
    const std::string_view clip_name = flatbuffers::GetStringView(name);
    const fb::Clip* found = find_clip(asset, clip_name);
    const Asset* owner = &asset;
    for (size_t k = 0; !found && k < more_clips.size(); ++k) {
      if (more_clips[k] == nullptr) continue;
      found = find_clip(*more_clips[k], clip_name);
      owner = more_clips[k];
    }
    if (!found)
      return Error{where + ": clip '" + std::string(clip_name) + "' not found in the file or the clip files given"};
    ClipView view{found};
    // A retarget node's clip plays on its source rig (graph_retarget.cpp), any other on the graph's.
    auto rig = graph_detail::retarget_clip_rig(d, static_cast<uint16_t>(d.clips.size()), asset, more_clips, where);
    if (!rig) return rig.error();
    if (Status st = check_clip_binding(view, *rig, owner->name() + ": clip '" + std::string(clip_name) + "'"); !st)
      return Error{where + ": " + st.message()};
    d.clips.push_back(view);
    auto prototype = make_sampling_cache(view, *rig);
    if (!prototype) return Error{where + ": " + prototype.error().message};
    d.prototypes.push_back(std::move(*prototype));
  }

  // Morph channels: the asset's meshes' target names; each clip's tracks bound to them once.
  for (size_t m = 0; m < asset.mesh_count(); ++m) collect_morph_channels(asset.mesh(m), d.channels);
  d.default_weights.assign(d.channels.size(), 0.0f);
  for (size_t m = asset.mesh_count(); m-- > 0;) {  // the first mesh holding a name gives its default
    std::vector<int32_t> target_channel(asset.mesh(m).morph_target_count());
    bind_morph_targets(asset.mesh(m), d.channels, target_channel);
    default_morph_weights(asset.mesh(m), target_channel, d.default_weights);
  }
  for (const ClipView& clip : d.clips) {
    std::vector<int32_t> track_channel(clip.morph_track_count());
    bind_morph_tracks(clip, d.channels, track_channel);
    d.clip_channels.push_back(std::move(track_channel));
  }

  const auto& nodes = *g->nodes();
  d.nodes.resize(nodes.size());
  const auto parents = d.skeleton.parents();
  std::vector<uint16_t> machine_nodes(g->machines() ? g->machines()->size() : 0, 0);
  for (flatbuffers::uoffset_t i = 0; i < nodes.size(); ++i) {
    const fb::Node& node = *nodes.Get(i);
    NodeInfo& info = d.nodes[i];
    info.floats = d.float_count;
    info.caches = d.cache_count;
    switch (node.data_type()) {
      case fb::NodeData::ClipNode: {
        info.kind = Kind::Clip;
        const auto* c = node.data_as_ClipNode();
        info.table = c;
        d.float_count += 1;  // time
        d.cache_count += 1;
        if (c->rate() == 0.0f && c->rate_parameter() < 0) {
          const ClipView& clip = d.clips[c->clip()];
          auto cache = make_sampling_cache(clip, d.skeleton);
          if (!cache) return Error{where + ": " + cache.error().message};
          Pose pose(d.joints);
          SampleOptions options;
          options.loop = c->loop();
          sample(clip, std::clamp(c->start_offset(), 0.0f, clip.duration()), options, *cache, pose);
          info.held = static_cast<int32_t>(d.held.size());
          d.held.push_back(std::move(pose));
        }
        break;
      }
      case fb::NodeData::RetargetNode: {
        info.kind = Kind::Retarget;
        const auto* r = node.data_as_RetargetNode();
        info.table = r;
        d.float_count += 1;  // time
        d.cache_count += 1;  // the clip on its source rig
        if (Status st =
                graph_detail::bind_retarget_node(d, info, *r, asset, more_clips, where + ": node " + std::to_string(i));
            !st)
          return st.error();
        break;
      }
      case fb::NodeData::BlendAlphaNode:
        info.kind = Kind::BlendAlpha;
        info.table = node.data_as_BlendAlphaNode();
        break;
      case fb::NodeData::SelectNode:
        info.kind = Kind::Select;
        info.table = node.data_as_SelectNode();
        d.float_count += node.data_as_SelectNode()->children()->size();  // child weights
        break;
      case fb::NodeData::LayeredBlendNode: {
        info.kind = Kind::Layered;
        const auto* t = node.data_as_LayeredBlendNode();
        info.table = t;
        info.aux = static_cast<uint32_t>(d.masks.size());
        d.float_count += t->layers()->size();  // current layer weights
        for (const fb::Layer* layer : *t->layers()) {
          std::vector<float> mask(d.joints, 0.0f);
          for (const fb::MaskEntry* e : *layer->mask()) build_joint_mask(parents, e->joint(), e->depth(), mask);
          // Mask roots and their ancestors: the joints a mesh-space blend needs model rotations of.
          LayerJoints lj;
          std::vector<uint8_t> on_chain(d.joints, 0), is_root(d.joints, 0);
          for (uint32_t j = 0; j < d.joints; ++j) {
            const int p = parents[j];
            if (!(mask[j] > 0.0f) || (p >= 0 && mask[p] > 0.0f)) continue;
            is_root[j] = 1;
            for (int a = static_cast<int>(j); a >= 0 && !on_chain[a]; a = parents[a]) on_chain[a] = 1;
          }
          for (uint32_t j = 0; j < d.joints; ++j) {
            if (!on_chain[j]) continue;
            lj.chain.push_back(static_cast<uint16_t>(j));
            lj.root.push_back(is_root[j]);
          }
          d.masks.push_back(std::move(mask));
          d.layer_joints.push_back(std::move(lj));
        }
        break;
      }
      case fb::NodeData::BlendSpaceNode: {
        info.kind = Kind::BlendSpace;
        const auto* t = node.data_as_BlendSpaceNode();
        info.table = t;
        const uint32_t count = t->samples()->size();
        d.float_count += 1 + count;  // phase, then the sample weights
        d.cache_count += count;
        info.samples = static_cast<uint32_t>(d.sample_x.size());
        for (const fb::BlendSample* smp : *t->samples()) {
          d.sample_x.push_back(smp->x());
          d.sample_duration.push_back(d.clips[smp->clip()].duration());
        }
        if (t->y_parameter() >= 0) {
          std::vector<glm::vec2> points;
          for (const fb::BlendSample* smp : *t->samples()) points.emplace_back(smp->x(), smp->y());
          auto space = make_blend_space_2d(points);
          if (!space) return Error{where + ": node " + std::to_string(i) + ": " + space.error().message};
          info.aux = static_cast<uint32_t>(d.spaces.size());
          d.spaces.push_back(std::move(*space));
        }
        break;
      }
      case fb::NodeData::AdditiveNode:
        info.kind = Kind::Additive;
        info.table = node.data_as_AdditiveNode();
        break;
      case fb::NodeData::StateMachineNode:
        info.kind = Kind::Machine;
        info.table = node.data_as_StateMachineNode();
        info.machine = node.data_as_StateMachineNode()->machine();
        machine_nodes[info.machine] = static_cast<uint16_t>(i);
        break;
      case fb::NodeData::MorphWeightsNode: {
        info.kind = Kind::Morph;
        const auto* t = node.data_as_MorphWeightsNode();
        info.table = t;
        info.aux = static_cast<uint32_t>(d.drive_channels.size());
        for (const fb::MorphDrive* drive : *t->drives()) {
          const auto it = std::find(d.channels.begin(), d.channels.end(), flatbuffers::GetStringView(drive->target()));
          d.drive_channels.push_back(it == d.channels.end() ? -1 : static_cast<int32_t>(it - d.channels.begin()));
        }
        break;
      }
      case fb::NodeData::TwoBoneIkNode: {
        info.kind = Kind::TwoBoneIk;
        const auto* t = node.data_as_TwoBoneIkNode();
        info.table = t;
        if (std::string e = chain_error(d.skeleton, {t->start(), t->mid(), t->end()}); !e.empty())
          return Error{where + ": node " + std::to_string(i) + " (two-bone IK): " + e};
        d.float_count += 1;  // reached
        d.procedural = true;
        break;
      }
      case fb::NodeData::AimNode: {
        info.kind = Kind::Aim;
        const auto* t = node.data_as_AimNode();
        info.table = t;
        for (flatbuffers::uoffset_t k = 1; k < t->chain()->size(); ++k)
          if (std::string e = chain_error(d.skeleton, {t->chain()->Get(k - 1)->joint(), t->chain()->Get(k)->joint()});
              !e.empty())
            return Error{where + ": node " + std::to_string(i) + " (aim): " + e};
        d.float_count += 1;  // reached
        d.procedural = true;
        break;
      }
      case fb::NodeData::FootPlacementNode:
      case fb::NodeData::FootLockNode: {
        const bool lock = node.data_type() == fb::NodeData::FootLockNode;
        const auto* legs = lock ? node.data_as_FootLockNode()->legs() : node.data_as_FootPlacementNode()->legs();
        for (const fb::FootLeg* leg : *legs)
          if (std::string e = chain_error(d.skeleton, {leg->hip(), leg->knee(), leg->ankle()}); !e.empty())
            return Error{where + ": node " + std::to_string(i) + " (foot " + (lock ? "lock" : "placement") + "): " + e};
        d.procedural = true;
        if (!lock) {
          info.kind = Kind::FootPlacement;
          info.table = node.data_as_FootPlacementNode();
          break;
        }
        info.kind = Kind::FootLock;
        const auto* t = node.data_as_FootLockNode();
        info.table = t;
        info.aux = static_cast<uint32_t>(d.leg_events.size());
        d.float_count += 1 + 9 * t->legs()->size();  // a flag, then per leg (graph_procedural.cpp kLockFloats)
        for (const fb::FootLeg* leg : *t->legs()) {
          d.leg_events.push_back(flatbuffers::GetStringView(leg->plant_event()));
          d.leg_events.push_back(flatbuffers::GetStringView(leg->lift_event()));
        }
        break;
      }
      case fb::NodeData::SpringNode: {
        info.kind = Kind::Spring;
        const auto* t = node.data_as_SpringNode();
        info.table = t;
        info.aux = static_cast<uint32_t>(d.springs.size());
        info.samples = static_cast<uint32_t>(d.colliders.size());
        for (const fb::SpringChainSettings* c : *t->chains()) {
          SpringSettings settings;
          settings.stiffness = c->stiffness();
          settings.drag = c->drag();
          settings.gravity =
              c->gravity() ? glm::vec3(c->gravity()->x(), c->gravity()->y(), c->gravity()->z()) : glm::vec3(0.0f);
          settings.radius = c->radius();
          settings.tail_length = c->tail_length();
          settings.step = t->step();
          settings.teleport_distance = t->teleport_distance();
          const std::vector<uint16_t> joints(c->joints()->begin(), c->joints()->end());
          auto chain = make_spring_chain(parents, joints, settings);
          if (!chain) return Error{where + ": node " + std::to_string(i) + ": " + chain.error().message};
          d.springs.push_back(std::move(*chain));
        }
        std::vector<SpringCollider> colliders;
        if (const auto* shapes = t->colliders())
          for (const fb::SpringColliderShape* c : *shapes)
            colliders.push_back(SpringCollider{c->joint(), glm::vec3(c->offset().x(), c->offset().y(), c->offset().z()),
                                               glm::vec3(c->tail().x(), c->tail().y(), c->tail().z()), c->radius()});
        d.colliders.push_back(std::move(colliders));
        d.procedural = true;
        break;
      }
      case fb::NodeData::SlotNode:  // decoded with the montages (bind_montages)
        info.kind = Kind::Slot;
        info.table = node.data_as_SlotNode();
        break;
      default: return Error{where + ": node " + std::to_string(i) + " has no kind"};  // validation forbids it
    }
  }

  for (NodeInfo& info : d.nodes) {  // procedural nodes: input and weight decoded once
    const auto decode = [&info](const auto* t) {
      info.input = t->input();
      info.weight = t->weight();
      info.weight_parameter = t->weight_parameter();
    };
    switch (info.kind) {
      case Kind::TwoBoneIk: decode(static_cast<const fb::TwoBoneIkNode*>(info.table)); break;
      case Kind::Aim: decode(static_cast<const fb::AimNode*>(info.table)); break;
      case Kind::FootPlacement: decode(static_cast<const fb::FootPlacementNode*>(info.table)); break;
      case Kind::FootLock: decode(static_cast<const fb::FootLockNode*>(info.table)); break;
      case Kind::Spring: decode(static_cast<const fb::SpringNode*>(info.table)); break;
      default: break;
    }
  }

  if (const auto* machines = g->machines()) {
    d.machines.resize(machines->size());
    for (flatbuffers::uoffset_t m = 0; m < machines->size(); ++m) {
      MachineInfo& mi = d.machines[m];
      mi.fb = machines->Get(m);
      mi.node = machine_nodes[m];
      if (const auto* transitions = mi.fb->transitions()) {
        for (const fb::Transition* t : *transitions) {
          TransitionInfo ti;
          ti.fb = t;
          ti.first_trigger = static_cast<uint32_t>(d.transition_triggers.size());
          if (const auto* cond = t->condition())
            for (const fb::ConditionInstr* c : *cond)
              if (c->op() == fb::ConditionOp::Trigger) d.transition_triggers.push_back(c->parameter());
          ti.trigger_count = static_cast<uint32_t>(d.transition_triggers.size()) - ti.first_trigger;
          mi.transitions.push_back(ti);
        }
      }
    }
  }

  if (Status st = bind_montages(d, where); !st) return Error{st.message()};  // slots first: mark_driven_channels

  // Each layer's morph mask: the channels some clip under it has a track for.
  for (size_t i = 0; i < d.nodes.size(); ++i) {
    if (d.nodes[i].kind != Kind::Layered) continue;
    const auto* t = static_cast<const fb::LayeredBlendNode*>(d.nodes[i].table);
    for (const fb::Layer* layer : *t->layers()) {
      std::vector<float> mask(d.channels.size(), 0.0f);
      if (const auto* targets = layer->morph_targets()) {  // named by the graph
        for (const flatbuffers::String* name : *targets) {
          const auto it = std::find(d.channels.begin(), d.channels.end(), flatbuffers::GetStringView(name));
          if (it != d.channels.end()) mask[static_cast<size_t>(it - d.channels.begin())] = 1.0f;
        }
      } else {
        mark_driven_channels(d, layer->node(), mask);
      }
      d.layer_morphs.push_back(std::move(mask));
    }
  }

  d.bind = Pose(d.joints);
  set_bind_pose(d.skeleton, d.bind);
  d.scratch_depth = 1 + scratch_needed(d, g->root());  // poses[0]: the root evaluates there
  return GraphDefinition(std::move(impl));
}

const fb::Graph& GraphDefinition::graph() const { return *impl_->graph; }
const SkeletonView& GraphDefinition::skeleton() const { return impl_->skeleton; }
uint32_t GraphDefinition::joint_count() const { return impl_->joints; }
size_t GraphDefinition::parameter_count() const { return impl_->graph->parameters()->size(); }
std::string_view GraphDefinition::parameter_name(size_t i) const {
  if (i >= parameter_count()) return {};
  return flatbuffers::GetStringView(impl_->graph->parameters()->Get(static_cast<flatbuffers::uoffset_t>(i))->name());
}
fb::ParameterType GraphDefinition::parameter_type(size_t i) const {
  if (i >= parameter_count()) return fb::ParameterType::Float;
  return impl_->graph->parameters()->Get(static_cast<flatbuffers::uoffset_t>(i))->type();
}
int GraphDefinition::find_parameter(std::string_view name) const {
  for (size_t i = 0; i < parameter_count(); ++i)
    if (parameter_name(i) == name) return static_cast<int>(i);
  return -1;
}
size_t GraphDefinition::machine_count() const { return impl_->machines.size(); }
std::string_view GraphDefinition::machine_name(size_t i) const {
  return i < machine_count() ? flatbuffers::GetStringView(impl_->machines[i].fb->name()) : std::string_view();
}
size_t GraphDefinition::state_count(size_t machine) const {
  return machine < machine_count() ? impl_->machines[machine].fb->states()->size() : 0;
}
std::string_view GraphDefinition::state_name(size_t machine, size_t state) const {
  if (state >= state_count(machine)) return {};
  return flatbuffers::GetStringView(
      impl_->machines[machine].fb->states()->Get(static_cast<flatbuffers::uoffset_t>(state))->name());
}
size_t GraphDefinition::node_count() const { return impl_->nodes.size(); }
size_t GraphDefinition::clip_count() const { return impl_->clips.size(); }
const ClipView& GraphDefinition::clip(size_t i) const { return impl_->clips[i]; }
std::span<const std::string_view> GraphDefinition::morph_channels() const { return impl_->channels; }

}  // namespace ossa
