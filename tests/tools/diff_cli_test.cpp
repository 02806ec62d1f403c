// diff_cli_test.cpp — ossa-diff as a CI job drives it: real sample assets cooked with the built
// ossa-cook into the test's temp dir, compared by the built ossa-diff, judged by exit status,
// text and JSON (validated against docs/schemas/ossa-diff.schema.json).
//
// The figures asserted here were measured on the samples (docs/DIFF.md quotes them): Pab's walk
// cooked at --clip-tolerance 0.1 and 0.5 differs by 0.45 mm, and the error ossa-diff measures at
// the clip's frames against a lossless cook matches what the cooker reported for the 0.5 mm cook to
// within 0.001 mm, which is the check that the two sides use the same measure. Cooking each
// sample takes well under a second, so every test cooks what it needs itself.
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include <ossa/loader/asset.h>
#include "blend_shape_fbx.h"
#include "test_files.h"

namespace fs = std::filesystem;
using ossa::test::run_command;

namespace {

std::string q(const fs::path& p) { return "'" + p.string() + "'"; }
std::string cook_cmd() { return q(ossa::test::bin_dir() / "ossa-cook"); }
std::string diff_cmd() { return q(ossa::test::bin_dir() / "ossa-diff"); }
fs::path asset(const char* rel) { return ossa::test::source_dir() / "assets" / rel; }

/// Cooks `source` with `flags` into dir/sub and returns the output, or an empty path on failure.
fs::path cook(const fs::path& dir, const std::string& sub, const fs::path& source, const std::string& flags = "") {
  const auto r = run_command(cook_cmd() + " " + q(source) + " -o " + q(dir / sub) + " -q " + flags);
  EXPECT_EQ(r.exit_code, 0) << r.err;
  const fs::path out = dir / sub / (source.stem().string() + ".ossa");
  return r.exit_code == 0 && fs::exists(out) ? out : fs::path();
}

/// Pab's rig, and its walk cooked against it with `flags` into dir/sub.
struct PabWalk {
  fs::path skeleton;
  fs::path walk(const fs::path& dir, const std::string& sub, const std::string& flags) const {
    return cook(dir, sub, asset("Pab/walk.fbx"), "--skeleton " + q(skeleton) + " " + flags);
  }
};
PabWalk pab(const fs::path& dir) { return {cook(dir, "rig", asset("Pab/skeleton.fbx"))}; }

nlohmann::json diff_json(const fs::path& a, const fs::path& b, const std::string& flags, int* exit_code) {
  const auto r = run_command(diff_cmd() + " " + q(a) + " " + q(b) + " --json " + flags);
  *exit_code = r.exit_code;
  EXPECT_TRUE(r.exit_code == 0 || r.exit_code == 1) << r.err;
  return nlohmann::json::parse(r.out, nullptr, false);
}

TEST(DiffCli, IdenticalCooksAreTheSame) {
  const fs::path dir = ossa::test::make_temp_dir("diff-same");
  const fs::path a = cook(dir, "a", asset("Fox/Fox.glb")), b = cook(dir, "b", asset("Fox/Fox.glb"));
  auto r = run_command(diff_cmd() + " " + q(a) + " " + q(b));
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("same within 0.1 mm"), std::string::npos) << r.out;

  const PabWalk rig = pab(dir);
  const fs::path w1 = rig.walk(dir, "w1", ""), w2 = rig.walk(dir, "w2", "");
  r = run_command(diff_cmd() + " " + q(w1) + " " + q(w2) + " --skeleton " + q(rig.skeleton) + " -v");
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("clip 'walk'"), std::string::npos) << "-v lists the compared clip: " << r.out;
}

