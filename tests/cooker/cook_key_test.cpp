// cook_key_test.cpp — ossa-cook as a build step: the cook key covers every file a cook read, the
// same tree cooked anywhere gives the same bytes and keys, up-to-date outputs are left alone, and
// --depfile / --list-inputs name what was read. Each test cooks a private copy of sample assets
// (never the repository's files), edits inputs one class at a time and checks which outputs the
// next run re-cooked, from the --report's "up_to_date" and from the outputs' bytes and mtimes.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <map>
#include <set>
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

/// A small tree: a glTF character, an FBX rig and an FBX clip with its event sidecar, and (when
/// ../shared is present) a .gltf with an external .bin and an external texture.
struct Tree {
  fs::path root;
  bool has_gltf_bin = false;
};

Tree make_tree(const fs::path& root) {
  Tree t{root};
  fs::create_directories(root / "chars");
  fs::create_directories(root / "pab");
  fs::copy_file(asset("RiggedSimple/RiggedSimple.glb"), root / "chars" / "RiggedSimple.glb");
  fs::copy_file(asset("Pab/skeleton.fbx"), root / "pab" / "skeleton.fbx");
  fs::copy_file(asset("Pab/walk.fbx"), root / "pab" / "walk.fbx");
  fs::copy_file(asset("Pab/walk.events.json"), root / "pab" / "walk.events.json");
  const fs::path shared = ossa::test::shared_assets() / "Khronos_embedded";
  if (fs::exists(shared / "interpolation_test.gltf")) {
    fs::create_directories(root / "gltf");
    fs::copy_file(shared / "interpolation_test.gltf", root / "gltf" / "interpolation_test.gltf");
    fs::copy_file(shared / "interpolation_test.bin", root / "gltf" / "interpolation_test.bin");
    // The texture it names (not shipped with it): a real image, as the cooker decodes it (a PNG
    // under a .jpg name is fine: images are identified by their bytes).
    EXPECT_TRUE(ossa::test::write_file(root / "gltf" / "l.jpg", ossa::test::tiny_png()));
    t.has_gltf_bin = true;
  }
  return t;
}

/// Files under `dir`, relative, with their bytes.
std::map<std::string, std::vector<uint8_t>> snapshot(const fs::path& dir) {
  std::map<std::string, std::vector<uint8_t>> out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) out[fs::relative(e.path(), dir).generic_string()] = *ossa::test::read_file(e.path());
  return out;
}

struct CookRun {
  int exit_code = -1;
  std::string err, out;
  nlohmann::json report;
  /// output file name (relative to the output dir) -> up_to_date
  std::map<std::string, bool> up_to_date;
};

/// Reads a --report into `run` (output relative to `out` -> up_to_date).
void read_report(const fs::path& report, const fs::path& out, CookRun& run) {
  auto text = ossa::test::read_text(report);
  if (!text) return;
  run.report = nlohmann::json::parse(*text);
  for (const auto& rec : run.report["records"])
    if (rec.contains("output"))
      run.up_to_date[fs::relative(rec["output"].get<std::string>(), out).generic_string()] =
          rec["up_to_date"].get<bool>();
}

/// The three steps of cooking the tree into `out`: the rig, the clip against the cooked rig
/// (--skeleton applies to a whole batch), and the characters. `extra` goes to every step.
CookRun cook(const Tree& t, const fs::path& out, const std::string& extra = "") {
  CookRun run;
  const std::string common = " -o " + q(out) + " --root " + q(t.root) + " -q " + extra;
  std::string others = q(t.root / "chars");
  if (t.has_gltf_bin) others += " " + q(t.root / "gltf");
  const std::string steps[] = {
      q(t.root / "pab" / "skeleton.fbx"),
      q(t.root / "pab" / "walk.fbx") + " --skeleton " + q(out / "pab" / "skeleton.ossa"),
      others,
  };
  for (size_t i = 0; i < std::size(steps); ++i) {
    const fs::path report = out.parent_path() / (out.filename().string() + "-report-" + std::to_string(i) + ".json");
    const auto r = run_command(cook_cmd() + " " + steps[i] + common + " --report " + q(report));
    run.err += r.err;
    run.out += r.out;
    if (r.exit_code != 0) {
      run.exit_code = r.exit_code;
      return run;
    }
    read_report(report, out, run);
  }
  run.exit_code = 0;
  return run;
}

