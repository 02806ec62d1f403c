// graph_compile_test.cpp — the graph compiler (cooker/graph/graph_compile.h) and its condition language
// (cooker/graph/graph_condition.h): valid graphs give the expected GraphDef (node order, indices, RPN,
// sorted transitions, merged events); every kind of mistake is refused with a message that starts
// with `file:line:col:` at the value at fault.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <string>
#include <vector>

#include "cooker/graph/graph_compile.h"
#include "cooker/graph/graph_condition.h"
#include "cooker/write/write_ossa.h"

namespace {

using namespace ossa::cook;

#define EXPECT_HAS(haystack, needle)                               \
  EXPECT_NE(std::string(haystack).find(needle), std::string::npos) \
      << "expected to find:\n  " << (needle) << "\nin:\n  " << (haystack)

const char* kParams = R"({
    "speed": {"type": "float", "default": 1, "min": 0, "max": 6},
    "lean": {"type": "float"},
    "crossed": {"type": "bool", "default": false},
    "stance": {"type": "int", "default": 0, "min": 0, "max": 2},
    "gait": {"type": "enum", "values": ["walk", "run", "idle"], "default": "run"},
    "stop": {"type": "trigger"}
  })";
enum : uint16_t { kSpeed, kLean, kCrossed, kStance, kGait, kStop };

const char* kClips = R"({"walk": "walk.fbx", "run": {"source": "run.fbx", "clip": "Take 001"}, "wave": "wave.fbx"})";

std::string graph(const std::string& root, const std::string& nodes = "{}", const std::string& params = kParams,
                  const std::string& clips = kClips) {
  return "{\n  \"ossa_graph\": 1,\n  \"name\": \"test\",\n  \"skeleton\": \"rig.fbx\",\n  \"clips\": " + clips +
         ",\n  \"parameters\": " + params + ",\n  \"nodes\": " + nodes + ",\n  \"root\": " + root + "\n}\n";
}

SourceSkeleton make_rig() {
  SourceSkeleton sk;
  for (auto [name, parent] : std::vector<std::pair<const char*, int>>{{"Hips", -1},
                                                                      {"Spine", 0},
                                                                      {"Head", 1},
                                                                      {"LeftArm", 1},
                                                                      {"RightArm", 1},
                                                                      {"LeftLeg", 0},
                                                                      {"LeftKnee", 5},
                                                                      {"LeftFoot", 6},
                                                                      {"Tail1", 0},
                                                                      {"Tail2", 8}}) {
    SourceJoint j;
    j.name = name;
    j.parent = parent;
    sk.joints.push_back(j);
  }
  return sk;
}

class GraphCompile : public ::testing::Test {
 protected:
  SourceSkeleton rig = make_rig();
  GraphContext context() const {
    GraphContext c;
    c.skeleton = &rig;
    c.clips = {{"walk", 1.0f, {{"foot_right", 0.0f}, {"foot_left", 0.5f}}}, {"run", 0.5f, {}}, {"wave", 2.0f, {}}};
    return c;
  }
  ossa::Result<CompiledGraph> compile(const std::string& text) { return compile_graph(text, "g.json", context()); }
  CompiledGraph ok(const std::string& text) {
    auto r = compile(text);
    EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message) << "\n" << text;
    return r.ok() ? std::move(*r) : CompiledGraph{};
  }
  std::string errors(const std::string& text) {
    auto r = compile(text);
    EXPECT_FALSE(r.ok()) << "compiled:\n" << text;
    return r.ok() ? std::string() : r.error().message;
  }
};

/// "g.json:LINE:COL: " of the nth occurrence of needle in text, `skip` characters into it.
std::string at(const std::string& text, std::string_view needle, int nth = 0, size_t skip = 0) {
  size_t pos = text.find(needle);
  for (int i = 0; i < nth && pos != std::string::npos; ++i) pos = text.find(needle, pos + 1);
  if (pos == std::string::npos) return "<needle '" + std::string(needle) + "' not in the text>";
  pos += skip;
  size_t line = 1, col = 1;
  for (size_t i = 0; i < pos; ++i) {
    if (text[i] == '\n') ++line, col = 1;
    else ++col;
  }
  return "g.json:" + std::to_string(line) + ":" + std::to_string(col) + ": ";
}

// ---------------------------------------------------------------------------------------------
// Valid graphs

TEST_F(GraphCompile, SingleClip) {
  const CompiledGraph c = ok(graph(R"({"clip": "run"})"));
  const GraphDef& g = c.graph;
  EXPECT_EQ(g.name, "test");
  EXPECT_EQ(g.skeleton_hash, skeleton_hash_of(rig));
  EXPECT_EQ(g.joint_count, 10);
  EXPECT_EQ(g.clips, (std::vector<std::string>{"walk", "run", "wave"}));  // "clips" order
  ASSERT_EQ(g.parameters.size(), 6u);
  EXPECT_EQ(g.parameters[kSpeed].type, ParamType::Float);
  EXPECT_EQ(g.parameters[kSpeed].min_value, 0.0f);
  EXPECT_EQ(g.parameters[kSpeed].max_value, 6.0f);
  EXPECT_EQ(g.parameters[kSpeed].default_value, 1.0f);
  EXPECT_EQ(g.parameters[kLean].min_value, -3.4e38f);  // no range: the format's defaults
  EXPECT_EQ(g.parameters[kGait].enum_values, (std::vector<std::string>{"walk", "run", "idle"}));
  EXPECT_EQ(g.parameters[kGait].default_value, 1.0f);  // "run" is value 1
  EXPECT_EQ(g.parameters[kStop].type, ParamType::Trigger);
  ASSERT_EQ(g.nodes.size(), 1u);
  EXPECT_EQ(g.root, 0);
  const auto* clip = std::get_if<ClipNodeDef>(&g.nodes[0].kind);
  ASSERT_NE(clip, nullptr);
  EXPECT_EQ(clip->clip, 1);
  EXPECT_EQ(clip->rate, 1.0f);
  EXPECT_EQ(clip->rate_parameter, -1);
  EXPECT_TRUE(clip->loop);
  EXPECT_TRUE(g.machines.empty());
  // walk and wave are declared and never played.
  ASSERT_EQ(c.warnings.size(), 2u);
  EXPECT_HAS(c.warnings[0], "clip 'walk' is declared but no node plays it");
}

