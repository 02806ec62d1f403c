// write_ossa.cpp — SourceScene + CookedMeshes -> .ossa bytes (write_ossa.h).
//
// FlatBuffers builds back to front, so every child (string, vector, sub-table) is created before
// its parent table starts. The order of creation is fixed — skeleton, meshes in order, clips in
// order, materials in order, provenance, file — and every input is an ordered container, so the
// bytes depend only on the input. Nothing time- or address-dependent is written.
//
// The GPU byte vectors (vertices, indices), embedded texture data and clips' key_values get
// 16-byte alignment from ForceVectorAlignment right before CreateVector: flatc 2.0.8 accepts
// force_align on vectors in the schema but generates nothing for it. The builder raises its minimum alignment to 16
// with it, and Finish pads the whole buffer to that, so "aligned from the end" is also "aligned from the start".
#include "cooker/write/write_ossa.h"
#include "cooker/write/write_montage.h"

#include <flatbuffers/flatbuffers.h>

#include <string_view>

#include <ossa/format/clip_codec.h>
#include <ossa/format/hash.h>
#include <ossa/version.h>

namespace ossa::cook {
namespace {

using flatbuffers::FlatBufferBuilder;
using flatbuffers::Offset;
using flatbuffers::Vector;

constexpr size_t kGpuAlignment = 16;

fb::Vec3 vec3(const glm::vec3& v) { return fb::Vec3(v.x, v.y, v.z); }
fb::Quat quat(const glm::quat& q) { return fb::Quat(q.x, q.y, q.z, q.w); }

// glm::mat4 is column-major (m[column][row]); so is fb::Mat4.
fb::Mat4 mat4(const glm::mat4& m) {
  float values[16];
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) values[c * 4 + r] = m[c][r];
  return fb::Mat4(flatbuffers::span<const float, 16>(values));
}

Offset<Vector<uint8_t>> aligned_bytes(FlatBufferBuilder& fbb, const std::vector<uint8_t>& bytes) {
  fbb.ForceVectorAlignment(bytes.size(), 1, kGpuAlignment);
  return fbb.CreateVector(bytes.data(), bytes.size());
}

Offset<fb::Skeleton> write_skeleton(FlatBufferBuilder& fbb, const SourceSkeleton& skeleton) {
  std::vector<Offset<flatbuffers::String>> names;
  std::vector<int16_t> parents;
  std::vector<fb::Vec3> translations, scales;
  std::vector<fb::Quat> rotations;
  std::vector<fb::Mat4> inverse_bind;
  for (const SourceJoint& j : skeleton.joints) {
    names.push_back(fbb.CreateString(j.name));
    parents.push_back(static_cast<int16_t>(j.parent));
    translations.push_back(vec3(j.translation));
    rotations.push_back(quat(j.rotation));
    scales.push_back(vec3(j.scale));
    inverse_bind.push_back(mat4(j.inverse_bind));
  }
  const auto names_v = fbb.CreateVector(names);
  const auto parents_v = fbb.CreateVector(parents);
  const auto translations_v = fbb.CreateVectorOfStructs(translations);
  const auto rotations_v = fbb.CreateVectorOfStructs(rotations);
  const auto scales_v = fbb.CreateVectorOfStructs(scales);
  const auto inverse_bind_v = fbb.CreateVectorOfStructs(inverse_bind);
  return fb::CreateSkeleton(fbb, names_v, parents_v, translations_v, rotations_v, scales_v, inverse_bind_v,
                            skeleton_hash_of(skeleton));
}

/// Format v9: a mesh's simulated region (cloth_build.h).
Offset<fb::Cloth> write_cloth(FlatBufferBuilder& fbb, const CookedCloth& c) {
  const auto optional_floats = [&](const std::vector<float>& v) {
    return v.empty() ? Offset<flatbuffers::Vector<float>>() : fbb.CreateVector(v);
  };
  const auto particle_vertices = fbb.CreateVector(c.particle_vertices);
  const auto inverse_masses = fbb.CreateVector(c.inverse_masses);
  const auto max_distances = optional_floats(c.max_distances);
  const auto backstops = optional_floats(c.backstops);
  const auto vertices = fbb.CreateVector(c.vertices);
  const auto vertex_particles = fbb.CreateVector(c.vertex_particles);
  const auto flipped = c.flipped.empty() ? Offset<flatbuffers::Vector<uint8_t>>() : fbb.CreateVector(c.flipped);
  const auto triangles = fbb.CreateVector(c.triangles);
  const auto stretch = fbb.CreateVectorOfStructs(c.stretch);
  const auto bend = fbb.CreateVectorOfStructs(c.bend);
  const auto tethers = fbb.CreateVectorOfStructs(c.tethers);
  const auto colliders = fbb.CreateVectorOfStructs(c.colliders);
  const fb::Vec3 gravity = vec3(c.gravity);
  return fb::CreateCloth(fbb, particle_vertices, inverse_masses, max_distances, backstops, vertices, vertex_particles,
                         flipped, triangles, stretch, bend, tethers, colliders, c.thickness, c.stretch_compliance,
                         c.bend_compliance, c.tether_scale, c.damping, c.drag, &gravity, c.linear_inertia,
                         c.angular_inertia, c.teleport_distance, c.max_speed);
}

Offset<fb::Mesh> write_mesh(FlatBufferBuilder& fbb, const CookedMesh& mesh) {
  const auto name = fbb.CreateString(mesh.name);
  const auto layout = fbb.CreateVectorOfStructs(mesh.layout);
  const auto vertices = aligned_bytes(fbb, mesh.vertices);
  const auto indices = aligned_bytes(fbb, mesh.indices);
  const auto submeshes = fbb.CreateVectorOfStructs(mesh.submeshes);
  const auto joints = fbb.CreateVector(mesh.joints);
  std::vector<fb::Mat4> inverse_bind;
  for (const glm::mat4& m : mesh.inverse_bind) inverse_bind.push_back(mat4(m));
  const auto inverse_bind_v = fbb.CreateVectorOfStructs(inverse_bind);
  const fb::Vec3 bounds_min = vec3(mesh.bounds_min), bounds_max = vec3(mesh.bounds_max);
  const fb::Vec3 offset = vec3(mesh.position_offset), scale = vec3(mesh.position_scale);
  std::vector<Offset<fb::MorphTarget>> targets;
  for (const CookedMorphTarget& t : mesh.morph_targets) {
    const auto target_name = fbb.CreateString(t.name);
    const auto vertices_v = fbb.CreateVector(t.vertices);
    const auto positions_v = fbb.CreateVector(t.position_deltas);
    const auto normals_v =
        t.normal_deltas.empty() ? Offset<flatbuffers::Vector<int16_t>>() : fbb.CreateVector(t.normal_deltas);
    const auto tangents_v =
        t.tangent_deltas.empty() ? Offset<flatbuffers::Vector<int16_t>>() : fbb.CreateVector(t.tangent_deltas);
    const fb::Vec3 ps = vec3(t.position_step), ns = vec3(t.normal_step), ts = vec3(t.tangent_step);
    targets.push_back(fb::CreateMorphTarget(fbb, target_name, vertices_v, positions_v, &ps, normals_v, &ns, tangents_v,
                                            &ts, t.default_weight, t.position_error, t.normal_error));
  }
  const auto targets_v =
      targets.empty() ? Offset<flatbuffers::Vector<Offset<fb::MorphTarget>>>() : fbb.CreateVector(targets);
  const Offset<fb::Cloth> cloth = mesh.cloth.empty() ? Offset<fb::Cloth>() : write_cloth(fbb, mesh.cloth);
  return fb::CreateMesh(fbb, name, mesh.vertex_count, mesh.vertex_stride, layout, vertices, mesh.index_format, indices,
                        submeshes, &bounds_min, &bounds_max, &offset, &scale, joints, inverse_bind_v, targets_v, cloth);
}

Offset<fb::RootMotion> write_root_motion(FlatBufferBuilder& fbb, const SourceRootMotion& rm) {
  std::vector<fb::Vec3> translations;
  translations.reserve(rm.translations.size());
  for (const glm::vec3& v : rm.translations) translations.push_back(vec3(v));
  const auto translations_v = fbb.CreateVectorOfStructs(translations);
  const auto yaws_v = fbb.CreateVector(rm.yaws);
  return fb::CreateRootMotion(fbb, translations_v, yaws_v, rm.up_axis);
}

// Every vector is written, empty or not, so readers see the same shape for every clip.
Offset<fb::Clip> write_clip(FlatBufferBuilder& fbb, const CompressedClip& clip, uint64_t skeleton_hash,
                            uint16_t joint_count) {
  const auto name = fbb.CreateString(clip.name);
  std::vector<fb::ConstantChannel> constants;
  constants.reserve(clip.constants.size());
  for (const CompressedConstant& c : clip.constants) {
    float stored[3] = {c.value[0], c.value[1], c.value[2]};
    const bool rotation = c.channel == static_cast<uint8_t>(fb::Channel::Rotation);
    if (rotation) rotation_to_stored(c.value, c.dropped & 3u, stored);
    constants.emplace_back(c.joint, static_cast<fb::Channel>(c.channel), rotation ? c.dropped : uint8_t{0},
                           fb::Vec3(stored[0], stored[1], stored[2]));
  }
  std::vector<fb::AnimatedChannel> animated;
  animated.reserve(clip.animated.size());
  for (const CompressedAnimated& a : clip.animated) {
    const uint8_t bits[3] = {static_cast<uint8_t>(a.bits.c[0]), static_cast<uint8_t>(a.bits.c[1]),
                             static_cast<uint8_t>(a.bits.c[2])};
    animated.emplace_back(a.joint, static_cast<fb::Channel>(a.channel), flatbuffers::span<const uint8_t, 3>(bits),
                          a.dropped, a.segment_offset_bits, a.first_key, a.key_count, a.bit_offset,
                          fb::Vec3(a.range_min[0], a.range_min[1], a.range_min[2]),
                          fb::Vec3(a.range_extent[0], a.range_extent[1], a.range_extent[2]));
  }
  const auto constants_v = fbb.CreateVectorOfStructs(constants);
  const auto animated_v = fbb.CreateVectorOfStructs(animated);
  const auto key_frames_v = fbb.CreateVector(clip.key_frames);
  // Decoders read 64 bits at a time: the stream ends with kKeyValuePadding zero bytes (the
  // compressor's BitWriter appends them; a hand-made clip without them gets them here).
  std::vector<uint8_t> key_values = clip.key_values;
  if (key_values.size() < kKeyValuePadding) key_values.resize(kKeyValuePadding, 0);
  const auto key_values_v = aligned_bytes(fbb, key_values);
  const auto compression = fb::CreateClipCompression(fbb, clip.tolerance, clip.probe_distance, clip.max_error,
                                                     clip.mean_error, clip.worst_joint, clip.raw_bytes);
  const auto root_motion = clip.has_root_motion ? write_root_motion(fbb, clip.root_motion) : Offset<fb::RootMotion>();
  std::vector<Offset<fb::ClipEvent>> events;
  for (const SourceEvent& e : clip.events) {
    const auto event_name = fbb.CreateString(e.name);
    events.push_back(fb::CreateClipEvent(fbb, event_name, e.time));
  }
  const auto events_v = fbb.CreateVector(events);
  std::vector<Offset<fb::MorphTrack>> tracks;
  for (const CompressedMorphTrack& t : clip.morph_weights) {
    const auto track_name = fbb.CreateString(t.name);
    const auto frames_v = fbb.CreateVector(t.key_frames);
    const auto values_v = fbb.CreateVector(t.values);
    tracks.push_back(
        fb::CreateMorphTrack(fbb, track_name, frames_v, values_v, t.range_min, t.range_extent, t.max_error));
  }
  const auto tracks_v =
      tracks.empty() ? Offset<flatbuffers::Vector<Offset<fb::MorphTrack>>>() : fbb.CreateVector(tracks);
  return fb::CreateClip(fbb, name, clip.grid.duration(), clip.grid.sample_rate, clip.grid.frame_count, skeleton_hash,
                        joint_count, constants_v, animated_v, key_frames_v, key_values_v, compression, root_motion,
                        events_v, tracks_v);
}

fb::Vec3 vec3(const Vec3Def& v) { return fb::Vec3(v[0], v[1], v[2]); }

Offset<flatbuffers::Vector<Offset<fb::FootLeg>>> write_legs(FlatBufferBuilder& fbb,
                                                            const std::vector<FootLegDef>& legs) {
  std::vector<Offset<fb::FootLeg>> out;
  for (const FootLegDef& leg : legs) {
    const auto plant = leg.plant_event.empty() ? Offset<flatbuffers::String>() : fbb.CreateString(leg.plant_event);
    const auto lift = leg.lift_event.empty() ? Offset<flatbuffers::String>() : fbb.CreateString(leg.lift_event);
    out.push_back(fb::CreateFootLeg(fbb, leg.hip, leg.knee, leg.ankle, leg.ground_parameter, leg.normal_parameter,
                                    leg.planted_parameter, plant, lift));
  }
  return fbb.CreateVector(out);
}

Offset<fb::Node> write_node(FlatBufferBuilder& fbb, const NodeDef& node) {
  const auto name = fbb.CreateString(node.name);
  fb::NodeData type = fb::NodeData::NONE;
  Offset<void> data;
  if (const auto* c = std::get_if<ClipNodeDef>(&node.kind)) {
    type = fb::NodeData::ClipNode;
    data = fb::CreateClipNode(fbb, c->clip, c->rate, c->rate_parameter, c->loop, c->start_offset).Union();
  } else if (const auto* a = std::get_if<BlendAlphaDef>(&node.kind)) {
    type = fb::NodeData::BlendAlphaNode;
    data = fb::CreateBlendAlphaNode(fbb, a->a, a->b, a->alpha_parameter).Union();
  } else if (const auto* s = std::get_if<SelectDef>(&node.kind)) {
    type = fb::NodeData::SelectNode;
    const auto children = fbb.CreateVector(s->children);
    data = fb::CreateSelectNode(fbb, s->parameter, children, s->blend_time).Union();
  } else if (const auto* l = std::get_if<LayeredDef>(&node.kind)) {
    type = fb::NodeData::LayeredBlendNode;
    std::vector<Offset<fb::Layer>> layers;
    for (const LayerDef& layer : l->layers) {
      std::vector<fb::MaskEntry> mask;
      for (const MaskEntryDef& m : layer.mask) mask.emplace_back(m.joint, m.depth);
      const auto mask_v = fbb.CreateVectorOfStructs(mask);
      Offset<flatbuffers::Vector<Offset<flatbuffers::String>>> morph_v;
      if (layer.morph_targets) morph_v = fbb.CreateVectorOfStrings(*layer.morph_targets);
      layers.push_back(fb::CreateLayer(fbb, layer.node, mask_v, layer.weight, layer.weight_parameter, layer.blend_time,
                                       layer.mesh_space_rotation, morph_v));
    }
    const auto layers_v = fbb.CreateVector(layers);
    data = fb::CreateLayeredBlendNode(fbb, l->base, layers_v).Union();
  } else if (const auto* b = std::get_if<BlendSpaceDef>(&node.kind)) {
    type = fb::NodeData::BlendSpaceNode;
    std::vector<fb::BlendSample> samples;
    for (const BlendSampleDef& smp : b->samples) samples.emplace_back(smp.clip, smp.x, smp.y);
    const auto samples_v = fbb.CreateVectorOfStructs(samples);
    data = fb::CreateBlendSpaceNode(fbb, b->x_parameter, b->y_parameter, samples_v, b->rate, b->loop).Union();
  } else if (const auto* d = std::get_if<AdditiveDef>(&node.kind)) {
    type = fb::NodeData::AdditiveNode;
    data = fb::CreateAdditiveNode(fbb, d->base, d->additive, d->weight, d->weight_parameter).Union();
  } else if (const auto* m = std::get_if<StateMachineRefDef>(&node.kind)) {
    type = fb::NodeData::StateMachineNode;
    data = fb::CreateStateMachineNode(fbb, m->machine).Union();
  } else if (const auto* w = std::get_if<MorphWeightsDef>(&node.kind)) {
    type = fb::NodeData::MorphWeightsNode;
    std::vector<Offset<fb::MorphDrive>> drives;
    for (const MorphDriveDef& drive : w->drives) {
      const auto target = fbb.CreateString(drive.target);
      drives.push_back(fb::CreateMorphDrive(fbb, target, drive.parameter, drive.scale));
    }
    const auto drives_v = fbb.CreateVector(drives);
    data = fb::CreateMorphWeightsNode(fbb, w->input, drives_v).Union();
  } else if (const auto* t = std::get_if<TwoBoneIkDef>(&node.kind)) {
    type = fb::NodeData::TwoBoneIkNode;
    const fb::Vec3 pole = vec3(t->pole), axis = vec3(t->mid_axis);
    data = fb::CreateTwoBoneIkNode(fbb, t->input, t->start, t->mid, t->end, t->target_parameter, t->pole_parameter,
                                   &pole, &axis, t->twist, t->soften, t->weight, t->weight_parameter)
               .Union();
  } else if (const auto* aim = std::get_if<AimDef>(&node.kind)) {
    type = fb::NodeData::AimNode;
    std::vector<fb::AimJoint> chain;
    for (const AimJointDef& j : aim->chain) chain.emplace_back(j.joint, j.weight, j.max_angle);
    const auto chain_v = fbb.CreateVectorOfStructs(chain);
    const fb::Vec3 forward = vec3(aim->forward), up = vec3(aim->up), pole = vec3(aim->pole);
    data = fb::CreateAimNode(fbb, aim->input, chain_v, aim->target_parameter, &forward, &up, &pole, aim->weight,
                             aim->weight_parameter)
               .Union();
  } else if (const auto* f = std::get_if<FootPlacementDef>(&node.kind)) {
    type = fb::NodeData::FootPlacementNode;
    const auto legs_v = write_legs(fbb, f->legs);
    const fb::Vec3 up = vec3(f->up);
    data = fb::CreateFootPlacementNode(fbb, f->input, f->pelvis, legs_v, &up, f->max_pelvis_drop, f->align, f->soften,
                                       f->weight, f->weight_parameter)
               .Union();
  } else if (const auto* lock = std::get_if<FootLockDef>(&node.kind)) {
    type = fb::NodeData::FootLockNode;
    const auto legs_v = write_legs(fbb, lock->legs);
    data = fb::CreateFootLockNode(fbb, lock->input, legs_v, lock->release_radius, lock->blend_time, lock->weight,
                                  lock->weight_parameter)
               .Union();
  } else if (const auto* rt = std::get_if<RetargetNodeDef>(&node.kind)) {
    type = fb::NodeData::RetargetNode;
    const auto source_v = fbb.CreateVector(rt->source_bones);
    const auto target_v = fbb.CreateVector(rt->target_bones);
    const auto rests = [&](const std::vector<RetargetRestRotationDef>& list) {
      std::vector<fb::RetargetRestRotation> out;
      for (const RetargetRestRotationDef& r : list)
        out.emplace_back(r.joint, fb::Quat(r.rotation[0], r.rotation[1], r.rotation[2], r.rotation[3]));
      return fbb.CreateVectorOfStructs(out);
    };
    const auto source_rest_v = rests(rt->source_rest_rotations);
    const auto target_rest_v = rests(rt->target_rest_rotations);
    data = fb::CreateRetargetNode(fbb, rt->clip, rt->source_skeleton_hash, rt->source_joint_count, source_v, target_v,
                                  rt->rate, rt->rate_parameter, rt->loop, rt->start_offset, rt->contacts,
                                  rt->source_rest, rt->target_rest, source_rest_v, target_rest_v)
               .Union();
  } else if (const auto* sp = std::get_if<SpringDef>(&node.kind)) {
    type = fb::NodeData::SpringNode;
    std::vector<Offset<fb::SpringChainSettings>> chains;
    for (const SpringChainDef& chain : sp->chains) {
      const auto joints_v = fbb.CreateVector(chain.joints);
      const fb::Vec3 gravity = vec3(chain.gravity);
      chains.push_back(fb::CreateSpringChainSettings(fbb, joints_v, chain.stiffness, chain.drag, &gravity, chain.radius,
                                                     chain.tail_length));
    }
    const auto chains_v = fbb.CreateVector(chains);
    std::vector<fb::SpringColliderShape> colliders;
    for (const SpringColliderDef& col : sp->colliders)
      colliders.emplace_back(col.joint, vec3(col.offset), vec3(col.tail), col.radius);
    const auto colliders_v = colliders.empty() ? Offset<flatbuffers::Vector<const fb::SpringColliderShape*>>()
                                               : fbb.CreateVectorOfStructs(colliders);
    data = fb::CreateSpringNode(fbb, sp->input, chains_v, colliders_v, sp->step, sp->teleport_distance, sp->weight,
                                sp->weight_parameter)
               .Union();
  } else if (const auto* slot = std::get_if<SlotDef>(&node.kind)) {
    type = fb::NodeData::SlotNode;
    data = write_slot_node(fbb, *slot).Union();
  }
  return fb::CreateNode(fbb, name, type, data);
}

Offset<fb::StateMachine> write_machine(FlatBufferBuilder& fbb, const StateMachineDef& machine) {
  const auto name = fbb.CreateString(machine.name);
  std::vector<Offset<fb::State>> states;
  for (const StateDef& st : machine.states) {
    const auto state_name = fbb.CreateString(st.name);
    states.push_back(fb::CreateState(fbb, state_name, st.node, st.restart));
  }
  const auto states_v = fbb.CreateVector(states);
  std::vector<Offset<fb::Transition>> transitions;
  for (const TransitionDef& t : machine.transitions) {
    std::vector<fb::ConditionInstr> condition;
    for (const CondInstr& c : t.condition)
      condition.emplace_back(static_cast<fb::ConditionOp>(c.op), c.parameter, c.value);
    const auto condition_v = fbb.CreateVectorOfStructs(condition);
    transitions.push_back(fb::CreateTransition(fbb, t.from, t.to, condition_v, t.exit_time, t.duration,
                                               static_cast<fb::TransitionMode>(t.mode)));
  }
  const auto transitions_v = fbb.CreateVector(transitions);
  return fb::CreateStateMachine(fbb, name, states_v, machine.entry, transitions_v);
}

Offset<fb::Graph> write_graph(FlatBufferBuilder& fbb, const GraphDef& graph) {
  const auto name = fbb.CreateString(graph.name);
  std::vector<Offset<fb::Parameter>> parameters;
  for (const GraphParameter& p : graph.parameters) {
    const auto param_name = fbb.CreateString(p.name);
    const auto values = p.enum_values.empty() ? Offset<Vector<Offset<flatbuffers::String>>>()
                                              : fbb.CreateVectorOfStrings(p.enum_values);
    const bool vector = p.type == ParamType::Vector;
    const fb::Vec3 default_vector(p.default_vector[0], p.default_vector[1], p.default_vector[2]);
    parameters.push_back(fb::CreateParameter(fbb, param_name, static_cast<fb::ParameterType>(p.type), p.default_value,
                                             p.min_value, p.max_value, values, vector ? &default_vector : nullptr,
                                             p.world ? fb::ParameterSpace::World : fb::ParameterSpace::Model));
  }
  const auto parameters_v = fbb.CreateVector(parameters);
  const auto clips_v = fbb.CreateVectorOfStrings(graph.clips);
  std::vector<Offset<fb::Node>> nodes;
  for (const NodeDef& node : graph.nodes) nodes.push_back(write_node(fbb, node));
  const auto nodes_v = fbb.CreateVector(nodes);
  std::vector<Offset<fb::StateMachine>> machines;
  for (const StateMachineDef& machine : graph.machines) machines.push_back(write_machine(fbb, machine));
  const auto machines_v = fbb.CreateVector(machines);
  const auto montages_v = write_montages(fbb, graph.montages);
  return fb::CreateGraph(fbb, name, graph.skeleton_hash, graph.joint_count, parameters_v, clips_v, nodes_v, machines_v,
                         graph.root, montages_v);
}

/// `written` holds the Texture table of every texture written so far, in the scene's order
/// (SourceTexture::same_as counts the same way): a repeat refers to its first use's table.
Offset<fb::Material> write_material(FlatBufferBuilder& fbb, const SourceMaterial& material,
                                    std::vector<Offset<fb::Texture>>& written) {
  const auto name = fbb.CreateString(material.name);
  std::vector<Offset<fb::Texture>> textures;
  for (const SourceTexture& t : material.textures) {
    if (t.same_as >= 0 && static_cast<size_t>(t.same_as) < written.size()) {
      const Offset<fb::Texture> shared = written[static_cast<size_t>(t.same_as)];
      written.push_back(shared);
      textures.push_back(shared);
      continue;
    }
    // Absent rather than empty: a referenced texture has no data, an embedded one may have no path.
    const auto path = t.path.empty() ? Offset<flatbuffers::String>() : fbb.CreateString(t.path);
    const auto mime = t.mime.empty() ? Offset<flatbuffers::String>() : fbb.CreateString(t.mime);
    const auto data = t.data.empty() ? Offset<Vector<uint8_t>>() : aligned_bytes(fbb, t.data);
    const Offset<fb::Texture> table =
        fb::CreateTexture(fbb, static_cast<fb::TextureRole>(t.role), path, mime, data,
                          static_cast<fb::TextureEncoding>(t.encoding), t.srgb, t.width, t.height, t.mip_count);
    written.push_back(table);
    textures.push_back(table);
  }
  const auto textures_v = fbb.CreateVector(textures);
  const fb::Vec3 ambient = vec3(material.ambient), diffuse = vec3(material.diffuse), specular = vec3(material.specular);
  const fb::Vec3 emissive = vec3(material.emissive);
  const fb::PbrFactors pbr(material.metallic, material.roughness);
  return fb::CreateMaterial(fbb, name, &ambient, &diffuse, &specular, material.shininess, material.opacity, textures_v,
                            material.emissive == glm::vec3(0.0f) ? nullptr : &emissive, material.pbr ? &pbr : nullptr);
}

}  // namespace

