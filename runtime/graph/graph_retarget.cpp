// graph_retarget.cpp — the graph's retarget node (format v10, fb::RetargetNode): a clip made for
// another humanoid rig, played on the graph's rig through the live retarget job
// (ossa/retarget/retarget.h), so one clip library cooked for one rig drives mixed characters.
//
// Definition: the node's clip binds to the source rig (its skeleton found by hash among the files
// the definition is made from), the retarget map is built from the two skeletons' bind poses and
// the bones the cooker stored, and the clip's foot contacts are found once by sampling it at every
// frame of its grid (the cook-time passes, ossa/retarget/foot_contacts.h), so the live node holds
// feet as `ossa-cook --retarget-to` does. Instance: a sampling cache on the source rig, a source
// pose and a retarget scratch, made at creation. Evaluation: the clip node's time arithmetic, then
// sample -> contacts at the time's frame -> retarget into the node's output. Events and morph
// weight tracks of the source clip are not played (the weights stay at their defaults).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <optional>
#include <string>

#include "graph/graph_internal.h"
#include <ossa/retarget/foot_contacts.h>

namespace ossa::graph_detail {
namespace {

const fb::RetargetNode* retarget_table(const fb::Graph& g, uint16_t clip) {
  for (const fb::Node* node : *g.nodes())
    if (node->data_type() == fb::NodeData::RetargetNode && node->data_as_RetargetNode()->clip() == clip)
      return node->data_as_RetargetNode();
  return nullptr;
}

/// The source rig a node names, by skeleton hash and joint count, in `asset` or `more`.
std::optional<SkeletonView> source_rig(const fb::RetargetNode& r, const Asset& asset,
                                       std::span<const Asset* const> more) {
  auto holds = [&](const Asset* a) {
    return a != nullptr && !a->skeleton().empty() && a->skeleton().hash() == r.source_skeleton_hash() &&
           a->skeleton().joint_count() == r.source_joint_count();
  };
  if (holds(&asset)) return asset.skeleton();
  for (const Asset* a : more)
    if (holds(a)) return a->skeleton();
  return std::nullopt;
}

std::string hash_text(uint64_t hash) {
  char text[24];
  std::snprintf(text, sizeof text, "%016llx", static_cast<unsigned long long>(hash));
  return text;
}

float retarget_rate(const GraphInstance::State& s, const fb::RetargetNode& r) {
  const float p = r.rate_parameter() >= 0 ? s.params[static_cast<size_t>(r.rate_parameter())] : 1.0f;
  return std::clamp(r.rate() * p, -1000.0f, 1000.0f);
}

}  // namespace

Result<SkeletonView> retarget_clip_rig(const GraphDefinition::Impl& d, uint16_t clip, const Asset& asset,
                                       std::span<const Asset* const> more, const std::string& where) {
  const fb::RetargetNode* r = retarget_table(*d.graph, clip);
  if (r == nullptr) return d.skeleton;
  auto found = source_rig(*r, asset, more);
  if (found) return *found;
  return Error{where + ": clip '" + std::string(flatbuffers::GetStringView(d.graph->clips()->Get(clip))) +
               "' is played by a retarget node on another rig (skeleton hash " + hash_text(r->source_skeleton_hash()) +
               ", " + std::to_string(r->source_joint_count()) +
               " joints), and no file given holds that skeleton: pass the source rig's .ossa among the clip files"};
}

Status bind_retarget_node(GraphDefinition::Impl& d, NodeInfo& info, const fb::RetargetNode& r, const Asset& asset,
                          std::span<const Asset* const> more, const std::string& where) {
  // The rig this node names (the clip was bound to the first retarget node's playing it; another
  // node naming another rig for the same clip is refused here by the binding check).
  auto found = source_rig(r, asset, more);
  if (!found)
    return Error{where + ": retarget node: no file given holds its source rig (skeleton hash " +
                 hash_text(r.source_skeleton_hash()) + ")"};
  const ClipView& clip = d.clips[r.clip()];
  if (Status st = check_clip_binding(clip, *found, "retarget node"); !st) return Error{where + ": " + st.message()};
  RetargetNodeData data;
  data.source = *found;
  // Both rigs as the retarget job reads them: bind poses and names from the skeletons, the bones
  // and rest settings the cooker decided (the loader checked every joint index against the rigs).
  struct Rig {
    std::vector<std::string_view> names;
    std::vector<Transform> bind;
    std::vector<RestRotation> rest_rotations;
    RetargetRig rig;
  };
  auto rig_of = [](const SkeletonView& sk, const flatbuffers::Vector<int16_t>& bones, uint8_t rest,
                   const flatbuffers::Vector<const fb::RetargetRestRotation*>* rotations, std::string_view name,
                   Rig& out) {
    for (size_t j = 0; j < sk.joint_count(); ++j) {
      out.names.push_back(sk.joint_name(j));
      const fb::Vec3& t = sk.bind_translations()[j];
      const fb::Quat& q = sk.bind_rotations()[j];
      const fb::Vec3& sc = sk.bind_scales()[j];
      out.bind.push_back(
          Transform{{t.x(), t.y(), t.z()}, glm::quat(q.w(), q.x(), q.y(), q.z()), {sc.x(), sc.y(), sc.z()}});
    }
    for (flatbuffers::uoffset_t b = 0; b < kHumanoidBoneCount && b < bones.size(); ++b)
      out.rig.humanoid.joints[b] = bones.Get(b);
    if (rotations != nullptr)
      for (const fb::RetargetRestRotation* x : *rotations) {
        const fb::Quat& q = x->rotation();
        out.rest_rotations.push_back(
            RestRotation{static_cast<int16_t>(x->joint()), glm::quat(q.w(), q.x(), q.y(), q.z())});
      }
    out.rig.name = name;
    out.rig.parents = sk.parents();
    out.rig.bind = out.bind;
    out.rig.names = out.names;
    out.rig.rest = rest == 1 ? RestPose::Bind : RestPose::Straighten;
    out.rig.rest_rotations = out.rest_rotations;
  };
  Rig s, t;
  rig_of(data.source, *r.source_bones(), r.source_rest(), r.source_rest_rotations(), "the retarget node's source rig",
         s);
  rig_of(d.skeleton, *r.target_bones(), r.target_rest(), r.target_rest_rotations(), "the graph's rig", t);
  if (Status st = check_humanoid(s.rig.humanoid, s.rig.parents, s.rig.name); !st)
    return Error{where + ": retarget node: " + st.message()};
  if (Status st = check_humanoid(t.rig.humanoid, t.rig.parents, t.rig.name); !st)
    return Error{where + ": retarget node: " + st.message()};
  auto map = make_retarget_map(s.rig, t.rig);
  if (!map) return Error{where + ": retarget node: " + map.error().message};
  data.map = std::move(*map);

  data.sample_rate = clip.sample_rate();
  if (r.contacts()) {
    // The cook-time passes over every frame of the clip's grid (retarget_clips.h): the clip's
    // floor from the source alone, where the retarget puts each ankle, then the contacts.
    auto cache = make_sampling_cache(clip, data.source);
    if (!cache) return Error{where + ": " + cache.error().message};
    RetargetScratch scratch = make_retarget_scratch(data.map);
    std::vector<Pose> frames;
    for (uint32_t f = 0; f < clip.frame_count(); ++f) {
      frames.emplace_back(static_cast<uint32_t>(data.source.joint_count()));
      SampleOptions options;
      options.loop = false;
      sample(clip, static_cast<float>(f) / clip.sample_rate(), options, *cache, frames.back());
    }
    std::vector<ContactFrame> feet(frames.size());
    for (size_t f = 0; f < frames.size(); ++f) {
      pose_source(data.map, frames[f], scratch);
      feet[f] = contact_frame(data.map, scratch);
    }
    data.floor = clip_floor(data.map, feet);
    Pose out(d.joints);
    RetargetInput in;
    in.source_floor = data.floor;
    for (size_t f = 0; f < frames.size(); ++f) {
      in.source = frames[f];
      retarget(data.map, in, scratch, out);
      feet[f].target_ankle = contact_frame(data.map, scratch).target_ankle;
    }
    data.contacts = find_foot_contacts(data.map, feet, clip.sample_rate(), data.floor);
  }
  info.aux = static_cast<uint32_t>(d.retargets.size());
  d.retargets.push_back(std::move(data));
  return {};
}

Result<RetargetInstance> make_retarget_instance(const GraphDefinition::Impl& d, const NodeInfo& info) {
  const RetargetNodeData& data = d.retargets[info.aux];
  RetargetInstance r;
  r.source = Pose(static_cast<uint32_t>(data.source.joint_count()));
  r.scratch = make_retarget_scratch(data.map);
  return r;
}

void evaluate_retarget(GraphInstance::State& s, uint16_t n, const Advance& advance, PoseSpan out, std::span<float> ow) {
  const NodeInfo& info = s.def->nodes[n];
  const auto& r = *static_cast<const fb::RetargetNode*>(info.table);
  const RetargetNodeData& data = s.def->retargets[info.aux];
  RetargetInstance& instance = s.retargets[info.aux];
  const ClipView& clip = s.def->clips[r.clip()];
  float& time = s.floats[info.floats];
  const float duration = clip.duration();
  const float rate = retarget_rate(s, r);
  if (advance.synced)
    time = advance_time(time, advance.phase * duration, rate < 0.0f ? -1.0f : 1.0f, duration, r.loop());
  else time = advance_time(time, advance.dt, rate, duration, r.loop());
  SampleOptions options;
  options.loop = r.loop();
  sample(clip, time, options, s.caches[info.caches], instance.source);
  std::array<FootContact, 2> held{};
  RetargetInput in;
  in.source = instance.source;
  in.source_floor = data.floor;
  if (!data.contacts.empty()) {
    foot_contacts_at(data.contacts, time * data.sample_rate, data.sample_rate, ContactSettings{}.blend_time, held);
    in.contacts = held;
  }
  retarget(data.map, in, instance.scratch, out);
  if (!ow.empty()) std::copy(s.def->default_weights.begin(), s.def->default_weights.end(), ow.begin());
}

void restart_retarget(GraphInstance::State& s, const NodeInfo& info) {
  const auto& r = *static_cast<const fb::RetargetNode*>(info.table);
  s.floats[info.floats] = std::clamp(r.start_offset(), 0.0f, s.def->clips[r.clip()].duration());
}

Cycle retarget_cycle(const GraphInstance::State& s, const NodeInfo& info) {
  const auto& r = *static_cast<const fb::RetargetNode*>(info.table);
  const float d = s.def->clips[r.clip()].duration();
  const float rate = std::fabs(retarget_rate(s, r));
  Cycle out;
  out.duration = d > 0.0f ? (rate > 1e-6f ? d / rate : d * 1e6f) : 1.0f;
  out.phase = d > 0.0f ? s.floats[info.floats] / d : 0.0f;
  out.loop = r.loop();
  return out;
}

void set_retarget_phase(GraphInstance::State& s, const NodeInfo& info, float p) {
  const auto& r = *static_cast<const fb::RetargetNode*>(info.table);
  const float d = s.def->clips[r.clip()].duration();
  s.floats[info.floats] = std::min(p * d, d);
}

}  // namespace ossa::graph_detail