TEST_F(GraphCompile, FullGraphIsPostOrderWithResolvedIndices) {
  const std::string nodes = R"({
    "fast": {"clip": "run", "rate": 1.5, "rate_parameter": "speed", "loop": false, "start": 0.25}
  })";
  const std::string root = R"({
    "name": "top",
    "layered": {"state_machine": {"name": "loco", "entry": "move",
      "states": {
        "move": {"node": {"blend_space": "speed", "samples": [{"clip": "run", "x": 4}, {"clip": "walk", "x": 1}]}},
        "turn": {"node": {"select": "gait", "children": {"idle": {"clip": "wave"}, "walk": {"clip": "walk"},
          "run": {"use": "fast"}},
                          "blend_time": 0.2},
                 "restart": false}
      },
      "transitions": [
        {"from": "move", "to": "turn", "when": "speed > 4 && !crossed", "priority": 2, "duration": 0.3,
          "mode": "sync_crossfade"},
        {"from": "any", "to": "move", "when": "stop", "mode": "inertialize", "duration": 0.2},
        {"from": "turn", "to": "move", "exit_time": 0.8, "priority": 2}
      ]}},
    "layers": [{"node": {"use": "fast"}, "mask": [{"joint": "Spine"}, {"joint": "LeftLeg", "depth": 0}], "weight": 0.5,
                "weight_parameter": "crossed", "blend_time": 0.25, "mesh_space_rotation": true}]
  })";
  const CompiledGraph c = ok(graph(root, nodes));
  const GraphDef& g = c.graph;
  ASSERT_EQ(g.nodes.size(), 8u);
  EXPECT_EQ(g.root, 7);

  const auto* space = std::get_if<BlendSpaceDef>(&g.nodes[0].kind);
  ASSERT_NE(space, nullptr);
  EXPECT_EQ(space->x_parameter, kSpeed);
  EXPECT_EQ(space->y_parameter, -1);
  ASSERT_EQ(space->samples.size(), 2u);
  EXPECT_EQ(space->samples[0].clip, 0);  // sorted by x: walk (1) before run (4)
  EXPECT_EQ(space->samples[0].x, 1.0f);
  EXPECT_EQ(space->samples[1].clip, 1);

  EXPECT_EQ(std::get<ClipNodeDef>(g.nodes[1].kind).clip, 2);  // wave (written first)
  EXPECT_EQ(std::get<ClipNodeDef>(g.nodes[2].kind).clip, 0);  // walk
  const auto& fast = std::get<ClipNodeDef>(g.nodes[3].kind);
  EXPECT_EQ(g.nodes[3].name, "fast");  // a use copy is named after the named node
  EXPECT_EQ(fast.clip, 1);
  EXPECT_EQ(fast.rate, 1.5f);
  EXPECT_EQ(fast.rate_parameter, kSpeed);
  EXPECT_FALSE(fast.loop);
  EXPECT_EQ(fast.start_offset, 0.25f);

  const auto& select = std::get<SelectDef>(g.nodes[4].kind);
  EXPECT_EQ(select.parameter, kGait);
  EXPECT_EQ(select.children, (std::vector<uint16_t>{2, 3, 1}));  // enum order walk, run, idle
  EXPECT_EQ(select.blend_time, 0.2f);

  EXPECT_EQ(std::get<StateMachineRefDef>(g.nodes[5].kind).machine, 0);
  EXPECT_EQ(std::get<ClipNodeDef>(g.nodes[6].kind).clip, 1);  // the second copy of "fast"
  EXPECT_EQ(g.nodes[6].name, "fast");

  const auto& layered = std::get<LayeredDef>(g.nodes[7].kind);
  EXPECT_EQ(g.nodes[7].name, "top");
  EXPECT_EQ(layered.base, 5);
  ASSERT_EQ(layered.layers.size(), 1u);
  const LayerDef& layer = layered.layers[0];
  EXPECT_EQ(layer.node, 6);
  ASSERT_EQ(layer.mask.size(), 2u);
  EXPECT_EQ(layer.mask[0].joint, 1);
  EXPECT_EQ(layer.mask[0].depth, -1);
  EXPECT_EQ(layer.mask[1].joint, 5);
  EXPECT_EQ(layer.mask[1].depth, 0);
  EXPECT_EQ(layer.weight, 0.5f);
  EXPECT_EQ(layer.weight_parameter, kCrossed);
  EXPECT_EQ(layer.blend_time, 0.25f);
  EXPECT_TRUE(layer.mesh_space_rotation);

  ASSERT_EQ(g.machines.size(), 1u);
  const StateMachineDef& m = g.machines[0];
  EXPECT_EQ(m.name, "loco");
  EXPECT_EQ(m.entry, 0);
  ASSERT_EQ(m.states.size(), 2u);
  EXPECT_EQ(m.states[0].name, "move");
  EXPECT_EQ(m.states[0].node, 0);
  EXPECT_TRUE(m.states[0].restart);
  EXPECT_EQ(m.states[1].name, "turn");
  EXPECT_EQ(m.states[1].node, 4);
  EXPECT_FALSE(m.states[1].restart);
  // Stable sort by priority: the priority-0 "any" first, then the two of priority 2 in file order.
  ASSERT_EQ(m.transitions.size(), 3u);
  const TransitionDef& any = m.transitions[0];
  EXPECT_EQ(any.from, -1);
  EXPECT_EQ(any.to, 0);
  EXPECT_EQ(any.mode, TransitionModeDef::Inertialize);
  EXPECT_EQ(any.duration, 0.2f);
  EXPECT_EQ(any.exit_time, -1.0f);
  ASSERT_EQ(any.condition.size(), 1u);
  EXPECT_EQ(any.condition[0].op, CondOp::Trigger);
  EXPECT_EQ(any.condition[0].parameter, kStop);
  const TransitionDef& up = m.transitions[1];
  EXPECT_EQ(up.from, 0);
  EXPECT_EQ(up.to, 1);
  EXPECT_EQ(up.mode, TransitionModeDef::SyncCrossfade);
  ASSERT_EQ(up.condition.size(), 4u);
  EXPECT_EQ(up.condition[0].op, CondOp::Greater);
  EXPECT_EQ(up.condition[0].parameter, kSpeed);
  EXPECT_EQ(up.condition[0].value, 4.0f);
  EXPECT_EQ(up.condition[1].op, CondOp::Bool);
  EXPECT_EQ(up.condition[1].parameter, kCrossed);
  EXPECT_EQ(up.condition[2].op, CondOp::Not);
  EXPECT_EQ(up.condition[3].op, CondOp::And);
  const TransitionDef& back = m.transitions[2];
  EXPECT_EQ(back.from, 1);
  EXPECT_EQ(back.exit_time, 0.8f);
  EXPECT_TRUE(back.condition.empty());  // no "when": always
  EXPECT_EQ(back.mode, TransitionModeDef::Crossfade);
  EXPECT_EQ(back.duration, 0.0f);
}

TEST_F(GraphCompile, EveryUseIsItsOwnCopy) {
  const CompiledGraph c = ok(graph(R"({"blend": [{"use": "w"}, {"use": "w", "name": "second"}], "alpha": "speed"})",
                                   R"({"w": {"blend": [{"clip": "walk"}, {"clip": "wave"}], "alpha": "lean"}})"));
  const GraphDef& g = c.graph;
  ASSERT_EQ(g.nodes.size(), 7u);
  const auto& top = std::get<BlendAlphaDef>(g.nodes[6].kind);
  EXPECT_EQ(top.a, 2);
  EXPECT_EQ(top.b, 5);
  EXPECT_EQ(top.alpha_parameter, kSpeed);
  EXPECT_EQ(g.nodes[2].name, "w");
  EXPECT_EQ(g.nodes[5].name, "second");
  const auto& first = std::get<BlendAlphaDef>(g.nodes[2].kind);
  EXPECT_EQ(first.a, 0);
  EXPECT_EQ(first.b, 1);
  EXPECT_EQ(first.alpha_parameter, kLean);
  EXPECT_EQ(std::get<BlendAlphaDef>(g.nodes[5].kind).a, 3);
}

TEST_F(GraphCompile, MachinesAreNumberedInTheOrderMet) {
  const std::string root = R"({"state_machine": {"name": "outer", "entry": "a", "states": {
      "a": {"node": {"state_machine": {"name": "inner", "entry": "x", "states": {"x": {"node": {"clip": "walk"}}}}}},
      "b": {"node": {"state_machine": {"name": "third", "entry": "y", "states": {"y": {"node": {"clip": "run"}}}}}}},
    "transitions": [{"from": "a", "to": "b", "when": "stance == 1"}]}})";
  const GraphDef g = ok(graph(root)).graph;
  ASSERT_EQ(g.machines.size(), 3u);
  EXPECT_EQ(g.machines[0].name, "outer");
  EXPECT_EQ(g.machines[1].name, "inner");
  EXPECT_EQ(g.machines[2].name, "third");
  ASSERT_EQ(g.nodes.size(), 5u);
  EXPECT_EQ(std::get<StateMachineRefDef>(g.nodes[1].kind).machine, 1);
  EXPECT_EQ(std::get<StateMachineRefDef>(g.nodes[3].kind).machine, 2);
  EXPECT_EQ(std::get<StateMachineRefDef>(g.nodes[4].kind).machine, 0);
  EXPECT_EQ(g.machines[0].states[0].node, 1);
  EXPECT_EQ(g.machines[0].states[1].node, 3);
  const CondInstr eq = g.machines[0].transitions[0].condition[0];
  EXPECT_EQ(eq.op, CondOp::Equal);
  EXPECT_EQ(eq.parameter, kStance);
  EXPECT_EQ(eq.value, 1.0f);
}

TEST_F(GraphCompile, SelectFormsAdditiveAnd2DBlendSpace) {
  const std::string root = R"({"additive": {"select": "crossed", "children": [{"clip": "walk"}, {"clip": "run"}]},
    "add": {"select": "stance", "children": [{"clip": "wave"}, {"blend_space": "speed", "y": "lean", "samples": [
      {"clip": "walk", "x": 0, "y": 0}, {"clip": "run", "x": 1, "y": 0}, {"clip": "wave", "x": 0, "y": 1}], "rate": 2,
        "loop": false}]},
    "weight": 0.75, "weight_parameter": "crossed"})";
  const GraphDef g = ok(graph(root)).graph;
  ASSERT_EQ(g.nodes.size(), 7u);
  EXPECT_EQ(std::get<SelectDef>(g.nodes[2].kind).children, (std::vector<uint16_t>{0, 1}));
  const auto& space = std::get<BlendSpaceDef>(g.nodes[4].kind);
  EXPECT_EQ(space.y_parameter, kLean);
  EXPECT_EQ(space.rate, 2.0f);
  EXPECT_FALSE(space.loop);
  ASSERT_EQ(space.samples.size(), 3u);  // 2D samples keep their order
  EXPECT_EQ(space.samples[2].clip, 2);
  EXPECT_EQ(space.samples[2].y, 1.0f);
  EXPECT_EQ(std::get<SelectDef>(g.nodes[5].kind).children, (std::vector<uint16_t>{3, 4}));
  const auto& add = std::get<AdditiveDef>(g.nodes[6].kind);
  EXPECT_EQ(add.base, 2);
  EXPECT_EQ(add.additive, 5);
  EXPECT_EQ(add.weight, 0.75f);
  EXPECT_EQ(add.weight_parameter, kCrossed);
  // A bool select may name its children too.
  const GraphDef named =
      ok(graph(R"({"select": "crossed", "children": {"true": {"clip": "run"}, "false": {"clip": "walk"}}})")).graph;
  EXPECT_EQ(std::get<SelectDef>(named.nodes[2].kind).children, (std::vector<uint16_t>{1, 0}));
}

