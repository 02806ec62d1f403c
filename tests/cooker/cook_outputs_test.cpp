// cook_outputs_test.cpp — what ossa-cook leaves in its output folder, for real, across runs:
// - an output is up to date only for the input that made it (`x.obj` then `x.gltf` into one folder
//   share `x.ossa`: the second must cook, not keep the OBJ's output);
// - temporaries left by writers that died (a batch killed mid-write) go at the next run, even
//   when every output is up to date, and a live writer's temporary stays;
// - output names up to NAME_MAX (242-255 bytes) cook: their temporaries fit too;
// - an up-to-date run reports the warnings of the cook that made the output (kept in its
//   provenance); an output from a cooker before that field reads as having none;
// - every write error (a full disk — a file-size limit here —, a read-only output, a name too long)
//   names the input it concerns, and a report that cannot be written does not silence the depfile.
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <sys/wait.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <string>

#include <nlohmann/json.hpp>

#include <ossa/loader/asset.h>
#include "cooker/write/atomic_file.h"
#include "test_files.h"

namespace fs = std::filesystem;
using ossa::test::run_command;

namespace {

std::string cook_cmd() { return (ossa::test::bin_dir() / "ossa-cook").string(); }
std::string q(const fs::path& p) { return "'" + p.string() + "'"; }

const std::string kObj = "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n";

std::string triangle_gltf() {
  return nlohmann::json{{"asset", {{"version", "2.0"}}},
                        {"scene", 0},
                        {"scenes", {{{"nodes", {0}}}}},
                        {"nodes", {{{"mesh", 0}}}},
                        {"meshes", {{{"primitives", {{{"attributes", {{"POSITION", 0}}}}}}}}},
                        {"buffers", {{{"uri", "tri.bin"}, {"byteLength", 36}}}},
                        {"bufferViews", {{{"buffer", 0}, {"byteLength", 36}}}},
                        {"accessors",
                         {{{"bufferView", 0},
                           {"componentType", 5126},
                           {"count", 3},
                           {"type", "VEC3"},
                           {"min", {0, 0, 0}},
                           {"max", {1, 1, 0}}}}}}
      .dump();
}

std::string triangle_bytes(float z = 0.0f) {
  const float v[9] = {0, 0, z, 1, 0, z, 0, 1, z};
  return std::string(reinterpret_cast<const char*>(v), sizeof v);
}

/// The one record of a --report file.
nlohmann::json only_record(const fs::path& report) {
  const auto text = ossa::test::read_text(report);
  if (!text) return {};
  const auto doc = nlohmann::json::parse(*text);
  return doc["records"].size() == 1 ? doc["records"][0] : nlohmann::json{};
}

class CookOutputs : public ::testing::Test {
 protected:
  void SetUp() override {
    dir = ossa::test::make_temp_dir("outputs");
    src = dir / "src";
    out = dir / "out";
    fs::create_directories(src);
  }
  void TearDown() override { fs::remove_all(dir); }
  fs::path dir, src, out;
};

TEST_F(CookOutputs, AnOutputIsUpToDateOnlyForTheInputThatMadeIt) {
  ASSERT_TRUE(ossa::test::write_file(src / "x.obj", kObj));
  ASSERT_TRUE(ossa::test::write_file(src / "x.gltf", triangle_gltf()));
  ASSERT_TRUE(ossa::test::write_file(src / "tri.bin", triangle_bytes()));
  const fs::path report = dir / "r.json";
  const auto cook = [&](const char* name) {
    const auto r = run_command(cook_cmd() + " " + q(src / name) + " -o " + q(out) + " -q --report " + q(report));
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return only_record(report);
  };
  EXPECT_FALSE(cook("x.obj")["up_to_date"].get<bool>());
  EXPECT_TRUE(cook("x.obj")["up_to_date"].get<bool>()) << "the same input again: up to date";
  // Another source, same output name: cooked, and the output now says it is the glTF's.
  nlohmann::json r = cook("x.gltf");
  EXPECT_FALSE(r["up_to_date"].get<bool>()) << "the OBJ's output was taken for the glTF's";
  EXPECT_NE(ossa::test::read_text(out / "x.ossa")->find("x.gltf"), std::string::npos);
  EXPECT_TRUE(cook("x.gltf")["up_to_date"].get<bool>());
  // An edit of the glTF's buffer re-cooks it; and back to the OBJ, which cooks again.
  ASSERT_TRUE(ossa::test::write_file(src / "tri.bin", triangle_bytes(1.0f)));
  EXPECT_FALSE(cook("x.gltf")["up_to_date"].get<bool>());
  EXPECT_FALSE(cook("x.obj")["up_to_date"].get<bool>());
}

/// Sources that warn, each in its own way: an OBJ with lines and a degenerate triangle, one with
/// no normals, a glTF in a folder below (paths in warnings stay portable).
std::vector<std::pair<std::string, std::string>> warning_sources() {
  return {{"lines.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 2 2 2\nf 1 2 3\nf 1 1 2\nl 1 4\n"},
          {"bare.obj", kObj},
          {"sub/tri.gltf", triangle_gltf()},
          {"sub/tri.bin", triangle_bytes()}};
}

TEST_F(CookOutputs, AnUpToDateRunReportsTheWarningsOfTheCookThatMadeTheOutput) {
  fs::create_directories(src / "sub");
  for (const auto& [name, text] : warning_sources()) ASSERT_TRUE(ossa::test::write_file(src / name, text));
  const fs::path report = dir / "r.json";
  const auto run = [&](const std::string& name, const std::string& flags) {
    const auto r =
        run_command(cook_cmd() + " " + q(src / name) + " -o " + q(out) + " " + flags + " --report " + q(report));
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return std::make_pair(only_record(report), r);
  };
  for (const char* name : {"lines.obj", "bare.obj", "sub/tri.gltf"}) {
    SCOPED_TRACE(name);
    const auto [first, first_run] = run(name, "");
    ASSERT_FALSE(first["up_to_date"].get<bool>());
    const auto warnings = first["warnings"];
    ASSERT_FALSE(warnings.empty()) << "the source was made to warn";
    EXPECT_NE(first_run.err.find(std::to_string(warnings.size()) + " warning"), std::string::npos) << first_run.err;
    // Up to date: the same warnings in the report, and -v prints each.
    const auto [again, verbose_run] = run(name, "-v");
    EXPECT_TRUE(again["up_to_date"].get<bool>());
    EXPECT_EQ(again["warnings"], warnings);
    for (const auto& w : warnings)
      EXPECT_NE(verbose_run.err.find(w.get<std::string>()), std::string::npos) << verbose_run.err;
    const auto [quiet, plain_run] = run(name, "");
    EXPECT_NE(plain_run.err.find(std::to_string(warnings.size()) + " warning"), std::string::npos) << plain_run.err;
  }
  // The output does not depend on where the tree is: no absolute path of it is kept.
  const auto bytes = ossa::test::read_text(out / "tri.ossa");
  ASSERT_TRUE(bytes);
  EXPECT_EQ(bytes->find(src.string()), std::string::npos);

  // An output written before the field existed: the same file without it (its vtable slot
  // cleared, as an older writer leaves it) is up to date and reports no warnings.
  auto file = ossa::test::read_file(out / "bare.ossa");
  ASSERT_TRUE(file);
  {
    const auto* root = ossa::fb::GetFile(file->data());
    const auto* prov = root->provenance();
    ASSERT_NE(prov->warnings(), nullptr);
    const auto* table = reinterpret_cast<const uint8_t*>(prov);
    int32_t soffset = 0;
    std::memcpy(&soffset, table, 4);
    uint8_t* vtable = file->data() + (table - file->data()) - soffset;
    uint16_t vtable_size = 0;
    std::memcpy(&vtable_size, vtable, 2);
    ASSERT_GT(vtable_size, ossa::fb::Provenance::VT_WARNINGS);
    std::memset(vtable + ossa::fb::Provenance::VT_WARNINGS, 0, 2);
    ASSERT_EQ(ossa::fb::GetFile(file->data())->provenance()->warnings(), nullptr);
  }
  ASSERT_TRUE(ossa::test::write_file(out / "bare.ossa", *file));
  ASSERT_TRUE(ossa::Asset::open((out / "bare.ossa").string()).ok());
  const auto [old, old_run] = run("bare.obj", "-v");
  EXPECT_TRUE(old["up_to_date"].get<bool>()) << "an older record is read, not a reason to cook";
  EXPECT_TRUE(old["warnings"].empty());
}

/// A pid that named a process a moment ago and names none now.
pid_t dead_pid() {
  const pid_t pid = ::fork();
  if (pid == 0) ::_exit(0);
  int status = 0;
  ::waitpid(pid, &status, 0);
  return pid;
}

TEST_F(CookOutputs, StaleTemporariesGoAtTheNextRunAndLiveOnesStay) {
  ASSERT_TRUE(ossa::test::write_file(src / "scene.obj", kObj));
  ASSERT_EQ(run_command(cook_cmd() + " " + q(src / "scene.obj") + " -o " + q(out) + " -q").exit_code, 0);
  const std::string name = "scene.ossa";
  const pid_t self = ::getpid();
  struct Temp {
    fs::path path;
    bool stale;
  };
  const Temp temps[] = {
      {out / ossa::cook::temporary_name(name, dead_pid(), 0), true},           // its writer is gone
      {out / ossa::cook::temporary_name(name, self, 7), false},                // a live writer, locked below
      {out / ossa::cook::temporary_name(name, self, 8), false},                // a live pid, not locked, fresh
      {out / ossa::cook::temporary_name(name, self, 9), true},                 // not locked and two hours old
      {out / ossa::cook::temporary_name("other.ossa", dead_pid(), 0), false},  // not this batch's output
  };
  for (const Temp& t : temps) ASSERT_TRUE(ossa::test::write_file(t.path, std::string(3 << 20, 'x')));
  const int lock_fd = ::open(temps[1].path.c_str(), O_RDONLY | O_CLOEXEC);
  ASSERT_EQ(::flock(lock_fd, LOCK_EX), 0);
  const auto two_hours_ago = fs::file_time_type::clock::now() - std::chrono::hours(2);
  fs::last_write_time(temps[3].path, two_hours_ago);
  fs::last_write_time(temps[1].path, two_hours_ago);  // old, but its lock says a writer holds it
  const auto r =
      run_command(cook_cmd() + " " + q(src / "scene.obj") + " -o " + q(out) + " --report " + q(dir / "r.json"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_TRUE(only_record(dir / "r.json")["up_to_date"].get<bool>());
  int wrong = 0;
  for (const Temp& t : temps) {
    const bool gone = !fs::exists(t.path);
    EXPECT_EQ(gone, t.stale) << t.path;
    wrong += gone != t.stale;
  }
  std::printf("stale temporaries: %zu left in the output folder, %d wrongly kept or removed\n", std::size(temps),
              wrong);
  ::close(lock_fd);
  EXPECT_TRUE(fs::exists(out / name));
}

TEST_F(CookOutputs, OutputNamesUpToNameMaxCookAndTheirTemporariesFit) {
  // Output names of 242..255 bytes (sources one byte shorter: ".obj" against ".ossa").
  for (size_t length = 242; length <= 255; ++length)
    ASSERT_TRUE(ossa::test::write_file(src / (std::string(length - 5, 'n') + ".obj"), kObj)) << length;
  const auto r = run_command(cook_cmd() + " " + q(src) + " -o " + q(out) + " -q");
  EXPECT_EQ(r.exit_code, 0) << r.err;
  size_t outputs = 0;
  for (const auto& e : fs::directory_iterator(out)) {
    EXPECT_EQ(e.path().extension(), ".ossa") << "nothing else is left: " << e.path();
    ++outputs;
  }
  EXPECT_EQ(outputs, 14u);
  for (size_t length : {228, 229, 255, 400}) {
    EXPECT_LE(ossa::cook::temporary_name(std::string(length, 'n'), 4194304, 4294967295u).size(), 255u) << length;
    EXPECT_NE(ossa::cook::temporary_prefix(std::string(length, 'n')),
              ossa::cook::temporary_prefix(std::string(length, 'm')));
  }
}

TEST_F(CookOutputs, WriteErrorsNameTheInputTheyConcern) {
  // A 255-byte source name makes a 256-byte output name: too long for any file system.
  const fs::path longest = src / (std::string(251, 'l') + ".obj");
  ASSERT_TRUE(ossa::test::write_file(longest, kObj));
  auto r = run_command(cook_cmd() + " " + q(longest) + " -o " + q(out) + " -q");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find(longest.string() + ": "), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("File name too long"), std::string::npos) << r.err;

  // A full disk: the file-size limit makes the same write(2) fail (EFBIG instead of ENOSPC).
  std::string big;
  for (int i = 0; i < 3000; ++i)
    big += "v " + std::to_string(i) + " 0 0\nv " + std::to_string(i) + " 1 0\nv " + std::to_string(i) + " 0 1\n";
  for (int i = 0; i < 3000; ++i)
    big += "f " + std::to_string(3 * i + 1) + " " + std::to_string(3 * i + 2) + " " + std::to_string(3 * i + 3) + "\n";
  ASSERT_TRUE(ossa::test::write_file(src / "big.obj", big));
  r = run_command("prlimit --fsize=65536 -- " + cook_cmd() + " " + q(src / "big.obj") + " -o " + q(out) + " -q");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(
      r.err.find((src / "big.obj").string() + ": " + (out / "big.ossa").string() + ": write failed: File too large"),
      std::string::npos)
      << r.err;
  EXPECT_EQ(r.err.find("signal"), std::string::npos) << "an error, not a signal: " << r.err;
  for (const auto& e : fs::directory_iterator(out)) ADD_FAILURE() << "left behind: " << e.path();

  // A read-only output is not replaced, and the message says for which input.
  ASSERT_TRUE(ossa::test::write_file(src / "ro.obj", kObj));
  ASSERT_EQ(run_command(cook_cmd() + " " + q(src / "ro.obj") + " -o " + q(out) + " -q").exit_code, 0);
  fs::permissions(out / "ro.ossa", fs::perms::owner_read | fs::perms::group_read | fs::perms::others_read);
  r = run_command(cook_cmd() + " " + q(src / "ro.obj") + " -o " + q(out) + " -q --force");
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find((src / "ro.obj").string() + ": " + (out / "ro.ossa").string() + ": is read-only"),
            std::string::npos)
      << r.err;
}

TEST_F(CookOutputs, AReportThatCannotBeWrittenDoesNotSilenceTheDepfile) {
  ASSERT_TRUE(ossa::test::write_file(src / "a.obj", kObj));
  ASSERT_TRUE(ossa::test::write_file(dir / "file", std::string_view("a file, not a folder")));
  const auto r = run_command(cook_cmd() + " " + q(src / "a.obj") + " -o " + q(out) + " -q --report " +
                             q(dir / "file" / "r.json") + " --depfile " + q(dir / "a.d"));
  EXPECT_EQ(r.exit_code, 1);
  EXPECT_NE(r.err.find("ossa-cook: report: " + (dir / "file" / "r.json").string()), std::string::npos) << r.err;
  const auto depfile = ossa::test::read_text(dir / "a.d");
  ASSERT_TRUE(depfile.has_value()) << "the depfile was skipped: " << r.err;
  EXPECT_NE(depfile->find((src / "a.obj").string()), std::string::npos) << *depfile;
}

}  // namespace