uint64_t key_of(const fs::path& file) {
  auto a = ossa::Asset::open(file.string());
  EXPECT_TRUE(a.ok()) << file;
  return a.ok() && a->file().provenance() ? a->file().provenance()->cook_key() : 0;
}

/// Rewrites a file with new bytes (or the same bytes, to change only its mtime).
void rewrite(const fs::path& path, std::string_view bytes) { ASSERT_TRUE(ossa::test::write_file(path, bytes)); }

void append_byte(const fs::path& path) {
  auto bytes = ossa::test::read_file(path);
  ASSERT_TRUE(bytes.has_value());
  bytes->push_back(0);
  ASSERT_TRUE(ossa::test::write_file(path, std::span<const uint8_t>(*bytes)));
}

/// Sets every file under `dir` an hour into the past, so a rewrite is visible whatever the
/// file system's timestamp granularity.
void age(const fs::path& dir) {
  const auto then = fs::file_time_type::clock::now() - std::chrono::hours(1);
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) fs::last_write_time(e.path(), then);
}

std::map<std::string, fs::file_time_type> mtimes(const fs::path& dir) {
  std::map<std::string, fs::file_time_type> out;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file()) out[fs::relative(e.path(), dir).generic_string()] = e.last_write_time();
  return out;
}

/// The outputs a run re-cooked (not up to date).
std::set<std::string> recooked(const CookRun& run) {
  std::set<std::string> out;
  for (const auto& [name, fresh] : run.up_to_date)
    if (!fresh) out.insert(name);
  return out;
}

TEST(CookKey, SameTreeElsewhereInAnotherOrderAndJobCountGivesSameBytesAndKeys) {
  const fs::path dir = ossa::test::make_temp_dir("key-where");
  const Tree a = make_tree(dir / "a" / "src");
  const Tree b = make_tree(dir / "somewhere" / "much" / "deeper" / "src");
  const CookRun ra = cook(a, dir / "a" / "out", "--jobs 1");
  ASSERT_EQ(ra.exit_code, 0) << ra.err;
  // The other tree: more jobs, and the characters' inputs named in reverse order.
  const fs::path out_b = dir / "b-out";
  const std::string common = " -o " + q(out_b) + " --root " + q(b.root) + " --jobs 2 -q";
  ASSERT_EQ(run_command(cook_cmd() + " " + q(b.root / "pab" / "skeleton.fbx") + common).exit_code, 0);
  ASSERT_EQ(run_command(cook_cmd() + " " + q(b.root / "pab" / "walk.fbx") + " --skeleton " +
                        q(out_b / "pab" / "skeleton.ossa") + common)
                .exit_code,
            0);
  std::string inputs = q(b.root / "chars");
  if (b.has_gltf_bin) inputs = q(b.root / "gltf") + " " + inputs;
  const auto rb = run_command(cook_cmd() + " " + inputs + common);
  ASSERT_EQ(rb.exit_code, 0) << rb.err;
  const auto sa = snapshot(dir / "a" / "out"), sb = snapshot(out_b);
  ASSERT_EQ(sa.size(), a.has_gltf_bin ? 4u : 3u);  // rig, clip, character (and the glTF)
  ASSERT_EQ(sa.size(), sb.size());
  for (const auto& [name, bytes] : sa) {
    ASSERT_TRUE(sb.count(name)) << name;
    EXPECT_TRUE(bytes == sb.at(name)) << name << " differs between the two trees";
    EXPECT_EQ(key_of(dir / "a" / "out" / name), key_of(out_b / name)) << name;
    EXPECT_NE(key_of(dir / "a" / "out" / name), 0u) << name;
  }
}

