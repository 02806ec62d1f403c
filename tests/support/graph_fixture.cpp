// graph_fixture.cpp — see graph_fixture.h.
#include "graph_fixture.h"

#include <gtest/gtest.h>

#include <memory>
#include <string>

#include "cooker/write/write_ossa.h"
#include "test_files.h"
#include <ossa/anim/pose_ops.h>
#include <ossa/format/clip_codec.h>

namespace ossa::test {
namespace fs = std::filesystem;
using namespace ossa::cook;

int PabRig::joint(std::string_view name) const {
  for (size_t i = 0; i < skeleton.joints.size(); ++i)
    if (skeleton.joints[i].name == name) return static_cast<int>(i);
  return -1;
}

namespace {

/// The skeleton of a cooked file as the cooker's model holds it (the inverse of the writer's
/// skeleton table; cook::load_reference_skeleton does the same for ossa-cook --skeleton).
SourceSkeleton read_skeleton(const Asset& asset) {
  const SkeletonView sk = asset.skeleton();
  SourceSkeleton out;
  out.metres_per_unit = asset.file().metres_per_unit();
  out.joints.resize(sk.joint_count());
  for (size_t i = 0; i < sk.joint_count(); ++i) {
    SourceJoint& j = out.joints[i];
    j.name = std::string(sk.joint_name(i));
    j.parent = sk.parents()[i];
    const fb::Vec3& t = sk.bind_translations()[i];
    const fb::Quat& r = sk.bind_rotations()[i];
    const fb::Vec3& sc = sk.bind_scales()[i];
    j.translation = {t.x(), t.y(), t.z()};
    j.rotation = glm::quat(r.w(), r.x(), r.y(), r.z());
    j.scale = {sc.x(), sc.y(), sc.z()};
    const auto* m = sk.inverse_bind()[i].m();
    for (int c = 0; c < 4; ++c)
      for (int r4 = 0; r4 < 4; ++r4) j.inverse_bind[c][r4] = m->Get(static_cast<flatbuffers::uoffset_t>(c * 4 + r4));
  }
  return out;
}

/// A cooked clip as the compressor made it (the inverse of the writer's Clip table), without its
/// events: tests add their own. Everything the writer stores comes back as it was written.
CompressedClip read_clip(const fb::Clip& c) {
  CompressedClip out;
  out.name = c.name()->str();
  out.grid.sample_rate = c.sample_rate();
  out.grid.frame_count = c.frame_count();
  for (const fb::ConstantChannel* k : *c.constants()) {
    CompressedConstant cc;
    cc.joint = k->joint();
    cc.channel = static_cast<uint8_t>(k->channel());
    cc.dropped = k->dropped();
    constant_value(*k, cc.value);  // the writer stores it again as these three components
    out.constants.push_back(cc);
  }
  for (const fb::AnimatedChannel* k : *c.animated()) {
    CompressedAnimated a;
    a.joint = k->joint();
    a.channel = static_cast<uint8_t>(k->channel());
    a.bits = widths_of(*k);
    a.dropped = k->dropped();
    a.segment_offset_bits = k->segment_offset_bits();
    a.first_key = k->first_key();
    a.key_count = k->key_count();
    a.bit_offset = k->bit_offset();
    a.range_min[0] = k->range_min().x();
    a.range_min[1] = k->range_min().y();
    a.range_min[2] = k->range_min().z();
    a.range_extent[0] = k->range_extent().x();
    a.range_extent[1] = k->range_extent().y();
    a.range_extent[2] = k->range_extent().z();
    out.animated.push_back(a);
  }
  out.key_frames.assign(c.key_frames()->begin(), c.key_frames()->end());
  out.key_values.assign(c.key_values()->begin(), c.key_values()->end());
  if (const fb::ClipCompression* k = c.compression()) {
    out.tolerance = k->tolerance();
    out.probe_distance = k->probe_distance();
    out.max_error = k->max_error();
    out.mean_error = k->mean_error();
    out.worst_joint = k->worst_joint();
    out.raw_bytes = k->raw_bytes();
  }
  if (const fb::RootMotion* rm = c.root_motion()) {
    out.has_root_motion = true;
    for (const fb::Vec3* v : *rm->translations()) out.root_motion.translations.emplace_back(v->x(), v->y(), v->z());
    out.root_motion.yaws.assign(rm->yaws()->begin(), rm->yaws()->end());
    out.root_motion.up_axis = rm->up_axis();
  }
  if (c.morph_weights() != nullptr) {
    for (const fb::MorphTrack* t : *c.morph_weights()) {
      CompressedMorphTrack m;
      m.name = t->name()->str();
      m.key_frames.assign(t->key_frames()->begin(), t->key_frames()->end());
      m.values.assign(t->values()->begin(), t->values()->end());
      m.range_min = t->range_min();
      m.range_extent = t->range_extent();
      m.max_error = t->max_error();
      out.morph_weights.push_back(std::move(m));
    }
  }
  return out;
}

}  // namespace

const PabRig* pab_rig() {
  static const std::unique_ptr<PabRig> rig = []() -> std::unique_ptr<PabRig> {
    const fs::path dir = fixtures_dir() / "Pab";
    auto skeleton = Asset::open((dir / "skeleton.ossa").string());
    if (!skeleton) {
      ADD_FAILURE() << "graph fixture: " << skeleton.error().message;
      return nullptr;
    }
    auto out = std::make_unique<PabRig>();
    out->skeleton = read_skeleton(*skeleton);
    out->metres_per_unit = out->skeleton.metres_per_unit;
    for (const char* name : {"walk", "jog", "run", "crossarms"}) {
      auto clip = Asset::open((dir / (std::string(name) + ".ossa")).string());
      if (!clip || clip->clip_count() != 1) {
        ADD_FAILURE() << "graph fixture: " << name << ": " << (clip ? "not one clip" : clip.error().message);
        return nullptr;
      }
      out->clips.push_back(read_clip(*clip->file().clips()->Get(0)));
      out->clips.back().name = name;
    }
    return out;
  }();
  return rig.get();
}

GraphDef pab_graph(const PabRig& rig, std::string name) {
  GraphDef g;
  g.name = std::move(name);
  g.skeleton_hash = skeleton_hash_of(rig.skeleton);
  g.joint_count = static_cast<uint16_t>(rig.skeleton.joints.size());
  for (const CompressedClip& c : rig.clips) g.clips.push_back(c.name);
  return g;
}

Result<Asset> make_graph_file(const PabRig& rig, const std::vector<GraphDef>& graphs,
                              const std::map<std::string, std::vector<SourceEvent>>& events) {
  SourceScene scene;
  scene.skeleton = rig.skeleton;
  scene.metres_per_unit = rig.metres_per_unit;
  std::vector<CompressedClip> clips = rig.clips;
  for (CompressedClip& c : clips)
    if (auto it = events.find(c.name); it != events.end()) c.events = it->second;
  WriteProvenance provenance;
  provenance.source_name = "graph_fixture";
  WriteOptions options;
  options.graphs = graphs;
  const std::vector<uint8_t> bytes = write_ossa(scene, {}, clips, provenance, options);
  return Asset::from_bytes(bytes, "graph_fixture.ossa");
}

uint16_t add_node(GraphDef& g, NodeKind kind, std::string name) {
  g.nodes.push_back(NodeDef{std::move(name), std::move(kind)});
  g.root = static_cast<uint16_t>(g.nodes.size() - 1);
  return g.root;
}

uint16_t add_param(GraphDef& g, std::string name, ParamType type, float value, std::vector<std::string> enum_values) {
  GraphParameter p;
  p.name = std::move(name);
  p.type = type;
  p.default_value = value;
  p.enum_values = std::move(enum_values);
  g.parameters.push_back(std::move(p));
  return static_cast<uint16_t>(g.parameters.size() - 1);
}

uint16_t clip_node(GraphDef& g, uint16_t clip, float rate, bool loop) {
  ClipNodeDef c;
  c.clip = clip;
  c.rate = rate;
  c.loop = loop;
  return add_node(g, c, g.clips[clip]);
}

std::vector<glm::mat4> Played::model() const {
  std::vector<glm::mat4> m(def->joint_count());
  local_to_model(def->skeleton().parents(), inst->pose(), m);
  return m;
}

Played play(const PabRig& rig, const cook::GraphDef& g,
            const std::map<std::string, std::vector<cook::SourceEvent>>& events) {
  Played p;
  auto asset = make_graph_file(rig, {g}, events);
  EXPECT_TRUE(asset.ok()) << (asset.ok() ? "" : asset.error().message);
  if (!asset.ok()) return p;
  p.asset = std::make_unique<Asset>(std::move(*asset));
  auto def = GraphDefinition::create(*p.asset, g.name);
  EXPECT_TRUE(def.ok()) << (def.ok() ? "" : def.error().message);
  if (!def.ok()) return p;
  p.def = std::make_unique<GraphDefinition>(std::move(*def));
  auto inst = GraphInstance::create(*p.def);
  EXPECT_TRUE(inst.ok()) << (inst.ok() ? "" : inst.error().message);
  if (inst.ok()) p.inst = std::make_unique<GraphInstance>(std::move(*inst));
  return p;
}

}  // namespace ossa::test