TEST_F(GraphCompile, MorphNodeDrivesTargetsFromParameters) {
  const std::string root =
      R"({"morph": {"clip": "walk"}, "drives": [{"target": "smile", "parameter": "lean", "scale": 0.5},
    {"target": "blink", "parameter": "crossed"}]})";
  const GraphDef g = ok(graph(root)).graph;
  ASSERT_EQ(g.nodes.size(), 2u);
  const auto& m = std::get<MorphWeightsDef>(g.nodes[1].kind);
  EXPECT_EQ(m.input, 0);
  ASSERT_EQ(m.drives.size(), 2u);
  EXPECT_EQ(m.drives[0].target, "smile");
  EXPECT_EQ(m.drives[0].parameter, kLean);
  EXPECT_EQ(m.drives[0].scale, 0.5f);
  EXPECT_EQ(m.drives[1].parameter, kCrossed);
  EXPECT_EQ(m.drives[1].scale, 1.0f);
  const std::string a = graph(R"({"morph": {"clip": "walk"}, "drives": [{"target": "smile", "parameter": "gait"}]})");
  EXPECT_HAS(errors(a), "parameter 'gait' is an enum; a drive's \"parameter\" needs a float or bool parameter");
  const std::string b = graph(R"({"morph": {"clip": "walk"}, "drives": []})");
  EXPECT_HAS(errors(b), at(b, "[]") + "\"drives\" is empty");
  const std::string c = graph(R"({"morph": {"clip": "walk"}, "drives": [{"target": "", "parameter": "lean"}]})");
  EXPECT_HAS(errors(c), "a drive's \"target\" is empty");
  // A layer may name the morph targets it blends.
  const GraphDef layered = ok(graph(R"({"layered": {"clip": "walk"}, "layers": [{"node": {"clip": "wave"},
    "mask": [{"joint": "Head"}], "morph_targets": ["smile", "blink"]}]})"))
                               .graph;
  const auto& layer = std::get<LayeredDef>(layered.nodes[2].kind).layers[0];
  ASSERT_TRUE(layer.morph_targets.has_value());
  EXPECT_EQ(*layer.morph_targets, (std::vector<std::string>{"smile", "blink"}));
  EXPECT_FALSE(std::get<LayeredDef>(ok(graph(R"({"layered": {"clip": "walk"}, "layers": [{"node": {"clip": "wave"},
    "mask": [{"joint": "Head"}]}]})"))
                                        .graph.nodes[2]
                                        .kind)
                   .layers[0]
                   .morph_targets.has_value());
  const std::string d = graph(R"({"layered": {"clip": "walk"}, "layers": [{"node": {"clip": "wave"},
    "mask": [{"joint": "Head"}], "morph_targets": ["smile", ""]}]})");
  EXPECT_HAS(errors(d), "a morph target name is empty");
}

TEST_F(GraphCompile, GraphEventsMergeWithTheClipsOwn) {
  const std::string clips = R"({"walk": {"source": "walk.fbx", "events": [
      {"name": "step", "time": 0.75}, {"name": "foot_left", "time": 0.5}, {"name": "end", "time": 1.00005}]},
    "run": "run.fbx", "wave": "wave.fbx"})";
  const CompiledGraph c = ok(graph(R"({"clip": "walk"})", "{}", kParams, clips));
  ASSERT_EQ(c.clip_events.size(), 3u);
  const auto& walk = c.clip_events[0];
  ASSERT_EQ(walk.size(), 4u);  // the sidecar's foot_left at 0.5 and the graph's are one event
  EXPECT_EQ(walk[0].name, "foot_right");
  EXPECT_EQ(walk[1].name, "foot_left");
  EXPECT_EQ(walk[2].name, "step");
  EXPECT_EQ(walk[3].name, "end");
  EXPECT_EQ(walk[3].time, 1.0f);  // within the slack after the end: clamped to the duration
  EXPECT_TRUE(c.clip_events[1].empty());
}

TEST_F(GraphCompile, NodeCountLimit) {
  // n0 is one node, n(k) blends two copies of n(k-1): n15 expands to 2^16 - 1 = 65535 nodes.
  std::string nodes = "{\"n0\": {\"clip\": \"walk\"}";
  for (int k = 1; k <= 16; ++k)
    nodes += ", \"n" + std::to_string(k) + "\": {\"blend\": [{\"use\": \"n" + std::to_string(k - 1) +
             "\"}, {\"use\": \"n" + std::to_string(k - 1) + "\"}], \"alpha\": \"speed\"}";
  nodes += "}";
  const CompiledGraph c = ok(graph(R"({"use": "n15"})", nodes));
  EXPECT_EQ(c.graph.nodes.size(), 65535u);
  EXPECT_EQ(c.graph.root, 65534);
  const std::string text = graph(R"({"use": "n16"})", nodes);
  EXPECT_HAS(errors(text), "the graph has more than 65535 nodes");
}

// ---------------------------------------------------------------------------------------------
// Conditions

std::vector<GraphParameter> condition_params() {
  std::vector<GraphParameter> p(6);
  p[kSpeed] = {"speed", ParamType::Float, 0, 0, 6, {}};
  p[kLean] = {"lean", ParamType::Float, 0, -1, 1, {}};
  p[kCrossed] = {"crossed", ParamType::Bool, 0, 0, 1, {}};
  p[kStance] = {"stance", ParamType::Int, 0, 0, 2, {}};
  p[kGait] = {"gait", ParamType::Enum, 0, 0, 2, {"walk", "run", "idle"}};
  p[kStop] = {"stop", ParamType::Trigger, 0, 0, 1, {}};
  return p;
}

/// RPN as text: "speed>4 crossed ! &&".
std::string rpn(std::string_view text) {
  const auto params = condition_params();
  const ConditionResult r = compile_condition(text, params);
  if (!r.ok) return "error@" + std::to_string(r.error_offset) + ": " + r.error;
  std::string out;
  for (const CondInstr& c : r.code) {
    if (!out.empty()) out += ' ';
    const std::string name = c.parameter < params.size() ? params[c.parameter].name : "?";
    char value[32];
    std::snprintf(value, sizeof value, "%g", static_cast<double>(c.value));
    switch (c.op) {
      case CondOp::True: out += "T"; break;
      case CondOp::Less: out += name + "<" + value; break;
      case CondOp::LessEqual: out += name + "<=" + value; break;
      case CondOp::Greater: out += name + ">" + value; break;
      case CondOp::GreaterEqual: out += name + ">=" + value; break;
      case CondOp::Equal: out += name + "==" + value; break;
      case CondOp::NotEqual: out += name + "!=" + value; break;
      case CondOp::Bool: out += name; break;
      case CondOp::Trigger: out += name + "!!"; break;
      case CondOp::Not: out += "!"; break;
      case CondOp::And: out += "&&"; break;
      case CondOp::Or: out += "||"; break;
    }
  }
  return out;
}

TEST(GraphCondition, PrecedenceAndParentheses) {
  EXPECT_EQ(rpn("crossed || speed > 4 && stop"), "crossed speed>4 stop!! && ||");  // && binds tighter
  EXPECT_EQ(rpn("(crossed || speed > 4) && stop"), "crossed speed>4 || stop!! &&");
  EXPECT_EQ(rpn("!crossed && speed >= 1.5"), "crossed ! speed>=1.5 &&");
  EXPECT_EQ(rpn("!(crossed && stop)"), "crossed stop!! && !");
  EXPECT_EQ(rpn("speed < 1 || speed <= 2 || lean > -0.5"), "speed<1 speed<=2 || lean>-0.5 ||");  // left-associative
  EXPECT_EQ(rpn("not crossed and stance != 2 or gait == idle"), "crossed ! stance!=2 && gait==2 ||");
  EXPECT_EQ(rpn("crossed == false"), "crossed==0");
  EXPECT_EQ(rpn("crossed != true"), "crossed!=1");
  EXPECT_EQ(rpn("gait != walk"), "gait!=0");
  EXPECT_EQ(rpn("true"), "T");
  EXPECT_EQ(rpn("false || stop"), "T ! stop!! ||");
  EXPECT_EQ(rpn("  ((speed>1e-1))  "), "speed>0.1");
  EXPECT_EQ(rpn("!!crossed"), "crossed ! !");
}

