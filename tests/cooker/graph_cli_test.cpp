// graph_cli_test.cpp — graph files and event sidecars as ossa-cook's users meet them: the Pab
// sample graph cooks into a self-contained character that loads, deterministically; a bad graph
// fails alone in a batch with `file:line:col` messages; sidecar events land on clips, sorted; the
// provenance hash follows every file a graph reads; the Pab foot events sit where the feet plant.
#include <gtest/gtest.h>

#include <cctype>
#include <cmath>
#include <filesystem>
#include <set>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include <ossa/loader/asset.h>
#include <ossa/anim/pose_ops.h>
#include <ossa/anim/sample.h>
#include "test_files.h"

namespace fs = std::filesystem;
using ossa::test::run_command;

namespace {

// Graph files written to temporary folders name the repository's sample sources, which lie outside
// their read sandbox (input_log.h): every cook here allows the samples folder.
std::string cook_cmd() {
  return (ossa::test::bin_dir() / "ossa-cook").string() + " --allow-dir '" +
         (ossa::test::source_dir() / "assets").string() + "'";
}
fs::path pab(const char* file) { return ossa::test::source_dir() / "assets" / "Pab" / file; }
std::string q(const fs::path& p) { return "'" + p.string() + "'"; }

using ossa::test::count_files;

std::string str(const flatbuffers::String* s) { return s ? s->str() : std::string(); }

/// A small graph over the Pab sources by absolute path (so it can live in any directory).
std::string small_graph(const std::string& root, const std::string& walk_source = pab("walk.fbx").string()) {
  return "{\n  \"ossa_graph\": 1,\n  \"name\": \"small\",\n  \"skeleton\": \"" + pab("skeleton.fbx").string() +
         "\",\n  \"clips\": {\"walk\": \"" + walk_source + "\", \"run\": \"" + pab("run.fbx").string() +
         "\"},\n  \"parameters\": {\"speed\": {\"type\": \"float\"}},\n  \"root\": " + root + "\n}\n";
}

const char* kSmallRoot = R"({"blend": [{"clip": "walk"}, {"clip": "run"}], "alpha": "speed"})";

int find_joint(const ossa::SkeletonView& sk, std::string_view name) {
  for (size_t j = 0; j < sk.joint_count(); ++j)
    if (sk.joint_name(j) == name) return static_cast<int>(j);
  return -1;
}

const ossa::fb::Clip* find_clip(const ossa::Asset& a, std::string_view name) {
  for (size_t c = 0; c < a.clip_count(); ++c)
    if (a.clip(c).name() == name) return a.clip(c).fb;
  return nullptr;
}

class PabGraph : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new fs::path(ossa::test::make_temp_dir("pab-graph"));
    result_ =
        new ossa::test::CommandResult(run_command(cook_cmd() + " " + q(pab("pab.graph.json")) + " -o " + q(*dir_)));
  }
  static void TearDownTestSuite() {
    delete dir_;
    delete result_;
  }
  static fs::path* dir_;
  static ossa::test::CommandResult* result_;
};
fs::path* PabGraph::dir_ = nullptr;
ossa::test::CommandResult* PabGraph::result_ = nullptr;

