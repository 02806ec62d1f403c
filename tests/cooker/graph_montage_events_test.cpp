// graph_montage_events_test.cpp — montage events are never lost or doubled (graph.h, graph_montage.cpp).
//
// A montage with instants, windows (one inside a loop section, one across the loop's end), a
// branching point and events at its very start and end is played under host scenarios (constant
// rate, rate changes, a jump, a listener's jump at a branching point) with frames of 1/15, 1/60 and
// 1/240 s and a 60 Hz run with a 0.5 s hitch across the loop's end. Every run must give exactly the
// event sequence of a 1/1920 s reference run of the same scenario (the host calls fall on frame
// starts in every schedule), and the reference itself the counts worked out by hand. Branching
// points are raised with the montage standing exactly at their time.
#include <gtest/gtest.h>

#include <cmath>
#include <map>
#include <string>
#include <vector>

#include "graph_fixture.h"
#include <ossa/graph/graph.h>

namespace ossa {
namespace {

using namespace ossa::cook;
using test::play;
using test::Played;

constexpr int kTicksPerSecond = 1920;  // 15, 60 and 240 Hz frames are whole numbers of ticks

GraphDef events_graph(const test::PabRig& rig) {
  GraphDef g = test::pab_graph(rig);
  SlotDef slot;
  slot.input = test::clip_node(g, test::kWalk);
  slot.slot = "body";
  slot.group = "actions";
  test::add_node(g, slot, "slot");
  MontageDef m;
  m.name = "m";
  m.group = "actions";
  m.tracks.push_back({"body", {{test::kCrossarms, 0.0f, 3.0f, 1.0f}}});
  m.sections = {{"start", 0.0f, 1}, {"loop", 1.0f, 1}, {"end", 2.0f, -1}};
  using K = MontageNotifyKindDef;
  m.notifies = {
      {"start", 0.0f, 0.0f, K::Instant},    {"w1", 0.25f, 0.5f, K::Window},       {"half", 0.5f, 0.0f, K::Instant},
      {"loop_top", 1.0f, 0.0f, K::Instant}, {"b", 1.0f, 0.0f, K::BranchingPoint}, {"wl", 1.25f, 0.5f, K::Window},
      {"loop_mid", 1.5f, 0.0f, K::Instant}, {"wx", 1.8f, 0.6f, K::Window},        {"near_end", 1.99f, 0.0f, K::Instant},
      {"end_mid", 2.5f, 0.0f, K::Instant},  {"last", 3.0f, 0.0f, K::Instant}};
  g.montages.push_back(m);
  return g;
}

struct Seen {
  MontageEventType type;
  std::string name;
  float position;
  bool interrupted;
};

enum class Scenario { Constant, RateChanges, Jump, ListenerJump };

struct Listener {
  int branches = 0;
  std::vector<float> branch_positions;  // the montage's position when each branching point was raised
  bool jump_on_second = false;
};

void on_event(GraphInstance& inst, const MontageEvent& e, void* user) {
  auto& l = *static_cast<Listener*>(user);
  if (e.type != MontageEventType::BranchingPoint) return;
  l.branch_positions.push_back(inst.montage_status(e.montage).position);
  if (++l.branches == 2 && l.jump_on_second) inst.jump_to_section(e.montage, 2);
}

/// Plays the scenario with frames of the given lengths (ticks; the last repeats) until the montage
/// ends; returns every montage event in order.
std::vector<Seen> run(Played& p, Scenario scenario, const std::vector<int>& frames, Listener* listener = nullptr) {
  std::vector<Seen> out;
  p.inst->reset();
  Listener own;
  if (!listener) listener = &own;
  listener->jump_on_second = scenario == Scenario::ListenerJump;
  p.inst->set_montage_listener(on_event, listener);
  EXPECT_TRUE(p.inst->play_montage("m"));
  int tick = 0;
  bool ended = false;
  for (size_t f = 0; !ended && tick < 10 * kTicksPerSecond; ++f) {
    const int length = frames[std::min(f, frames.size() - 1)];
    const auto at = [&](double seconds) { return tick == static_cast<int>(std::lround(seconds * kTicksPerSecond)); };
    // Host calls at whole 1/15 s, so every schedule makes them at the same moment.
    if (scenario == Scenario::RateChanges && at(0.4)) p.inst->set_montage_rate(0, 2.0f);
    if (scenario == Scenario::RateChanges && at(1.6)) p.inst->set_montage_rate(0, 0.5f);
    if (scenario == Scenario::Jump && at(1.2)) p.inst->jump_to_section("m", "start");
    const double next_at = scenario == Scenario::Jump ? 3.6 : scenario == Scenario::RateChanges ? 2.8 : 2.6;
    if (at(next_at)) p.inst->set_next_section("m", "loop", "end");
    p.inst->update(static_cast<float>(length) / kTicksPerSecond);
    tick += length;
    for (const MontageEvent& e : p.inst->montage_events()) {
      out.push_back({e.type, std::string(e.name), e.position, e.interrupted});
      ended |= e.type == MontageEventType::Ended;
    }
  }
  EXPECT_TRUE(ended);
  p.inst->set_montage_listener(nullptr);
  return out;
}

std::string describe(const Seen& s) {
  static const char* kTypes[] = {"Started", "BlendingOut", "Ended", "Notify", "Begin", "End", "Branch"};
  return std::string(kTypes[static_cast<int>(s.type)]) + " " + s.name + " @" + std::to_string(s.position);
}

/// Same events in the same order; a notify's position exactly its time (a window's end at a jump:
/// where the jump left from, to float rounding).
::testing::AssertionResult same_sequence(const std::vector<Seen>& expected, const std::vector<Seen>& actual) {
  const size_t n = std::max(expected.size(), actual.size());
  for (size_t i = 0; i < n; ++i) {
    if (i >= expected.size() || i >= actual.size() || expected[i].type != actual[i].type ||
        expected[i].name != actual[i].name || expected[i].interrupted != actual[i].interrupted ||
        (expected[i].type >= MontageEventType::Notify && std::fabs(expected[i].position - actual[i].position) > 1e-3f))
      return ::testing::AssertionFailure()
             << "event " << i << ": expected " << (i < expected.size() ? describe(expected[i]) : "none") << ", got "
             << (i < actual.size() ? describe(actual[i]) : "none") << " (" << expected.size() << " vs " << actual.size()
             << " events)";
  }
  return ::testing::AssertionSuccess();
}

std::map<std::string, int> count(const std::vector<Seen>& events, MontageEventType type) {
  std::map<std::string, int> out;
  for (const Seen& s : events)
    if (s.type == type) ++out[s.name];
  return out;
}

TEST(MontageEvents, EveryEventOnceAtAnyFrameRateAcrossAHitchRateChangesAndJumps) {
  NEED_RIG();
  Played p = play(*rig, events_graph(*rig));
  ASSERT_TRUE(p.inst);
  const std::vector<std::pair<const char*, std::vector<int>>> schedules = {
      {"15 Hz", {128}},
      {"60 Hz", {32}},
      {"240 Hz", {8}},
      // 60 Hz with a 0.5 s frame from 1.75 s to 2.25 s: across the loop's end (2 s) and back.
      {"0.5 s hitch", [] {
         std::vector<int> f(105, 32);  // 1.75 s
         f.push_back(960);
         f.push_back(32);
         return f;
       }()}};
  for (Scenario scenario : {Scenario::Constant, Scenario::RateChanges, Scenario::Jump, Scenario::ListenerJump}) {
    const std::vector<Seen> reference = run(p, scenario, {1});
    for (const auto& [label, frames] : schedules)
      EXPECT_TRUE(same_sequence(reference, run(p, scenario, frames)))
          << label << ", scenario " << static_cast<int>(scenario);

    // The reference, by hand. Windows always close as often as they open, in order.
    const auto notifies = count(reference, MontageEventType::Notify);
    const auto begins = count(reference, MontageEventType::NotifyBegin),
               ends = count(reference, MontageEventType::NotifyEnd);
    EXPECT_EQ(begins, ends);
    std::map<std::string, int> open;
    for (const Seen& s : reference) {
      if (s.type == MontageEventType::NotifyBegin) {
        EXPECT_EQ(++open[s.name], 1) << s.name << " opened twice";
      }
      if (s.type == MontageEventType::NotifyEnd) {
        EXPECT_EQ(--open[s.name], 0) << s.name << " closed unopened";
      }
    }
    EXPECT_EQ(count(reference, MontageEventType::Started).at(""), 1);
    EXPECT_EQ(count(reference, MontageEventType::Ended).at(""), 1);
    EXPECT_EQ(notifies.at("start"), scenario == Scenario::Jump ? 2 : 1);
    EXPECT_EQ(notifies.at("last"), 1) << "an event at the very end fires when the montage ends there";
    EXPECT_EQ(notifies.at("end_mid"), 1);
    if (scenario == Scenario::Constant) {
      // start section 0-1 s; loop passes 1-2 s and 2-3 s (told at 2.6 s to move on); end 3-4 s.
      EXPECT_EQ(notifies.at("half"), 1);
      EXPECT_EQ(notifies.at("loop_top"), 2);
      EXPECT_EQ(notifies.at("loop_mid"), 2);
      EXPECT_EQ(notifies.at("near_end"), 2);
      EXPECT_EQ(count(reference, MontageEventType::BranchingPoint).at("b"), 2);
      EXPECT_EQ(begins.at("w1"), 1);
      EXPECT_EQ(begins.at("wl"), 2);
      // wx spans the loop's end: the first pass's closes at the jump back to the loop's top, the
      // second stays open into the end section (2 s lies inside it) and closes at 2.4 s.
      EXPECT_EQ(begins.at("wx"), 2);
      float last_wx_end = 0.0f;
      for (const Seen& s : reference)
        if (s.type == MontageEventType::NotifyEnd && s.name == "wx") last_wx_end = s.position;
      EXPECT_FLOAT_EQ(last_wx_end, 2.4f);
    }
    if (scenario == Scenario::Jump) {
      EXPECT_EQ(notifies.at("half"), 2) << "the start section played twice";
    }
    if (scenario == Scenario::ListenerJump) {
      EXPECT_EQ(count(reference, MontageEventType::BranchingPoint).at("b"), 2);
      EXPECT_EQ(notifies.at("loop_mid"), 1) << "the second pass left at its top";
    }
  }
}

TEST(MontageEvents, BranchingPointsStandExactlyAtTheirTime) {
  NEED_RIG();
  Played p = play(*rig, events_graph(*rig));
  ASSERT_TRUE(p.inst);
  for (int frame : {128, 32, 8, 960}) {
    Listener l;
    run(p, Scenario::ListenerJump, {frame}, &l);
    ASSERT_EQ(l.branch_positions.size(), 2u) << frame;
    for (float at : l.branch_positions) EXPECT_EQ(at, 1.0f) << "frame of " << frame << " ticks";
  }
  // The listener's jump takes effect from the point: after the update that reached the second
  // branching point, the montage stands where the rest of that update played from the end section's start.
  p.inst->reset();
  Listener l;
  l.jump_on_second = true;
  p.inst->set_montage_listener(on_event, &l);
  p.inst->play_montage("m");
  const float dt = 0.3f;
  double played = 0.0;
  while (l.branches < 2) {
    p.inst->update(dt);
    played += dt;
  }
  // Timeline: 1 s of start, 1 s of loop, then the loop's top again at 2 s of play: jumped to 2.0.
  EXPECT_NEAR(p.inst->montage_status(0).position, 2.0 + (played - 2.0), 1e-5);
  EXPECT_EQ(p.inst->montage_status(0).section, 2);
  p.inst->set_montage_listener(nullptr);
}

}  // namespace
}  // namespace ossa
