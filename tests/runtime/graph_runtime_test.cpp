// graph_runtime_test.cpp — the animation graph evaluator (ossa/graph/graph.h) on Pab's real clips:
// transition weights, poses against hand-made blends, no pop at switches (measured in model
// space), synchronized phases, interruptions, triggers, nested machines, exit times across loops,
// events, determinism and allocation-free updates. Graphs are built in C++ (graph_fixture.h).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <random>

#include "allocation_counter.h"
#include "test_files.h"
#include "graph_fixture.h"
#include <ossa/graph/graph.h>
#include <ossa/anim/pose_ops.h>
#include <ossa/anim/sample.h>

namespace ossa {
namespace {

using namespace ossa::cook;
using test::PabRig;

using test::play;
using test::Played;

/// Two states playing clips a and b, a -> b on trigger "go" with the given mode and duration, and
/// b -> c (if c >= 0) on trigger "next".
GraphDef two_states(const PabRig& rig, uint16_t a, uint16_t b, TransitionModeDef mode, float duration, int c = -1,
                    TransitionModeDef next_mode = TransitionModeDef::Crossfade) {
  GraphDef g = test::pab_graph(rig);
  const uint16_t go = test::add_param(g, "go", ParamType::Trigger);
  const uint16_t next = test::add_param(g, "next", ParamType::Trigger);
  const uint16_t na = test::clip_node(g, a);
  const uint16_t nb = test::clip_node(g, b);
  StateMachineDef sm;
  sm.name = "m";
  sm.states = {{"a", na, true}, {"b", nb, true}};
  sm.transitions.push_back({0, 1, {{CondOp::Trigger, go, 0.0f}}, -1.0f, duration, mode});
  if (c >= 0) {
    const uint16_t nc = test::clip_node(g, static_cast<uint16_t>(c));
    sm.states.push_back({"c", nc, true});
    sm.transitions.push_back({1, 2, {{CondOp::Trigger, next, 0.0f}}, -1.0f, duration, next_mode});
  }
  g.machines.push_back(sm);
  test::add_node(g, StateMachineRefDef{0}, "m");
  return g;
}

struct ClipPlayer {
  ClipView clip;
  SamplingCache cache;
  Pose pose;
};

ClipPlayer player(const Played& p, uint16_t clip) {
  ClipPlayer out{p.def->clip(clip), {}, Pose(p.def->joint_count())};
  auto cache = make_sampling_cache(out.clip, p.def->skeleton());
  EXPECT_TRUE(cache.ok());
  out.cache = std::move(*cache);
  return out;
}

void sample_at(ClipPlayer& c, float t) { sample(c.clip, t, SampleOptions{}, c.cache, c.pose); }

float max_difference(ConstPoseSpan a, ConstPoseSpan b) {
  float worst = 0.0f;
  for (uint32_t j = 0; j < a.joint_count; ++j) {
    for (uint32_t k = 0; k < kPoseComponents; ++k) {
      float d = std::fabs(a[PoseComponent(k)][j] - b[PoseComponent(k)][j]);
      if (k == kRx || k == kRy || k == kRz || k == kRw) {  // q and -q are one rotation
        const float dot = a[kRx][j] * b[kRx][j] + a[kRy][j] * b[kRy][j] + a[kRz][j] * b[kRz][j] + a[kRw][j] * b[kRw][j];
        if (dot < 0.0f) d = std::fabs(a[PoseComponent(k)][j] + b[PoseComponent(k)][j]);
      }
      worst = std::max(worst, d);
    }
  }
  return worst;
}

/// Model-space joint positions of a local pose, relative to the root joint's: Pab's clips carry
/// their forward motion in the root, whose wrap at a loop would otherwise dwarf any pose pop.
std::vector<glm::vec3> positions(const Played& p, ConstPoseSpan pose) {
  std::vector<glm::mat4> model(p.def->joint_count());
  local_to_model(p.def->skeleton().parents(), pose, model);
  std::vector<glm::vec3> out;
  const glm::vec3 root(model[0][3]);
  for (const glm::mat4& m : model) out.emplace_back(glm::vec3(m[3]) - root);
  return out;
}

float max_step(const std::vector<glm::vec3>& a, const std::vector<glm::vec3>& b) {
  float worst = 0.0f;
  for (size_t j = 0; j < a.size(); ++j) worst = std::max(worst, glm::length(a[j] - b[j]));
  return worst;
}

// ---- transition weights and poses ------------------------------------------------------------

TEST(GraphCrossfade, WeightAfterAnyDtSequenceIsElapsedOverDuration) {
  NEED_RIG();
  const float duration = 0.5f;
  Played p = play(*rig, two_states(*rig, test::kWalk, test::kRun, TransitionModeDef::Crossfade, duration));
  ASSERT_TRUE(p.inst);
  ClipPlayer walk = player(p, test::kWalk), run = player(p, test::kRun);
  const float walk_d = walk.clip.duration(), run_d = run.clip.duration();
  float walk_t = 0.0f, run_t = 0.0f;
  for (float dt : {0.016f, 0.033f, 0.02f}) {
    p.inst->update(dt);
    walk_t = advance_time(walk_t, dt, 1.0f, walk_d, true);
  }
  EXPECT_EQ(p.inst->machine_status(0).current, 0);
  ASSERT_TRUE(p.inst->set_trigger(p.param("go")));
  float elapsed = 0.0f;
  for (float dt : {0.07f, 0.013f, 0.2f, 0.05f, 0.1f, 0.3f}) {
    p.inst->update(dt);
    elapsed += dt;
    walk_t = advance_time(walk_t, dt, 1.0f, walk_d, true);
    run_t = advance_time(run_t, dt, 1.0f, run_d, true);
    const MachineStatus st = p.inst->machine_status(0);
    const float w = std::min(1.0f, elapsed / duration);
    EXPECT_EQ(st.current, 1);
    EXPECT_EQ(st.weight, w) << "elapsed " << elapsed;
    EXPECT_EQ(st.previous, w < 1.0f ? 0 : -1);
    // The output is exactly the blend of the two clips sampled on their own clocks.
    sample_at(walk, walk_t);
    sample_at(run, run_t);
    Pose expected(p.def->joint_count());
    blend(walk.pose, run.pose, w, expected);
    EXPECT_LT(max_difference(p.inst->pose(), expected), 1e-5f) << "elapsed " << elapsed;
  }
  EXPECT_EQ(p.inst->value(p.param("go")), 0.0f) << "the trigger is consumed";
}

// ---- no pop at a switch -----------------------------------------------------------------------

struct PopResult {
  float steady = 0.0f;     // largest per-frame joint displacement of plain playback around the switch
  float at_switch = 0.0f;  // largest per-frame displacement over the transition
};

/// Plays walk for `before` seconds at 60 Hz, switches to run with `mode`, and measures the largest
/// model-space displacement of any joint between consecutive frames over the transition; the
/// steady reference is the largest of plain walk and plain run playback over the same span.
PopResult measure_pop(const PabRig& rig, TransitionModeDef mode, float duration, float before, int interrupt_to = -1) {
  const float dt = 1.0f / 60.0f;
  PopResult out;
  GraphDef g = interrupt_to >= 0 ? two_states(rig, test::kWalk, test::kRun, TransitionModeDef::Crossfade, duration,
                                              interrupt_to, mode)
                                 : two_states(rig, test::kWalk, test::kRun, mode, duration);
  Played p = play(rig, g);
  if (!p.inst) return out;
  std::vector<glm::vec3> prev;
  const int frames_before = static_cast<int>(before / dt);
  const int frames_after = static_cast<int>((duration + 0.3f) / dt);
  for (int f = 0; f < frames_before + frames_after; ++f) {
    if (f == frames_before) p.inst->set_trigger(p.param("go"));
    if (interrupt_to >= 0 && f == frames_before + static_cast<int>(0.4f * duration / dt))
      p.inst->set_trigger(p.param("next"));
    p.inst->update(dt);
    std::vector<glm::vec3> now = positions(p, p.inst->pose());
    if (f >= frames_before) out.at_switch = std::max(out.at_switch, max_step(prev, now));
    prev = std::move(now);
  }
  // Steady: each clip alone over the same frames.
  for (uint16_t clip :
       {uint16_t(test::kWalk), uint16_t(test::kRun), uint16_t(interrupt_to >= 0 ? interrupt_to : test::kRun)}) {
    ClipPlayer c = player(p, clip);
    std::vector<glm::vec3> last;
    for (int f = 0; f <= frames_before + frames_after; ++f) {
      sample_at(c, std::fmod(f * dt, c.clip.duration()));
      std::vector<glm::vec3> now = positions(p, c.pose);
      if (f > 0 && std::fmod(f * dt, c.clip.duration()) > dt) out.steady = std::max(out.steady, max_step(last, now));
      last = std::move(now);
    }
  }
  return out;
}

TEST(GraphPop, EveryBlendModeKeepsPerFrameDisplacementWithinPlainPlayback) {
  NEED_RIG();
  struct Case {
    const char* name;
    TransitionModeDef mode;
    float duration;
    int interrupt;
  } cases[] = {{"crossfade", TransitionModeDef::Crossfade, 0.3f, -1},
               {"sync_crossfade", TransitionModeDef::SyncCrossfade, 0.3f, -1},
               {"inertialize", TransitionModeDef::Inertialize, 0.3f, -1},
               {"crossfade interrupted by crossfade", TransitionModeDef::Crossfade, 0.3f, test::kCrossarms},
               {"crossfade interrupted by inertialize", TransitionModeDef::Inertialize, 0.3f, test::kCrossarms},
               {"instant switch (no blend)", TransitionModeDef::Crossfade, 0.0f, -1}};
  const float cm = rig->metres_per_unit * 100.0f;
  for (float before : {0.35f, 0.6f, 0.9f}) {
    for (const Case& c : cases) {
      const PopResult r = measure_pop(*rig, c.mode, c.duration, before, c.interrupt);
      std::printf("pop  %-38s switch at %.2f s: worst step %6.2f cm (plain playback %5.2f cm) ratio %.2f\n", c.name,
                  before, r.at_switch * cm, r.steady * cm, r.at_switch / r.steady);
      if (c.duration > 0.0f) {
        EXPECT_LE(r.at_switch, 1.25f * r.steady) << c.name << " at " << before;
      }
    }
  }
  // The measure sees pops: an instant switch at a mid-stride time jumps far more than a frame's motion.
  const PopResult instant = measure_pop(*rig, TransitionModeDef::Crossfade, 0.0f, 0.6f);
  EXPECT_GT(instant.at_switch, 2.0f * instant.steady);
}

// ---- synchronized crossfade --------------------------------------------------------------------

TEST(GraphSyncCrossfade, TargetStartsAtSourcePhaseAndStaysInStep) {
  NEED_RIG();
  Played p = play(*rig, two_states(*rig, test::kWalk, test::kRun, TransitionModeDef::SyncCrossfade, 0.5f));
  ASSERT_TRUE(p.inst);
  const size_t walk_node = 0, run_node = 1;
  for (int f = 0; f < 23; ++f) p.inst->update(1.0f / 60.0f);
  const float walk_phase = p.inst->node_phase(walk_node);
  p.inst->set_trigger(p.param("go"));
  float last = walk_phase;
  for (int f = 0; f < 40; ++f) {
    p.inst->update(1.0f / 60.0f);
    const MachineStatus st = p.inst->machine_status(0);
    if (st.previous < 0) break;
    const float wp = p.inst->node_phase(walk_node), rp = p.inst->node_phase(run_node);
    EXPECT_NEAR(wp, rp, 1e-4f) << "frame " << f;
    const float step = std::fmod(wp - last + 1.0f, 1.0f);
    EXPECT_GT(step, 0.0f);
    last = wp;
  }
  // Unsynchronized, the run restarts at 0 while the walk is mid-cycle.
  Played q = play(*rig, two_states(*rig, test::kWalk, test::kRun, TransitionModeDef::Crossfade, 0.5f));
  for (int f = 0; f < 23; ++f) q.inst->update(1.0f / 60.0f);
  q.inst->set_trigger(q.param("go"));
  q.inst->update(1.0f / 60.0f);
  EXPECT_GT(std::fabs(q.inst->node_phase(walk_node) - q.inst->node_phase(run_node)), 0.1f);
}

// ---- interruption ------------------------------------------------------------------------------

TEST(GraphInterruption, TransitionOutOfTheTargetTakesOverAndKeepsThePose) {
  NEED_RIG();
  Played p =
      play(*rig, two_states(*rig, test::kWalk, test::kRun, TransitionModeDef::Crossfade, 0.5f, test::kCrossarms));
  ASSERT_TRUE(p.inst);
  for (int f = 0; f < 10; ++f) p.inst->update(1.0f / 60.0f);
  p.inst->set_trigger(p.param("go"));
  for (int f = 0; f < 12; ++f) p.inst->update(1.0f / 60.0f);
  MachineStatus st = p.inst->machine_status(0);
  ASSERT_EQ(st.current, 1);
  ASSERT_EQ(st.previous, 0);
  const std::vector<glm::vec3> before = positions(p, p.inst->pose());
  p.inst->set_trigger(p.param("next"));
  p.inst->update(1.0f / 60.0f);
  st = p.inst->machine_status(0);
  EXPECT_EQ(st.current, 2);
  EXPECT_EQ(st.previous, 1) << "the interrupted target becomes the source";
  EXPECT_EQ(st.transition, 1);
  EXPECT_GT(st.inertial_remaining, 0.0f) << "the dropped source's share is carried by an offset";
  // Continuity: the first interrupted frame moves no joint further than plain playback of any of
  // the three clips ever does in a frame (measured the same way).
  float steady = 0.0f;
  for (uint16_t clip : {uint16_t(test::kWalk), uint16_t(test::kRun), uint16_t(test::kCrossarms)}) {
    ClipPlayer c = player(p, clip);
    std::vector<glm::vec3> last;
    for (float t = 0.0f; t + 1.0f / 60.0f < c.clip.duration(); t += 1.0f / 60.0f) {
      sample_at(c, t);
      std::vector<glm::vec3> now = positions(p, c.pose);
      if (!last.empty()) steady = std::max(steady, max_step(last, now));
      last = std::move(now);
    }
  }
  const float step = max_step(before, positions(p, p.inst->pose()));
  EXPECT_LE(step, steady);
  std::printf("interruption: first frame step %.2f cm, plain playback at most %.2f cm\n",
              step * rig->metres_per_unit * 100.0f, steady * rig->metres_per_unit * 100.0f);
}

// ---- triggers ----------------------------------------------------------------------------------

TEST(GraphTriggers, ConsumedByTheTransitionThatFiresOnly) {
  NEED_RIG();
  GraphDef g = test::pab_graph(*rig);
  const uint16_t t = test::add_param(g, "t", ParamType::Trigger);
  test::add_param(g, "other", ParamType::Trigger);
  const uint16_t a = test::clip_node(g, test::kWalk), b = test::clip_node(g, test::kRun);
  StateMachineDef sm;
  sm.name = "m";
  sm.states = {{"a", a, true}, {"b", b, true}};
  sm.transitions = {{0, 1, {{CondOp::Trigger, t, 0.0f}}, -1.0f, 0.1f, TransitionModeDef::Crossfade},
                    {1, 0, {{CondOp::Trigger, t, 0.0f}}, -1.0f, 0.1f, TransitionModeDef::Crossfade}};
  g.machines.push_back(sm);
  test::add_node(g, StateMachineRefDef{0});
  Played p = play(*rig, g);
  ASSERT_TRUE(p.inst);
  p.inst->set_trigger(p.param("other"));  // read by no transition: stays set, fires nothing
  p.inst->update(0.1f);
  EXPECT_EQ(p.inst->machine_status(0).current, 0);
  EXPECT_EQ(p.inst->value(p.param("other")), 1.0f);
  p.inst->set_trigger(p.param("t"));
  p.inst->update(0.05f);
  EXPECT_EQ(p.inst->machine_status(0).current, 1);
  EXPECT_EQ(p.inst->value(p.param("t")), 0.0f);
  for (int f = 0; f < 20; ++f) p.inst->update(0.05f);
  EXPECT_EQ(p.inst->machine_status(0).current, 1) << "one trigger fires one transition, once";
  p.inst->set_trigger(p.param("t"));
  p.inst->update(0.05f);
  EXPECT_EQ(p.inst->machine_status(0).current, 0);
  // Type checks: a trigger is not a bool, an index out of range changes nothing.
  EXPECT_FALSE(p.inst->set_bool(p.param("t"), true));
  EXPECT_FALSE(p.inst->set_trigger(99));
  EXPECT_TRUE(std::isnan(p.inst->value(99)));
}

// ---- nested machines, restart and resume ----------------------------------------------------------

GraphDef nested(const PabRig& rig, bool restart_inner) {
  GraphDef g = test::pab_graph(rig);
  const uint16_t fast = test::add_param(g, "fast", ParamType::Bool);
  const uint16_t away = test::add_param(g, "away", ParamType::Bool);
  const uint16_t walk = test::clip_node(g, test::kWalk), run = test::clip_node(g, test::kRun);
  StateMachineDef inner;
  inner.name = "inner";
  inner.states = {{"walk", walk, true}, {"run", run, true}};
  inner.transitions = {{0, 1, {{CondOp::Bool, fast, 0.0f}}, -1.0f, 0.2f, TransitionModeDef::Crossfade}};
  g.machines.push_back(inner);
  const uint16_t inner_node = test::add_node(g, StateMachineRefDef{0}, "inner");
  const uint16_t pose = test::clip_node(g, test::kCrossarms);
  StateMachineDef outer;
  outer.name = "outer";
  outer.states = {{"moving", inner_node, restart_inner}, {"posing", pose, true}};
  outer.transitions = {
      {0, 1, {{CondOp::Bool, away, 0.0f}}, -1.0f, 0.2f, TransitionModeDef::Inertialize},
      {1, 0, {{CondOp::Bool, away, 0.0f}, {CondOp::Not, 0, 0.0f}}, -1.0f, 0.2f, TransitionModeDef::Inertialize}};
  g.machines.push_back(outer);
  test::add_node(g, StateMachineRefDef{1}, "outer");
  return g;
}

TEST(GraphNested, InnerMachineRunsOnlyInsideItsStateAndRestartsOrResumes) {
  NEED_RIG();
  for (bool restart_inner : {true, false}) {
    Played p = play(*rig, nested(*rig, restart_inner));
    ASSERT_TRUE(p.inst);
    p.inst->set_bool(p.param("fast"), true);
    for (int f = 0; f < 30; ++f) p.inst->update(1.0f / 30.0f);
    EXPECT_EQ(p.inst->machine_status(0).current, 1);
    p.inst->set_bool(p.param("away"), true);
    p.inst->set_bool(p.param("fast"), false);
    for (int f = 0; f < 30; ++f) p.inst->update(1.0f / 30.0f);
    EXPECT_EQ(p.inst->machine_status(1).current, 1);
    EXPECT_EQ(p.inst->node_weight(2), 0.0f) << "the inner machine is not evaluated while posing";
    p.inst->set_bool(p.param("away"), false);
    p.inst->update(1.0f / 30.0f);
    EXPECT_EQ(p.inst->machine_status(1).current, 0);
    EXPECT_EQ(p.inst->machine_status(0).current, restart_inner ? 0 : 1)
        << (restart_inner ? "restart: back to the entry" : "resume: where it was");
  }
}

// ---- exit time ---------------------------------------------------------------------------------

TEST(GraphExitTime, FiresAtTheExitTimeOfTheLoopInWhichTheConditionHolds) {
  NEED_RIG();
  for (float exit_time : {0.5f, 1.75f}) {
    GraphDef g = test::pab_graph(*rig);
    const uint16_t go = test::add_param(g, "go", ParamType::Bool);
    const uint16_t a = test::clip_node(g, test::kWalk), b = test::clip_node(g, test::kRun);
    StateMachineDef sm;
    sm.name = "m";
    sm.states = {{"a", a, true}, {"b", b, true}};
    sm.transitions = {{0, 1, {{CondOp::Bool, go, 0.0f}}, exit_time, 0.1f, TransitionModeDef::Crossfade}};
    g.machines.push_back(sm);
    test::add_node(g, StateMachineRefDef{0});
    Played p = play(*rig, g);
    ASSERT_TRUE(p.inst);
    const float d = p.def->clip(test::kWalk).duration();
    const float dt = d / 20.0f;
    double u = 0.0;  // the walk's normalized time, as the machine counts it
    int fired_at = -1;
    double u_when_fired = 0.0;
    for (int f = 0; f < 100 && fired_at < 0; ++f) {
      if (u >= 1.2) p.inst->set_bool(go, true);  // condition becomes true in the second loop, past 0.5
      p.inst->update(dt);
      if (p.inst->machine_status(0).current == 1) {
        fired_at = f;
        u_when_fired = u;  // the normalized time the check saw (the last update's)
      }
      u += dt / d;
    }
    ASSERT_GE(fired_at, 0);
    const double expected = exit_time < 1.0f ? std::floor(1.2) + exit_time : std::max(1.2, double(exit_time));
    EXPECT_GE(u_when_fired, expected - 1e-4) << "exit time " << exit_time;
    EXPECT_LT(u_when_fired, expected + dt / d + 1e-4) << "exit time " << exit_time << ": fired late";
  }
}

// ---- events ------------------------------------------------------------------------------------

std::map<std::string, int> count_events(const GraphInstance& inst, std::map<std::string, int> counts = {}) {
  for (const GraphEvent& e : inst.events()) ++counts[std::string(e.name)];
  return counts;
}

TEST(GraphEvents, EachCrossingFiresOnceAcrossLoopsAnyStepAndReverse) {
  NEED_RIG();
  const float d = rig->clips[test::kWalk].grid.duration();
  const std::map<std::string, std::vector<SourceEvent>> events = {
      {"walk", {{"start", 0.0f}, {"left", 0.25f * d}, {"right", 0.75f * d}}}};
  for (float rate : {1.0f, -1.0f}) {
    GraphDef g = test::pab_graph(*rig);
    test::clip_node(g, test::kWalk, rate);
    Played p = play(*rig, g, events);
    ASSERT_TRUE(p.inst);
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> step(0.001f, 0.9f * d);
    std::map<std::string, int> counts;
    double played = 0.0;
    const double total = 5.37 * d;
    while (played < total) {
      const float dt = static_cast<float>(std::min<double>(step(rng), total - played));
      p.inst->update(dt);
      played += dt;
      counts = count_events(*p.inst, counts);
    }
    // Forward from 0 over 5.37 cycles: the events at phases 0 and 0.25 are reached 6 times (at
    // 0.25, 1.25, ... 5.25), the one at 0.75 five times. Backward from 0 (0, then d - ..., down):
    // phase 0 at cycles 0..5, phase 0.75 at 0.25 .. 5.25, phase 0.25 at 0.75 .. 4.75.
    if (rate > 0) {
      EXPECT_EQ(counts["start"], 6);
      EXPECT_EQ(counts["left"], 6);
      EXPECT_EQ(counts["right"], 5);
    } else {
      EXPECT_EQ(counts["start"], 6);
      EXPECT_EQ(counts["left"], 5);
      EXPECT_EQ(counts["right"], 6);
    }
  }
  // One update longer than several cycles reports every crossing.
  GraphDef g = test::pab_graph(*rig);
  test::clip_node(g, test::kWalk);
  Played p = play(*rig, g, events);
  p.inst->update(2.5f * d);
  std::map<std::string, int> counts = count_events(*p.inst);
  EXPECT_EQ(counts["start"], 3);
  EXPECT_EQ(counts["left"], 3);
  EXPECT_EQ(counts["right"], 2);
}

TEST(GraphEvents, DuringACrossfadeOnlyTheSideWithMostWeightFires) {
  NEED_RIG();
  const float wd = rig->clips[test::kWalk].grid.duration(), rd = rig->clips[test::kRun].grid.duration();
  std::map<std::string, std::vector<SourceEvent>> events;
  for (int k = 0; k < 20; ++k) {
    events["walk"].push_back({"walk", wd * k / 20.0f});
    events["run"].push_back({"run", rd * k / 20.0f});
  }
  Played p = play(*rig, two_states(*rig, test::kWalk, test::kRun, TransitionModeDef::Crossfade, 1.0f), events);
  ASSERT_TRUE(p.inst);
  p.inst->update(0.1f);
  p.inst->set_trigger(p.param("go"));
  int walk_after_half = 0, run_before_half = 0, walk_before = 0, run_after = 0;
  for (int f = 0; f < 60; ++f) {
    p.inst->update(1.0f / 30.0f);
    const float w = p.inst->machine_status(0).weight;
    for (const GraphEvent& e : p.inst->events()) {
      if (e.name == "walk") (w >= 0.5f ? walk_after_half : walk_before)++;
      if (e.name == "run") (w < 0.5f ? run_before_half : run_after)++;
    }
  }
  EXPECT_EQ(walk_after_half, 0);
  EXPECT_EQ(run_before_half, 0);
  EXPECT_GT(walk_before, 0);
  EXPECT_GT(run_after, 0);
}

// ---- determinism, allocation, reset --------------------------------------------------------------

void drive(GraphInstance& inst, const GraphDefinition& def, int frames, uint32_t seed,
           std::vector<char>* transitions = nullptr) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const int speed = def.find_parameter("speed"), crossed = def.find_parameter("crossed_arms"),
            stop = def.find_parameter("strike_pose");
  for (int f = 0; f < frames; ++f) {
    if (f % 15 == 0) inst.set_float(speed, 6.0f * u(rng));
    if (f % 40 == 0) inst.set_bool(crossed, u(rng) < 0.5f);
    if (f % 97 == 0) inst.set_trigger(stop);
    inst.update(1.0f / 60.0f + 0.004f * u(rng));
    const int t = inst.machine_status(0).transition;
    if (transitions && t >= 0 && static_cast<size_t>(t) < transitions->size())
      (*transitions)[static_cast<size_t>(t)] = 1;
  }
}

/// The Pab sample graph (assets/Pab/pab.graph.json) cooked by ossa-cook into the committed
/// fixtures (tests/fixtures/Pab/pab.ossa), opened once per process.
const Asset* pab_sample() {
  static const std::unique_ptr<Asset> asset = []() -> std::unique_ptr<Asset> {
    auto a = Asset::open((test::fixtures_dir() / "Pab" / "pab.ossa").string());
    EXPECT_TRUE(a.ok()) << (a.ok() ? "" : a.error().message);
    return a.ok() ? std::make_unique<Asset>(std::move(*a)) : nullptr;
  }();
  return asset.get();
}

TEST(GraphInstance, SampleGraphIsDeterministicAndAllocationFree) {
  const Asset* sample = pab_sample();
  ASSERT_NE(sample, nullptr) << "tests/fixtures/Pab/pab.ossa could not be opened";
  Played a;
  auto def = GraphDefinition::create(*sample, "pab");
  ASSERT_TRUE(def.ok()) << def.error().message;
  a.def = std::make_unique<GraphDefinition>(std::move(*def));
  auto first = GraphInstance::create(*a.def);
  ASSERT_TRUE(first.ok());
  a.inst = std::make_unique<GraphInstance>(std::move(*first));
  auto b = GraphInstance::create(*a.def);
  ASSERT_TRUE(b.ok());
  drive(*a.inst, *a.def, 50, 3);         // warm up (first sample decodes keys)
  std::vector<char> transitions(16, 0);  // sized before counting: the record must not allocate
  const size_t before = test::allocation_count();
  drive(*a.inst, *a.def, 2000, 5, &transitions);
  EXPECT_EQ(test::allocation_count(), before) << "update() allocated";
  // The drive visits every transition of the sample (so every blend mode) along the way.
  const auto* machine = a.def->graph().machines()->Get(0);
  for (int t = 0; t < static_cast<int>(machine->transitions()->size()); ++t)
    EXPECT_TRUE(transitions[static_cast<size_t>(t)]) << "transition " << t << " never ran";
  drive(*b, *a.def, 50, 3);
  drive(*b, *a.def, 2000, 5);
  const ConstPoseSpan pa = a.inst->pose(), pb = b->pose();
  EXPECT_EQ(std::memcmp(pa.base, pb.base, sizeof(float) * kPoseComponents * pa.stride), 0);
  for (uint32_t k = 0; k < pa.joint_count; ++k) ASSERT_TRUE(std::isfinite(pa[kRw][k]));
  // reset() gives a fresh instance's behaviour.
  a.inst->reset();
  auto c = GraphInstance::create(*a.def);
  drive(*a.inst, *a.def, 300, 9);
  drive(*c, *a.def, 300, 9);
  EXPECT_EQ(std::memcmp(a.inst->pose().base, c->pose().base, sizeof(float) * kPoseComponents * pa.stride), 0);
}

// ---- nodes -------------------------------------------------------------------------------------

TEST(GraphNodes, BlendSpaceWeightsAndSynchronizedPhase) {
  NEED_RIG();
  GraphDef g = test::pab_graph(*rig);
  const uint16_t speed = test::add_param(g, "speed", ParamType::Float, 1.9f);
  BlendSpaceDef bs;
  bs.x_parameter = speed;
  bs.samples = {{test::kWalk, 1.2f, 0.0f}, {test::kJog, 2.6f, 0.0f}, {test::kRun, 4.0f, 0.0f}};
  test::add_node(g, bs);
  Played p = play(*rig, g);
  ASSERT_TRUE(p.inst);
  const float dt = 0.1f;
  p.inst->update(dt);
  // Weights 0.5 / 0.5 between walk and jog: the cycle is the mean of their durations.
  const float wd = p.def->clip(test::kWalk).duration(), jd = p.def->clip(test::kJog).duration();
  const float phase = dt / (0.5f * wd + 0.5f * jd);
  EXPECT_NEAR(p.inst->node_phase(0), phase, 1e-6f);
  ClipPlayer walk = player(p, test::kWalk), jog = player(p, test::kJog);
  sample_at(walk, phase * wd);
  sample_at(jog, phase * jd);
  Pose expected(p.def->joint_count());
  blend(walk.pose, jog.pose, 0.5f, expected);
  EXPECT_LT(max_difference(p.inst->pose(), expected), 1e-5f);
}

TEST(GraphNodes, SelectBlendsOverItsBlendTimeAndLayerWeightEases) {
  NEED_RIG();
  GraphDef g = test::pab_graph(*rig);
  const uint16_t which = test::add_param(g, "which", ParamType::Enum, 0.0f, {"walk", "run"});
  const uint16_t arms = test::add_param(g, "arms", ParamType::Bool);
  const uint16_t walk = test::clip_node(g, test::kWalk), run = test::clip_node(g, test::kRun);
  const uint16_t sel = test::add_node(g, SelectDef{which, {walk, run}, 0.4f});
  const uint16_t cross = test::clip_node(g, test::kCrossarms);
  LayerDef layer;
  layer.node = cross;
  layer.mask = {{static_cast<uint16_t>(rig->joint("Spine")), -1}};
  layer.weight_parameter = static_cast<int16_t>(arms);
  layer.blend_time = 0.5f;
  test::add_node(g, LayeredDef{sel, {layer}});
  Played p = play(*rig, g);
  ASSERT_TRUE(p.inst);
  p.inst->update(0.1f);
  EXPECT_EQ(p.inst->node_weight(walk), 1.0f);
  EXPECT_EQ(p.inst->node_weight(run), 0.0f);
  EXPECT_TRUE(p.inst->set_enum(which, 1));
  EXPECT_FALSE(p.inst->set_enum(which, 2));
  EXPECT_TRUE(p.inst->set_bool(arms, true));
  p.inst->update(0.1f);
  EXPECT_NEAR(p.inst->node_weight(run), 0.25f / 1.0f, 1e-6f);  // 0.1 / 0.4, normalized by 0.75 + 0.25
  EXPECT_NEAR(p.inst->node_weight(cross), 0.2f, 1e-6f);        // 0.1 / 0.5
  p.inst->update(0.3f);
  EXPECT_EQ(p.inst->node_weight(run), 1.0f);
  EXPECT_EQ(p.inst->node_weight(walk), 0.0f);
  EXPECT_NEAR(p.inst->node_weight(cross), 0.8f, 1e-6f);
  // Joints outside the mask keep the base pose exactly.
  ClipPlayer r = player(p, test::kRun);
  sample_at(r, 0.4f);  // the run was advanced with every update (0.1 + 0.1 + 0.3 - it started at 0)
  const int hips = rig->joint("Hips");
  ASSERT_GE(hips, 0);
  for (PoseComponent k : {kTx, kTy, kTz, kRx, kRy, kRz, kRw})
    EXPECT_NEAR(p.inst->pose()[k][hips], ConstPoseSpan(r.pose)[k][hips], 1e-5f);
}

TEST(GraphNodes, MeshSpaceLayerGivesMaskedJointsTheLayersModelRotation) {
  NEED_RIG();
  GraphDef g = test::pab_graph(*rig);
  const uint16_t walk = test::clip_node(g, test::kWalk), cross = test::clip_node(g, test::kCrossarms);
  LayerDef layer;
  layer.node = cross;
  layer.mask = {{static_cast<uint16_t>(rig->joint("Spine1")), -1}};
  layer.mesh_space_rotation = true;
  test::add_node(g, LayeredDef{walk, {layer}});
  Played p = play(*rig, g);
  ASSERT_TRUE(p.inst);
  p.inst->update(0.3f);
  ClipPlayer c = player(p, test::kCrossarms), w = player(p, test::kWalk);
  sample_at(c, 0.3f);
  sample_at(w, 0.3f);
  std::vector<glm::mat4> out(p.def->joint_count()), layer_model(p.def->joint_count()), base_model(p.def->joint_count());
  local_to_model(p.def->skeleton().parents(), p.inst->pose(), out);
  local_to_model(p.def->skeleton().parents(), c.pose, layer_model);
  local_to_model(p.def->skeleton().parents(), w.pose, base_model);
  const int head = rig->joint("Head"), hips = rig->joint("Hips");
  ASSERT_GE(head, 0);
  const glm::quat q_out = glm::quat_cast(glm::mat3(out[head])), q_layer = glm::quat_cast(glm::mat3(layer_model[head]));
  EXPECT_GT(std::fabs(glm::dot(q_out, q_layer)), 1.0f - 1e-5f) << "the head keeps the layer's model orientation";
  EXPECT_LT(glm::length(glm::vec3(out[hips][3]) - glm::vec3(base_model[hips][3])), 1e-4f);
}

TEST(GraphNodes, AdditiveAddsTheDeltaFromBindPose) {
  NEED_RIG();
  GraphDef g = test::pab_graph(*rig);
  const uint16_t amount = test::add_param(g, "amount", ParamType::Float, 0.0f);
  const uint16_t walk = test::clip_node(g, test::kWalk), cross = test::clip_node(g, test::kCrossarms);
  test::add_node(g, AdditiveDef{walk, cross, 1.0f, static_cast<int16_t>(amount)});
  Played p = play(*rig, g);
  ASSERT_TRUE(p.inst);
  p.inst->update(0.2f);
  ClipPlayer w = player(p, test::kWalk), c = player(p, test::kCrossarms);
  sample_at(w, 0.2f);
  EXPECT_LT(max_difference(p.inst->pose(), w.pose), 1e-6f) << "weight 0: the base alone";
  p.inst->set_float(amount, 0.5f);
  p.inst->update(0.1f);
  sample_at(w, 0.3f);
  sample_at(c, 0.1f);  // the additive input only advances while it has weight
  Pose delta(p.def->joint_count()), bind(p.def->joint_count()), expected(p.def->joint_count());
  set_bind_pose(p.def->skeleton(), bind);
  make_additive(c.pose, bind, delta);
  add(w.pose, delta, 0.5f, expected);
  EXPECT_LT(max_difference(p.inst->pose(), expected), 1e-5f);
}

// ---- binding errors ----------------------------------------------------------------------------

TEST(GraphDefinition, ErrorsNameTheGraphAndWhatIsMissing) {
  NEED_RIG();
  GraphDef g = test::pab_graph(*rig, "loco");
  test::clip_node(g, test::kWalk);
  auto asset = test::make_graph_file(*rig, {g});
  ASSERT_TRUE(asset.ok()) << asset.error().message;
  auto missing = GraphDefinition::create(*asset, "nope");
  ASSERT_FALSE(missing.ok());
  EXPECT_NE(missing.error().message.find("no graph named 'nope' (graphs: loco)"), std::string::npos)
      << missing.error().message;
  GraphDef unknown_clip = g;
  unknown_clip.name = "other";
  unknown_clip.clips[0] = "moonwalk";
  auto asset2 = test::make_graph_file(*rig, {unknown_clip});
  ASSERT_TRUE(asset2.ok());
  auto bad = GraphDefinition::create(*asset2, "other");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("clip 'moonwalk' not found"), std::string::npos) << bad.error().message;
  GraphDef other_rig = g;
  other_rig.name = "rig";
  other_rig.skeleton_hash ^= 1;
  auto asset3 = test::make_graph_file(*rig, {other_rig});
  ASSERT_TRUE(asset3.ok());
  auto wrong = GraphDefinition::create(*asset3, "rig");
  ASSERT_FALSE(wrong.ok());
  EXPECT_NE(wrong.error().message.find("another rig"), std::string::npos) << wrong.error().message;
}

