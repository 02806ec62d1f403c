// cook_race_test.cpp — the read sandbox under a race (common/open_beneath.h): another
// process keeps swapping a name inside the tree between a regular file and a way out (a symlink to
// a secret, a folder replaced by a symlink to the secret's folder, a hard link to the secret) while
// the cook opens it thousands of times. Every read must return the tree's bytes or be refused; the
// secret's bytes must never come back. Run with openat2 (where the kernel has it) and with the
// component-wise walk that replaces it on older kernels, then end to end through ossa-cook.
//
// The race must actually be run: each case also requires that both outcomes were seen (the tree's
// file read, and a refusal), or the swapping never overlapped an open and the test proves nothing.
#include <fcntl.h>
#include <stdio.h>
#include <sys/stat.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>
#include <thread>

#include <nlohmann/json.hpp>

#include "cooker/model/input_log.h"
#include "common/open_beneath.h"
#include "test_files.h"

namespace fs = std::filesystem;
using namespace ossa::cook;

namespace {

enum class Swap { kFileSymlink, kFolderSymlink, kHardLink };

const char* swap_name(Swap s) {
  return s == Swap::kFileSymlink     ? "file <-> symlink"
         : s == Swap::kFolderSymlink ? "folder <-> symlink"
                                     : "file <-> hard link";
}

struct RaceCounts {
  size_t tried = 0, inside = 0, refused = 0, leaked = 0;
};

/// Swaps `tree/t.bin` (or the folder `tree/sub`) between the tree's own and a way out until `stop`:
/// rename(2) for files (the name always exists), renameat2(RENAME_EXCHANGE) for the folder.
void swapper(const fs::path& tree, const fs::path& secret_dir, Swap kind, const std::atomic<bool>& stop,
             std::atomic<size_t>& swaps) {
  const std::string tmp_file = (tree / ".tmp-file").string(), tmp_link = (tree / ".tmp-link").string();
  if (kind == Swap::kFolderSymlink) ::symlink(secret_dir.c_str(), tmp_link.c_str());
  while (!stop.load(std::memory_order_relaxed)) {
    if (kind == Swap::kFolderSymlink) {
      ::renameat2(AT_FDCWD, (tree / "sub").c_str(), AT_FDCWD, tmp_link.c_str(), RENAME_EXCHANGE);
    } else {
      ossa::test::write_file(tmp_file, std::string_view("INSIDE-BYTES"));
      std::rename(tmp_file.c_str(), (tree / "t.bin").c_str());
      if (kind == Swap::kFileSymlink) ::symlink((secret_dir / "t.bin").c_str(), tmp_link.c_str());
      else ::link((secret_dir / "t.bin").c_str(), tmp_link.c_str());
      std::rename(tmp_link.c_str(), (tree / "t.bin").c_str());
    }
    swaps.fetch_add(1, std::memory_order_relaxed);
  }
}

/// Opens tree/<name> through read_input at least `min_tries` times while the swapper runs.
RaceCounts race(const fs::path& dir, Swap kind, size_t min_tries) {
  const fs::path tree = dir / "tree", secret = dir / "secret";
  fs::create_directories(tree / "sub");
  fs::create_directories(secret);
  EXPECT_TRUE(ossa::test::write_file(secret / "t.bin", std::string_view("SECRET-BYTES")));
  EXPECT_TRUE(ossa::test::write_file(tree / "t.bin", std::string_view("INSIDE-BYTES")));
  EXPECT_TRUE(ossa::test::write_file(tree / "sub" / "t.bin", std::string_view("INSIDE-BYTES")));
  const fs::path target = kind == Swap::kFolderSymlink ? tree / "sub" / "t.bin" : tree / "t.bin";
  std::atomic<bool> stop{false};
  std::atomic<size_t> swaps{0};
  std::thread other(swapper, tree, secret, kind, std::cref(stop), std::ref(swaps));
  RaceCounts counts;
  const auto deadline = std::chrono::steady_clock::now() + std::chrono::seconds(20);
  {
    ReadSandboxScope sandbox({tree});
    while (counts.tried < min_tries ||
           ((counts.inside == 0 || counts.refused == 0) && std::chrono::steady_clock::now() < deadline)) {
      InputLog log;
      InputLogScope scope(&log);
      auto bytes = read_input(target);
      ++counts.tried;
      if (!bytes) {
        ++counts.refused;
        continue;
      }
      const std::string text(bytes->begin(), bytes->end());
      if (text == "INSIDE-BYTES") ++counts.inside;
      else ++counts.leaked;
    }
  }
  stop = true;
  other.join();
  EXPECT_GT(swaps.load(), 0u);
  return counts;
}

class SandboxRace : public ::testing::TestWithParam<std::tuple<Swap, bool>> {};

TEST_P(SandboxRace, TheSecretIsNeverRead) {
  const auto [kind, walk] = GetParam();
  if (!walk) {
    force_walk_for_testing(false);
    if (!have_openat2()) GTEST_SKIP() << "this kernel has no openat2: the walk cases cover it";
  }
  force_walk_for_testing(walk);
  const fs::path dir = ossa::test::make_temp_dir("race");
  const RaceCounts c = race(dir, kind, 6000);
  force_walk_for_testing(false);
  std::printf("race (%s, %s): %zu opens tried, %zu read the tree's file, %zu refused, %zu leaked the secret\n",
              swap_name(kind), walk ? "walk" : "openat2", c.tried, c.inside, c.refused, c.leaked);
  EXPECT_EQ(c.leaked, 0u);
  EXPECT_GT(c.inside, 0u) << "the race never let the tree's file through: nothing was tested";
  EXPECT_GT(c.refused, 0u) << "the race never showed the way out: nothing was tested";
  fs::remove_all(dir);
}

INSTANTIATE_TEST_SUITE_P(
    Swaps, SandboxRace,
    ::testing::Combine(::testing::Values(Swap::kFileSymlink, Swap::kFolderSymlink, Swap::kHardLink), ::testing::Bool()),
    [](const ::testing::TestParamInfo<std::tuple<Swap, bool>>& p) {
      const Swap s = std::get<0>(p.param);
      return std::string(s == Swap::kFileSymlink     ? "FileSymlink"
                         : s == Swap::kFolderSymlink ? "FolderSymlink"
                                                     : "HardLink") +
             (std::get<1>(p.param) ? "Walk" : "Openat2");
    });

// What the walk must still allow: links that stay inside the allowed folders, absolute or
// relative, and a link from the tree into an --allow-dir folder; and what it refuses.
TEST(SandboxWalk, FollowsLinksThatStayInsideAndRefusesTheRest) {
  const fs::path dir = ossa::test::make_temp_dir("walk");
  const fs::path tree = dir / "tree", lib = dir / "lib", secret = dir / "secret";
  for (const fs::path& p : {tree / "a" / "b", lib, secret}) fs::create_directories(p);
  ASSERT_TRUE(ossa::test::write_file(tree / "a" / "b" / "f.bin", std::string_view("F")));
  ASSERT_TRUE(ossa::test::write_file(lib / "l.bin", std::string_view("L")));
  ASSERT_TRUE(ossa::test::write_file(secret / "s.bin", std::string_view("S")));
  fs::create_symlink("a/b/f.bin", tree / "rel");
  fs::create_symlink(tree / "a" / "b" / "f.bin", tree / "abs");
  fs::create_symlink("../../rel", tree / "a" / "b" / "up");
  fs::create_symlink("../../tree/a", tree / "a" / "loop");  // out of the tree's root and back in
  fs::create_symlink(lib / "l.bin", tree / "tolib");
  fs::create_symlink("../secret/s.bin", tree / "out");
  fs::create_symlink(secret, tree / "outdir");
  fs::create_symlink("/proc/self/root" + secret.string() + "/s.bin", tree / "magic");
  fs::create_symlink("self", tree / "self");
  for (bool walk : {true, false}) {
    force_walk_for_testing(walk);
    if (!walk && !have_openat2()) continue;
    const ReadRoots roots({tree, lib});
    const auto outcome = [&](const fs::path& p) { return open_beneath(&roots, p, false, false).outcome; };
    EXPECT_EQ(outcome(tree / "rel"), OpenOutcome::kOpened) << walk;
    EXPECT_EQ(outcome(tree / "abs"), OpenOutcome::kOpened) << walk;
    EXPECT_EQ(outcome(tree / "a" / "b" / "up"), OpenOutcome::kOpened) << walk;
    EXPECT_EQ(outcome(tree / "a" / "loop" / "b" / "f.bin"), OpenOutcome::kOpened) << walk;
    EXPECT_EQ(outcome(tree / "tolib"), OpenOutcome::kOpened) << walk;
    EXPECT_EQ(outcome(tree / "out"), OpenOutcome::kOutside) << walk;
    EXPECT_EQ(outcome(tree / "outdir" / "s.bin"), OpenOutcome::kOutside) << walk;
    EXPECT_EQ(outcome(tree / "magic"), OpenOutcome::kOutside) << walk;
    EXPECT_EQ(outcome(tree / "self"), OpenOutcome::kError) << walk;  // ELOOP
    EXPECT_EQ(outcome(tree / "missing.bin"), OpenOutcome::kAbsent) << walk;
    EXPECT_EQ(outcome(tree / "a"), OpenOutcome::kNotRegular) << walk;
    EXPECT_EQ(outcome(secret / "s.bin"), OpenOutcome::kOutside) << walk;
    // Read for real: the bytes are the file's.
    OpenedFile f = open_beneath(&roots, tree / "a" / "b" / "up", true, false);
    ASSERT_EQ(f.outcome, OpenOutcome::kOpened);
    char c = 0;
    EXPECT_EQ(::read(f.fd, &c, 1), 1);
    EXPECT_EQ(c, 'F');
    ::close(f.fd);
  }
  force_walk_for_testing(false);
  fs::remove_all(dir);
}

// End to end: one batch of ossa-cook cooks many sources naming the swapped texture.
TEST(SandboxRaceCook, NoCookedOutputEmbedsTheSecret) {
  const fs::path dir = ossa::test::make_temp_dir("race-cook");
  const fs::path tree = dir / "tree", secret = dir / "secret";
  fs::create_directories(tree);
  fs::create_directories(secret);
  const std::string secret_png = ossa::test::tiny_png_with_text("SECRET-MARKER-7d1c");
  ASSERT_TRUE(ossa::test::write_file(secret / "t.png", secret_png));
  const float v[9] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  ASSERT_TRUE(ossa::test::write_file(tree / "tri.bin", std::string(reinterpret_cast<const char*>(v), sizeof v)));
  const nlohmann::json gltf = {{"asset", {{"version", "2.0"}}},
                               {"scene", 0},
                               {"scenes", {{{"nodes", {0}}}}},
                               {"nodes", {{{"mesh", 0}}}},
                               {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}, {"material", 0}}}}}}},
                               {"materials", {{{"pbrMetallicRoughness", {{"baseColorTexture", {{"index", 0}}}}}}}},
                               {"images", {{{"uri", "t.png"}}}},
                               {"textures", {{{"source", 0}}}},
                               {"buffers", {{{"uri", "tri.bin"}, {"byteLength", 36}}}},
                               {"bufferViews", {{{"buffer", 0}, {"byteLength", 36}}}},
                               {"accessors",
                                {{{"bufferView", 0},
                                  {"componentType", 5126},
                                  {"count", 3},
                                  {"type", "VEC3"},
                                  {"min", {0, 0, 0}},
                                  {"max", {1, 1, 0}}}}}};
  constexpr int kSources = 80;
  for (int k = 0; k < kSources; ++k)
    ASSERT_TRUE(ossa::test::write_file(tree / ("c" + std::to_string(k) + ".gltf"), gltf.dump()));
  const auto png = ossa::test::tiny_png();
  const std::string inside(png.begin(), png.end());
  std::atomic<bool> stop{false};
  std::atomic<size_t> swaps{0};
  // One exchange per swap (renameat2), as fast as the kernel allows: tree/t.png is the tree's file
  // or a symlink to the secret, never absent.
  ASSERT_TRUE(ossa::test::write_file(tree / "t.png", inside));
  fs::create_symlink(secret / "t.png", tree / ".link");
  std::thread other([&] {
    while (!stop.load()) {
      ::renameat2(AT_FDCWD, (tree / "t.png").c_str(), AT_FDCWD, (tree / ".link").c_str(), RENAME_EXCHANGE);
      swaps.fetch_add(1);
    }
  });
  const auto r = ossa::test::run_command((ossa::test::bin_dir() / "ossa-cook").string() + " '" + tree.string() +
                                         "' -o '" + (dir / "out").string() + "' --texture-format source --jobs 2 -q");
  stop = true;
  other.join();
  size_t cooked = 0, leaked = 0;
  for (const auto& e : fs::directory_iterator(dir / "out")) {
    const auto bytes = ossa::test::read_text(e.path());
    ASSERT_TRUE(bytes.has_value());
    ++cooked;
    if (bytes->find("SECRET-MARKER-7d1c") != std::string::npos) ++leaked;
  }
  std::printf("race through ossa-cook: %d sources, %zu cooked, %d refused, %zu embedded the secret (%zu swaps)\n",
              kSources, cooked, kSources - static_cast<int>(cooked), leaked, swaps.load());
  EXPECT_EQ(leaked, 0u);
  EXPECT_LE(r.exit_code, 1) << r.err;
  // A refused cook names the texture and why (the link leads out, or it changed while opened).
  if (cooked < static_cast<size_t>(kSources)) {
    EXPECT_NE(r.err.find("t.png"), std::string::npos) << r.err.substr(0, 2000);
  }
  fs::remove_all(dir);
}

}  // namespace
