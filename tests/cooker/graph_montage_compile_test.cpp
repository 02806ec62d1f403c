// graph_montage_compile_test.cpp — montages and slot nodes in graph files (cooker/graph/graph_montage.h,
// docs/GRAPH.md "Montages"): a valid file gives the expected MontageDef and SlotDef (defaults, section
// links, sorted events, units), and every kind of mistake is refused with `file:line:col:` at the
// value at fault, the way the rest of the graph compiler reports.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "cooker/graph/graph_compile.h"

namespace {

using namespace ossa::cook;

#define EXPECT_HAS(haystack, needle)                               \
  EXPECT_NE(std::string(haystack).find(needle), std::string::npos) \
      << "expected to find:\n  " << (needle) << "\nin:\n  " << (haystack)

SourceSkeleton make_rig() {
  SourceSkeleton sk;
  for (auto [name, parent] : std::vector<std::pair<const char*, int>>{
           {"Hips", -1}, {"Spine", 0}, {"Head", 1}, {"LeftArm", 1}, {"RightArm", 1}, {"LeftLeg", 0}}) {
    SourceJoint j;
    j.name = name;
    j.parent = parent;
    sk.joints.push_back(j);
  }
  return sk;
}

/// A graph whose root is `root` and whose "montages" are `montages`.
std::string graph(const std::string& montages, const std::string& root) {
  return "{\n  \"ossa_graph\": 1,\n  \"name\": \"test\",\n  \"skeleton\": \"rig.fbx\",\n"
         "  \"clips\": {\"walk\": \"walk.fbx\", \"wave\": \"wave.fbx\"},\n"
         "  \"parameters\": {\"lean\": {\"type\": \"float\"}},\n"
         "  \"montages\": " +
         montages + ",\n  \"root\": " + root + "\n}\n";
}

const std::string kSlot =
    R"({"slot": "arms", "group": "gestures", "input": {"clip": "walk"}, "mask": [{"joint": "Spine", "depth": 2}]})";

/// One montage named m on slot "arms" of group "gestures", with `body` spliced in.
std::string montage(const std::string& body) {
  return R"({"m": {"group": "gestures", "tracks": {"arms": [{"clip": "wave"}]}, "sections": {"all": {"time": 0}})" +
         (body.empty() ? "" : ", " + body) + "}}";
}

class MontageCompile : public ::testing::Test {
 protected:
  SourceSkeleton rig = make_rig();
  GraphContext context() const {
    GraphContext c;
    c.skeleton = &rig;
    c.clips = {{"walk", 1.0f, {}}, {"wave", 2.0f, {}}};
    return c;
  }
  CompiledGraph ok(const std::string& text) {
    auto r = compile_graph(text, "g.json", context());
    EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message) << "\n" << text;
    return r.ok() ? std::move(*r) : CompiledGraph{};
  }
  std::string errors(const std::string& text) {
    auto r = compile_graph(text, "g.json", context());
    EXPECT_FALSE(r.ok()) << "compiled:\n" << text;
    return r.ok() ? std::string() : r.error().message;
  }
};

/// "g.json:LINE:COL: " of the nth occurrence of needle in text.
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