TEST(GraphCondition, ErrorsSayWhereAndWhy) {
  EXPECT_EQ(rpn("speed"), "error@0: 'speed' is a float parameter: compare it with a number (speed > 0)");
  EXPECT_EQ(rpn("stance && crossed"), "error@0: 'stance' is an int parameter: compare it with a number (stance > 0)");
  EXPECT_EQ(rpn("gait"), "error@0: 'gait' is an enum parameter: compare it with one of its values (gait == walk)");
  EXPECT_EQ(rpn("crossed && stop > 0"), "error@11: 'stop' is a trigger: it cannot be compared, write it alone (stop)");
  EXPECT_EQ(rpn("speed > fast"), "error@8: 'speed' is a float parameter: compare it with a number");
  EXPECT_EQ(rpn("crossed < true"),
            "error@8: 'crossed' is a bool parameter: compare it only with == or != (or write it alone)");
  EXPECT_EQ(rpn("crossed == 1"), "error@11: 'crossed' is a bool parameter: compare it with true or false");
  EXPECT_EQ(rpn("gait > walk"), "error@5: 'gait' is an enum parameter: compare it only with == or !=, not >");
  EXPECT_EQ(rpn("gait == jog"), "error@8: 'jog' is not a value of enum 'gait' (values: walk, run, idle)");
  EXPECT_EQ(rpn("gait == 1"),
            "error@8: 'gait' is an enum parameter: compare it with one of its values (walk, run, idle)");
  EXPECT_EQ(rpn("sped > 1"),
            "error@0: unknown parameter 'sped' (did you mean 'speed'?); parameters: speed, lean, crossed, stance, "
            "gait, stop");
  EXPECT_EQ(rpn("speed = 1"), "error@6: '=' is not an operator; compare with '=='");
  EXPECT_EQ(rpn("crossed & stop"), "error@8: '&' is not an operator; use '&&' (or 'and')");
  EXPECT_EQ(rpn("crossed | stop"), "error@8: '|' is not an operator; use '||' (or 'or')");
  EXPECT_EQ(rpn("(crossed || stop"), "error@0: '(' is never closed");
  EXPECT_EQ(rpn("crossed)"), "error@7: ')' without a matching '('");
  EXPECT_EQ(rpn("crossed &&"),
            "error@10: the condition ends where a parameter, 'true', 'false', '!' or '(' was expected");
  EXPECT_EQ(rpn("crossed stop"), "error@8: expected '&&', '||' or the end of the condition, found 'stop'");
  EXPECT_EQ(rpn("speed > 1.2.3"), "error@8: invalid number '1.2.3'");
  EXPECT_EQ(rpn("crossed && #"), "error@11: unexpected '#'");
  EXPECT_EQ(rpn(""), "error@0: empty condition (leave \"when\" out for a transition that is always allowed)");
  EXPECT_EQ(rpn(std::string(1000, '(') + "crossed" + std::string(1000, ')')).substr(0, 29),
            "error@256: condition nested t");
}

TEST(GraphCondition, Identifiers) {
  EXPECT_TRUE(is_condition_identifier("speed_2"));
  EXPECT_TRUE(is_condition_identifier("_x"));
  EXPECT_FALSE(is_condition_identifier("2x"));
  EXPECT_FALSE(is_condition_identifier("my speed"));
  EXPECT_FALSE(is_condition_identifier("and"));
  EXPECT_FALSE(is_condition_identifier(""));
}

// ---------------------------------------------------------------------------------------------
// Invalid graphs: each message names file:line:col of the value at fault.

TEST_F(GraphCompile, VersionNameAndTopLevel) {
  const std::string no_version =
      "{\"name\": \"x\", \"skeleton\": \"s.fbx\", \"clips\": {}, \"root\": {\"clip\": \"a\"}}";
  EXPECT_HAS(errors(no_version), "g.json:1:1: not a graph file: \"ossa_graph\": 1 is missing");
  std::string v2 = graph(R"({"clip": "walk"})");
  v2.replace(v2.find("\"ossa_graph\": 1"), 15, "\"ossa_graph\": 2");
  EXPECT_HAS(errors(v2), at(v2, "2,") + "\"ossa_graph\" must be 1");
  const std::string typo =
      "{\"ossa_graph\": 1, \"name\": \"x\", \"skeleton\": \"s.fbx\", \"clips\": {\"walk\": \"w.fbx\"},\n"
      " \"parameter\": {}, \"root\": {\"clip\": \"walk\"}}";
  EXPECT_HAS(errors(typo), "g.json:2:2: unknown key \"parameter\" in a graph file (did you mean \"parameters\"?)");
  const std::string missing = "{\"ossa_graph\": 1}";
  const std::string m = errors(missing);
  EXPECT_HAS(m, "g.json:1:1: a graph needs a \"name\"");
  EXPECT_HAS(m, "g.json:1:1: a graph needs a \"skeleton\"");
  EXPECT_HAS(m, "g.json:1:1: a graph needs \"clips\"");
  EXPECT_HAS(m, "g.json:1:1: a graph needs a \"root\" node");
  EXPECT_HAS(errors("[1, 2]"), "g.json:1:1: a graph file must be an object, not an array");
  EXPECT_HAS(errors("{\"ossa_graph\": 1,}"), "g.json:1:18: expected a key after ','");
}

TEST_F(GraphCompile, UnknownClipJointAndParameter) {
  const std::string a = graph(R"({"clip": "wlak"})");
  EXPECT_HAS(errors(a), at(a, "\"wlak\"") + "unknown clip 'wlak' (did you mean 'walk'?); clips: 'walk', 'run', 'wave'");
  const std::string b =
      graph(R"({"layered": {"clip": "walk"}, "layers": [{"node": {"clip": "wave"}, "mask": [{"joint": "spine"}]}]})");
  EXPECT_HAS(errors(b), at(b, "\"spine\"") + "unknown joint 'spine' in a mask (did you mean 'Spine'?)");
  const std::string c = graph(R"({"blend": [{"clip": "walk"}, {"clip": "run"}], "alpha": "sped"})");
  EXPECT_HAS(errors(c), at(c, "\"sped\"") + "unknown parameter 'sped' in a blend's \"alpha\" (did you mean 'speed'?)");
  const std::string d = graph(R"({"clip": "walk", "rate_parameter": "nothing"})");
  EXPECT_HAS(errors(d), at(d, "\"nothing\"") + "unknown parameter 'nothing'");
}

TEST_F(GraphCompile, ParameterOfTheWrongType) {
  const std::string a = graph(R"({"blend": [{"clip": "walk"}, {"clip": "run"}], "alpha": "crossed"})");
  EXPECT_HAS(errors(a),
             at(a, "\"crossed\"", 1) + "parameter 'crossed' is a bool; a blend's \"alpha\" needs a float parameter");
  const std::string b = graph(R"({"select": "speed", "children": [{"clip": "walk"}]})");
  EXPECT_HAS(errors(b),
             at(b, "\"speed\"", 1) + "parameter 'speed' is a float; a select node needs a bool, int or enum parameter");
  const std::string c = graph(R"({"select": "stop", "children": [{"clip": "walk"}]})");
  EXPECT_HAS(errors(c), "parameter 'stop' is a trigger; a select node needs");
  const std::string d =
      graph(R"({"blend_space": "gait", "samples": [{"clip": "walk", "x": 0}, {"clip": "run", "x": 1}]})");
  EXPECT_HAS(errors(d),
             at(d, "\"gait\"", 1) + "parameter 'gait' is an enum; a blend space's x (\"blend_space\") needs a float");
  const std::string e =
      graph(R"({"layered": {"clip": "walk"}, "layers": [{"node": {"clip": "wave"}, "mask": [{"joint": "Spine"}],
      "weight_parameter": "stance"}]})");
  EXPECT_HAS(errors(e),
             at(e, "\"stance\"", 1) +
                 "parameter 'stance' is an int; a layer's \"weight_parameter\" needs a float or bool parameter");
  const std::string f = graph(R"({"clip": "walk", "rate_parameter": "crossed"})");
  EXPECT_HAS(errors(f), "parameter 'crossed' is a bool; \"rate_parameter\" needs a float parameter");
}

TEST_F(GraphCompile, ParameterDeclarations) {
  const std::string a =
      graph(R"({"clip": "walk"})", "{}", R"({"g": {"type": "enum", "values": ["a", "b"], "default": "c"}})");
  EXPECT_HAS(errors(a), at(a, "\"c\"") + "parameter 'g': default 'c' is not one of its values ('a', 'b')");
  const std::string b = graph(R"({"clip": "walk"})", "{}", R"({"s": {"type": "float", "min": 5, "max": 2}})");
  EXPECT_HAS(errors(b), at(b, "5") + "parameter 's': min 5 is greater than max 2");
  const std::string c = graph(R"({"clip": "walk"})", "{}", R"({"s": {"type": "float", "default": 9, "max": 2}})");
  EXPECT_HAS(errors(c), at(c, "9") + "parameter 's': default 9 is outside [min, max] = [-3.4e+38, 2]");
  const std::string d = graph(R"({"clip": "walk"})", "{}", R"({"n": {"type": "int", "default": 0.5}})");
  EXPECT_HAS(errors(d), at(d, "0.5") + "parameter 'n' \"default\" must be a whole number");
  const std::string e = graph(R"({"clip": "walk"})", "{}", R"({"s": {"type": "flaot"}})");
  EXPECT_HAS(errors(e), at(e, "\"flaot\"") + "unknown parameter type 'flaot' (did you mean 'float'?)");
  const std::string f = graph(R"({"clip": "walk"})", "{}", R"({"my speed": {"type": "float"}})");
  EXPECT_HAS(errors(f), at(f, "\"my speed\"") + "parameter name 'my speed' must be an identifier");
  const std::string g = graph(R"({"clip": "walk"})", "{}", R"({"t": {"type": "trigger", "default": true}})");
  EXPECT_HAS(errors(g), at(g, "\"default\"") + "unknown key \"default\" in parameter 't'; allowed keys: type");
  const std::string h = graph(R"({"clip": "walk"})", "{}", R"({"e": {"type": "enum", "values": ["a", "a"]}})");
  EXPECT_HAS(errors(h), at(h, "\"a\"", 1) + "parameter 'e': value 'a' is listed twice");
  const std::string i = graph(R"({"clip": "walk"})", "{}", R"({"b": {"type": "bool", "default": 1}})");
  EXPECT_HAS(errors(i), at(i, "1}") + "parameter 'b' \"default\" must be a boolean, not a number");
  const std::string j = graph(R"({"clip": "walk"})", "{}", R"({"s": {"default": 1}})");
  EXPECT_HAS(errors(j),
             at(j, "{\"default\"") + "parameter 's' needs a \"type\": float, int, bool, enum, trigger or vector");
}

