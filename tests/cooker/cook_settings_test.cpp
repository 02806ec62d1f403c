// cook_settings_test.cpp — per-asset cook settings (ossa.cook.json, <stem>.cook.json) as a user
// writes them: layering over the command line, clip renaming, a per-asset reference rig, clear
// errors at file:line:col, and settings files as inputs of the cook key (editing, adding or
// removing one re-cooks exactly the outputs it applies to).
#include <gtest/gtest.h>

#include <filesystem>
#include <map>
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

class CookSettings : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = ossa::test::make_temp_dir("settings");
    src = dir / "src";
    out = dir / "out";
    fs::create_directories(src);
    fs::copy_file(asset("Pab/walk.fbx"), src / "walk.fbx");
    fs::copy_file(asset("Pab/run.fbx"), src / "run.fbx");
    fs::copy_file(asset("RiggedSimple/RiggedSimple.glb"), src / "RiggedSimple.glb");
  }
  void write(const char* name, std::string_view text) { ASSERT_TRUE(ossa::test::write_file(src / name, text)); }

  /// Cooks src/ into out/ (extra options appended); returns exit code, fills report/err.
  int cook(const std::string& extra = "") {
    const auto r = run_command(cook_cmd() + " " + q(src) + " -o " + q(out) + " -q --report " + q(dir / "report.json") +
                               " " + extra);
    err = r.err;
    auto text = ossa::test::read_text(dir / "report.json");
    report = text ? nlohmann::json::parse(*text) : nlohmann::json();
    return r.exit_code;
  }
  /// The provenance options string of out/<name>.
  std::string options_of(const char* name) {
    auto a = ossa::Asset::open((out / name).string());
    EXPECT_TRUE(a.ok()) << name;
    return a.ok() ? a->file().provenance()->options()->str() : "";
  }
  std::vector<std::string> clip_names(const char* name) {
    std::vector<std::string> names;
    auto a = ossa::Asset::open((out / name).string());
    EXPECT_TRUE(a.ok());
    if (a.ok())
      for (size_t i = 0; i < a->clip_count(); ++i) names.emplace_back(a->clip(i).name());
    return names;
  }
  /// input file name -> up_to_date, for the ok records of the last report.
  std::map<std::string, bool> fresh() {
    std::map<std::string, bool> m;
    for (const auto& r : report["records"])
      if (r["status"] == "ok") m[fs::path(r["input"].get<std::string>()).filename().string()] = r["up_to_date"];
    return m;
  }

  fs::path dir, src, out;
  std::string err;
  nlohmann::json report;
};

TEST_F(CookSettings, LayersOverTheCommandLineInOrder) {
  write("ossa.cook.json", R"({"ossa_cook": 1,
    "defaults": {"clip_tolerance_mm": 0.5},
    "files": [{"match": "*.glb", "float_vertices": true},
              {"match": "r*.fbx", "clip_tolerance_mm": 2},
              {"match": "run.fbx", "clip_compression": true}]})");
  write("walk.cook.json", R"({"ossa_cook": 1, "clip_tolerance_mm": 0.25})");
  ASSERT_EQ(cook("--clip-tolerance 1 --no-clip-compression"), 0) << err;
  // Command line: lossless; the folder's defaults do not turn compression back on for walk...
  EXPECT_EQ(options_of("walk.ossa"), "vertices=quantized;clips=lossless");
  // ...but run's entry does, with the tolerance of the later matching entry.
  EXPECT_EQ(options_of("run.ossa"), "vertices=quantized;clips=0.002m@0.1m");
  EXPECT_EQ(options_of("RiggedSimple.ossa"), "vertices=float32;clips=lossless");
  ASSERT_EQ(cook("--clip-tolerance 1"), 0) << err;
  EXPECT_EQ(options_of("walk.ossa"), "vertices=quantized;clips=0.00025m@0.1m");  // the stem file wins
  EXPECT_EQ(options_of("run.ossa"), "vertices=quantized;clips=0.002m@0.1m");
  EXPECT_EQ(options_of("RiggedSimple.ossa"), "vertices=float32;clips=0.0005m@0.1m");  // folder defaults
}