TEST_F(MontageCompile, EveryFieldCompiles) {
  const std::string text = graph(R"({
    "wave_hello": {
      "group": "gestures",
      "tracks": {"arms": [{"clip": "wave", "start": 0.2, "end": 1.8, "rate": 2}, {"clip": "walk"}]},
      "sections": {"intro": {"time": 0}, "loop": {"time": 0.5, "next": "loop"}, "outro": {"time": 1.2, "next": null}},
      "blend_in": 0.1, "blend_out": {"time": 0.4, "curve": "inertialize"}, "blend_out_trigger": 0.2,
      "rate": 1.5, "root_motion": true,
      "events": [{"name": "b", "time": 0.9, "branch": true}, {"name": "hit", "time": 0.3},
                 {"name": "swing", "time": 0.1, "duration": 0.5}]
    },
    "plain": {"tracks": {"face": [{"clip": "walk", "end": 0.5}]}, "sections": {"a": {"time": 0}, "b": {"time": 0.25}}}
  })",
                                 R"({"slot": "face", "input": )" + kSlot + R"(, "mode": "override"})");
  const GraphDef g = ok(text).graph;
  ASSERT_EQ(g.nodes.size(), 3u);  // walk, arms slot, face slot (post-order)
  const auto* arms = std::get_if<SlotDef>(&g.nodes[1].kind);
  const auto* face = std::get_if<SlotDef>(&g.nodes[2].kind);
  ASSERT_TRUE(arms && face);
  EXPECT_EQ(arms->slot, "arms");
  EXPECT_EQ(arms->group, "gestures");
  EXPECT_EQ(arms->input, 0);
  ASSERT_EQ(arms->mask.size(), 1u);
  EXPECT_EQ(arms->mask[0].joint, 1);
  EXPECT_EQ(arms->mask[0].depth, 2);
  EXPECT_FALSE(arms->additive);
  EXPECT_EQ(face->group, "default");
  EXPECT_TRUE(face->mask.empty());
  EXPECT_EQ(face->input, 1);
  EXPECT_EQ(g.root, 2);

  ASSERT_EQ(g.montages.size(), 2u);
  const MontageDef& m = g.montages[0];
  EXPECT_EQ(m.name, "wave_hello");
  EXPECT_EQ(m.group, "gestures");
  ASSERT_EQ(m.tracks.size(), 1u);
  EXPECT_EQ(m.tracks[0].slot, "arms");
  ASSERT_EQ(m.tracks[0].segments.size(), 2u);
  EXPECT_EQ(m.tracks[0].segments[0].clip, 1);
  EXPECT_FLOAT_EQ(m.tracks[0].segments[0].start, 0.2f);
  EXPECT_FLOAT_EQ(m.tracks[0].segments[0].end, 1.8f);
  EXPECT_FLOAT_EQ(m.tracks[0].segments[0].rate, 2.0f);
  EXPECT_EQ(m.tracks[0].segments[1].clip, 0);
  EXPECT_FLOAT_EQ(m.tracks[0].segments[1].end, 1.0f);  // default: the clip's end
  ASSERT_EQ(m.sections.size(), 3u);
  EXPECT_EQ(m.sections[0].next, 1);   // absent: the section after it
  EXPECT_EQ(m.sections[1].next, 1);   // itself: a loop
  EXPECT_EQ(m.sections[2].next, -1);  // null: the end
  EXPECT_FLOAT_EQ(m.sections[1].start, 0.5f);
  EXPECT_FLOAT_EQ(m.blend_in, 0.1f);
  EXPECT_EQ(m.blend_in_curve, MontageCurveDef::Linear);
  EXPECT_FLOAT_EQ(m.blend_out, 0.4f);
  EXPECT_EQ(m.blend_out_curve, MontageCurveDef::Inertialize);
  EXPECT_FLOAT_EQ(m.blend_out_trigger, 0.2f);
  EXPECT_FLOAT_EQ(m.rate, 1.5f);
  EXPECT_TRUE(m.root_motion);
  ASSERT_EQ(m.notifies.size(), 3u);  // sorted by time
  EXPECT_EQ(m.notifies[0].name, "swing");
  EXPECT_EQ(m.notifies[0].kind, MontageNotifyKindDef::Window);
  EXPECT_FLOAT_EQ(m.notifies[0].duration, 0.5f);
  EXPECT_EQ(m.notifies[1].kind, MontageNotifyKindDef::Instant);
  EXPECT_EQ(m.notifies[2].kind, MontageNotifyKindDef::BranchingPoint);

  const MontageDef& plain = g.montages[1];  // defaults
  EXPECT_EQ(plain.group, "default");
  EXPECT_FLOAT_EQ(plain.blend_in, 0.25f);
  EXPECT_FLOAT_EQ(plain.blend_out, 0.25f);
  EXPECT_FLOAT_EQ(plain.blend_out_trigger, -1.0f);
  EXPECT_FLOAT_EQ(plain.rate, 1.0f);
  EXPECT_FALSE(plain.root_motion);
  EXPECT_EQ(plain.sections[0].next, 1);
  EXPECT_EQ(plain.sections[1].next, -1);  // the last: the end
}