TEST_F(PabGraph, CooksIntoACharacterThatLoads) {
  ASSERT_EQ(result_->exit_code, 0) << result_->err;
  EXPECT_EQ(count_files(*dir_), 1u);
  auto a = ossa::Asset::open((*dir_ / "pab.ossa").string());
  ASSERT_TRUE(a.ok()) << a.error().message;
  const ossa::SkeletonView sk = a->skeleton();
  ASSERT_EQ(sk.joint_count(), 67u);
  ASSERT_GE(a->mesh_count(), 1u);
  size_t submeshes = 0;
  for (size_t m = 0; m < a->mesh_count(); ++m) submeshes += a->mesh(m).submeshes().size();
  EXPECT_EQ(submeshes, 1u) << "arnaud.fbx's body only: the graph takes skeleton.fbx's rig without its mesh";
  EXPECT_EQ(a->material_count(), 1u);
  EXPECT_EQ(str(a->file().provenance()->source_name()), "pab.graph.json");

  ASSERT_EQ(a->clip_count(), 4u);
  const char* names[] = {"walk", "jog", "run", "crossarms"};
  for (size_t c = 0; c < 4; ++c) {
    EXPECT_EQ(a->clip(c).name(), names[c]);
    EXPECT_TRUE(ossa::check_clip_binding(a->clip(c), sk, names[c]).ok());
  }

  ASSERT_NE(a->file().graphs(), nullptr);
  ASSERT_EQ(a->file().graphs()->size(), 1u);
  const ossa::fb::Graph& g = *a->file().graphs()->Get(0);
  EXPECT_EQ(str(g.name()), "pab");
  EXPECT_EQ(g.skeleton_hash(), sk.hash());
  EXPECT_EQ(g.joint_count(), 67);
  ASSERT_EQ(g.clips()->size(), 4u);
  for (size_t c = 0; c < 4; ++c) EXPECT_EQ(g.clips()->Get(static_cast<flatbuffers::uoffset_t>(c))->str(), names[c]);
  ASSERT_EQ(g.parameters()->size(), 10u);
  EXPECT_EQ(str(g.parameters()->Get(0)->name()), "speed");
  EXPECT_EQ(str(g.parameters()->Get(1)->name()), "crossed_arms");
  EXPECT_EQ(g.parameters()->Get(2)->type(), ossa::fb::ParameterType::Trigger);
  const ossa::fb::Parameter& look = *g.parameters()->Get(3);
  EXPECT_EQ(str(look.name()), "look_target");
  EXPECT_EQ(look.type(), ossa::fb::ParameterType::Vector);
  ASSERT_NE(look.default_vector(), nullptr);
  EXPECT_FLOAT_EQ(look.default_vector()->y(), 160.0f) << "1.6 m in Pab's centimetres";

  // Root: a look-at over foot placement over foot locking over the upper-body montage slot over a
  // layer of crossed arms over the locomotion machine, from the spine up.
  const ossa::fb::Node& aim = *g.nodes()->Get(g.root());
  EXPECT_EQ(g.root(), g.nodes()->size() - 1);
  ASSERT_EQ(aim.data_type(), ossa::fb::NodeData::AimNode);
  ASSERT_EQ(aim.data_as_AimNode()->chain()->size(), 3u);
  EXPECT_EQ(aim.data_as_AimNode()->chain()->Get(2)->joint(), find_joint(sk, "Head"));
  const ossa::fb::Node& feet = *g.nodes()->Get(aim.data_as_AimNode()->input());
  ASSERT_EQ(feet.data_type(), ossa::fb::NodeData::FootPlacementNode);
  EXPECT_EQ(feet.data_as_FootPlacementNode()->pelvis(), find_joint(sk, "Hips"));
  ASSERT_EQ(feet.data_as_FootPlacementNode()->legs()->size(), 2u);
  const ossa::fb::Node& lock = *g.nodes()->Get(feet.data_as_FootPlacementNode()->input());
  ASSERT_EQ(lock.data_type(), ossa::fb::NodeData::FootLockNode);
  EXPECT_EQ(str(lock.data_as_FootLockNode()->legs()->Get(0)->plant_event()), "foot_left");
  const ossa::fb::Node& slot = *g.nodes()->Get(lock.data_as_FootLockNode()->input());
  ASSERT_EQ(slot.data_type(), ossa::fb::NodeData::SlotNode);
  EXPECT_EQ(str(slot.data_as_SlotNode()->slot()), "upper_body");
  ASSERT_NE(slot.data_as_SlotNode()->mask(), nullptr);
  EXPECT_EQ(slot.data_as_SlotNode()->mask()->Get(0)->joint(), find_joint(sk, "Spine1"));
  ASSERT_NE(g.montages(), nullptr);
  ASSERT_EQ(g.montages()->size(), 1u);
  const ossa::fb::Montage& montage = *g.montages()->Get(0);
  EXPECT_EQ(str(montage.name()), "cross_arms");
  ASSERT_EQ(montage.sections()->size(), 3u);
  EXPECT_EQ(montage.sections()->Get(1)->next(), 1) << "the loop section repeats until told";
  EXPECT_EQ(montage.sections()->Get(2)->next(), -1);
  const ossa::fb::Node& root = *g.nodes()->Get(slot.data_as_SlotNode()->input());
  ASSERT_EQ(root.data_type(), ossa::fb::NodeData::LayeredBlendNode);
  const auto* layered = root.data_as_LayeredBlendNode();
  ASSERT_EQ(layered->layers()->size(), 1u);
  const ossa::fb::Layer& layer = *layered->layers()->Get(0);
  ASSERT_EQ(layer.mask()->size(), 1u);
  EXPECT_EQ(layer.mask()->Get(0)->joint(), find_joint(sk, "Spine1"));
  EXPECT_EQ(layer.mask()->Get(0)->depth(), -1);
  EXPECT_EQ(layer.weight_parameter(), 1);
  EXPECT_TRUE(layer.mesh_space_rotation());
  EXPECT_FLOAT_EQ(layer.blend_time(), 0.3f);
  const ossa::fb::Node& base = *g.nodes()->Get(layered->base());
  ASSERT_EQ(base.data_type(), ossa::fb::NodeData::StateMachineNode);

  ASSERT_EQ(g.machines()->size(), 1u);
  const ossa::fb::StateMachine& m = *g.machines()->Get(0);
  EXPECT_EQ(str(m.name()), "locomotion");
  ASSERT_EQ(m.states()->size(), 3u);
  EXPECT_EQ(str(m.states()->Get(m.entry())->name()), "move");
  std::set<ossa::fb::TransitionMode> modes;
  for (const ossa::fb::Transition* t : *m.transitions()) modes.insert(t->mode());
  EXPECT_EQ(modes.size(), 3u) << "every transition mode is used";
  const ossa::fb::Node& move = *g.nodes()->Get(m.states()->Get(m.entry())->node());
  ASSERT_EQ(move.data_type(), ossa::fb::NodeData::BlendSpaceNode);
  EXPECT_EQ(move.data_as_BlendSpaceNode()->samples()->size(), 3u);
}