TEST(DiffCli, ClipToleranceDifferenceIsMeasuredAndJudged) {
  const fs::path dir = ossa::test::make_temp_dir("diff-tol");
  const PabWalk rig = pab(dir);
  const fs::path fine = rig.walk(dir, "fine", "--clip-tolerance 0.1"),
                 coarse = rig.walk(dir, "coarse", "--clip-tolerance 0.5");
  const std::string skel = "--skeleton " + q(rig.skeleton);
  int code = -1;
  const nlohmann::json j = diff_json(fine, coarse, skel, &code);
  EXPECT_EQ(code, 1);
  ASSERT_FALSE(j.is_discarded());
  ASSERT_EQ(j["sections"]["clips"]["items"].size(), 1u);
  const auto& clip = j["sections"]["clips"]["items"][0];
  const double error = clip["max_error_mm"].get<double>();
  // Measured 0.446 mm: the two cooks are each within their bound of the source (0.098 and 0.406 mm).
  EXPECT_GT(error, 0.2);
  EXPECT_LT(error, 1.0);
  EXPECT_FALSE(clip["worst_joint"].get<std::string>().empty());
  ASSERT_EQ(j["differences"].size(), 1u) << j["differences"].dump();
  EXPECT_EQ(j["differences"][0]["section"], "clips");
  EXPECT_EQ(j["differences"][0]["item"], "walk");
  EXPECT_EQ(j["differences"][0]["what"], "joint error");
  EXPECT_NEAR(j["differences"][0]["value"].get<double>(), error, 1e-5);

  auto r = run_command(diff_cmd() + " " + q(fine) + " " + q(coarse) + " " + skel);
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.out.find("clips 'walk': joint error: "), std::string::npos) << r.out;
  r = run_command(diff_cmd() + " " + q(fine) + " " + q(coarse) + " " + skel + " --tolerance-mm 0.1 -q");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(r.out, "") << "-q prints nothing";
  r = run_command(diff_cmd() + " " + q(fine) + " " + q(coarse) + " " + skel + " --tolerance-mm 2");
  EXPECT_EQ(r.exit_code, 0) << r.out;
}

TEST(DiffCli, ErrorIsTheCookersOwnMeasure) {
  const fs::path dir = ossa::test::make_temp_dir("diff-measure");
  const PabWalk rig = pab(dir);
  const fs::path exact = rig.walk(dir, "exact", "--no-clip-compression"),
                 coarse = rig.walk(dir, "coarse", "--clip-tolerance 0.5 --report " + q(dir / "report.json"));
  int code = -1;
  const nlohmann::json j = diff_json(exact, coarse, "--skeleton " + q(rig.skeleton), &code);
  ASSERT_FALSE(j.is_discarded());
  const auto& clip = j["sections"]["clips"]["items"][0];
  // The lossless cook is the source at every frame (to float precision) and plays it between
  // frames as a runtime does, and ossa-diff samples where the cooker measures (every frame and
  // three points between frames, probes 10 cm from the joints in model space): it reports the
  // figure the cooker recorded for the coarse cook. The runtime's rsqrt and a time's rounding to a
  // frame position make the rest.
  const double cooker = clip["new"]["cooker_max_error_mm"].get<double>();
  EXPECT_GT(cooker, 0.1);
  EXPECT_LE(cooker, 0.5);
  EXPECT_NEAR(clip["max_error_mm"].get<double>(), cooker, 0.001);
  EXPECT_LE(clip["max_error_at_frames_mm"].get<double>(), clip["max_error_mm"].get<double>());
  // --report and ossa-inspect say the same figure.
  std::ifstream in(dir / "report.json");
  const nlohmann::json report = nlohmann::json::parse(in, nullptr, false);
  ASSERT_FALSE(report.is_discarded());
  const double reported = report["records"][0]["clip_compression"][0]["max_error_mm"].get<double>();
  EXPECT_NEAR(reported, cooker, 1e-4);
  const auto inspect = run_command(q(ossa::test::bin_dir() / "ossa-inspect") + " --json " + q(coarse));
  ASSERT_EQ(inspect.exit_code, 0) << inspect.err;
  const nlohmann::json described = nlohmann::json::parse(inspect.out, nullptr, false);
  ASSERT_FALSE(described.is_discarded());
  EXPECT_NEAR(described["clips"][0]["compression"]["max_error_mm"].get<double>(), cooker, 1e-4);
}