TEST_F(GraphCompile, DuplicateNamesAreRefused) {
  const std::string a =
      graph(R"({"clip": "walk"})", "{}", R"({"speed": {"type": "float"}, "speed": {"type": "bool"}})");
  EXPECT_HAS(errors(a), at(a, "\"speed\"", 1) + "duplicate key \"speed\"");
  const std::string b = graph(
      R"({"state_machine": {"name": "m", "entry": "a", "states": {"a": {"node": {"clip": "walk"}},
        "a": {"node": {"clip": "run"}}}}})");
  EXPECT_HAS(errors(b), at(b, "\"a\": {\"node\"", 1) + "duplicate key \"a\"");
  const std::string c = graph(R"({"use": "x"})", R"({"x": {"clip": "walk"}, "x": {"clip": "run"}})");
  EXPECT_HAS(errors(c), at(c, "\"x\": {\"clip\": \"run\"") + "duplicate key \"x\"");
}

TEST_F(GraphCompile, SelectChildrenMustMatchTheParameter) {
  const std::string a =
      graph(R"({"select": "crossed", "children": [{"clip": "walk"}, {"clip": "run"}, {"clip": "wave"}]})");
  EXPECT_HAS(
      errors(a),
      at(a, "[{\"clip\"") +
          "a select on bool 'crossed' needs exactly 2 children, one per value in the order 'false', 'true', not 3");
  const std::string b = graph(R"({"select": "gait", "children": [{"clip": "walk"}, {"clip": "run"}]})");
  EXPECT_HAS(
      errors(b),
      "a select on enum 'gait' needs exactly 3 children, one per value in the order 'walk', 'run', 'idle', not 2");
  const std::string c = graph(
      R"({"select": "gait", "children": {"walk": {"clip": "walk"}, "run": {"clip": "run"}, "jog": {"clip": "wave"}}})");
  const std::string cm = errors(c);
  EXPECT_HAS(cm, at(c, "\"jog\"") + "'jog' is not a value of enum 'gait' (values: 'walk', 'run', 'idle')");
  EXPECT_HAS(cm, at(c, "{\"walk\": {") + "a select on 'gait' has no child for 'idle'");
  const std::string d = graph(R"({"select": "stance", "children": []})");
  EXPECT_HAS(errors(d), at(d, "[]") + "a select on int 'stance' needs at least one child");
  const std::string e = graph(R"({"select": "stance", "children": {"0": {"clip": "walk"}}})");
  EXPECT_HAS(errors(e), "a select on int 'stance' takes its children as an array");
}

TEST_F(GraphCompile, StateMachineStructure) {
  const std::string a = graph(R"({"state_machine": {"name": "m", "states": {"a": {"node": {"clip": "walk"}}}}})");
  EXPECT_HAS(errors(a), at(a, "{\"name\": \"m\"") + "state machine 'm' needs an \"entry\" state");
  const std::string b =
      graph(R"({"state_machine": {"name": "m", "entry": "idle", "states": {"a": {"node": {"clip": "walk"}}}}})");
  EXPECT_HAS(errors(b),
             at(b, "\"idle\"", 1) + "the entry state 'idle' is not a state of state machine 'm'; states: 'a'");
  const std::string c = graph(R"({"state_machine": {"name": "m", "entry": "a", "states": {
      "a": {"node": {"clip": "walk"}}, "b": {"node": {"clip": "run"}}, "c": {"node": {"clip": "wave"}}},
    "transitions": [{"from": "c", "to": "a"}]}})");
  const std::string cm = errors(c);
  EXPECT_HAS(
      cm, at(c, "\"b\"") +
              "state 'b' of state machine 'm' cannot be reached: no transition leads to it from the entry state 'a'");
  EXPECT_HAS(cm, at(c, "\"c\"") + "state 'c' of state machine 'm' cannot be reached");
  // Reachable through an "any" transition, or through a chain.
  ok(graph(R"({"state_machine": {"name": "m", "entry": "a", "states": {
      "a": {"node": {"clip": "walk"}}, "b": {"node": {"clip": "run"}}, "c": {"node": {"clip": "wave"}}},
    "transitions": [{"from": "any", "to": "b", "when": "stop"}, {"from": "b", "to": "c"}]}})"));
  const std::string d =
      graph(R"({"state_machine": {"name": "m", "entry": "a", "states": {"a": {"node": {"clip": "walk"}}},
    "transitions": [{"from": "a", "to": "runing"}, {"from": "z", "to": "a"}]}})");
  const std::string dm = errors(d);
  EXPECT_HAS(dm, at(d, "\"runing\"") + "\"to\" 'runing' is not a state of state machine 'm'; states: 'a'");
  EXPECT_HAS(dm, at(d, "\"z\"") + "\"from\" 'z' is not a state of state machine 'm'");
  const std::string e = graph(
      R"({"state_machine": {"name": "m", "entry": "a", "states": {"a": {"node": {"clip": "walk"}},
        "any": {"node": {"clip": "run"}}}}})");
  EXPECT_HAS(errors(e), at(e, "\"any\"") + "'any' is reserved");
  const std::string f = graph(R"({"state_machine": {"name": "m", "entry": "a", "states": {"a": {"clip": "walk"}}}})");
  EXPECT_HAS(errors(f),
             at(f, "\"clip\": \"walk\"}}}}") + "unknown key \"clip\" in a state; allowed keys: node, restart");
  const std::string g = graph(R"({"state_machine": {"entry": "a", "states": {}}})");
  const std::string gm = errors(g);
  EXPECT_HAS(gm, "a state machine needs \"name\"");
  EXPECT_HAS(gm, at(g, "{}}}") + "the state machine has no states");
}

TEST_F(GraphCompile, TimesAndDurationsMustNotBeNegative) {
  const std::string sm =
      R"({"state_machine": {"name": "m", "entry": "a", "states": {"a": {"node": {"clip": "walk"}},
        "b": {"node": {"clip": "run"}}},
    "transitions": [{"from": "a", "to": "b", "duration": -0.5, "exit_time": -1, "mode": "blend"}]}})";
  const std::string a = graph(sm);
  const std::string am = errors(a);
  EXPECT_HAS(am, at(a, "-0.5") + "\"duration\" (seconds) must be >= 0, not -0.5");
  EXPECT_HAS(am, at(a, "-1,") +
                     "\"exit_time\" (normalized time of the source state; leave it out for none) must be >= 0, not -1");
  EXPECT_HAS(am, at(a, "\"blend\"") + "unknown transition mode 'blend'; modes: crossfade, sync_crossfade, inertialize");
  const std::string b =
      graph(R"({"select": "crossed", "children": [{"clip": "walk"}, {"clip": "run"}], "blend_time": -0.1})");
  EXPECT_HAS(errors(b), at(b, "-0.1") + "\"blend_time\" must be >= 0, not -0.1");
  const std::string c = graph(R"({"clip": "walk", "start": 1.5})");
  EXPECT_HAS(errors(c), at(c, "1.5") + "\"start\" 1.5 s is outside clip 'walk' [0, 1 s]");
  const std::string d = graph(
      R"({"layered": {"clip": "walk"}, "layers": [{"node": {"clip": "wave"}, "mask": [{"joint": "Spine", "depth": -2}],
      "blend_time": -1, "weight": 2}]})");
  const std::string dm = errors(d);
  EXPECT_HAS(dm, at(d, "-2") + "a mask's \"depth\" (-1: all descendants) must be within [-1, 32767]");
  EXPECT_HAS(dm, at(d, "-1,") + "a layer's \"blend_time\" must be >= 0, not -1");
  EXPECT_HAS(dm, at(d, "\"weight\": 2", 0, 10) + "a layer's \"weight\" must be within [0, 1], not 2");
}