TEST_F(PabGraph, ClipsCarryTheirEvents) {
  ASSERT_EQ(result_->exit_code, 0) << result_->err;
  auto a = ossa::Asset::open((*dir_ / "pab.ossa").string());
  ASSERT_TRUE(a.ok());
  const ossa::fb::Clip* walk = find_clip(*a, "walk");
  ASSERT_NE(walk, nullptr);
  ASSERT_NE(walk->events(), nullptr);
  ASSERT_EQ(walk->events()->size(), 2u);  // from walk.events.json
  EXPECT_EQ(str(walk->events()->Get(0)->name()), "foot_right");
  EXPECT_NEAR(walk->events()->Get(0)->time(), 0.3333f, 1e-6f);
  EXPECT_EQ(str(walk->events()->Get(1)->name()), "foot_left");
  const ossa::fb::Clip* arms = find_clip(*a, "crossarms");
  ASSERT_NE(arms, nullptr);
  ASSERT_EQ(arms->events()->size(), 2u);  // from the graph file
  EXPECT_EQ(str(arms->events()->Get(0)->name()), "arms_crossed");
  EXPECT_EQ(str(arms->events()->Get(1)->name()), "arms_uncrossed");
}

// The foot events were placed by sampling the cooked clips: a foot plants at the frame where its
// ankle reaches the lowest height of its stance and stops moving forward. Check they still are.
TEST_F(PabGraph, FootEventsAreWhereTheFeetPlant) {
  ASSERT_EQ(result_->exit_code, 0) << result_->err;
  auto a = ossa::Asset::open((*dir_ / "pab.ossa").string());
  ASSERT_TRUE(a.ok());
  const ossa::SkeletonView sk = a->skeleton();
  const int left = find_joint(sk, "LeftFoot"), right = find_joint(sk, "RightFoot");
  ASSERT_GE(left, 0);
  ASSERT_GE(right, 0);
  for (const char* name : {"walk", "jog", "run"}) {
    SCOPED_TRACE(name);
    ossa::ClipView clip;
    for (size_t c = 0; c < a->clip_count(); ++c)
      if (a->clip(c).name() == name) clip = a->clip(c);
    ASSERT_NE(clip.fb, nullptr);
    auto cache = ossa::make_sampling_cache(clip, sk);
    ASSERT_TRUE(cache.ok());
    ossa::Pose pose(sk.joint_count());
    std::vector<glm::mat4> model(sk.joint_count());
    const uint32_t frames = clip.frame_count();  // the last frame repeats the first (a loop)
    std::vector<glm::vec3> feet[2];
    for (uint32_t f = 0; f < frames; ++f) {
      ossa::SampleOptions options;
      options.loop = false;
      ossa::sample(clip, static_cast<float>(f) / clip.sample_rate(), options, *cache, pose);
      ossa::local_to_model(sk.parents(), pose, model);
      feet[0].emplace_back(model[static_cast<size_t>(left)][3]);
      feet[1].emplace_back(model[static_cast<size_t>(right)][3]);
    }
    const auto* events = clip.fb->events();
    ASSERT_NE(events, nullptr);
    ASSERT_EQ(events->size(), 2u);
    for (const ossa::fb::ClipEvent* e : *events) {
      const int side = str(e->name()) == "foot_left" ? 0 : 1;
      const std::vector<glm::vec3>& p = feet[side];
      const uint32_t cycle = frames - 1;
      const auto f = static_cast<uint32_t>(std::lround(e->time() * clip.sample_rate())) % cycle;
      float lowest = p[0].y;
      for (uint32_t i = 0; i < cycle; ++i) lowest = std::min(lowest, p[i].y);
      const auto ground_step = [&](uint32_t i) {  // horizontal travel from frame i to i + 1, cm
        const glm::vec3 d = p[i + 1] - p[i];
        return std::sqrt(d.x * d.x + d.z * d.z);
      };
      EXPECT_LE(p[f].y, lowest + 1.0f) << str(e->name()) << " at frame " << f << ": the ankle is at its stance height";
      EXPECT_LT(ground_step(f), 2.0f) << str(e->name()) << " at frame " << f << ": the foot has stopped";
      EXPECT_GT(ground_step((f + cycle - 2) % cycle), 2.0f) << str(e->name()) << ": two frames before, it still moved";
    }
  }
}