TEST(DiffCli, FloatAndQuantizedVerticesDifferByLessThanAQuantizationStep) {
  const fs::path dir = ossa::test::make_temp_dir("diff-float");
  const fs::path quantized = cook(dir, "q", asset("CesiumMan/CesiumMan.glb"));
  const fs::path floats = cook(dir, "f", asset("CesiumMan/CesiumMan.glb"), "--float-vertices");
  int code = -1;
  const nlohmann::json j = diff_json(quantized, floats, "", &code);
  EXPECT_EQ(code, 1) << "the layout changed";
  ASSERT_FALSE(j.is_discarded());
  ASSERT_EQ(j["sections"]["meshes"]["items"].size(), 1u);
  const auto& mesh = j["sections"]["meshes"]["items"][0];
  EXPECT_TRUE(mesh["topology_same"].get<bool>());
  EXPECT_FALSE(mesh["layout_same"].get<bool>());
  // Half a unorm16 step along each axis of the quantized mesh's bounds, as a diagonal, in mm.
  auto a = ossa::Asset::open(quantized.string());
  ASSERT_TRUE(a.ok());
  const ossa::fb::Vec3* s = a->mesh(0).fb->position_scale();
  ASSERT_NE(s, nullptr);
  const double mm = 1000.0 * a->file().metres_per_unit();
  const double half_step = 0.5 * mm * std::sqrt(s->x() * s->x() + s->y() * s->y() + s->z() * s->z()) / 65535.0;
  const double displacement = mesh["max_displacement_mm"].get<double>();
  EXPECT_GT(displacement, 0.0);
  EXPECT_LE(displacement, half_step * 1.01);
  bool layout_named = false;
  for (const auto& d : j["differences"]) layout_named |= d["what"] == "layout" && d["item"] == mesh["name"];
  EXPECT_TRUE(layout_named) << j["differences"].dump();
}

TEST(DiffCli, ChangedSourcesAreNamedPrecisely) {
  const fs::path dir = ossa::test::make_temp_dir("diff-named");
  ossa::test::SyntheticSpec base, moved, renamed;
  moved.skeleton->translations[3] = ossa::fb::Vec3(0.505f, 0.5f, 0.0f);  // 'arm' 5 mm along x
  auto& v = moved.meshes[0].vertices[3].position;                        // 3 mm up, inside the bounds
  v = ossa::fb::Vec3(v.x(), v.y() + 0.003f, v.z());
  renamed.skeleton->names[2] = "skull";
  renamed.clips[0].name = "amble";
  ASSERT_TRUE(ossa::test::write_file(dir / "base.ossa", ossa::test::make_valid_file(base)));
  ASSERT_TRUE(ossa::test::write_file(dir / "moved.ossa", ossa::test::make_valid_file(moved)));
  ASSERT_TRUE(ossa::test::write_file(dir / "renamed.ossa", ossa::test::make_valid_file(renamed)));

  auto r = run_command(diff_cmd() + " " + q(dir / "base.ossa") + " " + q(dir / "moved.ossa"));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.out.find("skeleton 'arm': bind pose: 5 mm > 0.1 mm"), std::string::npos) << r.out;
  // 3 mm, give or take one unorm16 step of the 2 m high bounds (0.03 mm).
  const std::string mesh_line = "meshes 'body': vertex displacement: ";
  const size_t at = r.out.find(mesh_line);
  ASSERT_NE(at, std::string::npos) << r.out;
  EXPECT_NEAR(std::stod(r.out.substr(at + mesh_line.size())), 3.0, 0.031) << r.out;
  EXPECT_NE(r.out.find("mm > 0.1 mm (vertex 3)", at), std::string::npos) << r.out;

  // A different rig is a difference (exit 1), not a failure to compare (exit 2).
  r = run_command(diff_cmd() + " " + q(dir / "base.ossa") + " " + q(dir / "renamed.ossa"));
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.out.find("skeleton 'head': renamed: 'head' -> 'skull'"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("clips 'walk': removed"), std::string::npos) << r.out;
  EXPECT_NE(r.out.find("clips 'amble': added"), std::string::npos) << r.out;
}