TEST_F(CookSettings, RenamesClipsAndSwapsNames) {
  write("walk.cook.json", R"({"ossa_cook": 1, "clip_names": {"walk": "stroll"}})");
  ASSERT_EQ(cook(), 0) << err;
  EXPECT_EQ(clip_names("walk.ossa"), std::vector<std::string>{"stroll"});
  EXPECT_EQ(clip_names("run.ossa"), std::vector<std::string>{"run"});
  write("walk.cook.json", R"({"ossa_cook": 1, "clip_names": {"nope": "x"}})");
  EXPECT_EQ(cook(), 1);
  EXPECT_NE(err.find("rename clip 'nope', which it does not have"), std::string::npos) << err;
  EXPECT_EQ(clip_names("walk.ossa"), std::vector<std::string>{"stroll"}) << "a failed cook keeps the old output";
}

TEST_F(CookSettings, ASkeletonSettingCooksAgainstThatRig) {
  ASSERT_EQ(run_command(cook_cmd() + " " + q(asset("Pab/skeleton.fbx")) + " -o " + q(dir / "rig") + " -q").exit_code,
            0);
  write("ossa.cook.json", R"({"ossa_cook": 1, "files": [{"match": "*.fbx", "skeleton": "../rig/skeleton.ossa"}]})");
  // The rig lies outside the source folder: the read sandbox refuses it until it is allowed.
  EXPECT_EQ(cook(), 1);
  EXPECT_NE(err.find("rig/skeleton.ossa: refused: outside the folders this cook may read"), std::string::npos) << err;
  ASSERT_EQ(cook("--allow-dir " + q(dir / "rig")), 0) << err;
  auto rig = ossa::Asset::open((dir / "rig" / "skeleton.ossa").string());
  auto walk = ossa::Asset::open((out / "walk.ossa").string());
  ASSERT_TRUE(rig.ok() && walk.ok());
  EXPECT_TRUE(walk->skeleton().empty()) << "a clip-only file against the rig";
  EXPECT_EQ(walk->clip(0).skeleton_hash(), rig->skeleton().hash());
  EXPECT_NE(options_of("walk.ossa").find(";skeleton=skeleton.ossa@"), std::string::npos);
  EXPECT_FALSE(ossa::Asset::open((out / "RiggedSimple.ossa").string())->skeleton().empty());
}

TEST_F(CookSettings, TextureFormatPerFileAndOnTheCommandLine) {
  fs::copy_file(asset("Fox/Fox.glb"), src / "Fox.glb");
  const auto encoding_of = [&](const char* name) {
    auto a = ossa::Asset::open((out / name).string());
    EXPECT_TRUE(a.ok()) << name;
    return a.ok() ? std::string(ossa::fb::EnumNameTextureEncoding(a->material(0).textures()->Get(0)->encoding())) : "";
  };
  ASSERT_EQ(cook(), 0) << err;
  EXPECT_EQ(encoding_of("Fox.ossa"), "Bc1");
  EXPECT_EQ(options_of("Fox.ossa"), "vertices=quantized;clips=0.0001m@0.1m");  // the default is not spelt out
  // The report states what the texture became.
  bool reported = false;
  for (const auto& r : report["records"])
    if (fs::path(r["input"].get<std::string>()).filename() == "Fox.glb") {
      ASSERT_EQ(r["textures_cooked"].size(), 1u) << r.dump();
      EXPECT_EQ(r["textures_cooked"][0]["encoding"], "BC1");
      EXPECT_EQ(r["textures_cooked"][0]["srgb"], true);
      EXPECT_GT(r["textures_cooked"][0]["psnr_db"].get<double>(), 35.0);
      reported = true;
    }
  EXPECT_TRUE(reported);
  write("Fox.cook.json", R"({"ossa_cook": 1, "texture_format": "source"})");
  ASSERT_EQ(cook(), 0) << err;
  EXPECT_EQ(encoding_of("Fox.ossa"), "Source");
  EXPECT_EQ(options_of("Fox.ossa"), "vertices=quantized;clips=0.0001m@0.1m;textures=source");
  fs::remove(src / "Fox.cook.json");
  ASSERT_EQ(cook("--texture-format rgba8"), 0) << err;
  EXPECT_EQ(encoding_of("Fox.ossa"), "Rgba8");
  write("Fox.cook.json", R"({"ossa_cook": 1, "texture_format": "dxt"})");
  EXPECT_EQ(cook(), 1);
  EXPECT_NE(err.find("\"texture_format\" must be \"bc\", \"rgba8\" or \"source\""), std::string::npos) << err;
  EXPECT_EQ(run_command(cook_cmd() + " " + q(src) + " -o " + q(out) + " --texture-format dxt").exit_code, 2);
}