TEST_F(MontageCompile, TrackMistakesPointAtTheTrack) {
  std::string t =
      graph(R"({"m": {"group": "gestures", "tracks": {"arm": [{"clip": "wave"}]}, "sections": {"all": {"time": 0}}}})",
            kSlot);
  EXPECT_HAS(errors(t), at(t, "\"arm\"") + "unknown slot 'arm' in montage 'm' (did you mean 'arms'?); slots: 'arms'");
  t = graph(R"({"m": {"group": "other", "tracks": {"arms": [{"clip": "wave"}]}, "sections": {"all": {"time": 0}}}})",
            kSlot);
  EXPECT_HAS(errors(t),
             at(t, "\"arms\"", 0) + "montage 'm' (group 'other') has a track for slot 'arms' of group 'gestures'");
  t = graph(R"({"m": {"group": "gestures", "tracks": {"arms": [{"clip": "wav"}]}, "sections": {"all": {"time": 0}}}})",
            kSlot);
  EXPECT_HAS(errors(t), at(t, "\"wav\"") + "unknown clip 'wav' (did you mean 'wave'?)");
  t = graph(
      R"({"m": {"group": "gestures", "tracks": {"arms": [{"clip": "wave", "end": 2.5}]},
        "sections": {"all": {"time": 0}}}})",
      kSlot);
  EXPECT_HAS(errors(t), at(t, "2.5") + "a segment's \"end\" (clip seconds) must be within [0, 2], not 2.5");
  t = graph(
      R"({"m": {"group": "gestures", "tracks": {"arms": [{"clip": "wave", "start": 1, "end": 1}]},
        "sections": {"all": {"time": 0}}}})",
      kSlot);
  EXPECT_HAS(errors(t), at(t, "1}]") + "a segment's \"end\" (1 s) must be after its \"start\" (1 s)");
  t = graph(
      R"({"m": {"group": "gestures", "tracks": {"arms": [{"clip": "wave", "rate": 0}]},
        "sections": {"all": {"time": 0}}}})",
      kSlot);
  EXPECT_HAS(errors(t), at(t, "0}]") + "a segment's \"rate\" must be within [0.001, 1000], not 0");
  t = graph(R"({"m": {"group": "gestures", "tracks": {"arms": []}, "sections": {"all": {"time": 0}}}})", kSlot);
  EXPECT_HAS(errors(t), at(t, "[]") + "track 'arms' has no segments");
  t = graph(R"({"m": {"group": "gestures", "sections": {"all": {"time": 0}}}})", kSlot);
  EXPECT_HAS(errors(t), at(t, "{\"group\"") + "montage 'm' needs \"tracks\"");
}

TEST_F(MontageCompile, SectionMistakesPointAtTheSection) {
  auto with_sections = [](const std::string& sections) {
    return graph(
        R"({"m": {"group": "gestures", "tracks": {"arms": [{"clip": "wave"}]}, "sections": )" + sections + "}}", kSlot);
  };
  std::string t = with_sections(R"({"a": {"time": 0.5}})");
  EXPECT_HAS(errors(t), at(t, "0.5") + "the first section ('a') must start at time 0");
  t = with_sections(R"({"a": {"time": 0}, "b": {"time": 1}, "c": {"time": 0.5}})");
  EXPECT_HAS(errors(t), at(t, "0.5") + "section 'c' starts at 0.5 s, not after section 'b'");
  t = with_sections(R"({"a": {"time": 0}, "b": {"time": 2}})");
  EXPECT_HAS(errors(t), at(t, "2}") + "section 'b' starts at 2 s, not before the montage's end (2 s)");
  t = with_sections(R"({"a": {"time": 0, "next": "lop"}, "loop": {"time": 1}})");
  EXPECT_HAS(errors(t), at(t, "\"lop\"") + "\"next\" 'lop' is not a section of montage 'm' (did you mean 'loop'?)");
  t = with_sections(R"({"a": {"time": 0, "next": 1}})");
  EXPECT_HAS(errors(t), at(t, "1}}") + "\"next\" (a section name, or null: the montage ends) must be a string");
  t = with_sections(R"({})");
  EXPECT_HAS(errors(t), at(t, "{}") + "montage 'm' needs 1 to 256 sections");
  t = with_sections(R"({"a": {"next": null}})");
  EXPECT_HAS(errors(t), at(t, "{\"next\"") + "section 'a' needs \"time\"");
  t = with_sections(R"({"a": {"time": 0, "nxt": "a"}})");
  EXPECT_HAS(errors(t), at(t, "\"nxt\"") + "unknown key \"nxt\" in a section (did you mean \"next\"?)");
}