// What the loader refuses (runtime/loader/validate_graph.cpp) must be refused here, where the
// file says it: these compiled, then failed with "internal error, cooked bytes fail verification".
TEST_F(GraphCompile, WhatTheLoaderRefusesIsRefusedWhereTheFileSaysIt) {
  const std::string self = graph(R"({"state_machine": {"name": "m", "entry": "a", "states": {
      "a": {"node": {"clip": "walk"}}, "b": {"node": {"clip": "run"}}},
    "transitions": [{"from": "a", "to": "b"}, {"from": "b", "to": "b", "when": "stop"}]}})");
  EXPECT_HAS(errors(self), at(self, "\"b\", \"when\"") + "a transition from state 'b' to itself");
  const std::string far = graph(R"({"blend_space": "speed", "y": "lean", "samples": [
      {"clip": "walk", "x": 0, "y": 0}, {"clip": "run", "x": 3.4e38, "y": 0},
      {"clip": "wave", "x": 0, "y": -3.4e38}]})");
  const std::string fm = errors(far);
  EXPECT_HAS(fm, at(far, "3.4e38") + "a sample's \"x\" must be within [-1e+06, 1e+06], not 3.4e+38");
  EXPECT_HAS(fm, at(far, "-3.4e38") + "a sample's \"y\" must be within [-1e+06, 1e+06], not -3.4e+38");
  std::string many = R"({"blend_space": "speed", "y": "lean", "samples": [)";
  for (int i = 0; i < 2000; ++i)
    many += std::string(i ? ", " : "") + "{\"clip\": \"walk\", \"x\": " + std::to_string(i % 50) +
            ", \"y\": " + std::to_string(i / 50) + "}";
  const std::string mg = graph(many + "]}");
  EXPECT_HAS(errors(mg), at(mg, "[{") + "a blend space has 2000 samples; at most 1024");
  // The other bounds of the loader: rates, weights, times, nesting, conditions.
  const std::string rates = graph(R"({"additive": {"blend_space": "speed", "rate": 5000, "samples": [
      {"clip": "walk", "x": 0}, {"clip": "run", "x": 1}]}, "add": {"clip": "wave", "rate": -3.4e38}, "weight": 1000})");
  const std::string rm = errors(rates);
  EXPECT_HAS(rm, at(rates, "5000") + "\"rate\" must be within [-1000, 1000], not 5000");
  EXPECT_HAS(rm, at(rates, "-3.4e38") + "\"rate\" must be within [-1000, 1000], not -3.4e+38");
  EXPECT_HAS(rm, at(rates, "1000}") + "\"weight\" must be within [-100, 100], not 1000");
  const std::string times = graph(R"({"state_machine": {"name": "m", "entry": "a", "states": {
      "a": {"node": {"select": "crossed", "children": [{"clip": "walk"}, {"clip": "run"}], "blend_time": 1e7}},
      "b": {"node": {"clip": "run"}}},
    "transitions": [{"from": "a", "to": "b", "duration": 2e6, "exit_time": 3e38, "when": "speed > 1e39"}]}})");
  const std::string tm = errors(times);
  EXPECT_HAS(tm, at(times, "1e7") + "\"blend_time\" must be within [0, 1e+06], not 1e+07");
  EXPECT_HAS(tm, at(times, "2e6") + "\"duration\" (seconds) must be within [0, 1e+06], not 2e+06");
  EXPECT_HAS(tm, at(times, "3e38") + "\"exit_time\"");
  EXPECT_HAS(tm, at(times, "1e39") + "the number 1e39 is outside the range of a float");
  std::string deep = R"({"clip": "walk"})";
  for (int i = 0; i < 70; ++i) deep = R"({"blend": [)" + deep + R"(, {"clip": "run"}], "alpha": "lean"})";
  const std::string dg = graph(deep);
  EXPECT_HAS(errors(dg), "nodes nested deeper than 64 levels below the root");
  std::string ok64 = R"({"clip": "walk"})";
  for (int i = 0; i < 64; ++i) ok64 = R"({"blend": [)" + ok64 + R"(, {"clip": "run"}], "alpha": "lean"})";
  ok(graph(ok64));
  std::string cond = "speed > 0";
  for (int i = 1; i < 17; ++i) cond = "speed > " + std::to_string(i) + " || (" + cond + ")";
  const std::string cg = graph(R"({"state_machine": {"name": "m", "entry": "a", "states": {
      "a": {"node": {"clip": "walk"}}, "b": {"node": {"clip": "run"}}},
    "transitions": [{"from": "a", "to": "b", "when": ")" +
                               cond + R"("}]}})");
  EXPECT_HAS(errors(cg), "the condition holds more than 16 values at once here");
}

TEST_F(GraphCompile, UnknownKeysListTheAllowedOnes) {
  const std::string a =
      graph(R"({"select": "crossed", "children": [{"clip": "walk"}, {"clip": "run"}], "blendtime": 0.2})");
  EXPECT_HAS(errors(a),
             at(a, "\"blendtime\"") +
                 "unknown key \"blendtime\" in a select node (did you mean \"blend_time\"?); allowed keys: select, "
                 "children, blend_time, name");
  const std::string b = graph(R"({"clip": "walk", "looping": true})");
  EXPECT_HAS(errors(b), at(b, "\"looping\"") + "unknown key \"looping\" in a clip node (did you mean \"loop\"?)");
  const std::string c = graph(R"({"blendspace": "speed"})");
  EXPECT_HAS(errors(c),
             at(c, "\"blendspace\"") + "unknown key \"blendspace\" in a node (did you mean \"blend_space\"?)");
  const std::string d = graph(R"({"name": "x"})");
  EXPECT_HAS(errors(d), at(d, "{\"name\": \"x\"}") + "a node needs one of the keys clip, blend, select");
  const std::string e = graph(R"({"clip": "walk", "blend": [{"clip": "walk"}, {"clip": "run"}]})");
  EXPECT_HAS(errors(e),
             at(e, "\"blend\"") + "a node is exactly one kind, but this one has both \"clip\" and \"blend\"");
}

TEST_F(GraphCompile, WrongJsonTypes) {
  const std::string a = graph(R"({"clip": "walk", "rate": "fast", "loop": 1})");
  const std::string am = errors(a);
  EXPECT_HAS(am, at(a, "\"fast\"") + "\"rate\" must be a number, not a string");
  EXPECT_HAS(am, at(a, "1}") + "\"loop\" must be a boolean, not a number");
  const std::string b = graph(R"({"blend": {"a": 1}, "alpha": "speed"})");
  EXPECT_HAS(errors(b), at(b, "{\"a\"") + "\"blend\" ([A, B]) must be an array, not an object");
  const std::string c = graph(R"("walk")");
  EXPECT_HAS(errors(c), at(c, "\"walk\"\n") + "a node must be an object, not a string");
  const std::string d = graph(R"({"clip": "walk"})", "{}", "[]");
  EXPECT_HAS(errors(d), at(d, "[]") + "\"parameters\" must be an object, not an array");
  const std::string e = graph(R"({"clip": 3})");
  EXPECT_HAS(errors(e), at(e, "3}") + "a clip node (a clip name) must be a string, not a number");
  const std::string f = graph(R"({"blend": [{"clip": "walk"}], "alpha": "speed"})");
  EXPECT_HAS(errors(f), at(f, "[{") + "\"blend\" takes exactly 2 nodes [A, B], not 1");
}

TEST_F(GraphCompile, UseCyclesNameTheChain) {
  const std::string a = graph(R"({"use": "a"})", R"({"a": {"blend": [{"use": "b"}, {"clip": "walk"}], "alpha": "speed"},
                                                     "b": {"additive": {"clip": "run"}, "add": {"use": "a"}}})");
  EXPECT_HAS(errors(a), at(a, "\"a\"}}") + "named nodes use each other in a cycle: a -> b -> a");
  const std::string b = graph(R"({"use": "self"})", R"({"self": {"use": "self"}})");
  EXPECT_HAS(errors(b), at(b, "\"self\"}}") + "named nodes use each other in a cycle: self -> self");
  const std::string c = graph(R"({"use": "nope"})", R"({"yes": {"clip": "walk"}})");
  EXPECT_HAS(errors(c), at(c, "\"nope\"") + "unknown named node 'nope'; named nodes: 'yes'");
}

TEST_F(GraphCompile, BlendSpaceSamples) {
  const std::string a =
      graph(R"({"blend_space": "speed", "samples": [{"clip": "walk", "x": 1}, {"clip": "run", "x": 1}]})");
  EXPECT_HAS(errors(a), at(a, "{\"clip\": \"run\"") + "samples 'walk' and 'run' have the same x (1)");
  const std::string b = graph(R"({"blend_space": "speed", "y": "lean", "samples": [{"clip": "walk", "x": 0, "y": 0},
      {"clip": "run", "x": 1, "y": 1}, {"clip": "wave", "x": 2, "y": 2}]})");
  EXPECT_HAS(errors(b), at(b, "[{\"clip\": \"walk\", \"x\": 0,") + "blend space: all samples lie on one line");
  const std::string c = graph(R"({"blend_space": "speed", "y": "lean", "samples": [{"clip": "walk", "x": 0, "y": 0},
      {"clip": "run", "x": 1, "y": 1}, {"clip": "wave", "x": 0, "y": 0}]})");
  EXPECT_HAS(errors(c), at(c, "{\"clip\": \"wave\"") + "samples 'walk' and 'wave' are at the same point (0, 0)");
  const std::string d = graph(
      R"({"blend_space": "speed", "y": "lean", "samples": [{"clip": "walk", "x": 0, "y": 0}, {"clip": "run",
        "x": 1}]})");
  const std::string dm = errors(d);
  EXPECT_HAS(dm, at(d, "{\"clip\": \"run\"") + "a sample of a 2D blend space needs \"y\"");
  const std::string e =
      graph(R"({"blend_space": "speed", "samples": [{"clip": "walk", "x": 0, "y": 3}, {"clip": "run", "x": 1}]})");
  EXPECT_HAS(errors(e), at(e, "3}") + "\"y\" given but the blend space has no \"y\" parameter (1D)");
  const std::string f = graph(R"({"blend_space": "speed", "samples": [{"clip": "walk", "x": 0}]})");
  EXPECT_HAS(errors(f), at(f, "[{") + "a 1D blend space needs at least 2 samples");
}

