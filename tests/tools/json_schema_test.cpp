// json_schema_test.cpp — the JSON the tools write matches its documentation (docs/JSON.md,
// docs/schemas/), checked on real output with tests/support/json_schema_check.py (Debian's
// python3-jsonschema):
//  - the --report of a batch with successes and failures of every stage (unreadable, unparsable,
//    failing after import), and that a failed record names no output and keeps what it counted;
//  - ossa-inspect --json (and -v --json) of every kind of cooked sample and of every synthetic
//    variant of tests/support/test_files.h;
//  - that the schemas constrain: mutated documents (an unknown field, a wrong type, a failed
//    record naming an output, ...) are rejected, so the checks above cannot pass vacuously;
//  - that every object in the schemas is closed and every property described (--lint).
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "test_files.h"

namespace fs = std::filesystem;
using nlohmann::json;
using ossa::test::CommandResult;
using ossa::test::run_command;

namespace {

std::string q(const fs::path& p) { return "'" + p.string() + "'"; }
fs::path asset(const char* rel) { return ossa::test::source_dir() / "assets" / rel; }
fs::path schema(const char* name) {
  return ossa::test::source_dir() / "docs" / "schemas" / (std::string(name) + ".schema.json");
}
CommandResult tool(const char* name, const std::string& args) {
  return run_command(q(ossa::test::bin_dir() / name) + " " + args);
}

/// json_schema_check.py SCHEMA DOCS...: 0 all valid, 1 some invalid, 2 unreadable.
CommandResult check(const fs::path& schema_file, const std::vector<fs::path>& docs) {
  std::string cmd =
      "/usr/bin/python3 " + q(ossa::test::source_dir() / "tests/support/json_schema_check.py") + " " + q(schema_file);
  for (const fs::path& d : docs) cmd += " " + q(d);
  return run_command(cmd);
}

json read_json(const fs::path& path) {
  const auto text = ossa::test::read_text(path);
  EXPECT_TRUE(text.has_value()) << path;
  return text ? json::parse(*text) : json();
}

bool write_json(const fs::path& path, const json& doc) { return ossa::test::write_file(path, doc.dump(2) + "\n"); }

const json* find_record(const json& report, const std::string& input_suffix) {
  for (const json& r : report["records"]) {
    const std::string in = r["input"].get<std::string>();
    if (in.size() >= input_suffix.size() &&
        in.compare(in.size() - input_suffix.size(), input_suffix.size(), input_suffix) == 0)
      return &r;
  }
  return nullptr;
}

/// A record's source_bytes counts every file the cook read: a source and its events sidecar; a
/// glTF with its buffer and every texture image (the shared AnimeBoy, when ../shared is there).
TEST(CookReportSchema, SourceBytesCountEveryFileRead) {
  const fs::path dir = ossa::test::make_temp_dir("schema-report-bytes");
  const CommandResult r =
      tool("ossa-cook", q(asset("Pab/walk.fbx")) + " -q -o " + q(dir / "out") + " --report " + q(dir / "report.json"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json report = read_json(dir / "report.json");
  ASSERT_EQ(report["records"].size(), 1u);
  EXPECT_EQ(report["records"][0]["source_bytes"].get<uint64_t>(),
            fs::file_size(asset("Pab/walk.fbx")) + fs::file_size(asset("Pab/walk.events.json")));
  // An up-to-date output's record counts the same files.
  const CommandResult again =
      tool("ossa-cook", q(asset("Pab/walk.fbx")) + " -q -o " + q(dir / "out") + " --report " + q(dir / "again.json"));
  ASSERT_EQ(again.exit_code, 0) << again.err;
  const json second = read_json(dir / "again.json");
  EXPECT_EQ(second["records"][0]["up_to_date"], true);
  EXPECT_EQ(second["records"][0]["source_bytes"], report["records"][0]["source_bytes"]);

  const fs::path boy = ossa::test::shared_assets() / "AnimeBoy";
  if (!fs::exists(boy / "scene.gltf")) GTEST_SKIP() << "no " << boy << ": the glTF half is not checked";
  uint64_t everything = 0;
  for (const auto& e : fs::recursive_directory_iterator(boy))
    if (e.is_regular_file() && (e.path().extension() == ".gltf" || e.path().extension() == ".bin" ||
                                e.path().extension() == ".png" || e.path().extension() == ".jpg"))
      everything += e.file_size();
  const CommandResult g =
      tool("ossa-cook", q(boy / "scene.gltf") + " -q -o " + q(dir / "boy") + " --report " + q(dir / "boy.json"));
  ASSERT_EQ(g.exit_code, 0) << g.err;
  const json boy_report = read_json(dir / "boy.json");
  const uint64_t counted = boy_report["records"][0]["source_bytes"].get<uint64_t>();
  EXPECT_GT(counted, fs::file_size(boy / "scene.gltf") + fs::file_size(boy / "scene.bin")) << "the images count";
  EXPECT_LE(counted, everything) << "only files that are there";
}

// ---------------------------------------------------------------------------------------------
// ossa-cook --report

TEST(CookReportSchema, BatchWithFailuresIsValidAndFailedRecordsNameNoOutput) {
  const fs::path dir = ossa::test::make_temp_dir("schema-report");
  const fs::path src = dir / "src", out = dir / "out", report_path = dir / "report.json";
  fs::create_directories(src);
  // Three ways to fail: not a model, not there, and failing after a successful import (its events
  // sidecar is broken), which must keep the counts read before the failure.
  ASSERT_TRUE(ossa::test::write_file(src / "bad.fbx", std::string_view("this is a text file, not an FBX\n")));
  fs::copy_file(asset("RiggedSimple/RiggedSimple.glb"), src / "rigged.glb");
  ASSERT_TRUE(ossa::test::write_file(src / "rigged.events.json", std::string_view("{ \"clips\": [ oops ] }\n")));
  const CommandResult r =
      tool("ossa-cook", q(src / "bad.fbx") + " " + q(src / "missing.gltf") + " " + q(src / "rigged.glb") + " " +
                            q(asset("Fox/Fox.glb")) + " -q -j 2 -o " + q(out) + " --report " + q(report_path));
  ASSERT_EQ(r.exit_code, 1) << r.err;

  const CommandResult v = check(schema("ossa-cook-report"), {report_path});
  EXPECT_EQ(v.exit_code, 0) << v.out << v.err;

  const json report = read_json(report_path);
  EXPECT_EQ(report["schema"], "ossa-cook-report");
  EXPECT_EQ(report["schema_version"], 1);
  EXPECT_EQ(report["inputs"], 4);
  EXPECT_EQ(report["failed"], 3);
  size_t failed = 0, ok = 0;
  for (const json& rec : report["records"]) {
    const fs::path input = rec["input"].get<std::string>();
    const fs::path would_be = out / (input.stem().string() + ".ossa");
    if (rec["status"] == "failed") {
      ++failed;
      EXPECT_FALSE(rec.contains("output")) << "a failed record names an output: " << rec.dump();
      EXPECT_FALSE(rec.contains("cooked_bytes")) << rec.dump();
      EXPECT_FALSE(fs::exists(would_be)) << would_be << " exists for a failed input";
      // The file at fault: the input, or for a broken sidecar the sidecar beside it.
      EXPECT_NE(rec["error"].get<std::string>().find(input.stem().string()), std::string::npos) << rec.dump();
      EXPECT_GE(rec["seconds"].get<double>(), 0.0);
    } else {
      ++ok;
      ASSERT_TRUE(rec.contains("output")) << rec.dump();
      const fs::path written = rec["output"].get<std::string>();
      ASSERT_TRUE(fs::exists(written)) << written;
      EXPECT_EQ(rec["cooked_bytes"].get<uint64_t>(), fs::file_size(written));
      EXPECT_EQ(rec["source_bytes"].get<uint64_t>(), fs::file_size(input));
    }
  }
  EXPECT_EQ(failed, 3u);
  EXPECT_EQ(ok, 1u);

  // What each failure knew.
  const json* bad = find_record(report, "bad.fbx");
  const json* missing = find_record(report, "missing.gltf");
  const json* rigged = find_record(report, "rigged.glb");
  ASSERT_TRUE(bad && missing && rigged);
  EXPECT_EQ((*bad)["source_bytes"].get<uint64_t>(), fs::file_size(src / "bad.fbx")) << "it was read, then refused";
  EXPECT_FALSE(bad->contains("joints")) << "nothing was imported: " << bad->dump();
  EXPECT_EQ((*missing)["source_bytes"], 0);
  EXPECT_FALSE(missing->contains("clips"));
  EXPECT_NE((*rigged)["error"].get<std::string>().find("rigged.events.json"), std::string::npos) << rigged->dump();
  EXPECT_EQ((*rigged)["source_bytes"].get<uint64_t>(), fs::file_size(src / "rigged.glb"));
  EXPECT_GT((*rigged)["joints"].get<int>(), 0) << "imported before the sidecar failed: " << rigged->dump();
  EXPECT_EQ((*rigged)["clips"], 1);
  EXPECT_EQ((*rigged)["materials"].get<int>(), 1);
  EXPECT_FALSE(rigged->contains("meshes")) << "meshes were never built: " << rigged->dump();
  EXPECT_EQ(ossa::test::count_files(out), 1u) << "only Fox.ossa was written";
}

TEST(CookReportSchema, GraphFileReportIsValid) {
  const fs::path dir = ossa::test::make_temp_dir("schema-report-graph");
  const CommandResult r = tool(
      "ossa-cook", q(asset("Pab/pab.graph.json")) + " -q -o " + q(dir / "out") + " --report " + q(dir / "report.json"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const CommandResult v = check(schema("ossa-cook-report"), {dir / "report.json"});
  EXPECT_EQ(v.exit_code, 0) << v.out << v.err;
  const json report = read_json(dir / "report.json");
  ASSERT_EQ(report["records"].size(), 1u);
  EXPECT_EQ(report["records"][0]["clip_compression"].size(), 4u);
  EXPECT_GT(report["records"][0]["source_bytes"].get<uint64_t>(), fs::file_size(asset("Pab/pab.graph.json")))
      << "a graph counts the sources it read";
}

// ---------------------------------------------------------------------------------------------
// ossa-inspect --json

/// Writes `ossa-inspect --json` and `ossa-inspect -v --json` of every .ossa below `dir` next to
/// it; returns the JSON files.
std::vector<fs::path> describe_all(const fs::path& dir) {
  std::vector<fs::path> cooked, docs;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file() && e.path().extension() == ".ossa") cooked.push_back(e.path());
  std::sort(cooked.begin(), cooked.end());
  for (const fs::path& f : cooked) {
    for (const char* flags : {"--json", "--json -v"}) {
      const fs::path doc = fs::path(f).replace_extension(std::string(flags).size() > 6 ? ".v.json" : ".json");
      const CommandResult r = tool("ossa-inspect", q(f) + " " + flags + " > " + q(doc));
      EXPECT_EQ(r.exit_code, 0) << f << ": " << r.err;
      docs.push_back(doc);
    }
  }
  return docs;
}

TEST(InspectSchema, EveryCookedSampleKindIsValid) {
  const fs::path dir = ossa::test::make_temp_dir("schema-inspect");
  const std::string a = q(ossa::test::source_dir() / "assets");
  const auto cook = [&](const std::string& args) {
    const CommandResult r = tool("ossa-cook", "-q " + args);
    EXPECT_EQ(r.exit_code, 0) << args << "\n" << r.err;
  };
  // Rig + mesh (FBX), meshes + clips (glTF, two of them), a graph character.
  cook(q(asset("Pab/skeleton.fbx")) + " " + q(asset("Fox/Fox.glb")) + " " + q(asset("CesiumMan/CesiumMan.glb")) + " " +
       q(asset("Pab/pab.graph.json")) + " --root " + a + " -o " + q(dir / "plain"));
  // Skeleton and clip without a mesh (a clip source on its own); root motion.
  cook(q(asset("Pab/walk.fbx")) + " --root-motion -o " + q(dir / "standalone"));
  // Clip-only and mesh-only files bound to a cooked rig.
  cook(q(asset("Pab/walk.fbx")) + " " + q(asset("Pab/arnaud.fbx")) + " --skeleton " +
       q(dir / "plain" / "Pab" / "skeleton.ossa") + " -o " + q(dir / "bound"));
  // Float32 vertices, lossless clips.
  cook(q(asset("RiggedSimple/RiggedSimple.glb")) + " --float-vertices --no-clip-compression -o " + q(dir / "float"));

  const std::vector<fs::path> docs = describe_all(dir);
  ASSERT_EQ(docs.size(), 2u * 8u) << "8 cooked files, each described plain and with -v";
  const CommandResult v = check(schema("ossa-inspect"), docs);
  EXPECT_EQ(v.exit_code, 0) << v.out << v.err;

  // The kinds above are what they claim to be, so the validation covered each shape.
  const json graph = read_json(dir / "plain" / "Pab" / "pab.json");
  EXPECT_EQ(graph["schema"], "ossa-inspect");
  EXPECT_EQ(graph["schema_version"], 1);
  EXPECT_EQ(graph["graphs"].size(), 1u);
  const json clip_only = read_json(dir / "bound" / "walk.v.json");
  EXPECT_TRUE(clip_only["skeleton"].is_null());
  EXPECT_TRUE(clip_only["meshes"].empty());
  EXPECT_FALSE(clip_only["clips"][0]["channels"].empty());
  EXPECT_TRUE(clip_only["clips"][0]["channels"][0]["joint_name"].is_null()) << "no rig in the file to name joints";
  const json standalone = read_json(dir / "standalone" / "walk.json");
  EXPECT_TRUE(standalone["skeleton"].is_object());
  EXPECT_TRUE(standalone["meshes"].empty());
  EXPECT_TRUE(standalone["clips"][0]["root_motion"].is_object());
  const json fox = read_json(dir / "plain" / "Fox" / "Fox.v.json");
  EXPECT_EQ(fox["clips"].size(), 3u);
  EXPECT_TRUE(fox["clips"][0]["channels"][0]["joint_name"].is_string());
  const json lossless = read_json(dir / "float" / "RiggedSimple.json");
  EXPECT_EQ(lossless["clips"][0]["compression"]["tolerance"], 0.0);
}

TEST(InspectSchema, EverySyntheticVariantIsValid) {
  const fs::path dir = ossa::test::make_temp_dir("schema-synthetic");
  auto variants = ossa::test::valid_variants();
  ossa::test::SyntheticSpec skeleton_only;  // a rig and nothing else
  skeleton_only.meshes.clear();
  skeleton_only.clips.clear();
  skeleton_only.materials.clear();
  skeleton_only.provenance = false;
  variants.emplace_back("skeleton-only", skeleton_only);
  for (const auto& [name, spec] : variants) {
    const std::vector<uint8_t> bytes = ossa::test::make_valid_file(spec);
    ASSERT_TRUE(ossa::test::write_file(dir / (name + ".ossa"), bytes)) << name;
  }
  const std::vector<fs::path> docs = describe_all(dir);
  ASSERT_EQ(docs.size(), 2 * variants.size());
  const CommandResult v = check(schema("ossa-inspect"), docs);
  EXPECT_EQ(v.exit_code, 0) << v.out << v.err;
  const json only = read_json(dir / "skeleton-only.json");
  EXPECT_TRUE(only["skeleton"].is_object());
  EXPECT_TRUE(only["provenance"].is_null());
  EXPECT_TRUE(only["clips"].empty() && only["meshes"].empty() && only["materials"].empty());
}

// ---------------------------------------------------------------------------------------------
// The schemas constrain

struct Mutation {
  const char* what;
  std::function<void(json&)> apply;
};

/// Each mutation of a valid document must be rejected (named with its error), and the document
/// itself accepted. One run of the checker for all of them: a Python start with jsonschema costs
/// more than the checks themselves, and the checker reports every document on its own.
void expect_rejected(const fs::path& schema_file, const json& valid, const std::vector<Mutation>& mutations,
                     const fs::path& dir) {
  ASSERT_TRUE(write_json(dir / "valid.json", valid));
  std::vector<fs::path> files = {dir / "valid.json"};
  for (const Mutation& m : mutations) {
    json doc = valid;
    m.apply(doc);
    ASSERT_NE(doc, valid) << m.what << ": the mutation changed nothing";
    files.push_back(dir / ("mutated-" + std::to_string(files.size() - 1) + ".json"));
    ASSERT_TRUE(write_json(files.back(), doc));
  }
  const CommandResult r = check(schema_file, files);
  EXPECT_EQ(r.exit_code, 1) << r.out << r.err;
  EXPECT_NE(r.out.find(files[0].string() + ": valid against"), std::string::npos) << r.out << r.err;
  EXPECT_EQ(r.err.find(files[0].string() + ": "), std::string::npos) << r.err;
  for (size_t i = 0; i < mutations.size(); ++i) {
    const std::string named = files[i + 1].string() + ": ";
    EXPECT_EQ(r.out.find(named + "valid against"), std::string::npos) << mutations[i].what << " was accepted";
    EXPECT_NE(r.err.find(named), std::string::npos) << mutations[i].what << ": no error named it:\n" << r.err;
  }
}

TEST(SchemasConstrain, MutatedReportsAreRejected) {
  const fs::path dir = ossa::test::make_temp_dir("schema-mutate-report");
  ASSERT_TRUE(ossa::test::write_file(dir / "bad.fbx", std::string_view("not an FBX")));
  const CommandResult r = tool("ossa-cook", q(dir / "bad.fbx") + " " + q(asset("Fox/Fox.glb")) + " -q -o " +
                                                q(dir / "out") + " --report " + q(dir / "report.json"));
  ASSERT_EQ(r.exit_code, 1) << r.err;
  const json report = read_json(dir / "report.json");
  ASSERT_EQ(report["records"][0]["status"], "failed");
  ASSERT_EQ(report["records"][1]["status"], "ok");
  expect_rejected(
      schema("ossa-cook-report"), report,
      {
          {"an unknown top-level field", [](json& d) { d["colour"] = "blue"; }},
          {"an unknown record field", [](json& d) { d["records"][1]["speed"] = 1; }},
          {"an unknown clip field", [](json& d) { d["records"][1]["clip_compression"][0]["x"] = 1; }},
          {"a count as a string", [](json& d) { d["records"][1]["joints"] = "24"; }},
          {"a negative size", [](json& d) { d["records"][1]["source_bytes"] = -1; }},
          {"an error as a string", [](json& d) { d["records"][1]["clip_compression"][0]["max_error_mm"] = "0.1"; }},
          {"a failed record naming an output", [](json& d) { d["records"][0]["output"] = "out/bad.ossa"; }},
          {"a failed record with cooked bytes", [](json& d) { d["records"][0]["cooked_bytes"] = 10; }},
          {"a failed record without its error", [](json& d) { d["records"][0].erase("error"); }},
          {"an ok record without its output", [](json& d) { d["records"][1].erase("output"); }},
          {"an ok record without a count", [](json& d) { d["records"][1].erase("vertices"); }},
          {"an ok record with an error", [](json& d) { d["records"][1]["error"] = "?"; }},
          {"an unknown status", [](json& d) { d["records"][1]["status"] = "maybe"; }},
          {"another schema name", [](json& d) { d["schema"] = "ossa-inspect"; }},
          {"another schema version", [](json& d) { d["schema_version"] = 2; }},
          {"no schema version", [](json& d) { d.erase("schema_version"); }},
      },
      dir);
}

TEST(SchemasConstrain, MutatedInspectDocumentsAreRejected) {
  const fs::path dir = ossa::test::make_temp_dir("schema-mutate-inspect");
  ASSERT_EQ(tool("ossa-cook", q(asset("Fox/Fox.glb")) + " -q -o " + q(dir)).exit_code, 0);
  const CommandResult r = tool("ossa-inspect", q(dir / "Fox.ossa") + " --json -v");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const json doc = json::parse(r.out);
  expect_rejected(
      schema("ossa-inspect"), doc,
      {
          {"an unknown top-level field", [](json& d) { d["vertices"] = 1; }},
          {"an unknown joint field", [](json& d) { d["skeleton"]["joints"][0]["weight"] = 1.0; }},
          {"an unknown channel field", [](json& d) { d["clips"][0]["channels"][0]["x"] = 0; }},
          {"an unknown vertex format", [](json& d) { d["meshes"][0]["layout"][0]["format"] = "Float64x9"; }},
          {"an error as a string", [](json& d) { d["clips"][0]["compression"]["max_error_mm"] = "small"; }},
          {"a bounds vector of two", [](json& d) { d["meshes"][0]["bounds"]["min"].erase(2); }},
          {"a short hash", [](json& d) { d["content_hash"] = "abc"; }},
          {"no content hash", [](json& d) { d.erase("content_hash"); }},
          {"a negative count", [](json& d) { d["meshes"][0]["vertex_count"] = -3; }},
          {"bits out of range", [](json& d) { d["clips"][0]["channels"][0]["bits"] = 33; }},
          {"another schema version", [](json& d) { d["schema_version"] = 0; }},
      },
      dir);
}

TEST(SchemasConstrain, EveryObjectIsClosedAndEveryPropertyDescribed) {
  const std::string checker = q(ossa::test::source_dir() / "tests" / "support" / "json_schema_check.py");
  const CommandResult lint = run_command("/usr/bin/python3 " + checker + " --lint " + q(schema("ossa-cook-report")) +
                                         " " + q(schema("ossa-inspect")) + " " + q(schema("ossa-diff")));
  EXPECT_EQ(lint.exit_code, 0) << lint.out << lint.err;

  // The lint itself catches both lapses.
  const fs::path dir = ossa::test::make_temp_dir("schema-lint");
  json open_object = read_json(schema("ossa-inspect"));
  open_object["properties"]["skeleton"]["oneOf"][1].erase("additionalProperties");
  json undescribed = read_json(schema("ossa-cook-report"));
  undescribed["$defs"]["record"]["properties"]["seconds"].erase("description");
  ASSERT_TRUE(write_json(dir / "open.schema.json", open_object));
  ASSERT_TRUE(write_json(dir / "undescribed.schema.json", undescribed));
  for (const char* name : {"open.schema.json", "undescribed.schema.json"}) {
    const CommandResult r = run_command("/usr/bin/python3 " + checker + " --lint " + q(dir / name));
    EXPECT_EQ(r.exit_code, 1) << name << " passed the lint: " << r.out;
  }

  // docs/JSON.md links both schemas (and keeps the row for ossa-diff's).
  const auto page = ossa::test::read_text(ossa::test::source_dir() / "docs" / "JSON.md");
  ASSERT_TRUE(page.has_value());
  for (const char* link : {"(schemas/ossa-cook-report.schema.json)", "(schemas/ossa-inspect.schema.json)",
                           "schemas/ossa-diff.schema.json"})
    EXPECT_NE(page->find(link), std::string::npos) << "docs/JSON.md lacks " << link;
}

}  // namespace
