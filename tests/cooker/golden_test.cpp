// golden_test.cpp — regression on cooked output, and the determinism promise.
//
// Cooks the repo's sample assets and every source in ../shared/assets (skipped with a notice when
// absent), compares `ossa-inspect --json` of each output with the checked-in golden under
// tests/golden/, and checks that cooking again, and with --jobs 1 instead of --jobs 2, gives
// identical bytes. Goldens change only on purpose: run with OSSA_UPDATE_GOLDENS=1 to rewrite
// them, and say why in the commit message.
//
// Each test cooks what it needs itself (CTest runs every test in its own process).
#include <gtest/gtest.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include <ossa/loader/asset.h>
#include "skinning_reference.h"
#include "test_files.h"

namespace fs = std::filesystem;
using ossa::test::run_command;

namespace {

std::string q(const fs::path& p) { return "'" + p.string() + "'"; }
std::string tool(const char* name) { return (ossa::test::bin_dir() / name).string(); }
bool updating() {
  const char* v = std::getenv("OSSA_UPDATE_GOLDENS");
  return v != nullptr && std::string(v) == "1";
}

std::vector<fs::path> cooked_files(const fs::path& dir) {
  std::vector<fs::path> files;
  for (const auto& e : fs::recursive_directory_iterator(dir))
    if (e.is_regular_file() && e.path().extension() == ".ossa") files.push_back(fs::relative(e.path(), dir));
  std::sort(files.begin(), files.end());
  return files;
}

/// One cook invocation; fails the test (and returns false) on a non-zero exit.
bool cook(const std::string& args) {
  const auto r = run_command(tool("ossa-cook") + " --quiet " + args);
  EXPECT_EQ(r.exit_code, 0) << "ossa-cook " << args << "\n" << r.err;
  return r.exit_code == 0;
}

/// The repo's samples, cooked the way scripts/demo.sh cooks them (the Pab graph into its own tree).
bool cook_repo_assets(const fs::path& out, int jobs) {
  const fs::path a = ossa::test::source_dir() / "assets";
  const std::string j = " --jobs " + std::to_string(jobs);
  return cook(q(a / "Pab" / "skeleton.fbx") + " " + q(a / "CesiumMan") + " " + q(a / "Fox") + " " +
              q(a / "RiggedSimple") + " --root " + q(a) + " -o " + q(out) + j) &&
         cook(q(a / "Pab" / "arnaud.fbx") + " " + q(a / "Pab" / "walk.fbx") + " " + q(a / "Pab" / "jog.fbx") + " " +
              q(a / "Pab" / "run.fbx") + " " + q(a / "Pab" / "crossarms.fbx") + " --skeleton " +
              q(out / "Pab" / "skeleton.ossa") + " --root " + q(a) + " -o " + q(out / "bound") + j) &&
         cook(q(a / "Pab" / "pab.graph.json") + " --root " + q(a) + " -o " + q(out / "graph") + j);
}

/// Every source in ../shared/assets standalone (Collada into its own tree: Pab has skeleton.fbx and
/// skeleton.dae, which would both cook to skeleton.ossa), plus the Pab clip files against the Pab rig.
bool cook_shared_assets(const fs::path& out, int jobs) {
  const fs::path s = ossa::test::shared_assets();
  const std::string j = " --jobs " + std::to_string(jobs);
  std::vector<fs::path> sources;
  for (const auto& e : fs::recursive_directory_iterator(s)) {
    const std::string ext = e.path().extension().string();
    if (e.is_regular_file() && (ext == ".fbx" || ext == ".gltf" || ext == ".glb" || ext == ".dae" || ext == ".bvh"))
      sources.push_back(e.path());
  }
  std::sort(sources.begin(), sources.end());
  std::string collada, others;
  for (const fs::path& p : sources) (p.extension() == ".dae" ? collada : others) += " " + q(p);
  std::string pab;
  for (const char* f : {"walk", "jog", "run", "crossarms", "atlas", "crackhead", "locomotions"})
    pab += " " + q(s / "Pab" / (std::string(f) + ".fbx"));
  return cook(others + " --root " + q(s) + " -o " + q(out) + j) &&
         cook(collada + " --root " + q(s) + " -o " + q(out / "collada") + j) &&
         cook(pab + " --skeleton " + q(out / "Pab" / "skeleton.ossa") + " --root " + q(s) + " -o " + q(out / "bound") +
              j);
}

/// The cooker's promise to skin_cpu's range loops, on every skinned mesh cooked: influence classes
/// never decrease along the vertex buffer (one contiguous range per class). Meshes whose
/// quantized vertices merge (most of ../shared/assets) are where it once broke.
void expect_class_order(const fs::path& cooked) {
  size_t skinned = 0;
  for (const fs::path& rel : cooked_files(cooked)) {
    auto asset = ossa::Asset::open((cooked / rel).string());
    ASSERT_TRUE(asset.ok()) << rel << ": " << asset.error().message;
    for (size_t i = 0; i < asset->mesh_count(); ++i) {
      const ossa::MeshView mesh = asset->mesh(i);
      const ossa::fb::VertexAttribute* w = mesh.attribute(ossa::fb::VertexSemantic::Weights);
      if (w == nullptr || w->format() != ossa::fb::VertexFormat::Unorm8x4) continue;
      ++skinned;
      const uint32_t drop = ossa::test::skinning_reference::first_class_drop(mesh);
      EXPECT_EQ(drop, mesh.vertex_count())
          << rel << " mesh " << i << ": vertex " << drop << " is of a lower influence class than the one before it";
    }
  }
  EXPECT_GT(skinned, 0u) << cooked;
}

void expect_goldens(const fs::path& cooked, const fs::path& golden_dir) {
  const auto files = cooked_files(cooked);
  ASSERT_FALSE(files.empty());
  for (const fs::path& rel : files) {
    const auto r = run_command(tool("ossa-inspect") + " --json " + q(cooked / rel));
    ASSERT_EQ(r.exit_code, 0) << rel << ": " << r.err;
    const auto actual = nlohmann::json::parse(r.out);
    const fs::path golden = golden_dir / fs::path(rel).replace_extension(".json");
    if (updating()) {
      fs::create_directories(golden.parent_path());
      ASSERT_TRUE(ossa::test::write_file(golden, actual.dump(1) + "\n"));
      continue;
    }
    const auto expected_text = ossa::test::read_text(golden);
    if (!expected_text) {
      ADD_FAILURE() << "no golden " << golden << " for " << rel << " (OSSA_UPDATE_GOLDENS=1 writes it)";
      continue;
    }
    const auto expected = nlohmann::json::parse(*expected_text);
    if (expected != actual) {
      const auto patch = nlohmann::json::diff(expected, actual);
      std::string first;
      for (size_t i = 0; i < patch.size() && i < 8; ++i) first += "\n  " + patch[i].dump();
      ADD_FAILURE() << rel << " differs from " << golden << " in " << patch.size() << " places:" << first;
    }
  }
  // A golden with no cooked file means an input silently disappeared.
  if (updating() || !fs::exists(golden_dir)) return;
  for (const auto& e : fs::recursive_directory_iterator(golden_dir)) {
    if (!e.is_regular_file()) continue;
    EXPECT_TRUE(fs::exists(cooked / fs::relative(e.path(), golden_dir).replace_extension(".ossa")))
        << "golden " << e.path() << " has no cooked file";
  }
}

void expect_same_bytes(const fs::path& a, const fs::path& b) {
  const auto fa = cooked_files(a), fb = cooked_files(b);
  ASSERT_EQ(fa, fb);
  for (const fs::path& rel : fa) {
    const auto x = ossa::test::read_file(a / rel), y = ossa::test::read_file(b / rel);
    ASSERT_TRUE(x && y) << rel;
    EXPECT_TRUE(*x == *y) << rel << ": " << a << " and " << b << " differ (" << x->size() << " vs " << y->size()
                          << " bytes)";
  }
}

// One cook of the samples is compared with the goldens and with two more: --jobs 1, and --jobs 2
// again.
TEST(Golden, RepoAssetsMatchGoldensAndCookDeterministically) {
  const fs::path a = ossa::test::make_temp_dir("golden-repo"), b = ossa::test::make_temp_dir("det-b"),
                 c = ossa::test::make_temp_dir("det-c");
  ASSERT_TRUE(cook_repo_assets(a, 2));
  expect_goldens(a, ossa::test::source_dir() / "tests" / "golden" / "assets");
  expect_class_order(a);
  ASSERT_TRUE(cook_repo_assets(b, 1));
  ASSERT_TRUE(cook_repo_assets(c, 2));
  expect_same_bytes(a, b);  // --jobs 2 vs --jobs 1
  expect_same_bytes(a, c);  // twice
}

TEST(Golden, SharedAssetsMatchGoldensAndCookDeterministically) {
  if (!fs::exists(ossa::test::shared_assets() / "README.md"))
    GTEST_SKIP() << "notice: " << ossa::test::shared_assets() << " is absent; shared-asset goldens not checked";
  const fs::path a = ossa::test::make_temp_dir("golden-shared-a"), b = ossa::test::make_temp_dir("golden-shared-b");
  ASSERT_TRUE(cook_shared_assets(a, 2));
  expect_goldens(a, ossa::test::source_dir() / "tests" / "golden" / "shared");
  expect_class_order(a);
  ASSERT_TRUE(cook_shared_assets(b, 1));
  expect_same_bytes(a, b);
}

}  // namespace
