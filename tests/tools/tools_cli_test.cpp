// tools_cli_test.cpp — the command-line conventions every tool shares (tools/cli/cli.h),
// checked on the real binaries: --version's line, --help, exit status 2 with a "did you mean" for
// a mistyped option and for a missing argument, -q and -v. Nothing here needs a display: ossa-view
// answers these before it opens a window (its -q / -v on a rendered scene are in viewer_test).
// The helper's pure functions (edit distance, closest name) are tested directly.
#include <gtest/gtest.h>

#include <algorithm>
#include <cstring>
#include <filesystem>
#include <regex>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <ossa/loader/asset.h>
#include <ossa/version.h>

#include "tools/cli/cli.h"
#include "test_files.h"

namespace fs = std::filesystem;
using ossa::test::CommandResult;
using ossa::test::run_command;

namespace {

const char* const kTools[] = {"ossa-cook", "ossa-inspect", "ossa-view", "ossa-diff"};

std::string q(const fs::path& p) { return "'" + p.string() + "'"; }
CommandResult run_tool(const std::string& tool, const std::string& args) {
  return run_command(q(ossa::test::bin_dir() / tool) + " " + args);
}
fs::path asset(const char* rel) { return ossa::test::source_dir() / "assets" / rel; }

TEST(ToolsCli, VersionLineAndStatus) {
  const std::regex line(R"(^(ossa-[a-z]+) ([0-9]+\.[0-9]+\.[0-9]+) \(format ([0-9]+)\)\n$)");
  for (const char* tool : kTools) {
    const CommandResult r = run_tool(tool, "--version");
    EXPECT_EQ(r.exit_code, 0) << tool << ": " << r.err;
    std::smatch m;
    ASSERT_TRUE(std::regex_match(r.out, m, line)) << tool << " printed '" << r.out << "'";
    EXPECT_EQ(m[1].str(), tool);
    EXPECT_EQ(m[2].str(), ossa::kVersionString);
    EXPECT_EQ(m[3].str(), std::to_string(ossa::kFormatVersion));
    EXPECT_TRUE(r.err.empty()) << tool << ": " << r.err;
  }
}

TEST(ToolsCli, HelpListsTheSharedOptionsAndExitStatuses) {
  for (const char* tool : kTools) {
    const CommandResult r = run_tool(tool, "--help");
    EXPECT_EQ(r.exit_code, 0) << tool << ": " << r.err;
    for (const char* expected : {"Usage:", "--version", "-q,--quiet", "-v,--verbose", "Exit status: 0 success; 1 ",
                                 "; 2 usage error or cannot run."})
      EXPECT_NE(r.out.find(expected), std::string::npos) << tool << " --help lacks '" << expected << "':\n" << r.out;
  }
}

TEST(ToolsCli, UnknownOptionIsAUsageErrorWithTheClosestMatch) {
  struct Case {
    const char* tool;
    std::string args;
    const char* typo;
    const char* guess;
  };
  const std::string fox = q(asset("Fox/Fox.glb"));
  const std::vector<Case> cases = {
      {"ossa-cook", fox + " -o /nonexistent --skeletn ref.ossa", "--skeletn", "--skeleton"},
      {"ossa-cook", fox + " -o /nonexistent --clip-tolerence=0.2", "--clip-tolerence", "--clip-tolerance"},
      {"ossa-inspect", "x.ossa --jsn", "--jsn", "--json"},
      {"ossa-view", "x.ossa --crwod 3", "--crwod", "--crowd"},
      {"ossa-view", "x.ossa --screnshot a.png", "--screnshot", "--screenshot"},
      {"ossa-diff", "a.ossa b.ossa --tolerance-m 1", "--tolerance-m", "--tolerance-mm"},
  };
  for (const Case& c : cases) {
    const CommandResult r = run_tool(c.tool, c.args);
    EXPECT_EQ(r.exit_code, 2) << c.tool << " " << c.args << "\n" << r.err;
    EXPECT_NE(r.err.find(std::string("unknown option ") + c.typo + ": did you mean " + c.guess + "?"),
              std::string::npos)
        << c.tool << " " << c.args << "\n"
        << r.err;
    EXPECT_NE(r.err.find(std::string("run '") + c.tool + " --help'"), std::string::npos) << r.err;
    EXPECT_TRUE(r.out.empty()) << r.out;
  }
  // Nothing close: still status 2, and no guess.
  const CommandResult far = run_tool("ossa-inspect", "x.ossa --frobnicate-everything");
  EXPECT_EQ(far.exit_code, 2) << far.err;
  EXPECT_NE(far.err.find("--frobnicate-everything"), std::string::npos) << far.err;
  EXPECT_EQ(far.err.find("did you mean"), std::string::npos) << far.err;
}

TEST(ToolsCli, MissingRequiredArgumentIsAUsageError) {
  const std::vector<std::pair<const char*, std::string>> cases = {
      {"ossa-cook", q(asset("Fox/Fox.glb"))},  // no -o
      {"ossa-cook", "-o /tmp"},                // no input
      {"ossa-inspect", ""},
      {"ossa-view", "--frames 1"},
      {"ossa-diff", "a.ossa"},
  };
  for (const auto& [tool, args] : cases) {
    const CommandResult r = run_tool(tool, args);
    EXPECT_EQ(r.exit_code, 2) << tool << " " << args << "\n" << r.err;
    EXPECT_NE(r.err.find("is required"), std::string::npos) << tool << " " << args << "\n" << r.err;
    EXPECT_NE(r.err.find(std::string("run '") + tool + " --help'"), std::string::npos) << r.err;
  }
}

TEST(ToolsCli, BadValuesAndConflictingFlagsAreUsageErrors) {
  const std::string fox = q(asset("Fox/Fox.glb"));
  EXPECT_EQ(run_tool("ossa-cook", fox + " -o /tmp --jobs 0").exit_code, 2);
  EXPECT_EQ(run_tool("ossa-cook", fox + " -o /tmp --up-axis w").exit_code, 2);
  EXPECT_EQ(run_tool("ossa-view", "x.ossa --size 10by10").exit_code, 2);
  for (const char* tool : kTools) {
    const CommandResult r = run_tool(tool, std::string(tool) == "ossa-cook" ? fox + " -o /tmp -q -v" : "x.ossa -q -v");
    EXPECT_EQ(r.exit_code, 2) << tool << ": " << r.err;
    EXPECT_NE(r.err.find("excludes"), std::string::npos) << tool << ": " << r.err;
  }
}

TEST(ToolsCli, CookQuietPrintsNothingVerbosePrintsClipDetail) {
  const fs::path dir = ossa::test::make_temp_dir("tools-cook");
  const std::string fox = q(asset("Fox/Fox.glb"));
  const CommandResult normal = run_tool("ossa-cook", fox + " -o " + q(dir / "normal"));
  ASSERT_EQ(normal.exit_code, 0) << normal.err;
  EXPECT_NE(normal.out.find("Fox.ossa"), std::string::npos) << "the summary table: " << normal.out;
  EXPECT_NE(normal.err.find("[1/1]"), std::string::npos) << normal.err;

  const CommandResult quiet = run_tool("ossa-cook", fox + " -o " + q(dir / "quiet") + " -q");
  ASSERT_EQ(quiet.exit_code, 0) << quiet.err;
  EXPECT_TRUE(quiet.out.empty()) << quiet.out;
  EXPECT_TRUE(quiet.err.empty()) << quiet.err;
  EXPECT_TRUE(fs::exists(dir / "quiet" / "Fox.ossa"));

  const CommandResult verbose = run_tool("ossa-cook", fox + " -o " + q(dir / "verbose") + " --verbose");
  ASSERT_EQ(verbose.exit_code, 0) << verbose.err;
  EXPECT_NE(verbose.err.find("clip 'Walk'"), std::string::npos) << verbose.err;
  EXPECT_NE(verbose.err.find("options vertices=quantized"), std::string::npos) << verbose.err;
  EXPECT_NE(verbose.err.find("warning: "), std::string::npos) << "Fox has no normals: " << verbose.err;
  EXPECT_EQ(normal.err.find("warning: "), std::string::npos) << "warnings one by one only with -v: " << normal.err;

  // Quiet still names failures.
  ASSERT_TRUE(ossa::test::write_file(dir / "bad.fbx", std::string_view("not an FBX")));
  const CommandResult failed = run_tool("ossa-cook", q(dir / "bad.fbx") + " -o " + q(dir / "failed") + " -q");
  EXPECT_EQ(failed.exit_code, 1);
  EXPECT_TRUE(failed.out.empty()) << failed.out;
  EXPECT_NE(failed.err.find("bad.fbx"), std::string::npos) << failed.err;
}

TEST(ToolsCli, InspectQuietOnlyAnswersByStatusVerboseListsChannels) {
  const fs::path dir = ossa::test::make_temp_dir("tools-inspect");
  ASSERT_EQ(run_tool("ossa-cook", q(asset("Fox/Fox.glb")) + " -q -o " + q(dir)).exit_code, 0);
  const std::string fox = q(dir / "Fox.ossa");

  const CommandResult normal = run_tool("ossa-inspect", fox);
  ASSERT_EQ(normal.exit_code, 0) << normal.err;
  EXPECT_NE(normal.out.find("clip 1 'Walk'"), std::string::npos) << normal.out;
  EXPECT_EQ(normal.out.find("channels"), std::string::npos) << normal.out;

  const CommandResult quiet = run_tool("ossa-inspect", fox + " -q");
  EXPECT_EQ(quiet.exit_code, 0) << quiet.err;
  EXPECT_TRUE(quiet.out.empty()) << quiet.out;
  EXPECT_TRUE(quiet.err.empty()) << quiet.err;

  const CommandResult verbose = run_tool("ossa-inspect", fox + " -v");
  ASSERT_EQ(verbose.exit_code, 0) << verbose.err;
  EXPECT_NE(verbose.out.find("'b_Hip_01' translation: "), std::string::npos) << verbose.out;

  // 1: not a valid .ossa (named); 2: nothing to read at all.
  ASSERT_TRUE(ossa::test::write_file(dir / "junk.ossa", std::string_view("junk junk junk junk")));
  const CommandResult junk = run_tool("ossa-inspect", q(dir / "junk.ossa") + " -q");
  EXPECT_EQ(junk.exit_code, 1);
  EXPECT_NE(junk.err.find("junk.ossa"), std::string::npos) << junk.err;
  const CommandResult missing = run_tool("ossa-inspect", q(dir / "missing.ossa"));
  EXPECT_EQ(missing.exit_code, 2);
  EXPECT_NE(missing.err.find("missing.ossa"), std::string::npos) << missing.err;
}

/// -v says how skin_cpu will walk each skinned mesh: its vertices per influence class and whether
/// they run in class order (the cooker's order). The same mesh with its vertex records reversed
/// has the same classes, out of order.
TEST(ToolsCli, InspectVerboseSaysWhetherVerticesRunByInfluenceClass) {
  const fs::path dir = ossa::test::make_temp_dir("tools-inspect-influences");
  ASSERT_EQ(run_tool("ossa-cook", q(asset("Fox/Fox.glb")) + " -q -o " + q(dir)).exit_code, 0);
  const fs::path fox = dir / "Fox.ossa";
  const auto influences = [](const fs::path& file, size_t* vertices) {
    const CommandResult r = run_tool("ossa-inspect", q(file) + " -v --json");
    EXPECT_EQ(r.exit_code, 0) << r.err;
    const nlohmann::json d = nlohmann::json::parse(r.out);
    *vertices = d["meshes"][0]["vertex_count"].get<size_t>();
    return d["meshes"][0].value("influences", nlohmann::json());
  };
  size_t n = 0;
  const nlohmann::json cooked = influences(fox, &n);
  ASSERT_TRUE(cooked.is_object()) << cooked;
  const auto by_class = cooked["vertices_by_class"].get<std::vector<size_t>>();
  ASSERT_EQ(by_class.size(), 5u);
  size_t sum = 0, classes = 0;
  for (const size_t c : by_class) {
    sum += c;
    classes += c > 0 ? 1 : 0;
  }
  EXPECT_EQ(sum, n);
  ASSERT_GE(classes, 2u) << "Fox should mix influence classes";
  EXPECT_TRUE(cooked["class_ordered"].get<bool>());
  EXPECT_EQ(cooked["class_runs"].get<size_t>(), classes);
  const CommandResult text = run_tool("ossa-inspect", q(fox) + " -v");
  EXPECT_NE(text.out.find("vertex order   by influence class (" + std::to_string(classes) + " ranges"),
            std::string::npos)
      << text.out;
  EXPECT_EQ(run_tool("ossa-inspect", q(fox) + " --json").out.find("influences"), std::string::npos);

  // The vertex records reversed (the index buffer is not read here).
  auto bytes = ossa::test::read_file(fox);
  ASSERT_TRUE(bytes);
  {
    auto a = ossa::Asset::from_bytes(*bytes, "Fox.ossa");
    ASSERT_TRUE(a) << a.error().message;
    const ossa::MeshView mesh = a->mesh(0);
    const size_t at = static_cast<size_t>(mesh.vertex_bytes().data() - a->bytes().data()),
                 stride = mesh.vertex_stride();
    std::vector<uint8_t> reversed(bytes->size());
    std::copy(bytes->begin(), bytes->end(), reversed.begin());
    for (size_t v = 0; v < n; ++v)
      std::memcpy(reversed.data() + at + v * stride, bytes->data() + at + (n - 1 - v) * stride, stride);
    *bytes = std::move(reversed);
  }
  ASSERT_TRUE(ossa::test::write_file(dir / "reversed.ossa", std::span<const uint8_t>(*bytes)));
  size_t m = 0;
  const nlohmann::json out_of_order = influences(dir / "reversed.ossa", &m);
  ASSERT_TRUE(out_of_order.is_object()) << out_of_order;
  EXPECT_EQ(out_of_order["vertices_by_class"], cooked["vertices_by_class"]);
  EXPECT_FALSE(out_of_order["class_ordered"].get<bool>());
  EXPECT_EQ(out_of_order["class_runs"].get<size_t>(), classes);
  EXPECT_NE(
      run_tool("ossa-inspect", q(dir / "reversed.ossa") + " -v").out.find("vertex order   not by influence class"),
      std::string::npos);
}

/// Several files in one call: each described in turn, a bad one named without stopping the
/// others, the status the worst of them; --json gives an array for several files and the object
/// alone for one.
TEST(ToolsCli, InspectTakesSeveralFiles) {
  const fs::path dir = ossa::test::make_temp_dir("tools-inspect-many");
  ASSERT_EQ(
      run_tool("ossa-cook", q(asset("Fox/Fox.glb")) + " " + q(asset("CesiumMan/CesiumMan.glb")) + " -q -o " + q(dir))
          .exit_code,
      0);
  ASSERT_TRUE(ossa::test::write_file(dir / "junk.ossa", std::string_view("junk junk junk junk")));
  const std::string fox = q(dir / "Fox.ossa"), cesium = q(dir / "CesiumMan.ossa");

  const CommandResult both = run_tool("ossa-inspect", fox + " " + cesium);
  ASSERT_EQ(both.exit_code, 0) << both.err;
  const size_t first = both.out.find("Fox.ossa"), second = both.out.find("CesiumMan.ossa");
  EXPECT_NE(first, std::string::npos) << both.out;
  EXPECT_NE(second, std::string::npos) << both.out;
  EXPECT_LT(first, second) << "in the order given";

  const CommandResult mixed =
      run_tool("ossa-inspect", fox + " " + q(dir / "junk.ossa") + " " + q(dir / "missing.ossa") + " " + cesium);
  EXPECT_EQ(mixed.exit_code, 2) << "the worst: a file that is not there";
  EXPECT_NE(mixed.err.find("junk.ossa"), std::string::npos) << mixed.err;
  EXPECT_NE(mixed.err.find("missing.ossa"), std::string::npos) << mixed.err;
  EXPECT_NE(mixed.out.find("CesiumMan.ossa"), std::string::npos) << "a bad file stopped the rest:\n" << mixed.out;
  EXPECT_EQ(run_tool("ossa-inspect", "-q " + fox + " " + q(dir / "junk.ossa")).exit_code, 1);

  const CommandResult array = run_tool("ossa-inspect", "--json " + fox + " " + cesium);
  ASSERT_EQ(array.exit_code, 0) << array.err;
  const auto many = nlohmann::json::parse(array.out, nullptr, false);
  ASSERT_TRUE(many.is_array()) << array.out.substr(0, 200);
  ASSERT_EQ(many.size(), 2u);
  EXPECT_EQ(many[0]["file"], "Fox.ossa");
  EXPECT_EQ(many[1]["file"], "CesiumMan.ossa");
  const CommandResult single = run_tool("ossa-inspect", "--json " + fox);
  ASSERT_EQ(single.exit_code, 0) << single.err;
  const auto one = nlohmann::json::parse(single.out, nullptr, false);
  ASSERT_TRUE(one.is_object());
  EXPECT_EQ(one, many[0]);
}

TEST(CliHelper, EditDistance) {
  EXPECT_EQ(ossa::cli::edit_distance("", ""), 0u);
  EXPECT_EQ(ossa::cli::edit_distance("abc", ""), 3u);
  EXPECT_EQ(ossa::cli::edit_distance("kitten", "sitting"), 3u);
  EXPECT_EQ(ossa::cli::edit_distance("--skeletn", "--skeleton"), 1u);
  EXPECT_EQ(ossa::cli::edit_distance("--jobs", "--josb"), 2u);  // a transposition is two edits
}

TEST(CliHelper, ClosestName) {
  const std::vector<std::string> known = {"--skeleton", "--root", "--root-motion", "--report", "-o", "--output"};
  EXPECT_EQ(ossa::cli::closest_name("--skeletn", known), "--skeleton");
  EXPECT_EQ(ossa::cli::closest_name("--skeletn=ref.ossa", known), "--skeleton");
  EXPECT_EQ(ossa::cli::closest_name("--rot", known), "--root");
  EXPECT_EQ(ossa::cli::closest_name("--reprot", known), "--report");
  EXPECT_EQ(ossa::cli::closest_name("--frobnicate", known), "");
  EXPECT_EQ(ossa::cli::closest_name("--x", {}), "");
}

TEST(CliHelper, VersionLineNamesTheTool) {
  EXPECT_EQ(ossa::cli::version_line("ossa-diff"), std::string("ossa-diff ") + ossa::kVersionString + " (format " +
                                                      std::to_string(ossa::kFormatVersion) + ")");
}

// A 30,000-joint chain is within the format's joint limit: ossa-inspect prints it in bounded
// lines (indentation stops at 32 levels and the depth is written instead), iteratively.
TEST(ToolsCli, InspectPrintsADeepChainInBoundedLines) {
  constexpr int kJoints = 30000;
  ossa::test::SyntheticSpec spec;
  ossa::test::SyntheticSkeleton& sk = *spec.skeleton;
  sk.names.clear();
  sk.parents.clear();
  sk.translations.clear();
  sk.rotations.clear();
  sk.scales.clear();
  for (int j = 0; j < kJoints; ++j) {
    sk.names.push_back("j" + std::to_string(j));
    sk.parents.push_back(static_cast<int16_t>(j - 1));
    sk.translations.push_back({0, 0.001f, 0});
    sk.rotations.push_back({0, 0, 0, 1});
    sk.scales.push_back({1, 1, 1});
  }
  spec.meshes.clear();
  spec.clips.clear();
  spec.materials.clear();
  const fs::path file = ossa::test::make_temp_dir("deep-chain") / "chain.ossa";
  ASSERT_TRUE(ossa::test::write_file(file, ossa::test::make_valid_file(spec)));
  const CommandResult r = run_tool("ossa-inspect", "'" + file.string() + "'");
  ASSERT_EQ(r.exit_code, 0) << r.err.substr(0, 500);
  EXPECT_NE(r.out.find("(depth 29999) [29999] j29999"), std::string::npos);
  EXPECT_LT(r.out.size(), size_t{4} << 20) << "bounded output";
}

// The exit statuses docs/CLI.md states per tool, case by case: 0 success, 1 the tool's job
// failed, 2 a usage error or the tool cannot run. Real files: the committed fixtures (cooked Pab)
// and a file of garbage; ossa-view's "no display" is run with DISPLAY unset.
TEST(ToolsCli, ExitStatusesAreTheDocumentedOnes) {
  const fs::path dir = ossa::test::make_temp_dir("exit-status");
  const fs::path fixtures = ossa::test::fixtures_dir() / "Pab";
  const fs::path garbage = dir / "garbage.ossa";
  ASSERT_TRUE(ossa::test::write_file(garbage, std::vector<uint8_t>(1000, 0x5a)));
  fs::create_directories(dir / "empty");
  const std::string skeleton = q(fixtures / "skeleton.ossa"), walk = q(fixtures / "walk.ossa");
  const std::string walk_rm = q(ossa::test::fixtures_dir() / "root-motion" / "Pab" / "walk.ossa");
  const std::string out = " -o " + q(dir / "out") + " -q";
  struct Case {
    const char* tool;
    std::string args;
    int status;
  };
  const Case cases[] = {
      {"ossa-cook", q(asset("RiggedSimple/RiggedSimple.glb")) + out, 0},
      {"ossa-cook", q(dir / "no-such-source.fbx") + out, 1},                              // a failed input, named
      {"ossa-cook", q(dir / "empty") + out, 2},                                           // no source found
      {"ossa-cook", q(asset("Pab/walk.fbx")) + " " + q(asset("Pab/walk.fbx")) + out, 2},  // outputs collide
      {"ossa-cook", q(asset("Pab/walk.fbx")) + " --skeleton " + q(dir / "no-rig.ossa") + out, 2},
      {"ossa-inspect", "-q " + skeleton, 0},
      {"ossa-inspect", "-q " + q(garbage), 1},
      {"ossa-inspect", "-q " + q(dir / "no-such.ossa"), 2},
      {"ossa-diff", "-q " + skeleton + " " + skeleton, 0},
      {"ossa-diff", "-q " + walk + " " + walk_rm + " --skeleton " + skeleton, 1},
      {"ossa-diff", "-q " + skeleton + " " + q(garbage), 2},
      {"ossa-diff", "-q " + skeleton + " " + q(dir / "no-such.ossa"), 2},
  };
  for (const Case& c : cases) {
    const CommandResult r = run_tool(c.tool, c.args);
    EXPECT_EQ(r.exit_code, c.status) << c.tool << " " << c.args << "\n" << r.err;
  }
  // ossa-view: a file it cannot show is 1 (checked before any window), no display is 2.
  const std::string view = "env -u DISPLAY -u WAYLAND_DISPLAY " + q(ossa::test::bin_dir() / "ossa-view") + " ";
  EXPECT_EQ(run_command(view + q(dir / "no-such.ossa")).exit_code, 1);
  EXPECT_EQ(run_command(view + q(garbage)).exit_code, 1);
  EXPECT_EQ(run_command(view + skeleton).exit_code, 2);
}

}  // namespace
