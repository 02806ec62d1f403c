// cooker_cli_test.cpp — ossa-cook as a user drives it: batches with failures, output planning,
// --root, --skeleton, --report, and the promise that nothing half-written or lost is left behind.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include <ossa/loader/asset.h>
#include "test_files.h"

namespace fs = std::filesystem;
using ossa::test::run_command;

namespace {

std::string cook_cmd() { return (ossa::test::bin_dir() / "ossa-cook").string(); }
fs::path asset(const char* rel) { return ossa::test::source_dir() / "assets" / rel; }
std::string q(const fs::path& p) { return "'" + p.string() + "'"; }

using ossa::test::count_files;

TEST(CookerCli, CooksOneFileThatVerifies) {
  const fs::path out = ossa::test::make_temp_dir("cli-one");
  const auto r = run_command(cook_cmd() + " " + q(asset("RiggedSimple/RiggedSimple.glb")) + " -o " + q(out));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto a = ossa::Asset::open((out / "RiggedSimple.ossa").string());
  ASSERT_TRUE(a.ok()) << a.error().message;
  EXPECT_GT(a->skeleton().joint_count(), 0u);
  EXPECT_GT(a->mesh_count(), 0u);
  EXPECT_EQ(count_files(out), 1u) << "only the output, no temporary files";
}

TEST(CookerCli, BadInputsFailAloneAndTheBatchGoesOn) {
  const fs::path dir = ossa::test::make_temp_dir("cli-bad");
  const fs::path src = dir / "src", out = dir / "out";
  fs::create_directories(src);
  ASSERT_TRUE(ossa::test::write_file(src / "garbage.fbx", std::string_view("this is not an FBX file\n")));
  ASSERT_TRUE(ossa::test::write_file(src / "empty.glb", std::string_view("")));
  const auto r = run_command(cook_cmd() + " " + q(src / "garbage.fbx") + " " + q(src / "missing.gltf") + " " +
                             q(asset("RiggedSimple/RiggedSimple.glb")) + " " + q(src / "empty.glb") + " " +
                             q(asset("Fox/Fox.glb")) + " -o " + q(out) + " --jobs 2 --report " +
                             q(dir / "report.json"));
  EXPECT_EQ(r.exit_code, 1);
  // Each failure is named on stderr with its file.
  EXPECT_NE(r.err.find("garbage.fbx"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("missing.gltf"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("empty.glb"), std::string::npos) << r.err;
  // The good inputs were cooked, the bad ones left nothing.
  EXPECT_TRUE(ossa::Asset::open((out / "RiggedSimple.ossa").string()).ok());
  EXPECT_TRUE(ossa::Asset::open((out / "Fox.ossa").string()).ok());
  EXPECT_FALSE(fs::exists(out / "garbage.ossa"));
  EXPECT_FALSE(fs::exists(out / "missing.ossa"));
  EXPECT_FALSE(fs::exists(out / "empty.ossa"));
  EXPECT_EQ(count_files(out), 2u);

  auto text = ossa::test::read_text(dir / "report.json");
  ASSERT_TRUE(text.has_value());
  const auto report = nlohmann::json::parse(*text);
  EXPECT_EQ(report["inputs"], 5);
  EXPECT_EQ(report["failed"], 3);
  ASSERT_EQ(report["records"].size(), 5u);
  EXPECT_EQ(report["records"][0]["status"], "failed");
  EXPECT_NE(report["records"][0]["error"].get<std::string>().find("garbage.fbx"), std::string::npos);
  EXPECT_EQ(report["records"][1]["status"], "failed");
  EXPECT_EQ(report["records"][2]["status"], "ok");
  EXPECT_GT(report["records"][2]["joints"].get<int>(), 0);
  EXPECT_GT(report["records"][2]["cooked_bytes"].get<int>(), 0);
  EXPECT_EQ(report["records"][4]["status"], "ok");
  EXPECT_EQ(report["records"][4]["clips"], 3);
}

TEST(CookerCli, FailedCookKeepsThePreviousOutput) {
  const fs::path dir = ossa::test::make_temp_dir("cli-keep");
  const fs::path out = dir / "out";
  fs::create_directories(out);
  ASSERT_TRUE(ossa::test::write_file(dir / "thing.fbx", std::string_view("not a model")));
  ASSERT_TRUE(ossa::test::write_file(out / "thing.ossa", std::string_view("previous output")));
  const auto r = run_command(cook_cmd() + " " + q(dir / "thing.fbx") + " -o " + q(out));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_EQ(ossa::test::read_text(out / "thing.ossa").value_or(""), "previous output");
  EXPECT_EQ(count_files(out), 1u);
}

TEST(CookerCli, OutputCollisionRefusedBeforeCooking) {
  const fs::path dir = ossa::test::make_temp_dir("cli-collide");
  fs::create_directories(dir / "a");
  fs::create_directories(dir / "b");
  fs::copy_file(asset("RiggedSimple/RiggedSimple.glb"), dir / "a" / "model.glb");
  fs::copy_file(asset("CesiumMan/CesiumMan.glb"), dir / "b" / "model.glb");
  const auto r = run_command(cook_cmd() + " " + q(dir / "a" / "model.glb") + " " + q(dir / "b" / "model.glb") +
                             " -o " + q(dir / "out"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("would both write"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out" / "model.ossa"));

  // With --root the tree is mirrored and both cook.
  const auto m = run_command(cook_cmd() + " " + q(dir / "a") + " " + q(dir / "b") + " --root " + q(dir) + " -o " +
                             q(dir / "out"));
  ASSERT_EQ(m.exit_code, 0) << m.err;
  EXPECT_TRUE(ossa::Asset::open((dir / "out" / "a" / "model.ossa").string()).ok());
  EXPECT_TRUE(ossa::Asset::open((dir / "out" / "b" / "model.ossa").string()).ok());
}

/// A BVH of a two-joint chain with `frames` frames, each a little different.
std::string generated_bvh(int frames) {
  std::string s =
      "HIERARCHY\nROOT hips\n{\n OFFSET 0 0 0\n CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation "
      "Yrotation\n JOINT spine\n {\n  OFFSET 0 1 0\n  CHANNELS 3 Zrotation Xrotation Yrotation\n"
      "  End Site\n  {\n   OFFSET 0 1 0\n  }\n }\n}\nMOTION\nFrames: " + std::to_string(frames) +
      "\nFrame Time: 0.033333\n";
  for (int f = 0; f < frames; ++f) s += "0 1 0 0 0 " + std::to_string(f * 3) + " " + std::to_string(f * 2) + " 0 0\n";
  return s;
}

/// A one-triangle OBJ (a static mesh).
std::string generated_obj(float size) {
  const std::string v = std::to_string(size);
  return "v 0 0 0\nv " + v + " 0 0\nv 0 " + v + " 0\nvn 0 0 1\nf 1//1 2//1 3//1\n";
}

// Sources of one folder that share a stem (a studio tree has skeleton.dae beside skeleton.fbx) each
// get an output of their own, named by the input's file name; a source alone with its stem keeps
// <stem>.ossa; everything loads and a second run finds every output up to date.
TEST(CookerCli, SameStemSourcesOfOneFolderKeepTheirExtension) {
  const fs::path dir = ossa::test::make_temp_dir("cli-same-stem");
  const fs::path src = dir / "src";
  for (const char* sub : {"rig", "clips", "other"}) fs::create_directories(src / sub);
  ASSERT_TRUE(ossa::test::write_file(src / "rig" / "skel.bvh", generated_bvh(4)));
  ASSERT_TRUE(ossa::test::write_file(src / "rig" / "skel.obj", generated_obj(1.0f)));
  fs::copy_file(asset("RiggedSimple/RiggedSimple.glb"), src / "rig" / "skel.glb");
  ASSERT_TRUE(ossa::test::write_file(src / "clips" / "walk.bvh", generated_bvh(7)));
  fs::copy_file(asset("CesiumMan/CesiumMan.glb"), src / "clips" / "walk.glb");
  ASSERT_TRUE(ossa::test::write_file(src / "clips" / "walk.OBJ", generated_obj(2.0f)));
  ASSERT_TRUE(ossa::test::write_file(src / "other" / "skel.bvh", generated_bvh(5)));
  ASSERT_TRUE(ossa::test::write_file(src / "lone.bvh", generated_bvh(3)));

  const fs::path out = dir / "out";
  const std::string cmd = cook_cmd() + " " + q(src) + " --root " + q(src) + " -o " + q(out) + " --jobs 2";
  const auto r = run_command(cmd + " --report " + q(dir / "first.json"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const std::vector<std::string> expected = {"rig/skel.bvh.ossa",   "rig/skel.obj.ossa", "rig/skel.glb.ossa",
                                             "clips/walk.bvh.ossa", "clips/walk.glb.ossa", "clips/walk.OBJ.ossa",
                                             "other/skel.ossa",     "lone.ossa"};
  for (const std::string& name : expected) {
    auto a = ossa::Asset::open((out / name).string());
    EXPECT_TRUE(a.ok()) << name << ": " << (a.ok() ? "" : a.error().message);
  }
  EXPECT_EQ(count_files(out), expected.size()) << "one output per input, nothing else";
  // Distinct sources gave distinct outputs: the two BVH of one stem are not the same bytes as the GLB.
  EXPECT_NE(ossa::test::read_file(out / "rig" / "skel.bvh.ossa"), ossa::test::read_file(out / "rig" / "skel.glb.ossa"));

  const auto again = run_command(cmd + " --report " + q(dir / "second.json"));
  ASSERT_EQ(again.exit_code, 0) << again.err;
  const auto report = nlohmann::json::parse(ossa::test::read_text(dir / "second.json").value_or("{}"), nullptr, false);
  ASSERT_TRUE(report.contains("records")) << report.dump();
  ASSERT_EQ(report["records"].size(), expected.size());
  for (const auto& rec : report["records"]) EXPECT_TRUE(rec["up_to_date"].get<bool>()) << rec.dump();

  // One file of a pair cooked alone keeps the short name: the rule looks at the batch's inputs only.
  const auto alone = run_command(cook_cmd() + " " + q(src / "rig" / "skel.bvh") + " -o " + q(dir / "alone"));
  ASSERT_EQ(alone.exit_code, 0) << alone.err;
  EXPECT_TRUE(fs::exists(dir / "alone" / "skel.ossa"));
}

TEST(CookerCli, InputOutsideRootIsAnError) {
  const fs::path dir = ossa::test::make_temp_dir("cli-root");
  const auto r = run_command(cook_cmd() + " " + q(asset("Fox/Fox.glb")) + " --root " + q(dir) + " -o " +
                             q(dir / "out"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("not inside --root"), std::string::npos) << r.err;
}

TEST(CookerCli, ClipOnlyFileBindsToItsSkeleton) {
  const fs::path dir = ossa::test::make_temp_dir("cli-skel");
  auto r = run_command(cook_cmd() + " " + q(asset("Pab/skeleton.fbx")) + " -o " + q(dir));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = run_command(cook_cmd() + " " + q(asset("Pab/walk.fbx")) + " --skeleton " + q(dir / "skeleton.ossa") +
                  " -o " + q(dir / "clips"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto skel = ossa::Asset::open((dir / "skeleton.ossa").string());
  auto walk = ossa::Asset::open((dir / "clips" / "walk.ossa").string());
  ASSERT_TRUE(skel.ok() && walk.ok());
  EXPECT_TRUE(walk->skeleton().empty()) << "a clip-only file carries no skeleton of its own";
  ASSERT_GE(walk->clip_count(), 1u);
  EXPECT_EQ(walk->clip(0).skeleton_hash(), skel->skeleton().hash());
  EXPECT_TRUE(ossa::check_clip_binding(walk->clip(0), skel->skeleton(), "walk.ossa").ok());
  EXPECT_GT(walk->clip(0).constants().size() + walk->clip(0).animated().size(), 10u);
}

TEST(CookerCli, ClipAgainstTheWrongRigNamesMissingJoints) {
  const fs::path dir = ossa::test::make_temp_dir("cli-wrong");
  auto r = run_command(cook_cmd() + " " + q(asset("Fox/Fox.glb")) + " -o " + q(dir));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = run_command(cook_cmd() + " " + q(asset("Pab/walk.fbx")) + " --skeleton " + q(dir / "Fox.ossa") + " -o " +
                  q(dir / "clips"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("walk.fbx"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("Hips"), std::string::npos) << "names a Pab joint missing from the Fox rig: " << r.err;
  EXPECT_FALSE(fs::exists(dir / "clips" / "walk.ossa"));
}

TEST(CookerCli, BadSkeletonReferenceIsAUsageError) {
  const fs::path dir = ossa::test::make_temp_dir("cli-badref");
  ASSERT_TRUE(ossa::test::write_file(dir / "ref.ossa", std::string_view("nope")));
  const auto r = run_command(cook_cmd() + " " + q(asset("Pab/walk.fbx")) + " --skeleton " + q(dir / "ref.ossa") +
                             " -o " + q(dir / "out"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("ref.ossa"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out"));
}

TEST(CookerCli, FloatVerticesOption) {
  const fs::path dir = ossa::test::make_temp_dir("cli-float");
  auto r = run_command(cook_cmd() + " " + q(asset("CesiumMan/CesiumMan.glb")) + " --float-vertices -o " + q(dir));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto a = ossa::Asset::open((dir / "CesiumMan.ossa").string());
  ASSERT_TRUE(a.ok());
  ASSERT_GT(a->mesh_count(), 0u);
  const auto* pos = a->mesh(0).attribute(ossa::fb::VertexSemantic::Position);
  ASSERT_NE(pos, nullptr);
  EXPECT_EQ(pos->format(), ossa::fb::VertexFormat::Float32x3);
  EXPECT_NE(std::string(a->file().provenance()->options()->c_str()).find("float32"), std::string::npos);
}

}  // namespace

namespace {

TEST(CookerCli, ProgressLinesCountFailuresAndEstimateTheRest) {
  const fs::path dir = ossa::test::make_temp_dir("cli-progress");
  const auto r = run_command(cook_cmd() + " " + q(dir / "missing.fbx") + " " + q(asset("RiggedSimple/RiggedSimple.glb")) +
                             " " + q(asset("Fox/Fox.glb")) + " -o " + q(dir / "out") + " --jobs 1");
  EXPECT_EQ(r.exit_code, 1);
  // Not a terminal: one line per input, done/total, failures so far, and an ETA until the last.
  EXPECT_NE(r.err.find("[1/3, 1 failed, ETA 0:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("] FAILED " + (dir / "missing.fbx").string()), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("[2/3, 1 failed, ETA 0:"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("[3/3, 1 failed] "), std::string::npos) << r.err;
}

}  // namespace

namespace {

TEST(CookerCli, Latin1AndControlCharactersInNamesNeitherAbortTheReportNorReachTheTerminal) {
  const fs::path dir = ossa::test::make_temp_dir("cli-names");
  // A Latin-1 file name (old tools) and one carrying a terminal escape sequence, both garbage.
  const fs::path latin1 = dir / "caf\xe9.fbx", escape = dir / "evil\x1b[2Jname.fbx";
  ASSERT_TRUE(ossa::test::write_file(latin1, std::string_view("not an fbx")));
  ASSERT_TRUE(ossa::test::write_file(escape, std::string_view("not an fbx")));
  const auto r = run_command(cook_cmd() + " " + q(latin1) + " " + q(escape) + " " +
                             q(asset("RiggedSimple/RiggedSimple.glb")) + " -o " + q(dir / "out") + " --report " +
                             q(dir / "report.json"));
  EXPECT_EQ(r.exit_code, 1) << r.err;  // not 134: the report is written
  const auto text = ossa::test::read_text(dir / "report.json");
  ASSERT_TRUE(text.has_value());
  const auto report = nlohmann::json::parse(*text);  // valid UTF-8 JSON
  EXPECT_EQ(report["records"][0]["input"].get<std::string>(), (dir / "caf\xc3\xa9.fbx").string()) << "Latin-1 transcoded";
  EXPECT_EQ(r.err.find('\x1b'), std::string::npos) << "no raw escape byte reaches stderr";
  EXPECT_NE(r.err.find("evil\\x1b[2Jname.fbx"), std::string::npos) << r.err;
}

}  // namespace

namespace {

TEST(CookerCli, AReadOnlyOutputIsRefusedNotReplaced) {
  const fs::path dir = ossa::test::make_temp_dir("cli-readonly");
  const std::string cmd = cook_cmd() + " " + q(asset("RiggedSimple/RiggedSimple.glb")) + " -o " + q(dir) + " -q";
  ASSERT_EQ(run_command(cmd).exit_code, 0);
  const fs::path out = dir / "RiggedSimple.ossa";
  ASSERT_TRUE(ossa::test::write_file(out, std::string_view("kept")));
  fs::permissions(out, fs::perms::owner_read | fs::perms::group_read | fs::perms::others_read);
  const auto r = run_command(cmd + " --force");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("RiggedSimple.ossa: is read-only, not replaced"), std::string::npos) << r.err;
  EXPECT_EQ(ossa::test::read_text(out).value_or(""), "kept");
  EXPECT_EQ(count_files(dir), 1u) << "no temporary left";
}

TEST(CookerCli, TemporariesOfDeadCooksAreCleanedUp) {
  const fs::path dir = ossa::test::make_temp_dir("cli-stale");
  // pid 2^22 + 1 is above Linux's pid_max limit, so no process has it: a cook killed long ago.
  const fs::path stale = dir / ".RiggedSimple.ossa.tmp-4194305-0";
  const fs::path other = dir / ".Other.ossa.tmp-4194305-0";
  ASSERT_TRUE(ossa::test::write_file(stale, std::string_view("half")));
  ASSERT_TRUE(ossa::test::write_file(other, std::string_view("half")));
  const auto r = run_command(cook_cmd() + " " + q(asset("RiggedSimple/RiggedSimple.glb")) + " -o " + q(dir) + " -q");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_FALSE(fs::exists(stale)) << "this output's stale temporary is removed";
  EXPECT_TRUE(fs::exists(other)) << "another output's is left to its own cook";
}

TEST(CookerCli, ANulByteInAGraphPathIsRefused) {
  const fs::path dir = ossa::test::make_temp_dir("cli-nul");
  fs::copy_file(asset("Pab/skeleton.fbx"), dir / "skeleton.fbx");
  fs::copy_file(asset("Pab/walk.fbx"), dir / "walk.fbx");
  // "skeleton.fbx\u0000.txt" names skeleton.fbx to any C API: it must not be read as that.
  ASSERT_TRUE(ossa::test::write_file(dir / "g.graph.json", std::string_view(
      R"({"ossa_graph": 1, "name": "g", "skeleton": "skeleton.fbx\u0000.txt", "clips": {"walk": "walk.fbx"},)"
      R"( "parameters": {}, "root": {"clip": "walk"}})")));
  const auto r = run_command(cook_cmd() + " " + q(dir / "g.graph.json") + " -o " + q(dir / "out"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("refused: contains a NUL byte"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out" / "g.ossa"));
}

}  // namespace