TEST_F(GraphCompile, ConditionErrorsPointInsideTheString) {
  const std::string text = graph(
      R"({"state_machine": {"name": "m", "entry": "a", "states": {"a": {"node": {"clip": "walk"}},
        "b": {"node": {"clip": "run"}}},
    "transitions": [{"from": "a", "to": "b", "when": "speed > 4 && !crosed"}]}})");
  // The column of 'c' of "crosed" inside the string.
  EXPECT_HAS(errors(text), at(text, "crosed") + "unknown parameter 'crosed'");
  const std::string t2 = graph(
      R"({"state_machine": {"name": "m", "entry": "a", "states": {"a": {"node": {"clip": "walk"}},
        "b": {"node": {"clip": "run"}}},
    "transitions": [{"from": "a", "to": "b", "when": "stop == true"}]}})");
  EXPECT_HAS(errors(t2), at(t2, "stop == true") + "'stop' is a trigger: it cannot be compared");
}

TEST_F(GraphCompile, EveryProblemIsReportedOnce) {
  const std::string text = graph(R"({"blend": [{"clip": "wlak"}, {"use": "w"}], "alpha": "crossed"})",
                                 R"({"w": {"clip": "nope", "rate": "x"}})");
  const std::string m = errors(text);
  EXPECT_HAS(m, "unknown clip 'wlak'");
  EXPECT_HAS(m, "unknown clip 'nope'");
  EXPECT_HAS(m, "\"rate\" must be a number");
  EXPECT_HAS(m, "parameter 'crossed' is a bool");
  EXPECT_EQ(std::count(m.begin(), m.end(), '\n'), 3) << m;  // four lines, no cascades, no repeats
}

TEST_F(GraphCompile, EventProblemsInTheGraphFile) {
  const std::string clips =
      R"({"walk": {"source": "walk.fbx", "events": [{"name": "", "time": 0.1}, {"name": "late", "time": 1.5},
    {"name": "early", "time": -0.1}, {"time": 0.2}]}})";
  const std::string text = graph(R"({"clip": "walk"})", "{}", kParams, clips);
  const std::string m = errors(text);
  EXPECT_HAS(m, at(text, "\"\"") + "an event's \"name\" must not be empty");
  EXPECT_HAS(m, at(text, "1.5") + "event 'late' of clip 'walk': time 1.5 s is after the clip's end (1 s)");
  EXPECT_HAS(m, at(text, "-0.1") + "event 'early' of clip 'walk': time -0.1 s is negative");
  EXPECT_HAS(m, at(text, "{\"time\": 0.2}") + "an event needs a \"name\"");
}

TEST_F(GraphCompile, UnusedNamedNodesAreStillChecked) {
  const std::string text = graph(R"({"clip": "walk"})", R"({"spare": {"clip": "runn"}})");
  EXPECT_HAS(errors(text), at(text, "\"runn\"") + "unknown clip 'runn'");
  const CompiledGraph c = ok(graph(R"({"clip": "walk"})", R"({"spare": {"state_machine": {"name": "s", "entry": "a",
      "states": {"a": {"node": {"clip": "run"}}}}}})"));
  EXPECT_EQ(c.graph.nodes.size(), 1u);  // checked, then left out
  EXPECT_TRUE(c.graph.machines.empty());
  bool warned = false;
  for (const std::string& w : c.warnings)
    warned = warned || w.find("named node 'spare' is never used") != std::string::npos;
  EXPECT_TRUE(warned);
}

// Robustness: mangled graph files compile or fail with positioned messages, never crash.
TEST_F(GraphCompile, MutatedGraphsFailCleanly) {
  const std::string base = graph(R"G({"layered": {"state_machine": {"name": "m", "entry": "a", "states": {
      "a": {"node": {"blend_space": "speed", "samples": [{"clip": "walk", "x": 1}, {"clip": "run", "x": 4}]}},
      "b": {"node": {"select": "gait", "children": {"walk": {"use": "w"}, "run": {"clip": "run"},
        "idle": {"clip": "wave"}}}}},
    "transitions": [{"from": "a", "to": "b", "when": "speed > 4 && !(crossed || stop)", "exit_time": 0.5},
                    {"from": "any", "to": "a", "when": "gait == walk", "mode": "inertialize", "priority": -1}]}},
    "layers": [{"node": {"additive": {"use": "w"}, "add": {"clip": "wave"}}, "mask": [{"joint": "Spine",
      "depth": 1}]}]})G",
                                 R"({"w": {"blend": [{"clip": "walk"}, {"clip": "run"}], "alpha": "lean"}})");
  ok(base);
  const auto all_lines_positioned = [](const std::string& message) {
    for (size_t start = 0; start < message.size();) {
      if (message.compare(start, 7, "g.json:") != 0) return false;
      const size_t end = message.find('\n', start);
      start = end == std::string::npos ? message.size() : end + 1;
    }
    return !message.empty();
  };
  for (size_t n = 0; n < base.size(); n += 7) {
    auto r = compile(base.substr(0, n));
    ASSERT_FALSE(r.ok());
    ASSERT_TRUE(all_lines_positioned(r.error().message)) << r.error().message;
  }
  // Swap in words from the graph's own vocabulary, so many mutants parse and reach the compiler.
  const std::vector<std::string> words = {"\"walk\"", "\"speed\"", "\"gait\"", "\"w\"",    "\"a\"", "\"any\"",
                                          "-1",       "0",         "2.5",      "[]",       "{}",    "true",
                                          "null",     "\"\"",      "\"stop\"", "\"Spine\""};
  uint64_t state = 0x2545F4914F6CDD1Dull;
  const auto next = [&] {
    state ^= state << 13;
    state ^= state >> 7;
    state ^= state << 17;
    return state;
  };
  size_t compiled = 0, reached_compiler = 0;
  for (int round = 0; round < 3000; ++round) {
    std::string m = base;
    for (int e = 0, edits = 1 + static_cast<int>(next() % 3); e < edits; ++e) {
      // Replace one JSON token (a quoted string or a number) with a word.
      size_t at = next() % m.size();
      const size_t quote = m.find('"', at);
      if (quote == std::string::npos) continue;
      const size_t close = m.find('"', quote + 1);
      if (close == std::string::npos) continue;
      m.replace(quote, close - quote + 1, words[next() % words.size()]);
    }
    auto r = compile(m);
    if (r.ok()) {
      ++compiled;
      const GraphDef& g = r->graph;
      ASSERT_FALSE(g.nodes.empty());
      ASSERT_EQ(g.root, g.nodes.size() - 1);
    } else {
      ASSERT_TRUE(all_lines_positioned(r.error().message)) << r.error().message;
      if (r.error().message.find("expected") == std::string::npos) ++reached_compiler;
    }
  }
  EXPECT_GT(reached_compiler, 100u);
  EXPECT_GT(compiled, 10u);
}