TEST(GraphCli, CookingIsDeterministicAndFollowsTheOptions) {
  const fs::path dir = ossa::test::make_temp_dir("graph-det");
  auto r = run_command(cook_cmd() + " " + q(pab("pab.graph.json")) + " -o " + q(dir / "a") + " --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = run_command(cook_cmd() + " " + q(pab("pab.graph.json")) + " -o " + q(dir / "b") + " --quiet --jobs 1");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto x = ossa::test::read_file(dir / "a" / "pab.ossa"), y = ossa::test::read_file(dir / "b" / "pab.ossa");
  ASSERT_TRUE(x && y);
  EXPECT_TRUE(*x == *y) << "cooking twice gives different bytes";

  // --root-motion and --clip-tolerance apply to the graph's clips; --skeleton does not apply (a
  // warning, printed one by one with -v).
  fs::create_directories(dir / "sk");
  r = run_command(cook_cmd() + " " + q(pab("skeleton.fbx")) + " -o " + q(dir / "sk") + " --quiet");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = run_command(cook_cmd() + " " + q(pab("pab.graph.json")) + " -o " + q(dir / "c") +
                  " --root-motion --clip-tolerance 1 -v --skeleton " + q(dir / "sk" / "skeleton.ossa"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("--skeleton is not used for a graph file"), std::string::npos) << r.err;
  auto c = ossa::Asset::open((dir / "c" / "pab.ossa").string());
  ASSERT_TRUE(c.ok()) << c.error().message;
  const std::string options = str(c->file().provenance()->options());
  EXPECT_NE(options.find("root_motion=y"), std::string::npos) << options;
  EXPECT_NE(options.find("clips=0.001m"), std::string::npos) << options;
  EXPECT_EQ(options.find("skeleton="), std::string::npos) << options;
  for (size_t i = 0; i < c->clip_count(); ++i) {
    EXPECT_NE(c->clip(i).root_motion(), nullptr) << c->clip(i).name();
    EXPECT_FLOAT_EQ(c->clip(i).compression()->tolerance(), 0.1f) << "1 mm in centimetres";
  }
}

TEST(GraphCli, ABadGraphFailsAloneInABatch) {
  const fs::path dir = ossa::test::make_temp_dir("graph-batch");
  ASSERT_TRUE(ossa::test::write_file(dir / "good.graph.json", small_graph(kSmallRoot)));
  const std::string bad = small_graph(R"({"blend": [{"clip": "walk"}, {"clip": "jog"}], "alpha": "speed"})");
  ASSERT_TRUE(ossa::test::write_file(dir / "bad.graph.json", bad));
  const fs::path out = dir / "out";
  const auto r = run_command(cook_cmd() + " " + q(dir / "bad.graph.json") + " " + q(dir / "good.graph.json") + " " +
                             q(ossa::test::source_dir() / "assets" / "RiggedSimple" / "RiggedSimple.glb") + " -o " +
                             q(out) + " --jobs 2");
  EXPECT_EQ(r.exit_code, 1);
  const std::string where = (dir / "bad.graph.json").string() + ":7:49: unknown clip 'jog'";
  EXPECT_NE(r.err.find(where), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(out / "bad.ossa"));
  EXPECT_TRUE(ossa::Asset::open((out / "good.ossa").string()).ok());
  EXPECT_TRUE(ossa::Asset::open((out / "RiggedSimple.ossa").string()).ok());
  EXPECT_EQ(count_files(out), 2u);
}

// Values the runtime's loader refuses compiled into files that then failed verification ("internal
// error, cooked bytes fail verification", no position). Through ossa-cook, each is refused with
// `file:line:col`, and the same graph within bounds cooks into a file that loads.
TEST(GraphCli, WhatTheLoaderWouldRefuseIsRefusedWithAPosition) {
  const fs::path dir = ossa::test::make_temp_dir("graph-bounds");
  const auto graph = [](const std::string& root) {
    return "{\n  \"ossa_graph\": 1,\n  \"name\": \"b\",\n  \"skeleton\": \"" + pab("skeleton.fbx").string() +
           "\",\n  \"clips\": {\"walk\": \"" + pab("walk.fbx").string() + "\", \"run\": \"" + pab("run.fbx").string() +
           "\"},\n  \"parameters\": {\"speed\": {\"type\": \"float\"}, \"lean\": {\"type\": \"float\"}, "
           "\"stop\": {\"type\": \"trigger\"}},\n  \"root\": " +
           root + "\n}\n";
  };
  const auto machine = [](const std::string& transition) {
    return R"({"state_machine": {"name": "m", "entry": "a", "states": {"a": {"node": {"clip": "walk"}},
      "b": {"node": {"clip": "run"}}},
      "transitions": [{"from": "a", "to": "b"}, )" +
           transition + "]}}";
  };
  std::string grid;
  for (int i = 0; i < 2000; ++i)
    grid += std::string(i ? ", " : "") + R"({"clip": ")" + (i % 2 ? "walk" : "run") + R"(", "x": )" +
            std::to_string(i % 50) + R"(, "y": )" + std::to_string(i / 50) + "}";
  std::string deep = R"({"clip": "walk"})";
  for (int i = 0; i < 70; ++i) deep = R"({"blend": [)" + deep + R"(, {"clip": "run"}], "alpha": "lean"})";
  const std::vector<std::pair<std::string, std::string>> cases = {
      {"self", machine(R"({"from": "b", "to": "b", "when": "stop"})")},
      {"far", R"({"blend_space": "speed", "y": "lean", "samples": [{"clip": "walk", "x": 0, "y": 0},
        {"clip": "run", "x": 3.4e38, "y": 0}, {"clip": "walk", "x": 0, "y": 1}]})"},
      {"grid", R"({"blend_space": "speed", "y": "lean", "samples": [)" + grid + "]}"},
      {"rate", R"({"clip": "walk", "rate": 3.4e38})"},
      {"weight", R"({"additive": {"clip": "walk"}, "add": {"clip": "run"}, "weight": 1e30})"},
      {"duration", machine(R"({"from": "b", "to": "a", "duration": 1e30})")},
      {"literal", machine(R"({"from": "b", "to": "a", "when": "speed > 1e39"})")},
      {"deep", deep},
  };
  for (const auto& [name, root] : cases) ASSERT_TRUE(ossa::test::write_file(dir / (name + ".graph.json"), graph(root)));
  ASSERT_TRUE(ossa::test::write_file(dir / "fine.graph.json",
                                     graph(machine(R"({"from": "b", "to": "a", "when": "stop", "duration": 1e6})"))));
  const auto r = run_command(cook_cmd() + " " + q(dir) + " -o " + q(dir / "out") + " --jobs 2");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.err.find("internal error"), std::string::npos) << r.err.substr(0, 3000);
  for (const auto& [name, root] : cases) {
    const std::string file = (dir / (name + ".graph.json")).string() + ":";
    const size_t at = r.err.find(file);
    ASSERT_NE(at, std::string::npos) << name << ": " << r.err.substr(0, 3000);
    // file:LINE:COL: what
    size_t k = at + file.size(), digits = 0;
    while (k < r.err.size() && std::isdigit(static_cast<unsigned char>(r.err[k]))) ++k, ++digits;
    EXPECT_TRUE(digits > 0 && r.err[k] == ':' && std::isdigit(static_cast<unsigned char>(r.err[k + 1])))
        << name << ": " << r.err.substr(at, 200);
    EXPECT_FALSE(fs::exists(dir / "out" / (name + ".ossa"))) << name;
  }
  EXPECT_TRUE(ossa::Asset::open((dir / "out" / "fine.ossa").string()).ok());
}