TEST_F(MontageCompile, BlendRateAndEventMistakes) {
  std::string t = graph(montage(R"("blend_in": {"time": 0.2, "curve": "cubc"})"), kSlot);
  EXPECT_HAS(errors(t), at(t, "\"cubc\"") + "unknown blend curve 'cubc' (did you mean 'cubic'?)");
  t = graph(montage(R"("blend_out": -1)"), kSlot);
  EXPECT_HAS(errors(t), at(t, "-1") + "montage 'm' \"blend_out\" (seconds) must be within [0, 1e+06], not -1");
  t = graph(montage(R"("blendin": 0.2)"), kSlot);
  EXPECT_HAS(errors(t), at(t, "\"blendin\"") + "unknown key \"blendin\" in montage 'm' (did you mean \"blend_in\"?)");
  t = graph(montage(R"("rate": 0)"), kSlot);
  EXPECT_HAS(errors(t), at(t, "\"rate\": 0", 0, 8) + "montage 'm' \"rate\" must be within [0.001, 1000], not 0");
  t = graph(montage(R"("blend_out_trigger": -0.5)"), kSlot);
  EXPECT_HAS(errors(t), at(t, "-0.5") + "montage 'm' \"blend_out_trigger\" (seconds before the end) must be within");
  t = graph(montage(R"("root_motion": "yes")"), kSlot);
  EXPECT_HAS(errors(t), at(t, "\"yes\"") + "montage 'm' \"root_motion\" must be a boolean");
  t = graph(montage(R"("events": [{"name": "hit", "time": 3}])"), kSlot);
  EXPECT_HAS(errors(t), at(t, "3}") + "a montage event's \"time\" (timeline seconds) must be within [0, 2], not 3");
  t = graph(montage(R"("events": [{"name": "hit", "time": 1, "duration": 0}])"), kSlot);
  EXPECT_HAS(errors(t), at(t, "0}]") + "a montage event's \"duration\" must be above 0");
  t = graph(montage(R"("events": [{"name": "hit", "time": 1, "duration": 0.5, "branch": true}])"), kSlot);
  EXPECT_HAS(errors(t), at(t, "true") + "a branching point is an instant: it cannot also have a \"duration\"");
  t = graph(montage(R"("events": [{"time": 1}])"), kSlot);
  EXPECT_HAS(errors(t), at(t, "{\"time\": 1}") + "a montage event needs \"name\"");
  // Every problem of a montage is reported, each once, in the order of the file.
  t = graph(montage(R"("rate": -2, "events": [{"name": "a", "time": 9}], "blend_in": {"curve": "x"})"), kSlot);
  const std::string e = errors(t);
  EXPECT_HAS(e, at(t, "-2"));
  EXPECT_HAS(e, at(t, "9}"));
  EXPECT_HAS(e, at(t, "\"x\""));
  EXPECT_LT(e.find(at(t, "-2")), e.find(at(t, "9}")));
}

