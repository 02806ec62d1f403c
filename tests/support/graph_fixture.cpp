// graph_fixture.cpp — see graph_fixture.h.
#include "graph_fixture.h"

#include <gtest/gtest.h>

#include <cstdio>
#include <memory>

#include "cooker/import/import_scene.h"
#include "cooker/write/write_ossa.h"
#include "test_files.h"
#include <ossa/anim/pose_ops.h>

namespace ossa::test {
namespace fs = std::filesystem;
using namespace ossa::cook;

int PabRig::joint(std::string_view name) const {
  for (size_t i = 0; i < skeleton.joints.size(); ++i)
    if (skeleton.joints[i].name == name) return static_cast<int>(i);
  return -1;
}

const PabRig* pab_rig() {
  static const std::unique_ptr<PabRig> rig = []() -> std::unique_ptr<PabRig> {
    const fs::path dir = source_dir() / "assets" / "Pab";
    if (!fs::exists(dir / "skeleton.fbx")) return nullptr;
    auto out = std::make_unique<PabRig>();
    auto rig_scene = import_scene((dir / "skeleton.fbx").string());
    if (!rig_scene) {
      std::fprintf(stderr, "graph fixture: %s\n", rig_scene.error().message.c_str());
      return nullptr;
    }
    out->skeleton = rig_scene->skeleton;
    out->metres_per_unit = rig_scene->metres_per_unit;
    ImportOptions options;
    options.reference = &out->skeleton;
    for (const char* name : {"walk", "jog", "run", "crossarms"}) {
      auto scene = import_scene((dir / (std::string(name) + ".fbx")).string(), options);
      if (!scene || scene->clips.empty()) {
        std::fprintf(stderr, "graph fixture: %s: %s\n", name, scene ? "no clip" : scene.error().message.c_str());
        return nullptr;
      }
      auto clip = compress_clip(scene->clips[0], out->skeleton, out->metres_per_unit, ClipCompressionOptions{});
      if (!clip) {
        std::fprintf(stderr, "graph fixture: %s: %s\n", name, clip.error().message.c_str());
        return nullptr;
      }
      clip->name = name;
      out->clips.push_back(std::move(*clip));
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