TEST_F(CookSettings, MistakesNameTheSettingsFileLineAndColumnAndFailOnlyTheirInputs) {
  write("walk.cook.json", "{\"ossa_cook\": 1,\n  \"clip_tolerence_mm\": 1, \"up_axis\": \"w\"}");
  EXPECT_EQ(cook(), 1);
  EXPECT_NE(err.find("walk.cook.json:2:3: unknown key \"clip_tolerence_mm\""), std::string::npos) << err;
  EXPECT_NE(err.find("did you mean \"clip_tolerance_mm\""), std::string::npos) << err;
  EXPECT_NE(err.find("walk.cook.json:2:38: \"up_axis\" must be \"x\", \"y\" or \"z\""), std::string::npos) << err;
  EXPECT_EQ(fresh().count("walk.fbx"), 0u);
  EXPECT_EQ(fresh().count("run.fbx"), 1u) << "the other inputs cook";
  EXPECT_FALSE(fs::exists(out / "walk.ossa"));

  fs::remove(src / "walk.cook.json");
  write("ossa.cook.json", R"({"ossa_cook": 2, "files": [{"float_vertices": true}], "default": {}})");
  EXPECT_EQ(cook(), 1);
  EXPECT_NE(err.find("\"ossa_cook\" must be 1"), std::string::npos) << err;
  EXPECT_NE(err.find("needs \"match\""), std::string::npos) << err;
  EXPECT_NE(err.find("unknown key \"default\""), std::string::npos) << err;
  EXPECT_TRUE(fresh().empty()) << "a folder's settings apply to every input in it";
}

TEST_F(CookSettings, SettingsFilesAreInputsOfTheCookKey) {
  ASSERT_EQ(cook(), 0) << err;
  ASSERT_EQ(cook(), 0) << err;
  EXPECT_EQ(fresh(), (std::map<std::string, bool>{{"RiggedSimple.glb", true}, {"run.fbx", true}, {"walk.fbx", true}}));
  // Adding a stem file: only its input. Editing it: only its input. Removing it: only its input.
  write("run.cook.json", R"({"ossa_cook": 1, "clip_tolerance_mm": 0.3})");
  ASSERT_EQ(cook(), 0) << err;
  EXPECT_EQ(fresh(), (std::map<std::string, bool>{{"RiggedSimple.glb", true}, {"run.fbx", false}, {"walk.fbx", true}}));
  write("run.cook.json", R"({"ossa_cook": 1, "clip_tolerance_mm": 0.3} )");
  ASSERT_EQ(cook(), 0) << err;
  EXPECT_EQ(fresh().at("run.fbx"), false);
  EXPECT_EQ(fresh().at("walk.fbx"), true);
  fs::remove(src / "run.cook.json");
  ASSERT_EQ(cook(), 0) << err;
  EXPECT_EQ(fresh().at("run.fbx"), false);
  // A folder file applies to every input of the folder.
  write("ossa.cook.json", R"({"ossa_cook": 1, "files": [{"match": "*.glb", "float_vertices": false}]})");
  ASSERT_EQ(cook(), 0) << err;
  EXPECT_EQ(fresh(),
            (std::map<std::string, bool>{{"RiggedSimple.glb", false}, {"run.fbx", false}, {"walk.fbx", false}}));
  // Its records list it among the inputs read.
  bool listed = false;
  for (const auto& f : report["records"][0]["inputs_read"]) listed = listed || f["path"] == "ossa.cook.json";
  EXPECT_TRUE(listed) << report["records"][0].dump();
}

}  // namespace