TEST(GraphCli, ErrorsFromASourceNameTheGraphAndTheSource) {
  const fs::path dir = ossa::test::make_temp_dir("graph-src");
  const std::string text = small_graph(kSmallRoot, (dir / "missing.fbx").string());
  ASSERT_TRUE(ossa::test::write_file(dir / "g.graph.json", text));
  ASSERT_TRUE(ossa::test::write_file(dir / "broken.fbx", std::string_view("not an fbx")));
  ASSERT_TRUE(ossa::test::write_file(dir / "h.graph.json", small_graph(kSmallRoot, (dir / "broken.fbx").string())));
  const auto r =
      run_command(cook_cmd() + " " + q(dir / "g.graph.json") + " " + q(dir / "h.graph.json") + " -o " + q(dir / "out"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find((dir / "g.graph.json").string() + ":5:21: " + (dir / "missing.fbx").string() +
                       ": no such source file"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find((dir / "h.graph.json").string() + ":5:21: " + (dir / "broken.fbx").string() + ": "),
            std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir / "out"));
}

TEST(GraphCli, DirectoriesPickUpGraphFilesButNotOtherJson) {
  const fs::path dir = ossa::test::make_temp_dir("graph-dir");
  const fs::path src = dir / "src";
  fs::create_directories(src);
  fs::copy_file(pab("walk.fbx"), src / "walk.fbx");
  fs::copy_file(pab("walk.events.json"), src / "walk.events.json");
  ASSERT_TRUE(ossa::test::write_file(src / "notes.json", std::string_view("{\"not\": \"a graph\"}")));
  ASSERT_TRUE(ossa::test::write_file(src / "mini.graph.json", small_graph(kSmallRoot)));
  const auto sk = run_command(cook_cmd() + " " + q(pab("skeleton.fbx")) + " -o " + q(dir / "sk") + " --quiet");
  ASSERT_EQ(sk.exit_code, 0) << sk.err;
  const auto r = run_command(cook_cmd() + " " + q(src) + " --skeleton " + q(dir / "sk" / "skeleton.ossa") + " -o " +
                             q(dir / "out"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(fs::exists(dir / "out" / "mini.ossa"));  // X.graph.json -> X.ossa
  EXPECT_TRUE(fs::exists(dir / "out" / "walk.ossa"));
  EXPECT_EQ(count_files(dir / "out"), 2u) << "no output for notes.json or walk.events.json";
}

TEST(GraphCli, CookKeyFollowsEveryFileTheGraphReads) {
  const fs::path dir = ossa::test::make_temp_dir("graph-hash");
  fs::copy_file(pab("walk.fbx"), dir / "walk.fbx");
  ASSERT_TRUE(ossa::test::write_file(dir / "g.graph.json", small_graph(kSmallRoot, (dir / "walk.fbx").string())));
  const auto hash_after_cook = [&](const char* out) -> uint64_t {
    const auto r = run_command(cook_cmd() + " " + q(dir / "g.graph.json") + " -o " + q(dir / out) + " --quiet");
    EXPECT_EQ(r.exit_code, 0) << r.err;
    auto a = ossa::Asset::open((dir / out / "g.ossa").string());
    EXPECT_TRUE(a.ok());
    return a.ok() ? a->file().provenance()->cook_key() : 0;
  };
  const uint64_t without_sidecar = hash_after_cook("a");
  ASSERT_TRUE(ossa::test::write_file(
      dir / "walk.events.json",
      std::string_view(R"({"ossa_events": 1, "clips": {"walk": [{"name": "x", "time": 0.5}]}})")));
  const uint64_t with_sidecar = hash_after_cook("b");
  EXPECT_NE(with_sidecar, without_sidecar);
  ASSERT_TRUE(ossa::test::write_file(
      dir / "walk.events.json",
      std::string_view(R"({"ossa_events": 1, "clips": {"walk": [{"name": "x", "time": 0.6}]}})")));
  EXPECT_NE(hash_after_cook("c"), with_sidecar);
  EXPECT_EQ(hash_after_cook("d"), hash_after_cook("e"));
  auto a = ossa::Asset::open((dir / "c" / "g.ossa").string());
  ASSERT_TRUE(a.ok());
  const ossa::fb::Clip* walk = find_clip(*a, "walk");
  ASSERT_NE(walk, nullptr);
  ASSERT_EQ(walk->events()->size(), 1u);
  EXPECT_FLOAT_EQ(walk->events()->Get(0)->time(), 0.6f);
}

// ---------------------------------------------------------------------------------------------
// Event sidecars on plain source cooks

class Sidecar : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = ossa::test::make_temp_dir("sidecar");
    fs::copy_file(pab("walk.fbx"), dir / "walk.fbx");
    const auto r = run_command(cook_cmd() + " " + q(pab("skeleton.fbx")) + " -o " + q(dir / "sk") + " --quiet");
    ASSERT_EQ(r.exit_code, 0) << r.err;
  }
  ossa::test::CommandResult cook() {
    return run_command(cook_cmd() + " " + q(dir / "walk.fbx") + " --skeleton " + q(dir / "sk" / "skeleton.ossa") +
                       " -o " + q(dir / "out"));
  }
  fs::path dir;
};

TEST_F(Sidecar, EventsAreAttachedSortedAndClamped) {
  ASSERT_TRUE(ossa::test::write_file(dir / "walk.events.json", std::string_view(R"({
  "ossa_events": 1,
  "clips": {
    "walk": [{"name": "late", "time": 1.0}, {"name": "end", "time": 1.33339}, {"name": "early", "time": 0.1}],
    "*": [{"name": "start", "time": 0}, {"name": "early", "time": 0.1}]
  }
})")));
  const auto r = cook();
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto a = ossa::Asset::open((dir / "out" / "walk.ossa").string());
  ASSERT_TRUE(a.ok()) << a.error().message;
  const auto* events = a->clip(0).fb->events();
  ASSERT_NE(events, nullptr);
  std::vector<std::string> names;
  for (const ossa::fb::ClipEvent* e : *events) names.push_back(str(e->name()));
  EXPECT_EQ(names, (std::vector<std::string>{"start", "early", "late", "end"}));  // sorted, one "early"
  EXPECT_FLOAT_EQ(events->Get(3)->time(), a->clip(0).duration());                 // clamped to the clip's end
}

TEST_F(Sidecar, MistakesNameTheSidecarAndLeaveNoOutput) {
  ASSERT_TRUE(ossa::test::write_file(dir / "walk.events.json", std::string_view(R"({
  "ossa_events": 1,
  "clips": {
    "Walk": [{"name": "foot", "time": 0.2}],
    "walk": [{"name": "foot", "time": 2.5}, {"name": "", "time": 0.2}, {"nam": "x", "time": 0.3}]
  }
})")));
  const auto r = cook();
  EXPECT_EQ(r.exit_code, 1);
  const std::string sidecar = (dir / "walk.events.json").string();
  EXPECT_NE(r.err.find(sidecar + ":4:5: no clip named 'Walk' in walk.fbx (its clips: 'walk')"), std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find(sidecar + ":5:39: event 'foot' of clip 'walk': time 2.5 s is after the clip's end"),
            std::string::npos)
      << r.err;
  EXPECT_NE(r.err.find(sidecar + ":5:54: an event's \"name\" must not be empty"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find(sidecar + ":5:73: unknown key \"nam\" in an event (did you mean \"name\"?)"), std::string::npos)
      << r.err;
  EXPECT_FALSE(fs::exists(dir / "out" / "walk.ossa"));

  ASSERT_TRUE(ossa::test::write_file(dir / "walk.events.json", std::string_view("{\"clips\": {}}")));
  const auto v = cook();
  EXPECT_EQ(v.exit_code, 1);
  EXPECT_NE(v.err.find(sidecar + ":1:1: not an events file: \"ossa_events\": 1 is missing"), std::string::npos)
      << v.err;
  ASSERT_TRUE(
      ossa::test::write_file(dir / "walk.events.json", std::string_view("{\"ossa_events\": 1, \"clips\": {},}")));
  const auto s = cook();
  EXPECT_EQ(s.exit_code, 1);
  EXPECT_NE(s.err.find(sidecar + ":1:32: expected a key after ','"), std::string::npos) << s.err;
}

}  // namespace