TEST(CookKey, UpToDateOutputsAreNeitherCookedNorRewritten) {
  const fs::path dir = ossa::test::make_temp_dir("key-fresh");
  const Tree t = make_tree(dir / "src");
  const fs::path out = dir / "out";
  ASSERT_EQ(cook(t, out).exit_code, 0);
  age(out);
  const auto before = snapshot(out);
  const auto times = mtimes(out);

  const CookRun again = cook(t, out);
  ASSERT_EQ(again.exit_code, 0) << again.err;
  ASSERT_FALSE(again.up_to_date.empty());
  EXPECT_TRUE(recooked(again).empty()) << "nothing changed, nothing is re-cooked";
  EXPECT_EQ(mtimes(out), times) << "up-to-date outputs keep their mtime";
  EXPECT_EQ(snapshot(out), before);

  // A new mtime with the same bytes changes nothing: the key is of contents.
  auto walk = ossa::test::read_text(t.root / "pab" / "walk.events.json");
  ASSERT_TRUE(walk.has_value());
  rewrite(t.root / "pab" / "walk.events.json", *walk);
  EXPECT_TRUE(recooked(cook(t, out)).empty());
  EXPECT_EQ(mtimes(out), times);

  // --force re-cooks everything, to the same bytes.
  const CookRun forced = cook(t, out, "--force");
  EXPECT_EQ(recooked(forced).size(), forced.up_to_date.size());
  EXPECT_EQ(snapshot(out), before);

  // Other options make other bytes: nothing is up to date.
  const CookRun floats = cook(t, out, "--float-vertices");
  EXPECT_EQ(recooked(floats).size(), floats.up_to_date.size());
}

TEST(CookKey, ChangingAnyInputRecooksExactlyTheOutputsThatReadIt) {
  const fs::path dir = ossa::test::make_temp_dir("key-change");
  const Tree t = make_tree(dir / "src");
  const fs::path out = dir / "out";
  ASSERT_EQ(cook(t, out).exit_code, 0);
  using Set = std::set<std::string>;

  // An event sidecar's contents.
  auto events = ossa::test::read_text(t.root / "pab" / "walk.events.json");
  ASSERT_TRUE(events.has_value());
  rewrite(t.root / "pab" / "walk.events.json", *events + " ");
  EXPECT_EQ(recooked(cook(t, out)), (Set{"pab/walk.ossa"}));
  EXPECT_TRUE(recooked(cook(t, out)).empty());

  // A sidecar that did not exist: its absence was part of the key.
  rewrite(t.root / "chars" / "RiggedSimple.events.json", R"({"ossa_events": 1, "clips": {}})");
  EXPECT_EQ(recooked(cook(t, out)), (Set{"chars/RiggedSimple.ossa"}));
  fs::remove(t.root / "chars" / "RiggedSimple.events.json");
  EXPECT_EQ(recooked(cook(t, out)), (Set{"chars/RiggedSimple.ossa"}));

  // The --skeleton reference's contents (re-cooked with other options, so other bytes): the clip
  // cooked against it is out of date.
  ASSERT_EQ(run_command(cook_cmd() + " " + q(t.root / "pab" / "skeleton.fbx") + " -o " + q(out) + " --root " +
                        q(t.root) + " -q --float-vertices")
                .exit_code,
            0);
  const fs::path report = dir / "ref-report.json";
  ASSERT_EQ(run_command(cook_cmd() + " " + q(t.root / "pab" / "walk.fbx") + " -o " + q(out) + " --root " + q(t.root) +
                        " --skeleton " + q(out / "pab" / "skeleton.ossa") + " --report " + q(report) + " -q")
                .exit_code,
            0);
  CookRun ref;
  read_report(report, out, ref);
  EXPECT_EQ(recooked(ref), (Set{"pab/walk.ossa"}));
  ASSERT_EQ(cook(t, out).exit_code, 0);  // back to the quantized rig (re-cooks walk again)

  if (!t.has_gltf_bin) GTEST_SKIP() << "../shared/assets not present: no .gltf with an external buffer";
  // A glTF's external buffer, and a texture it names.
  append_byte(t.root / "gltf" / "interpolation_test.bin");
  EXPECT_EQ(recooked(cook(t, out)), (Set{"gltf/interpolation_test.ossa"}));
  append_byte(t.root / "gltf" / "l.jpg");
  EXPECT_EQ(recooked(cook(t, out)), (Set{"gltf/interpolation_test.ossa"}));
  EXPECT_TRUE(recooked(cook(t, out)).empty());
}