TEST(GraphValidation, MalformedGraphTablesAreRejectedWithTheirFault) {
  NEED_RIG();
  struct Case {
    const char* expect;
    std::function<void(GraphDef&)> spoil;
  };
  const std::vector<Case> cases = {
      {"must be an earlier node", [](GraphDef& g) { std::get<BlendAlphaDef>(g.nodes[2].kind).b = 2; }},
      {"already used", [](GraphDef& g) { std::get<BlendAlphaDef>(g.nodes[2].kind).b = 0; }},
      {"cannot be used here", [](GraphDef& g) { std::get<BlendAlphaDef>(g.nodes[2].kind).alpha_parameter = 1; }},
      {"parameter 7 is out of range",
       [](GraphDef& g) { std::get<BlendAlphaDef>(g.nodes[2].kind).alpha_parameter = 7; }},
      {"clip 9 is out of range", [](GraphDef& g) { std::get<ClipNodeDef>(g.nodes[0].kind).clip = 9; }},
      {"root 5 is not a node", [](GraphDef& g) { g.root = 5; }},
      {"start offset", [](GraphDef& g) { std::get<ClipNodeDef>(g.nodes[0].kind).start_offset = -1.0f; }},
      {"default 9 lies outside",
       [](GraphDef& g) {
         g.parameters[0].max_value = 1.0f;
         g.parameters[0].default_value = 9.0f;
       }},
      {"an enum needs at least one value", [](GraphDef& g) { g.parameters[1].type = ParamType::Enum; }},
  };
  for (const Case& c : cases) {
    GraphDef g = test::pab_graph(*rig);
    test::add_param(g, "alpha", ParamType::Float, 0.5f);
    test::add_param(g, "flag", ParamType::Bool);
    const uint16_t a = test::clip_node(g, test::kWalk), b = test::clip_node(g, test::kRun);
    test::add_node(g, BlendAlphaDef{a, b, 0});
    ASSERT_TRUE(test::make_graph_file(*rig, {g}).ok()) << c.expect;
    c.spoil(g);
    auto asset = test::make_graph_file(*rig, {g});
    ASSERT_FALSE(asset.ok()) << c.expect;
    EXPECT_NE(asset.error().message.find(c.expect), std::string::npos) << asset.error().message;
    EXPECT_NE(asset.error().message.find("graph 0 'test'"), std::string::npos) << asset.error().message;
  }
  // Conditions: malformed reverse Polish programs and mistyped parameters.
  const std::vector<std::pair<const char*, std::vector<CondInstr>>> conditions = {
      {"'and' / 'or' needs two operands", {{CondOp::Bool, 1, 0.0f}, {CondOp::And, 0, 0.0f}}},
      {"leaves 2 values", {{CondOp::Bool, 1, 0.0f}, {CondOp::Bool, 1, 0.0f}}},
      {"'not' with nothing", {{CondOp::Not, 0, 0.0f}}},
      {"has type Float", {{CondOp::Trigger, 0, 0.0f}}},
      {"comparison value is not finite", {{CondOp::Less, 0, NAN}}},
  };
  for (const auto& [expect, program] : conditions) {
    GraphDef g = test::pab_graph(*rig);
    test::add_param(g, "alpha", ParamType::Float, 0.5f);
    test::add_param(g, "flag", ParamType::Bool);
    const uint16_t a = test::clip_node(g, test::kWalk), b = test::clip_node(g, test::kRun);
    StateMachineDef sm;
    sm.name = "m";
    sm.states = {{"a", a, true}, {"b", b, true}};
    sm.transitions = {{0, 1, program, -1.0f, 0.1f, TransitionModeDef::Crossfade}};
    g.machines.push_back(sm);
    test::add_node(g, StateMachineRefDef{0});
    auto asset = test::make_graph_file(*rig, {g});
    ASSERT_FALSE(asset.ok()) << expect;
    EXPECT_NE(asset.error().message.find(expect), std::string::npos) << asset.error().message;
  }
}

}  // namespace
}  // namespace ossa
