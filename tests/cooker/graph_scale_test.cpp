// graph_scale_test.cpp — the graph compiler's checks on graphs as large as a file can make them:
// a chain of 100,000 named nodes each using the next, a state machine of 100,000 states, and
// graphs just inside the format's limits (30,000 states, each playing a clip of its own at a rate
// of its own parameter). Each must be refused or compiled with `file:line:col` messages; the work
// must grow linearly with the file (these took 74.6 s and 34 s when name lookups and the
// reachability walk were linear scans, and re-checking unused named nodes re-expanded every chain).
// This suite has a CTest time limit (tests/CMakeLists.txt) far above what linear work needs here;
// bench/bench_graph.cpp measures the time itself.
#include <gtest/gtest.h>

#include <string>

#include "cooker/graph/graph_compile.h"

namespace {

using namespace ossa::cook;

#define EXPECT_HAS(haystack, needle)                               \
  EXPECT_NE(std::string(haystack).find(needle), std::string::npos) \
      << "expected to find:\n  " << (needle) << "\nin:\n  " << std::string(haystack).substr(0, 2000)

SourceSkeleton rig() {
  SourceSkeleton sk;
  SourceJoint hips;
  hips.name = "Hips";
  hips.parent = -1;
  sk.joints.push_back(hips);
  return sk;
}

/// A graph file around `root`, with named `nodes`, `params` and clips c0..c(clips-1) from one source.
std::string graph(const std::string& root, const std::string& nodes, const std::string& params, size_t clips) {
  std::string c = "{";
  for (size_t i = 0; i < clips; ++i) c += (i ? ", \"c" : "\"c") + std::to_string(i) + "\": \"clip.fbx\"";
  c += "}";
  return "{\"ossa_graph\": 1, \"name\": \"scale\", \"skeleton\": \"rig.fbx\",\n\"clips\": " + c +
         ",\n\"parameters\": " + params + ",\n\"nodes\": " + nodes + ",\n\"root\": " + root + "\n}\n";
}

ossa::Result<CompiledGraph> compile(const std::string& text, size_t clips) {
  static const SourceSkeleton sk = rig();
  GraphContext ctx;
  ctx.skeleton = &sk;
  for (size_t i = 0; i < clips; ++i) ctx.clips.push_back({"c" + std::to_string(i), 1.0f, {}});
  return compile_graph(text, "g.json", ctx);
}

/// A machine of `states` states s0..s(n-1), each playing clip c(i % clips) at the rate of
/// parameter p(i % params), with transitions s(i) -> s(i+1).
std::string machine(size_t states, size_t clips, size_t params) {
  std::string s = "{\"state_machine\": {\"name\": \"m\", \"entry\": \"s0\", \"states\": {";
  for (size_t i = 0; i < states; ++i)
    s += (i ? ",\n\"s" : "\"s") + std::to_string(i) + "\": {\"node\": {\"clip\": \"c" + std::to_string(i % clips) +
         "\", \"rate_parameter\": \"p" + std::to_string(i % params) + "\"}}";
  s += "},\n\"transitions\": [";
  for (size_t i = 0; i + 1 < states; ++i)
    s += (i ? ",\n" : "") + std::string("{\"from\": \"s") + std::to_string(i) + "\", \"to\": \"s" +
         std::to_string(i + 1) + "\", \"when\": \"p" + std::to_string(i % params) + " > 0.5\"}";
  return s + "]}}";
}

std::string float_params(size_t n) {
  std::string p = "{";
  for (size_t i = 0; i < n; ++i) p += (i ? ", \"p" : "\"p") + std::to_string(i) + "\": {\"type\": \"float\"}";
  return p + "}";
}

TEST(GraphScale, AUseChainOf100kNamedNodesIsRefusedWhereItGoesTooDeep) {
  constexpr size_t kChain = 100000;
  std::string nodes = "{";
  for (size_t i = 0; i < kChain; ++i)
    nodes += (i ? ",\n\"n" : "\"n") + std::to_string(i) + "\": " +
             (i + 1 < kChain ? "{\"use\": \"n" + std::to_string(i + 1) + "\"}" : std::string("{\"clip\": \"c0\"}"));
  nodes += "}";
  const auto r = compile(graph("{\"use\": \"n0\"}", nodes, "{}", 1), 1);
  ASSERT_FALSE(r.ok());
  EXPECT_HAS(r.error().message, "g.json:");
  EXPECT_HAS(r.error().message, "nodes nested deeper than 256 levels");
}

TEST(GraphScale, AMachineOf100kStatesIsRefusedByItsSize) {
  const auto r = compile(graph(machine(100000, 1, 1), "{}", float_params(1), 1), 1);
  ASSERT_FALSE(r.ok());
  EXPECT_HAS(r.error().message, "g.json:");
  EXPECT_HAS(r.error().message, "state machine 'm' has more than 32767 states");
}

TEST(GraphScale, AMachineOf30kStatesWith30kClipsAndParametersCompiles) {
  constexpr size_t kStates = 30000;
  const auto r = compile(graph(machine(kStates, kStates, kStates), "{}", float_params(kStates), kStates), kStates);
  ASSERT_TRUE(r.ok()) << r.error().message.substr(0, 2000);
  ASSERT_EQ(r->graph.machines.size(), 1u);
  EXPECT_EQ(r->graph.machines[0].states.size(), kStates);
  EXPECT_EQ(r->graph.machines[0].transitions.size(), kStates - 1);
  EXPECT_EQ(r->graph.nodes.size(), kStates + 1);
}

TEST(GraphScale, ManyMistakesInAHugeMachineStayCheapAndShort) {
  // 30,000 transitions naming states that do not exist: each is reported (up to the checker's
  // limit), without each message listing 30,000 state names.
  std::string text = machine(30000, 1, 1);
  for (size_t at = text.find("\"to\": \"s"); at != std::string::npos; at = text.find("\"to\": \"s", at + 1))
    text.replace(at, 8, "\"to\": \"x");
  const auto r = compile(graph(text, "{}", float_params(1), 1), 1);
  ASSERT_FALSE(r.ok());
  EXPECT_HAS(r.error().message, "is not a state of state machine 'm'");
  EXPECT_HAS(r.error().message, "more problems not shown");
  EXPECT_LT(r.error().message.size(), 200000u);
}

}  // namespace