TEST(CookKey, DepfileAndListInputsNameEveryFileRead) {
  const fs::path dir = ossa::test::make_temp_dir("key-deps");
  const Tree t = make_tree(dir / "src");
  const fs::path out = dir / "out";
  ASSERT_EQ(cook(t, out).exit_code, 0);

  // --list-inputs: what the cooks read, one absolute path per line, and nothing written.
  const fs::path listed_out = dir / "listed";
  const std::string inputs = q(t.root / "pab" / "walk.fbx") + " --skeleton " + q(out / "pab" / "skeleton.ossa");
  const auto list =
      run_command(cook_cmd() + " " + inputs + " -o " + q(listed_out) + " --root " + q(t.root) + " --list-inputs");
  ASSERT_EQ(list.exit_code, 0) << list.err;
  EXPECT_FALSE(fs::exists(listed_out)) << "--list-inputs writes nothing";
  std::set<std::string> lines;
  for (size_t at = 0; at < list.out.size();) {
    const size_t end = list.out.find('\n', at);
    lines.insert(list.out.substr(at, end - at));
    at = end == std::string::npos ? list.out.size() : end + 1;
  }
  const auto canon = [](const fs::path& p) { return fs::weakly_canonical(p).string(); };
  const std::set<std::string> expected = {canon(t.root / "pab" / "walk.fbx"),
                                          canon(t.root / "pab" / "walk.events.json"),
                                          canon(out / "pab" / "skeleton.ossa")};
  EXPECT_EQ(lines, expected) << list.out;

  // --depfile: one rule per output naming the same files (absent ones are not prerequisites).
  const fs::path dep = dir / "cook.d";
  ASSERT_EQ(
      run_command(cook_cmd() + " " + inputs + " -o " + q(out) + " --root " + q(t.root) + " --depfile " + q(dep) + " -q")
          .exit_code,
      0);
  auto text = ossa::test::read_text(dep);
  ASSERT_TRUE(text.has_value());
  ASSERT_EQ(text->rfind(canon(out / "pab" / "walk.ossa") + ":", 0), 0u) << *text;
  for (const std::string& f : expected) EXPECT_NE(text->find("  " + f), std::string::npos) << f << "\n" << *text;
  EXPECT_EQ(text->find("RiggedSimple"), std::string::npos) << "only the outputs of this run";

  if (!t.has_gltf_bin) GTEST_SKIP() << "../shared/assets not present: no .gltf with an external buffer";
  // A glTF's buffer and texture are prerequisites; its sidecar, looked for and absent, is not.
  ASSERT_EQ(run_command(cook_cmd() + " " + q(t.root / "gltf") + " -o " + q(out) + " --root " + q(t.root) +
                        " --depfile " + q(dep) + " -q")
                .exit_code,
            0);
  text = ossa::test::read_text(dep);
  ASSERT_TRUE(text.has_value());
  for (const char* f : {"interpolation_test.gltf", "interpolation_test.bin", "l.jpg"})
    EXPECT_NE(text->find("  " + canon(t.root / "gltf" / f)), std::string::npos) << f << "\n" << *text;
  EXPECT_EQ(text->find("events.json"), std::string::npos) << *text;
}

TEST(CookKey, AnInputNamedWithoutAFolderRecordsTheSameRelativeInputs) {
  const fs::path dir = ossa::test::make_temp_dir("key-cwd");
  const Tree t = make_tree(dir / "src");
  const fs::path chars = t.root / "chars";
  ASSERT_EQ(run_command(cook_cmd() + " " + q(chars / "RiggedSimple.glb") + " -o " + q(dir / "a") + " -q").exit_code, 0);
  ASSERT_EQ(
      run_command("cd " + q(chars) + " && " + cook_cmd() + " RiggedSimple.glb -o " + q(dir / "b") + " -q").exit_code,
      0);
  const auto a = ossa::test::read_file(dir / "a" / "RiggedSimple.ossa"),
             b = ossa::test::read_file(dir / "b" / "RiggedSimple.ossa");
  ASSERT_TRUE(a && b);
  EXPECT_TRUE(*a == *b) << "the same bytes whether the input is named with its folder or from it";
  auto asset = ossa::Asset::open((dir / "b" / "RiggedSimple.ossa").string());
  ASSERT_TRUE(asset.ok());
  const auto* prov = asset->file().provenance();
  EXPECT_NE(prov->source_hash(), 0u);
  for (const auto* f : *prov->inputs()) EXPECT_NE(f->path()->str().front(), '/') << f->path()->str();
}

}  // namespace
