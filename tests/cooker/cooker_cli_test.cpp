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
  const auto r =
      run_command(cook_cmd() + " " + q(src / "garbage.fbx") + " " + q(src / "missing.gltf") + " " +
                  q(asset("RiggedSimple/RiggedSimple.glb")) + " " + q(src / "empty.glb") + " " +
                  q(asset("Fox/Fox.glb")) + " -o " + q(out) + " --jobs 2 --report " + q(dir / "report.json"));
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
  const auto r = run_command(cook_cmd() + " " + q(dir / "a" / "model.glb") + " " + q(dir / "b" / "model.glb") + " -o " +
                             q(dir / "out"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("would both write"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out" / "model.ossa"));

  // With --root the tree is mirrored and both cook.
  const auto m =
      run_command(cook_cmd() + " " + q(dir / "a") + " " + q(dir / "b") + " --root " + q(dir) + " -o " + q(dir / "out"));
  ASSERT_EQ(m.exit_code, 0) << m.err;
  EXPECT_TRUE(ossa::Asset::open((dir / "out" / "a" / "model.ossa").string()).ok());
  EXPECT_TRUE(ossa::Asset::open((dir / "out" / "b" / "model.ossa").string()).ok());
}

/// A BVH of a two-joint chain with `frames` frames, each a little different.
std::string generated_bvh(int frames) {
  std::string s =
      "HIERARCHY\nROOT hips\n{\n OFFSET 0 0 0\n CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation "
      "Yrotation\n JOINT spine\n {\n  OFFSET 0 1 0\n  CHANNELS 3 Zrotation Xrotation Yrotation\n"
      "  End Site\n  {\n   OFFSET 0 1 0\n  }\n }\n}\nMOTION\nFrames: " +
      std::to_string(frames) + "\nFrame Time: 0.033333\n";
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
  const std::vector<std::string> expected = {
      "rig/skel.bvh.ossa",   "rig/skel.obj.ossa",   "rig/skel.glb.ossa", "clips/walk.bvh.ossa",
      "clips/walk.glb.ossa", "clips/walk.OBJ.ossa", "other/skel.ossa",   "lone.ossa"};
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

/// A skinned one-triangle glTF 1.0 document: every top-level collection an object keyed by id, the
/// skin naming its joints. `version` "" leaves the "asset" block out (Assimp then finds no reader).
nlohmann::json gltf1_document(const std::string& version, int extra_joints) {
  using J = nlohmann::json;
  const std::vector<double> identity = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  J doc;
  if (!version.empty()) doc["asset"] = {{"version", version}};
  doc["buffers"]["buf"] = {
      {"byteLength", 268},
      {"uri",
       "data:application/octet-stream;base64,AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAAAAAAAAAAAAAAAAAAA"
       "AAAAgD8AAAAAAAAAAAAAAAAAAIA/AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAAAAAAAAAAAAAAAIA/"
       "AAAAAAAAAAAAAAAAAAABAAIAAA"
       "AAAIA/AAAAAAAAAAAAAAAAAAAAAAAAgD8AAAAAAAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAAAAAAIA/AACAPwAAAAAAAAAAAAAAAA"
       "AAAAAAAIA/AAAAAAAAAAAAAAAAAAAAAAAAgD8AAAAAAAAAAAAAAL8AAAAAAACAPw=="}};
  doc["bufferViews"]["vattr"] = {{"buffer", "buf"}, {"byteOffset", 0}, {"byteLength", 132}, {"target", 34962}};
  doc["bufferViews"]["vidx"] = {{"buffer", "buf"}, {"byteOffset", 132}, {"byteLength", 6}, {"target", 34963}};
  doc["bufferViews"]["vibm"] = {{"buffer", "buf"}, {"byteOffset", 140}, {"byteLength", 128}};
  const auto accessor = [](const char* view, int offset, int type, int count, const char* shape) {
    return J{{"bufferView", view}, {"byteOffset", offset}, {"componentType", type}, {"count", count}, {"type", shape}};
  };
  doc["accessors"]["apos"] = accessor("vattr", 0, 5126, 3, "VEC3");
  doc["accessors"]["apos"]["min"] = {0, 0, 0};
  doc["accessors"]["apos"]["max"] = {1, 1, 0};
  doc["accessors"]["ajnt"] = accessor("vattr", 36, 5126, 3, "VEC4");
  doc["accessors"]["awgt"] = accessor("vattr", 84, 5126, 3, "VEC4");
  doc["accessors"]["aidx"] = accessor("vidx", 0, 5123, 3, "SCALAR");
  doc["accessors"]["aibm"] = accessor("vibm", 0, 5126, 2, "MAT4");
  doc["materials"]["mat"] = {{"values", {{"diffuse", {0.8, 0.8, 0.8, 1}}}}};
  doc["meshes"]["tri"]["primitives"] =
      J::array({{{"attributes", {{"POSITION", "apos"}, {"JOINT", "ajnt"}, {"WEIGHT", "awgt"}}},
                 {"indices", "aidx"},
                 {"material", "mat"},
                 {"mode", 4}}});
  doc["skins"]["skin"] = {
      {"bindShapeMatrix", identity}, {"inverseBindMatrices", "aibm"}, {"jointNames", {"j_root", "j_tip"}}};
  doc["nodes"]["root"] = {{"children", {"j_root", "body"}}};
  doc["nodes"]["j_root"] = {{"jointName", "j_root"}, {"children", {"j_tip"}}};
  doc["nodes"]["j_tip"] = {{"jointName", "j_tip"}, {"translation", {0, 0.5, 0}}, {"children", J::array()}};
  for (int i = 0; i < extra_joints; ++i) {
    const std::string name = "j_extra" + std::to_string(i);
    const std::string parent = i == 0 ? "j_tip" : "j_extra" + std::to_string(i - 1);
    doc["nodes"][name] = {{"jointName", name}, {"translation", {0, 0.25, 0}}};
    doc["nodes"][parent]["children"].push_back(name);
  }
  doc["nodes"]["body"] = {{"meshes", {"tri"}}, {"skin", "skin"}, {"skeletons", {"j_root"}}};
  doc["scenes"]["s"] = {{"nodes", {"root"}}};
  doc["scene"] = "s";
  return doc;
}

// glTF 1.0 keys "skins", "nodes" and the rest by id in objects; the checks written for 2.0's arrays
// must not refuse it ("its \"skins\" is not an array"): each variant cooks to a file that loads.
TEST(CookerCli, Gltf1DocumentsCook) {
  const fs::path dir = ossa::test::make_temp_dir("cli-gltf1");
  const std::vector<std::pair<std::string, std::pair<std::string, int>>> variants = {
      {"v10", {"1.0", 0}}, {"v101", {"1.0.1", 2}}, {"v10b", {"1.0", 1}}, {"v1", {"1", 3}}};
  for (const auto& [name, spec] : variants) {
    const fs::path file = dir / (name + ".gltf");
    ASSERT_TRUE(ossa::test::write_file(file, gltf1_document(spec.first, spec.second).dump(1)));
    const auto r = run_command(cook_cmd() + " " + q(file) + " -o " + q(dir / "out"));
    EXPECT_EQ(r.exit_code, 0) << name << ": " << r.err;
    EXPECT_EQ(r.err.find("is not an array"), std::string::npos) << r.err;
    auto a = ossa::Asset::open((dir / "out" / (name + ".ossa")).string());
    ASSERT_TRUE(a.ok()) << name << ": " << (a.ok() ? "" : a.error().message);
    EXPECT_EQ(a->mesh_count(), 1u) << name;
  }
  // A 2.0 document whose "skins" is an object is still refused by name, before Assimp reads it.
  auto bad = gltf1_document("2.0", 0);
  const fs::path file = dir / "v2.gltf";
  ASSERT_TRUE(ossa::test::write_file(file, bad.dump()));
  const auto r = run_command(cook_cmd() + " " + q(file) + " -o " + q(dir / "out"));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("\"skins\" is not an array"), std::string::npos) << r.err;
}

// A file that is not a model (a README, notes, an image, a file with no extension) is named as such,
// not answered with Assimp's guess at a format it never was ("FBX-Tokenize ... unexpected
// double-quote"); a model extension with broken content keeps Assimp's own message.
TEST(CookerCli, NonModelFilesAreNamedAsSuch) {
  const fs::path dir = ossa::test::make_temp_dir("cli-not-model");
  const std::string prose = "# Notes\n\nThe \"walk\" clip loops; see {this} and [that].\n";
  const std::vector<std::pair<std::string, std::string>> files = {
      {"README.md", prose + ossa::test::read_text(ossa::test::source_dir() / "README.md").value_or("")},
      {"notes.txt", prose},
      {"picture.png",
       std::string(reinterpret_cast<const char*>(ossa::test::tiny_png().data()), ossa::test::tiny_png().size())},
      {"LICENSE", "Permission is hereby granted, \"free of charge\", to any person\n"},
      {"data.csv", "time,x,y\n0,1,2\n"}};
  for (const auto& [name, text] : files) {
    ASSERT_TRUE(ossa::test::write_file(dir / name, text));
    const auto r = run_command(cook_cmd() + " " + q(dir / name) + " -o " + q(dir / "out"));
    EXPECT_EQ(r.exit_code, 1) << name << ": " << r.err;
    EXPECT_NE(r.err.find(name + ": not a model file ossa-cook can read (FBX, glTF, GLB, DAE, BVH, OBJ"),
              std::string::npos)
        << r.err;
    EXPECT_EQ(r.err.find("Tokenize"), std::string::npos) << r.err;
  }
  // Known model extensions with broken content: Assimp's reader says what is wrong.
  for (const char* name : {"broken.fbx", "broken.dae", "broken.obj"}) {
    ASSERT_TRUE(ossa::test::write_file(dir / name, prose));
    const auto r = run_command(cook_cmd() + " " + q(dir / name) + " -o " + q(dir / "out"));
    EXPECT_NE(r.exit_code, 0) << name;
    EXPECT_EQ(r.err.find("not a model file"), std::string::npos) << name << ": " << r.err;
  }
}

TEST(CookerCli, InputOutsideRootIsAnError) {
  const fs::path dir = ossa::test::make_temp_dir("cli-root");
  const auto r =
      run_command(cook_cmd() + " " + q(asset("Fox/Fox.glb")) + " --root " + q(dir) + " -o " + q(dir / "out"));
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("not inside --root"), std::string::npos) << r.err;
}

TEST(CookerCli, ClipOnlyFileBindsToItsSkeleton) {
  const fs::path dir = ossa::test::make_temp_dir("cli-skel");
  auto r = run_command(cook_cmd() + " " + q(asset("Pab/skeleton.fbx")) + " -o " + q(dir));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  r = run_command(cook_cmd() + " " + q(asset("Pab/walk.fbx")) + " --skeleton " + q(dir / "skeleton.ossa") + " -o " +
                  q(dir / "clips"));
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

// A studio tree cooked with one command and no --skeleton: a clip-only source binds to its
// folder's rig (a source named skeleton.* or after its folder, cooked first in the same batch; of
// the same format when there are several), and one with no rig beside it is said to have become a
// rig of its own, by name.
TEST(CookerCli, ClipOnlySourcesInATreeBindToTheirFolderRig) {
  const fs::path dir = ossa::test::make_temp_dir("cli-folder-rig");
  const fs::path tree = dir / "tree", out = dir / "out";
  for (const char* d : {"Pab", "Pabby", "Lone"}) fs::create_directories(tree / d);
  fs::copy_file(asset("Pab/skeleton.fbx"), tree / "Pab" / "skeleton.fbx");
  fs::copy_file(asset("Pab/walk.fbx"), tree / "Pab" / "walk.fbx");
  fs::copy_file(asset("Pab/skeleton.fbx"), tree / "Pabby" / "Pabby.fbx");
  fs::copy_file(asset("Pab/run.fbx"), tree / "Pabby" / "run.fbx");
  fs::copy_file(asset("Pab/run.fbx"), tree / "Lone" / "run.fbx");
  // The Collada pair from the shared assets, when present: walk.dae must take skeleton.dae.
  const fs::path shared = ossa::test::shared_assets() / "Pab";
  const bool collada = fs::exists(shared / "skeleton.dae") && fs::exists(shared / "walk.dae");
  if (collada) {
    fs::copy_file(shared / "skeleton.dae", tree / "Pab" / "skeleton.dae");
    fs::copy_file(shared / "walk.dae", tree / "Pab" / "walk.dae");
  }
  const std::string command = cook_cmd() + " " + q(tree) + " -o " + q(out) + " --root " + q(tree) +
                              " --jobs 2 -v --report " + q(dir / "r.json");
  const auto r = run_command(command);
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const auto bound = [&](const fs::path& clip_file, const fs::path& rig_file) {
    SCOPED_TRACE(clip_file.string());
    auto clip = ossa::Asset::open((out / clip_file).string());
    auto rig = ossa::Asset::open((out / rig_file).string());
    ASSERT_TRUE(clip.ok() && rig.ok());
    EXPECT_TRUE(clip->skeleton().empty()) << "bound to its folder's rig, it carries none of its own";
    ASSERT_GE(clip->clip_count(), 1u);
    EXPECT_EQ(clip->clip(0).skeleton_hash(), rig->skeleton().hash());
    EXPECT_TRUE(ossa::check_clip_binding(clip->clip(0), rig->skeleton(), clip_file.string()).ok());
  };
  const std::string fbx = collada ? ".fbx" : "";  // same-stem sources keep their extension
  bound(fs::path("Pab") / ("walk" + fbx + ".ossa"), fs::path("Pab") / ("skeleton" + fbx + ".ossa"));
  bound(fs::path("Pabby") / "run.ossa", fs::path("Pabby") / "Pabby.ossa");
  if (collada) bound(fs::path("Pab") / "walk.dae.ossa", fs::path("Pab") / "skeleton.dae.ossa");
  // Alone, the clip keeps a rig of its own, and the warning names it.
  auto lone = ossa::Asset::open((out / "Lone" / "run.ossa").string());
  ASSERT_TRUE(lone.ok());
  EXPECT_FALSE(lone->skeleton().empty());
  EXPECT_NE(r.err.find("warning: " + (tree / "Lone" / "run.fbx").string() +
                       ": holds clips and no mesh, so it is cooked with a rig of its own"),
            std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("Pab/walk.fbx: holds clips and no mesh"), std::string::npos) << r.err;
  EXPECT_EQ(r.err.find("skeleton.fbx: holds clips and no mesh"), std::string::npos) << r.err;
  // Again: everything up to date, the bound clips included.
  const auto again = run_command(command);
  ASSERT_EQ(again.exit_code, 0) << again.err;
  const auto report = nlohmann::json::parse(*ossa::test::read_text(dir / "r.json"));
  for (const auto& record : report["records"]) EXPECT_TRUE(record["up_to_date"].get<bool>()) << record["input"];
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
  const auto r =
      run_command(cook_cmd() + " " + q(dir / "missing.fbx") + " " + q(asset("RiggedSimple/RiggedSimple.glb")) + " " +
                  q(asset("Fox/Fox.glb")) + " -o " + q(dir / "out") + " --jobs 1");
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
  const auto r =
      run_command(cook_cmd() + " " + q(latin1) + " " + q(escape) + " " + q(asset("RiggedSimple/RiggedSimple.glb")) +
                  " -o " + q(dir / "out") + " --report " + q(dir / "report.json"));
  EXPECT_EQ(r.exit_code, 1) << r.err;  // not 134: the report is written
  const auto text = ossa::test::read_text(dir / "report.json");
  ASSERT_TRUE(text.has_value());
  const auto report = nlohmann::json::parse(*text);  // valid UTF-8 JSON
  EXPECT_EQ(report["records"][0]["input"].get<std::string>(), (dir / "caf\xc3\xa9.fbx").string())
      << "Latin-1 transcoded";
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
  ASSERT_TRUE(ossa::test::write_file(
      dir / "g.graph.json",
      std::string_view(
          R"({"ossa_graph": 1, "name": "g", "skeleton": "skeleton.fbx\u0000.txt", "clips": {"walk": "walk.fbx"},)"
          R"( "parameters": {}, "root": {"clip": "walk"}})")));
  const auto r = run_command(cook_cmd() + " " + q(dir / "g.graph.json") + " -o " + q(dir / "out"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("refused: contains a NUL byte"), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir / "out" / "g.ossa"));
}

}  // namespace