TEST_F(GraphCompile, ManifestListsWhatToImport) {
  const std::string text =
      "{\"ossa_graph\": 1, \"name\": \"n\", \"skeleton\": \"rig/s.fbx\", \"meshes\": [\"a.fbx\", \"b.glb\"],\n"
      " \"clips\": {\"walk\": \"w.fbx\", \"run\": {\"source\": \"r.fbx\", \"clip\": \"Take 001\"}},\n"
      " \"root\": {\"clip\": \"walk\"}}";
  auto doc = ossa::cook::json::parse(text, "g.json");
  ASSERT_TRUE(doc.ok());
  auto m = read_graph_manifest(*doc);
  ASSERT_TRUE(m.ok()) << m.error().message;
  EXPECT_EQ(m->name, "n");
  EXPECT_EQ(m->skeleton, "rig/s.fbx");
  EXPECT_EQ(m->meshes, (std::vector<std::string>{"a.fbx", "b.glb"}));
  ASSERT_EQ(m->clips.size(), 2u);
  EXPECT_EQ(m->clips[0].name, "walk");
  EXPECT_EQ(m->clips[0].source, "w.fbx");
  EXPECT_EQ(m->clips[0].source_clip, "");
  EXPECT_EQ(m->clips[1].source_clip, "Take 001");
  EXPECT_EQ(m->clips[1].pos.line, 2u);
  auto bad = ossa::cook::json::parse(
      "{\"ossa_graph\": 1, \"name\": \"n\", \"skeleton\": 5, \"clips\": {\"w\": {\"clip\": \"x\"}}, \"root\": {}}",
      "g.json");
  ASSERT_TRUE(bad.ok());
  auto mb = read_graph_manifest(*bad);
  ASSERT_FALSE(mb.ok());
  EXPECT_HAS(mb.error().message, "g.json:1:44: \"skeleton\" (the rig's source file) must be a string, not a number");
  EXPECT_HAS(mb.error().message, "g.json:1:62: clip 'w' needs a \"source\" file");

  // The object form: the rig without its source's meshes.
  auto rig_only = ossa::cook::json::parse(
      "{\"ossa_graph\": 1, \"name\": \"n\", \"skeleton\": {\"source\": \"s.fbx\", \"meshes\": false},\n"
      " \"clips\": {\"w\": \"w.fbx\"}, \"root\": {\"clip\": \"w\"}}",
      "g.json");
  ASSERT_TRUE(rig_only.ok());
  auto mr = read_graph_manifest(*rig_only);
  ASSERT_TRUE(mr.ok()) << mr.error().message;
  EXPECT_EQ(mr->skeleton, "s.fbx");
  EXPECT_FALSE(mr->skeleton_meshes);
  EXPECT_TRUE(m->skeleton_meshes) << "the string form keeps the source's meshes";
  auto bad_rig = ossa::cook::json::parse(
      "{\"ossa_graph\": 1, \"name\": \"n\", \"skeleton\": {\"meshes\": \"no\", \"mesh\": 1},\n"
      " \"clips\": {\"w\": \"w.fbx\"}, \"root\": {\"clip\": \"w\"}}",
      "g.json");
  ASSERT_TRUE(bad_rig.ok());
  auto mbr = read_graph_manifest(*bad_rig);
  ASSERT_FALSE(mbr.ok());
  EXPECT_HAS(mbr.error().message, "g.json:1:44: \"skeleton\" needs a \"source\"");
  EXPECT_HAS(mbr.error().message, "\"meshes\" must be a boolean");
  EXPECT_HAS(mbr.error().message, "unknown key \"mesh\"");
}

// ---- procedural nodes (format v6) ----------------------------------------------------------------

const char* kVectorParams = R"({
    "speed": {"type": "float", "default": 1, "min": 0, "max": 6},
    "look": {"type": "vector", "default": [0, 1.5, 2], "space": "world"},
    "ground": {"type": "float"},
    "normal": {"type": "vector", "default": [0, 1, 0], "direction": true},
    "planted": {"type": "bool"}
  })";

TEST_F(GraphCompile, VectorParametersAndProceduralNodesCompileWithUnitsConverted) {
  rig.metres_per_unit = 0.01f;  // a rig in centimetres: the file's metres become 100 units
  const CompiledGraph c = ok(graph(R"({
    "name": "springs", "spring": {
      "name": "lock", "foot_lock": {
        "name": "feet", "foot_placement": {
          "name": "ik", "two_bone_ik": {"clip": "walk"}, "start": "Hips", "mid": "LeftLeg", "end": "LeftFoot",
          "target": "look", "pole": [0, 0, 1], "twist": 90, "soften": 0.9},
        "pelvis": "Hips", "max_pelvis_drop": 0.2,
        "legs": [{"hip": "Hips", "knee": "LeftLeg", "ankle": "LeftFoot", "ground": "ground", "normal": "normal"}]},
      "legs": [{"hip": "LeftLeg", "knee": "LeftKnee", "ankle": "LeftFoot", "planted": "planted"}],
      "release_radius": 0.1},
    "chains": [{"joints": ["Tail1", "Tail2"], "radius": 0.02}],
    "colliders": [{"joint": "Hips", "offset": [0, 0.1, 0], "radius": 0.15}]})",
                                   "{}", kVectorParams));
  const GraphDef& g = c.graph;
  ASSERT_EQ(g.parameters.size(), 5u);
  EXPECT_EQ(g.parameters[1].type, ParamType::Vector);
  EXPECT_TRUE(g.parameters[1].world);
  EXPECT_FLOAT_EQ(g.parameters[1].default_vector[1], 150.0f);
  EXPECT_FLOAT_EQ(g.parameters[3].default_vector[1], 1.0f) << "a direction is not a length";
  ASSERT_EQ(g.nodes.size(), 5u);
  const auto& ik = std::get<TwoBoneIkDef>(g.nodes[1].kind);
  EXPECT_EQ(ik.start, 0);
  EXPECT_EQ(ik.mid, 5);
  EXPECT_EQ(ik.end, 7);
  EXPECT_EQ(ik.target_parameter, 1);
  EXPECT_NEAR(ik.twist, 1.5707963f, 1e-6f);
  const auto& feet = std::get<FootPlacementDef>(g.nodes[2].kind);
  EXPECT_FLOAT_EQ(feet.max_pelvis_drop, 20.0f);
  EXPECT_EQ(feet.legs[0].ground_parameter, 2);
  EXPECT_EQ(feet.legs[0].normal_parameter, 3);
  const auto& lock = std::get<FootLockDef>(g.nodes[3].kind);
  EXPECT_FLOAT_EQ(lock.release_radius, 10.0f);
  EXPECT_EQ(lock.legs[0].planted_parameter, 4);
  const auto& spring = std::get<SpringDef>(g.nodes[4].kind);
  ASSERT_EQ(spring.chains.size(), 1u);
  EXPECT_EQ(spring.chains[0].joints, (std::vector<uint16_t>{8, 9}));
  EXPECT_FLOAT_EQ(spring.chains[0].gravity[1], -981.0f);  // 9.81 m/s^2 in cm
  EXPECT_FLOAT_EQ(spring.chains[0].radius, 2.0f);
  EXPECT_FLOAT_EQ(spring.colliders[0].offset[1], 10.0f);
  EXPECT_FLOAT_EQ(spring.colliders[0].tail[1], 10.0f);  // a sphere: the tail defaults to the offset
}

TEST_F(GraphCompile, ProceduralNodeMistakesAreReportedWhereTheyAre) {
  // A chain whose joints are not ancestors in order.
  const std::string a = graph(R"({"two_bone_ik": {"clip": "walk"}, "start": "LeftLeg", "mid": "Spine", "end": "Head",
    "target": "look"})",
                              "{}", kVectorParams);
  EXPECT_HAS(errors(a), "a two_bone_ik node: joint 'LeftLeg' is not an ancestor of 'Spine'");
  // The target must be a vector parameter.
  const std::string b =
      graph(R"({"aim": {"clip": "walk"}, "chain": [{"joint": "Head"}], "target": "speed"})", "{}", kVectorParams);
  EXPECT_HAS(errors(b), "parameter 'speed' is a float; \"target\" needs a vector parameter");
  // A vector parameter cannot be read by a condition.
  const std::string c =
      graph(R"({"state_machine": {"name": "m", "entry": "a", "states": {"a": {"node": {"clip": "walk"}},
    "b": {"node": {"clip": "run"}}}, "transitions": [{"from": "a", "to": "b", "when": "look > 1"}]}})",
            "{}", kVectorParams);
  EXPECT_HAS(errors(c), "'look' is a vector parameter: conditions cannot read it");
  // A foot lock leg needs a way to know when it is planted.
  const std::string d = graph(R"({"foot_lock": {"clip": "walk"}, "legs": [{"hip": "LeftLeg", "knee": "LeftKnee",
    "ankle": "LeftFoot"}]})",
                              "{}", kVectorParams);
  EXPECT_HAS(errors(d), "a foot_lock leg needs \"planted\" (a parameter) or both \"plant_event\" and \"lift_event\"");
  // A spring chain lists each joint's child next.
  const std::string e =
      graph(R"({"spring": {"clip": "walk"}, "chains": [{"joints": ["Tail1", "Head"]}]})", "{}", kVectorParams);
  EXPECT_HAS(errors(e), "spring chain joint 'Head' is not a child of 'Tail1'");
  // Vector values need three numbers; an unknown space is named.
  const std::string f = graph(R"({"clip": "walk"})", "{}", R"({"v": {"type": "vector", "default": [1, 2]}})");
  EXPECT_HAS(errors(f), "needs 3 numbers, not 2");
  const std::string h = graph(R"({"clip": "walk"})", "{}", R"({"v": {"type": "vector", "space": "screen"}})");
  EXPECT_HAS(errors(h), "\"space\" is 'screen'; spaces: model, world");
  // An unknown joint names the node's role and suggests the right one.
  const std::string k = graph(R"({"two_bone_ik": {"clip": "walk"}, "start": "hips", "mid": "LeftLeg", "end": "LeftFoot",
    "target": "look"})",
                              "{}", kVectorParams);
  EXPECT_HAS(errors(k), "unknown joint 'hips' in a two_bone_ik node \"start\" (did you mean 'Hips'?)");
}

}  // namespace