std::vector<uint8_t> write_ossa(const SourceScene& scene, std::span<const CookedMesh> meshes,
                                std::span<const CompressedClip> clips, const WriteProvenance& provenance,
                                const WriteOptions& options) {
  FlatBufferBuilder fbb(1 << 16);

  // A file without joints has no skeleton table (readers see "no skeleton", not an empty one).
  Offset<fb::Skeleton> skeleton;
  if (options.include_skeleton && !scene.skeleton.joints.empty()) skeleton = write_skeleton(fbb, scene.skeleton);

  std::vector<Offset<fb::Mesh>> mesh_offsets;
  for (const CookedMesh& mesh : meshes) mesh_offsets.push_back(write_mesh(fbb, mesh));
  const auto meshes_v = fbb.CreateVector(mesh_offsets);

  const uint64_t rig_hash = skeleton_hash_of(scene.skeleton);
  const auto joint_count = static_cast<uint16_t>(scene.skeleton.joints.size());
  std::vector<Offset<fb::Clip>> clip_offsets;
  for (const CompressedClip& clip : clips) clip_offsets.push_back(write_clip(fbb, clip, rig_hash, joint_count));
  const auto clips_v = fbb.CreateVector(clip_offsets);

  std::vector<Offset<fb::Material>> material_offsets;
  std::vector<Offset<fb::Texture>> written_textures;
  for (const SourceMaterial& material : scene.materials)
    material_offsets.push_back(write_material(fbb, material, written_textures));
  const auto materials_v = fbb.CreateVector(material_offsets);

  // Named first: the order of evaluation of function arguments is unspecified, the bytes must not be.
  const auto source_name = fbb.CreateString(provenance.source_name);
  const auto cooker_version = fbb.CreateString(kCookerVersion);
  const auto options_text = fbb.CreateString(provenance.options);
  std::vector<Offset<fb::InputFile>> input_offsets;
  for (const InputFile& f : provenance.inputs) {
    const auto path = fbb.CreateString(f.path);
    input_offsets.push_back(fb::CreateInputFile(fbb, path, f.hash, f.size, !f.present));
  }
  const auto inputs_v = fbb.CreateVector(input_offsets);
  // Absent when empty: a warning-free file keeps the bytes it had before the field existed.
  const auto warnings_v = provenance.warnings.empty() ? Offset<Vector<Offset<flatbuffers::String>>>()
                                                      : fbb.CreateVectorOfStrings(provenance.warnings);
  const auto prov = fb::CreateProvenance(fbb, source_name, provenance.source_hash, cooker_version, options_text,
                                         inputs_v, provenance.cook_key, warnings_v);

  std::vector<Offset<fb::Graph>> graph_offsets;
  for (const GraphDef& graph : options.graphs) graph_offsets.push_back(write_graph(fbb, graph));
  const auto graphs_v = graph_offsets.empty() ? Offset<Vector<Offset<fb::Graph>>>() : fbb.CreateVector(graph_offsets);

  const auto root = fb::CreateFile(fbb, kFormatVersion, scene.metres_per_unit, skeleton, meshes_v, clips_v, materials_v,
                                   prov, graphs_v);
  fb::FinishFileBuffer(fbb, root);
  return std::vector<uint8_t>(fbb.GetBufferPointer(), fbb.GetBufferPointer() + fbb.GetSize());
}

}  // namespace ossa::cook