TEST_F(MontageCompile, SlotNodeMistakes) {
  const std::string ms = montage("");
  std::string t = graph(ms, R"({"slot": "arms", "group": "gestures"})");
  EXPECT_HAS(errors(t), at(t, "{\"slot\"") + "a slot node needs \"input\"");
  t = graph(ms, R"({"slot": "arms", "group": "gestures", "input": {"clip": "walk"}, "mode": "add"})");
  EXPECT_HAS(errors(t), at(t, "\"add\"") + "unknown slot mode 'add'; modes: override, additive");
  t = graph(ms, R"({"slot": "arms", "group": "gestures", "input": {"clip": "walk"}, "mask": []})");
  EXPECT_HAS(errors(t), at(t, "[]") + "\"mask\" is empty: leave it out to play on every joint");
  t = graph(ms, R"({"slot": "arms", "group": "gestures", "input": {"clip": "walk"}, "mask": [{"joint": "spine"}]})");
  EXPECT_HAS(errors(t), at(t, "\"spine\"") + "unknown joint 'spine' in a slot's mask (did you mean 'Spine'?)");
  t = graph(ms, R"({"slot": "", "group": "gestures", "input": {"clip": "walk"}})");
  EXPECT_HAS(errors(t), at(t, "\"\"") + "\"slot\"");
  t = graph(ms, R"({"slot": "arms", "group": "gestures", "input": {"clip": "walk"}, "masks": []})");
  EXPECT_HAS(errors(t), at(t, "\"masks\"") + "unknown key \"masks\" in a slot node (did you mean \"mask\"?)");
  // One slot name, one group.
  t = graph(ms, R"({"slot": "arms", "group": "other", "input": )" + kSlot + "}");
  EXPECT_HAS(errors(t),
             at(t, "\"arms\"", 1) + "slot 'arms' is in group 'other' here and in group 'gestures' elsewhere");
}

TEST_F(MontageCompile, SlotWhereItWouldPlayNothingIsRefused) {
  // Inside a layer weighted by a parameter: its montages would show only while the parameter is set.
  std::string t = graph(montage(""), R"({"layered": {"clip": "walk"}, "layers": [{"node": )" + kSlot +
                                         R"(, "mask": [{"joint": "Spine"}], "weight_parameter": "lean"}]})");
  EXPECT_HAS(errors(t), at(t, "\"arms\"", 1) +
                            "slot 'arms' is inside a layer (or an additive's added input) whose "
                            "weight can be 0");
  t = graph(montage(""), R"({"additive": {"clip": "walk"}, "add": )" + kSlot + R"(, "weight": 0})");
  EXPECT_HAS(errors(t), at(t, "\"arms\"", 1) + "slot 'arms' is inside a layer");
  // Over the layered node, or in a layer of fixed weight, it is fine.
  ok(graph(montage(""), R"({"slot": "arms", "group": "gestures", "input": {"layered": {"clip": "walk"}, "layers": [
        {"node": {"clip": "wave"}, "mask": [{"joint": "Spine"}], "weight_parameter": "lean"}]}})"));
  ok(graph(montage(""), R"({"layered": {"clip": "walk"}, "layers": [{"node": )" + kSlot +
                            R"(, "mask": [{"joint": "Spine"}], "weight": 1}]})"));
}

TEST_F(MontageCompile, SlotsOfUnusedNamedNodesDoNotCount) {
  // A named node never used is still checked, but its slot is not a slot of the graph.
  const std::string t =
      "{\n  \"ossa_graph\": 1,\n  \"name\": \"test\",\n  \"skeleton\": \"rig.fbx\",\n"
      "  \"clips\": {\"walk\": \"walk.fbx\", \"wave\": \"wave.fbx\"},\n"
      "  \"nodes\": {\"spare\": " +
      kSlot +
      "},\n"
      "  \"montages\": " +
      montage("") + ",\n  \"root\": {\"clip\": \"walk\"}\n}\n";
  EXPECT_HAS(errors(t), at(t, "\"arms\"", 1) + "unknown slot 'arms' in montage 'm'; the graph has no slot nodes");
}

}  // namespace