TEST(DiffCli, UnusableInputsAndUsageErrorsExitTwo) {
  const fs::path dir = ossa::test::make_temp_dir("diff-bad");
  const fs::path good = cook(dir, "a", asset("RiggedSimple/RiggedSimple.glb"));
  ASSERT_TRUE(ossa::test::write_file(dir / "notes.txt", std::string_view("this is not an .ossa file\n")));
  auto r = run_command(diff_cmd() + " " + q(good) + " " + q(dir / "notes.txt"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("notes.txt"), std::string::npos) << "the loader's message names the file: " << r.err;
  r = run_command(diff_cmd() + " " + q(dir / "missing.ossa") + " " + q(good) + " -q");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("missing.ossa"), std::string::npos) << r.err;

  // Unknown flag, no files, a bad tolerance, a third file: CLI11 would exit 105-109 itself.
  const std::string pair = q(good) + " " + q(good);
  for (const std::string& args : {pair + " --frobnicate", std::string(), pair + " --tolerance-mm -1",
                                  pair + " --tolerance-mm abc", pair + " " + q(good)}) {
    r = run_command(diff_cmd() + " " + args);
    EXPECT_EQ(r.exit_code, 2) << "'" << args << "' is a usage error: " << r.err;
  }
  r = run_command(diff_cmd() + " --help");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("--tolerance-mm"), std::string::npos);
  r = run_command(diff_cmd() + " --version");
  EXPECT_EQ(r.exit_code, 0);
  EXPECT_NE(r.out.find("ossa-diff"), std::string::npos) << r.out;
}

TEST(DiffCli, ClipOnlyFileNeedsItsSkeleton) {
  const fs::path dir = ossa::test::make_temp_dir("diff-cliponly");
  const PabWalk rig = pab(dir);
  const fs::path walk = rig.walk(dir, "w", "");
  auto r = run_command(diff_cmd() + " " + q(walk) + " " + q(walk));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("walk.ossa"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("--skeleton"), std::string::npos) << r.err;
  // A rig the clips were not cooked for is named too.
  const fs::path fox = cook(dir, "fox", asset("Fox/Fox.glb"));
  r = run_command(diff_cmd() + " " + q(walk) + " " + q(walk) + " --skeleton " + q(fox));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("Fox.ossa"), std::string::npos) << r.err;
}

TEST(DiffCli, MorphOnlyClipsCompareWithoutASkeleton) {
  // A blend-shape face (no joints) whose take drives two morph weights: nothing to play on a rig,
  // its weights are compared per track at the clip's frames and between.
  const fs::path dir = ossa::test::make_temp_dir("diff-morph");
  const std::string face = ossa::test::kBlendShapeFbx;
  fs::create_directories(dir / "src");
  fs::create_directories(dir / "changed");
  ASSERT_TRUE(ossa::test::write_file(dir / "src" / "face.fbx", face));
  std::string changed = face;
  const size_t at = changed.find("a: 0,100,0");
  ASSERT_NE(at, std::string::npos);
  changed.replace(at, 10, "a: 0,80,0");  // smile peaks at 0.8 instead of 1.0
  ASSERT_TRUE(ossa::test::write_file(dir / "changed" / "face.fbx", changed));
  const fs::path a = cook(dir, "a", dir / "src" / "face.fbx"), b = cook(dir, "b", dir / "changed" / "face.fbx");
  ASSERT_FALSE(a.empty());
  ASSERT_FALSE(b.empty());
  auto r = run_command(diff_cmd() + " " + q(a) + " " + q(a) + " -v");
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;
  EXPECT_NE(r.out.find("2 morph tracks, max weight difference 0"), std::string::npos) << r.out;
  int code = 0;
  const nlohmann::json j = diff_json(a, b, "", &code);
  EXPECT_EQ(code, 1);
  ASSERT_TRUE(j.contains("sections")) << j.dump();
  ASSERT_EQ(j["sections"]["clips"]["items"].size(), 1u) << j.dump();
  const auto& item = j["sections"]["clips"]["items"][0];
  EXPECT_TRUE(item["sampled"].get<bool>());
  EXPECT_EQ(item["morph_tracks_compared"].get<int>(), 2);
  EXPECT_NEAR(item["max_morph_weight_error"].get<double>(), 0.2, 1e-3) << item.dump();
  bool named = false;
  for (const auto& d : j["differences"]) named = named || d.dump().find("morph weight") != std::string::npos;
  EXPECT_TRUE(named) << j["differences"].dump();
}

