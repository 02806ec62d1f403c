// bench_first_frame.cpp — ossa-bench-first-frame: how long from starting a viewer process to its
// first finished frame, for a cooked file versus the same source loaded through Assimp?
//
//   ossa-bench-first-frame [--runs N] [--size WxH] [--msaa N] [--assets DIR] [SOURCE...]
//
// The repo's samples (CesiumMan, Fox, RiggedSimple, Pab's skeleton.fbx, and Pab's arnaud.fbx
// cooked against that skeleton, as scripts/demo.sh does) — or the SOURCE files given instead —
// are cooked in-process into a temporary directory. Then, per asset, N runs of each variant alternate, each a fresh child process:
//   cooked: ossa-view FILE.ossa --frames 1 --first-frame-time --no-grid (the real viewer,
//           headless, drawing only the character as the other side does);
//   assimp: this program re-run as --assimp-child SOURCE (bench/first_frame_assimp.h).
// Both create a hidden GLFW window with a 3.3 core context and draw one frame into an offscreen
// framebuffer of the same size and multisampling, then glFinish and print a line. The time is
// taken here, in the parent: from just before posix_spawn to reading that line, so process start,
// dynamic linking, context creation, loading, upload and the frame all count, the same way for
// both. Output: a table of medians (asset, cooked ms, assimp ms, ratio). Needs an X display
// (run under `xvfb-run -a` on a machine without one). Not a test: the numbers depend on the
// machine; the README quotes one run.
#include <fcntl.h>
#include <poll.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "bench/first_frame_assimp.h"
#include "cooker/cook.h"
#include "viewer/options.h"

extern char** environ;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

struct Asset {
  std::string label;
  fs::path source;
  fs::path cooked;
};

/// Spawns argv with stdout on a pipe; returns the milliseconds until a line starting with
/// "first-frame-ms" arrives, or nullopt when the child fails (its stderr is passed through).
std::optional<double> time_child(const std::vector<std::string>& args) {
  int fds[2];
  if (pipe(fds) != 0) return std::nullopt;
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addclose(&actions, fds[0]);
  posix_spawn_file_actions_adddup2(&actions, fds[1], STDOUT_FILENO);
  posix_spawn_file_actions_addclose(&actions, fds[1]);
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  pid_t pid = -1;
  const auto t0 = Clock::now();
  const int rc = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  close(fds[1]);
  if (rc != 0) {
    close(fds[0]);
    std::fprintf(stderr, "ossa-bench-first-frame: cannot start %s: %s\n", argv[0], std::strerror(rc));
    return std::nullopt;
  }
  std::optional<double> ms;
  std::string line;
  pollfd p{fds[0], POLLIN, 0};
  while (!ms && poll(&p, 1, 60000) > 0) {
    char buf[256];
    const ssize_t n = read(fds[0], buf, sizeof buf);
    if (n <= 0) break;
    for (ssize_t i = 0; i < n && !ms; ++i) {
      if (buf[i] != '\n') {
        line += buf[i];
        continue;
      }
      if (line.rfind("first-frame-ms", 0) == 0) ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
      line.clear();
    }
  }
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) return std::nullopt;
  return ms;
}

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  return v.empty() ? -1.0 : v[v.size() / 2];
}

fs::path self_dir() {
  std::error_code ec;
  const fs::path exe = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::path(".") : exe.parent_path();
}

}  // namespace

