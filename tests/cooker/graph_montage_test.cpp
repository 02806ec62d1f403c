// graph_montage_test.cpp — montage playback (ossa/graph/graph.h, runtime/graph/graph_montage.cpp) on
// Pab's real clips: blend weights over time for every curve, the automatic blend out at any rate
// (in playing seconds on both sides), a loop section that repeats until told, jumps, interruption
// by a montage of the same group without a pop (within the bound the graph's transitions meet) and
// coexistence with one of another group, and every event exactly once at 15, 60 and 240 Hz and
// across a 0.5 s hitch, a rate change and a section jump. Graphs are built in C++ (graph_fixture.h).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <string>
#include <vector>

#include "graph_fixture.h"
#include <ossa/anim/pose_ops.h>
#include <ossa/anim/sample.h>
#include <ossa/graph/graph.h>

namespace ossa {
namespace {

using namespace ossa::cook;
using test::PabRig;
using test::play;
using test::Played;

/// A full-body slot "body" (group "actions") over `base`, or masked below `mask_joint`.
uint16_t add_slot(GraphDef& g, uint16_t base, std::string slot = "body", std::string group = "actions",
                  int mask_joint = -1) {
  SlotDef s;
  s.input = base;
  s.slot = std::move(slot);
  s.group = std::move(group);
  if (mask_joint >= 0) s.mask.push_back({static_cast<uint16_t>(mask_joint), -1});
  return test::add_node(g, s, "slot");
}

/// A montage of one track on `slot`: the segments laid end to end, the sections given.
MontageDef make_montage(std::string name, std::vector<MontageSegmentDef> segments,
                        std::vector<MontageSectionDef> sections, float blend_in = 0.2f, float blend_out = 0.2f,
                        MontageCurveDef curve = MontageCurveDef::Linear, std::string slot = "body",
                        std::string group = "actions") {
  MontageDef m;
  m.name = std::move(name);
  m.group = std::move(group);
  m.tracks.push_back({std::move(slot), std::move(segments)});
  m.sections = std::move(sections);
  m.blend_in = blend_in;
  m.blend_out = blend_out;
  m.blend_in_curve = m.blend_out_curve = curve;
  return m;
}

float curve(MontageCurveDef c, float u) {
  u = std::clamp(u, 0.0f, 1.0f);
  if (c == MontageCurveDef::Cubic) return u * u * (3.0f - 2.0f * u);
  if (c == MontageCurveDef::Inertialize) return 1.0f;
  return u;
}

/// Model-space joint positions relative to the root joint (the clips carry their forward motion in it).
std::vector<glm::vec3> positions(const Played& p, ConstPoseSpan pose) {
  std::vector<glm::mat4> model(p.def->joint_count());
  local_to_model(p.def->skeleton().parents(), pose, model);
  std::vector<glm::vec3> out;
  for (const glm::mat4& m : model) out.emplace_back(glm::vec3(m[3]) - glm::vec3(model[0][3]));
  return out;
}

float max_step(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b) {
  float worst = 0.0f;
  for (size_t j = 0; j < a.size(); ++j) worst = std::max(worst, glm::length(a[j] - b[j]));
  return worst;
}

// ---- blend weights ---------------------------------------------------------------------------

TEST(MontageBlend, WeightsFollowEachCurveInAndOut) {
  NEED_RIG();
  const float dt = 1.0f / 60.0f, blend_in = 0.4f, blend_out = 0.3f;
  for (MontageCurveDef c : {MontageCurveDef::Linear, MontageCurveDef::Cubic, MontageCurveDef::Inertialize}) {
    GraphDef g = test::pab_graph(*rig);
    add_slot(g, test::clip_node(g, test::kWalk));
    g.montages.push_back(
        make_montage("m", {{test::kCrossarms, 0.0f, 8.0f, 1.0f}}, {{"all", 0.0f, -1}}, blend_in, blend_out, c));
    Played p = play(*rig, g);
    ASSERT_TRUE(p.inst);
    ASSERT_TRUE(p.inst->play_montage("m"));
    for (int k = 1; k <= 36; ++k) {
      p.inst->update(dt);
      const MontageStatus st = p.inst->montage_status(0);
      ASSERT_TRUE(st.playing);
      EXPECT_NEAR(st.weight, curve(c, k * dt / blend_in), 2e-6f) << static_cast<int>(c) << " frame " << k;
      EXPECT_EQ(st.slot_weight, st.weight) << "a full-body slot shows it at its weight";
    }
    ASSERT_TRUE(p.inst->stop_montage("m"));
    bool ended = false;
    for (int k = 1; k <= 30 && !ended; ++k) {
      p.inst->update(dt);
      for (const MontageEvent& e : p.inst->montage_events())
        if (e.type == MontageEventType::Ended) ended = e.interrupted;
      const float expected = 1.0f - curve(c, k * dt / blend_out);
      if (!ended) {
        EXPECT_NEAR(p.inst->montage_status(0).weight, expected, 2e-6f) << static_cast<int>(c) << " out " << k;
      }
      if (c != MontageCurveDef::Inertialize) {
        EXPECT_EQ(ended, expected <= 0.0f) << "frame " << k;
      }
    }
    EXPECT_TRUE(ended) << "a stopped montage ends, interrupted";
    EXPECT_FALSE(p.inst->montage_playing(0));
  }
}

TEST(MontageBlend, AutomaticBlendOutIsTimedInPlayingSecondsAtAnyRate) {
  // The pitfall: a trigger in seconds compared with a rate-scaled (timeline) distance starts the blend
  // out too early at rates above 1 and too late below. Here both sides are playing seconds.
  NEED_RIG();
  const float dt = 1.0f / 240.0f, length = 2.0f, blend_out = 0.4f;
  for (float trigger : {-1.0f, 0.2f}) {
    for (float rate : {0.5f, 1.0f, 2.0f, 3.0f}) {
      GraphDef g = test::pab_graph(*rig);
      add_slot(g, test::clip_node(g, test::kWalk));
      MontageDef m = make_montage("m", {{test::kCrossarms, 0.0f, length, 1.0f}}, {{"all", 0.0f, -1}}, 0.1f, blend_out);
      m.blend_out_trigger = trigger;
      g.montages.push_back(m);
      Played p = play(*rig, g);
      ASSERT_TRUE(p.inst);
      p.inst->play_montage(0, rate);
      const float starts = length / rate - (trigger >= 0.0f ? trigger : blend_out);  // playing seconds
      float began = -1.0f, ended = -1.0f, weight_at_end = -1.0f, ended_at = -1.0f;
      for (int k = 1; k <= 3000 && ended < 0.0f; ++k) {
        const float before = p.inst->montage_status(0).position;
        p.inst->update(dt);
        for (const MontageEvent& e : p.inst->montage_events()) {
          if (e.type == MontageEventType::BlendingOut) {
            began = k * dt;
            EXPECT_FALSE(e.interrupted);
          }
          if (e.type == MontageEventType::Ended) ended = k * dt, ended_at = e.position;
        }
        if (before < length && p.inst->montage_status(0).position >= length)
          weight_at_end = p.inst->montage_status(0).weight;
      }
      EXPECT_NEAR(began, starts, dt) << "rate " << rate << " trigger " << trigger;
      EXPECT_NEAR(ended, starts + blend_out, dt) << "rate " << rate << " trigger " << trigger;
      EXPECT_EQ(ended_at, length) << "it reached its end";
      if (trigger < 0.0f) {
        EXPECT_EQ(weight_at_end, -1.0f) << "blended out (and ended) in the update that reached its end, rate " << rate;
      } else {
        EXPECT_NEAR(weight_at_end, 0.5f, 0.02f) << "the end is held while the blend finishes, rate " << rate;
      }
    }
  }
}

// ---- sections ----------------------------------------------------------------------------------

GraphDef looping_graph(const PabRig& rig) {
  GraphDef g = test::pab_graph(rig);
  add_slot(g, test::clip_node(g, test::kWalk));
  MontageDef m = make_montage("m", {{test::kCrossarms, 0.0f, 1.5f, 1.0f}},
                              {{"start", 0.0f, 1}, {"loop", 0.5f, 1}, {"end", 1.0f, -1}}, 0.125f, 0.25f);
  m.notifies.push_back({"loop_begin", 0.5f, 0.0f, MontageNotifyKindDef::BranchingPoint});
  g.montages.push_back(m);
  return g;
}

TEST(MontageSections, LoopRepeatsUntilToldThenPlaysTheEnd) {
  NEED_RIG();
  Played p = play(*rig, looping_graph(*rig));
  ASSERT_TRUE(p.inst);
  const float dt = 1.0f / 64.0f;  // binary-exact steps: section ends fall on frames
  ASSERT_TRUE(p.inst->play_montage("m"));
  int passes = 0;
  for (int k = 1; k <= 64 * 5; ++k) {
    p.inst->update(dt);
    for (const MontageEvent& e : p.inst->montage_events())
      if (e.type == MontageEventType::BranchingPoint) ++passes;
    const MontageStatus st = p.inst->montage_status(0);
    ASSERT_TRUE(st.playing && !st.blending_out) << "frame " << k;
    if (k > 32) {
      EXPECT_EQ(st.section, 1) << "frame " << k;
      EXPECT_GE(st.position, 0.5f);
      EXPECT_LT(st.position, 1.0f);
    }
  }
  // The loop begins at 0.5 s and every 0.5 s after: 9 passes fired within 5 s. The tenth has just
  // begun (the montage stands at the loop's start) and fires with the update that plays from there.
  EXPECT_EQ(passes, 9);
  EXPECT_EQ(p.inst->montage_status(0).position, 0.5f);
  // Told to move on: the pass begun finishes, then the end section plays and the montage ends.
  ASSERT_TRUE(p.inst->set_next_section("m", "loop", "end"));
  bool in_end = false, ended = false;
  for (int k = 1; k <= 64 && !ended; ++k) {
    p.inst->update(dt);
    for (const MontageEvent& e : p.inst->montage_events()) {
      if (e.type == MontageEventType::BranchingPoint) ++passes;
      if (e.type == MontageEventType::Ended) ended = !e.interrupted;
    }
    if (!ended && p.inst->montage_status(0).section == 2) in_end = true;
  }
  EXPECT_EQ(passes, 10) << "the pass begun, and no other";
  EXPECT_TRUE(in_end);
  EXPECT_TRUE(ended) << "it ended on its own (not interrupted)";
  // jump_to_section moves at once.
  ASSERT_TRUE(p.inst->play_montage("m", 1.0f, "loop"));
  p.inst->update(dt);
  EXPECT_EQ(p.inst->montage_status(0).section, 1);
  ASSERT_TRUE(p.inst->jump_to_section("m", "start"));
  EXPECT_EQ(p.inst->montage_status(0).section, 0);
  EXPECT_EQ(p.inst->montage_status(0).position, 0.0f);
  EXPECT_FALSE(p.inst->jump_to_section("m", "nowhere"));
  EXPECT_FALSE(p.inst->set_next_section("m", "loop", "nowhere"));
  EXPECT_FALSE(p.inst->play_montage("nothing"));
  EXPECT_FALSE(p.inst->play_montage(0, -1.0f));
  EXPECT_FALSE(p.inst->play_montage(0, std::nanf("")));
}

// ---- interruption and groups ----------------------------------------------------------------------

TEST(MontageInterruption, SameGroupTakesOverWithoutAPopAndOtherGroupsPlayOn) {
  NEED_RIG();
  const float dt = 1.0f / 60.0f;
  const float walk_d = rig->clips[test::kWalk].grid.duration(), run_d = rig->clips[test::kRun].grid.duration();
  for (MontageCurveDef c : {MontageCurveDef::Linear, MontageCurveDef::Cubic, MontageCurveDef::Inertialize}) {
    for (float at : {0.35f, 0.6f, 0.9f}) {
      GraphDef g = test::pab_graph(*rig);
      // The pair and the times of the graph's own pop test (graph_runtime_test GraphPop): walk, then run.
      const uint16_t body = add_slot(g, test::clip_node(g, test::kJog));
      add_slot(g, body, "head", "looks", rig->joint("Neck"));
      g.montages.push_back(
          make_montage("walk", {{test::kWalk, 0.0f, walk_d, 1.0f}}, {{"loop", 0.0f, 0}}, 0.3f, 0.3f, c));
      g.montages.push_back(make_montage("run", {{test::kRun, 0.0f, run_d, 1.0f}}, {{"loop", 0.0f, 0}}, 0.3f, 0.3f, c));
      g.montages.push_back(make_montage("look", {{test::kCrossarms, 0.0f, 4.0f, 1.0f}}, {{"all", 0.0f, -1}}, 0.3f, 0.3f,
                                        MontageCurveDef::Linear, "head", "looks"));
      Played p = play(*rig, g);
      ASSERT_TRUE(p.inst);
      p.inst->play_montage("walk");
      p.inst->play_montage("look");
      std::vector<glm::vec3> prev;
      float worst = 0.0f;
      const int switch_frame = static_cast<int>(at / dt);
      bool interrupted_end = false;
      for (int f = 0; f < switch_frame + 40; ++f) {
        if (f == switch_frame) {
          p.inst->play_montage("run");
          bool blending_out = false;
          for (const MontageEvent& e : p.inst->montage_events())
            if (e.type == MontageEventType::BlendingOut && e.montage == 0) blending_out = e.interrupted;
          EXPECT_TRUE(blending_out) << "the walk montage is interrupted at once";
        }
        p.inst->update(dt);
        for (const MontageEvent& e : p.inst->montage_events())
          if (e.type == MontageEventType::Ended && e.montage == 0) interrupted_end = e.interrupted;
        std::vector<glm::vec3> now = positions(p, p.inst->pose());
        if (f >= switch_frame - 1 && !prev.empty()) worst = std::max(worst, max_step(prev, now));
        prev = std::move(now);
      }
      EXPECT_TRUE(interrupted_end);
      EXPECT_FALSE(p.inst->montage_playing(0));
      EXPECT_TRUE(p.inst->montage_playing(1));
      // The other group's montage played on untouched.
      const MontageStatus look = p.inst->montage_status(2);
      EXPECT_TRUE(look.playing && !look.blending_out);
      EXPECT_EQ(look.weight, 1.0f);
      // Steady: the per-frame motion of the clips themselves (walk, run; crossarms on the neck).
      float steady = 0.0f;
      for (uint16_t clip : {uint16_t(test::kWalk), uint16_t(test::kRun), uint16_t(test::kCrossarms)}) {
        const ClipView view = p.def->clip(clip);
        auto cache = make_sampling_cache(view, p.def->skeleton());
        Pose pose(p.def->joint_count());
        std::vector<glm::vec3> last;
        for (int f = 0; f < 150; ++f) {
          sample(view, std::fmod(f * dt, view.duration()), SampleOptions{}, *cache, pose);
          std::vector<glm::vec3> now = positions(p, pose);
          if (f > 0 && std::fmod(f * dt, view.duration()) > dt) steady = std::max(steady, max_step(last, now));
          last = std::move(now);
        }
      }
      const float cm = rig->metres_per_unit * 100.0f;
      std::printf("interrupt %-11s at %.2f s: worst step %5.2f cm, plain playback %5.2f cm\n",
                  c == MontageCurveDef::Linear  ? "linear"
                  : c == MontageCurveDef::Cubic ? "cubic"
                                                : "inertialize",
                  at, worst * cm, steady * cm);
      EXPECT_LE(worst, 1.25f * steady) << "curve " << static_cast<int>(c) << " at " << at;
    }
  }
}

}  // namespace
}  // namespace ossa