TEST(DiffCli, JsonOutputMatchesItsSchema) {
  const fs::path dir = ossa::test::make_temp_dir("diff-schema");
  const PabWalk rig = pab(dir);
  const fs::path fine = rig.walk(dir, "fine", ""), coarse = rig.walk(dir, "coarse", "--clip-tolerance 0.5");
  const fs::path fox = cook(dir, "fox", asset("Fox/Fox.glb")),
                 fox_float = cook(dir, "foxf", asset("Fox/Fox.glb"), "--float-vertices");
  ossa::test::SyntheticSpec base, changed;
  base.graph = changed.graph = true;
  base.clips[0].events = {{"step", 0.5f}};
  changed.clips[0].events = {{"step", 0.6f}};
  changed.skeleton->names[3] = "left_arm";
  changed.skeleton->translations[1] = ossa::fb::Vec3(0.0f, 1.01f, 0.0f);
  (*changed.materials[0].textures[0].data)[40] ^= 1;
  ASSERT_TRUE(ossa::test::write_file(dir / "base.ossa", ossa::test::make_valid_file(base)));
  ASSERT_TRUE(ossa::test::write_file(dir / "changed.ossa", ossa::test::make_valid_file(changed)));

  const struct {
    fs::path a, b;
    std::string flags;
    int expected;
    const char* out;
  } cases[] = {{fox, fox, "", 0, "same.json"},
               {fox, fox_float, "", 1, "float.json"},
               {fine, coarse, "--skeleton " + q(rig.skeleton), 1, "clips.json"},
               {dir / "base.ossa", dir / "changed.ossa", "", 1, "synthetic.json"}};
  std::string docs;
  for (const auto& c : cases) {
    const auto r = run_command(diff_cmd() + " " + q(c.a) + " " + q(c.b) + " --json " + c.flags);
    EXPECT_EQ(r.exit_code, c.expected) << c.out << ": " << r.err;
    ASSERT_TRUE(ossa::test::write_file(dir / c.out, r.out));
    const auto j = nlohmann::json::parse(r.out, nullptr, false);
    ASSERT_FALSE(j.is_discarded()) << c.out;
    EXPECT_EQ(j["same"].get<bool>(), c.expected == 0);
    EXPECT_EQ(j["differences"].empty(), c.expected == 0);
    docs += " " + q(dir / c.out);
  }
  const std::string check = "/usr/bin/python3 " +
                            q(ossa::test::source_dir() / "tests" / "support" / "json_schema_check.py") + " " +
                            q(ossa::test::source_dir() / "docs" / "schemas" / "ossa-diff.schema.json");
  auto r = run_command(check + docs);
  EXPECT_EQ(r.exit_code, 0) << r.out << r.err;

  // The schema is strict: a field it does not describe fails (so the check above can fail).
  auto j = nlohmann::json::parse(*ossa::test::read_text(dir / "clips.json"));
  j["sections"]["clips"]["items"][0]["undocumented"] = 1;
  ASSERT_TRUE(ossa::test::write_file(dir / "extra.json", j.dump()));
  r = run_command(check + " " + q(dir / "extra.json"));
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_NE(r.err.find("undocumented"), std::string::npos) << r.err;
}

}  // namespace