int main(int argc, char** argv) {
  int runs = 7, width = 640, height = 480, samples = 4;
  fs::path assets_dir = OSSA_BENCH_SOURCE_DIR "/assets";
  std::string child_source;
  std::vector<fs::path> sources;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--runs" && has_value) runs = std::max(1, std::atoi(argv[++i]));
    else if (a == "--msaa" && has_value) samples = std::max(1, std::atoi(argv[++i]));
    else if (a == "--assets" && has_value) assets_dir = argv[++i];
    else if (a == "--assimp-child" && has_value) child_source = argv[++i];
    else if (a == "--size" && has_value) {
      const auto wh = ossa::view::parse_size(argv[++i]);
      if (!wh) {
        std::fprintf(stderr, "--size: expected WxH\n");
        return 2;
      }
      width = wh->first;
      height = wh->second;
    } else if (!a.empty() && a[0] != '-') {
      sources.emplace_back(a);
    } else {
      std::printf("usage: ossa-bench-first-frame [--runs N] [--size WxH] [--msaa N] [--assets DIR] [SOURCE...]\n");
      return a == "-h" || a == "--help" ? 0 : 2;
    }
  }
  if (!child_source.empty()) return ossa::bench::run_assimp_first_frame(child_source, width, height, samples);

  if (const char* d = std::getenv("DISPLAY"); d == nullptr || *d == '\0') {
    std::fprintf(stderr, "ossa-bench-first-frame: needs an X display (DISPLAY is not set): run it under xvfb-run -a\n");
    return 2;
  }
  const fs::path tmp = fs::temp_directory_path() / ("ossa-bench-first-frame-" + std::to_string(getpid()));
  std::vector<Asset> assets = {
      {"CesiumMan", assets_dir / "CesiumMan/CesiumMan.glb", tmp / "CesiumMan.ossa"},
      {"Fox", assets_dir / "Fox/Fox.glb", tmp / "Fox.ossa"},
      {"RiggedSimple", assets_dir / "RiggedSimple/RiggedSimple.glb", tmp / "RiggedSimple.ossa"},
      {"Pab skeleton", assets_dir / "Pab/skeleton.fbx", tmp / "skeleton.ossa"},
      {"Pab arnaud", assets_dir / "Pab/arnaud.fbx", tmp / "arnaud.ossa"},
  };
  if (!sources.empty()) {
    assets.clear();
    for (size_t i = 0; i < sources.size(); ++i) {
      assets.push_back({sources[i].stem().string(), sources[i], tmp / (std::to_string(i) + ".ossa")});
    }
  }
  // Cook as scripts/demo.sh does: arnaud against the cooked Pab skeleton.
  int status = 0;
  ossa::cook::SourceSkeleton reference;
  for (Asset& a : assets) {
    ossa::cook::CookOptions options;
    if (sources.empty() && a.label == "Pab arnaud") {
      auto r = ossa::cook::load_reference_skeleton(tmp / "skeleton.ossa");
      if (!r) {
        std::fprintf(stderr, "ossa-bench-first-frame: %s\n", r.error().message.c_str());
        return 1;
      }
      reference = std::move(*r);
      options.reference = &reference;
      options.reference_name = "skeleton.ossa";
    }
    const ossa::cook::CookRecord rec = ossa::cook::cook_file(a.source, a.cooked, options);
    if (!rec.ok) {
      std::fprintf(stderr, "ossa-bench-first-frame: %s\n", rec.error.c_str());
      return 1;
    }
  }

  const std::string viewer = (self_dir() / "ossa-view").string();
  const std::string self = (self_dir() / "ossa-bench-first-frame").string();
  const std::string size = std::to_string(width) + "x" + std::to_string(height), msaa = std::to_string(samples);
  std::printf("# first frame, process start to glFinish, median of %d runs, %s, MSAA %s\n", runs, size.c_str(), msaa.c_str());
  std::printf("%-20s %10s %10s %7s\n", "asset", "cooked ms", "assimp ms", "ratio");
  for (const Asset& a : assets) {
    std::vector<double> cooked, assimp;
    for (int r = 0; r < runs; ++r) {
      const auto c = time_child({viewer, a.cooked.string(), "--frames", "1", "--first-frame-time", "--no-grid", "--size",
                                 size, "--msaa", msaa});
      const auto s = time_child({self, "--assimp-child", a.source.string(), "--size", size, "--msaa", msaa});
      if (!c || !s) {
        std::fprintf(stderr, "ossa-bench-first-frame: %s: a run failed\n", a.label.c_str());
        status = 1;
        break;
      }
      cooked.push_back(*c);
      assimp.push_back(*s);
    }
    if (cooked.empty()) continue;
    const double mc = median(cooked), ms = median(assimp);
    std::printf("%-20s %10.1f %10.1f %6.2fx\n", a.label.c_str(), mc, ms, ms / mc);
    std::fflush(stdout);
  }
  std::error_code ec;
  fs::remove_all(tmp, ec);
  return status;
}
