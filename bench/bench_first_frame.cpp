// bench_first_frame.cpp — ossa-bench-first-frame: how long from starting a viewer process to its
// first finished frame, for a cooked file versus the same source loaded through Assimp?
//
//   ossa-bench-first-frame [--runs N] [--size WxH] [--msaa N] [--assets DIR] [--shared DIR] [SOURCE...]
//
// The repo's samples (CesiumMan, Fox, RiggedSimple, Pab's skeleton.fbx, and Pab's arnaud.fbx
// cooked against that skeleton, as scripts/demo.sh does) — or the SOURCE files given instead —
// are cooked in-process into a temporary directory. Then, per asset, N runs of each variant alternate, each a fresh
// child process:
//   cooked: ossa-view FILE.ossa --frames 1 --first-frame-time --no-grid (the real viewer,
//           headless, drawing only the character as the other side does);
//   assimp: this program re-run as --assimp-child SOURCE (bench/first_frame_assimp.h).
// Both create a hidden GLFW window with a 3.3 core context and draw one frame into an offscreen
// framebuffer of the same size and multisampling, then glFinish and print a line. The time is
// taken here, in the parent: from just before posix_spawn to reading that line, so process start,
// dynamic linking, context creation, loading, upload and the frame all count, the same way for
// both. Output: a table of medians (asset, cooked ms, assimp ms, speedup) and the GPU memory each
// side's textures took (the children print it; the cooked side's is its BC / RGBA8 mip chains,
// the Assimp side's RGBA8 plus the chain glGenerateMipmap makes). The textured characters of
// ../shared/assets (AnimeBoy) join the repo's samples when that folder is there, and a last row
// loads every character there at once: one process per side shows each in turn, one frame each
// (first_frame_ossa.cpp, first_frame_assimp.h). Needs an X display
// (run under `xvfb-run -a` on a machine without one). Not a test: the numbers depend on the
// machine; docs/MEASURING.md quotes one run.
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
#include "bench/machine.h"

extern char** environ;
namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

struct Asset {
  std::string label;
  fs::path source;
  fs::path cooked;
};

struct ChildRun {
  double ms = 0.0;
  uint64_t texture_bytes = 0;  // GPU memory the child's textures took (its "texture-bytes" line)
};

/// Spawns argv with stdout on a pipe; returns the milliseconds until a line starting with
/// "first-frame-ms" arrives and the "texture-bytes" the child printed before it, or nullopt when
/// the child fails (its stderr is passed through).
std::optional<ChildRun> time_child(const std::vector<std::string>& args) {
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
  uint64_t texture_bytes = 0;
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
      if (line.rfind("first-frame-ms", 0) == 0)
        ms = std::chrono::duration<double, std::milli>(Clock::now() - t0).count();
      if (line.rfind("texture-bytes ", 0) == 0) texture_bytes = std::strtoull(line.c_str() + 14, nullptr, 10);
      line.clear();
    }
  }
  close(fds[0]);
  int status = 0;
  waitpid(pid, &status, 0);
  if (!WIFEXITED(status) || WEXITSTATUS(status) != 0 || !ms) return std::nullopt;
  return ChildRun{*ms, texture_bytes};
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
  fs::path shared_dir = OSSA_BENCH_SOURCE_DIR "/../shared/assets";
  bool assimp_child = false, ossa_child = false, empty_child = false;
  std::vector<fs::path> sources;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool has_value = i + 1 < argc;
    if (a == "--runs" && has_value) runs = std::max(1, std::atoi(argv[++i]));
    else if (a == "--msaa" && has_value) samples = std::max(1, std::atoi(argv[++i]));
    else if (a == "--assets" && has_value) assets_dir = argv[++i];
    else if (a == "--shared" && has_value) shared_dir = argv[++i];
    else if (a == "--assimp-child") assimp_child = true;
    else if (a == "--ossa-child") ossa_child = true;
    else if (a == "--empty-child") empty_child = true;
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
      std::printf(
          "usage: ossa-bench-first-frame [--runs N] [--size WxH] [--msaa N] [--assets DIR] [--shared DIR] "
          "[SOURCE...]\n");
      return a == "-h" || a == "--help" ? 0 : 2;
    }
  }
  if (assimp_child || ossa_child) {
    std::vector<std::string> files;
    for (const fs::path& p : sources) files.push_back(p.string());
    return assimp_child ? ossa::bench::run_assimp_first_frame(files, width, height, samples)
                        : ossa::bench::run_ossa_first_frame(files, width, height, samples);
  }
  if (empty_child) return ossa::bench::run_empty_first_frame(width, height, samples);

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
  // The textured characters of ../shared/assets, where it is beside the checkout.
  std::error_code exists_ec;
  if (fs::exists(shared_dir / "AnimeBoy/scene.gltf", exists_ec))
    assets.push_back({"AnimeBoy (13 tex)", shared_dir / "AnimeBoy/scene.gltf", tmp / "AnimeBoy.ossa"});
  if (!sources.empty()) {
    assets.clear();
    for (size_t i = 0; i < sources.size(); ++i) {
      assets.push_back({sources[i].stem().string(), sources[i], tmp / (std::to_string(i) + ".ossa")});
    }
  }
  // Every character of ../shared/assets at once (one process each side, each shown in turn): the
  // first .glb / .gltf / .fbx of each folder whose cook has a mesh.
  std::vector<fs::path> all_sources, all_cooked;
  if (sources.empty() && fs::is_directory(shared_dir, exists_ec)) {
    std::vector<fs::path> folders;
    for (const auto& e : fs::directory_iterator(shared_dir, exists_ec))
      if (e.is_directory()) folders.push_back(e.path());
    std::sort(folders.begin(), folders.end());
    for (const fs::path& folder : folders) {
      std::vector<fs::path> files;
      for (const auto& e : fs::directory_iterator(folder, exists_ec)) {
        const std::string ext = e.path().extension().string();
        if (e.is_regular_file() && (ext == ".glb" || ext == ".gltf" || ext == ".fbx")) files.push_back(e.path());
      }
      std::sort(files.begin(), files.end());
      if (files.empty()) continue;
      const fs::path out = tmp / "all" / (folder.filename().string() + ".ossa");
      ossa::cook::CookOptions options;
      const ossa::cook::CookRecord rec = ossa::cook::cook_file(files.front(), out, options);
      if (!rec.ok || rec.meshes.value_or(0) == 0) continue;  // clip-only folders (Pab's clips, CMU)
      all_sources.push_back(files.front());
      all_cooked.push_back(out);
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
  std::printf("# %s\n", ossa::bench::machine_line().c_str());
  std::printf("# first frame, process start to glFinish, median of %d runs, %s, MSAA %s\n", runs, size.c_str(),
              msaa.c_str());
  std::printf(
      "# texture MiB: GPU memory of the textures each side uploaded (cooked: the file's mip chains;\n"
      "# assimp: RGBA8 + glGenerateMipmap's chain)\n");
  std::printf(
      "# floor: a child making the same context and framebuffer and drawing nothing; 'over floor' is\n"
      "# each side's median minus the floor's (the work it does for its asset)\n");
  std::printf("%-20s %9s %9s %9s %7s %9s %9s %7s %10s %10s %6s\n", "asset", "cooked ms", "assimp ms", "floor ms",
              "speedup", "ossa over", "asmp over", "speedup", "cooked tex", "assimp tex", "tex");
  const auto mib = [](uint64_t b) { return static_cast<double>(b) / (1024.0 * 1024.0); };
  const std::vector<std::string> frame_args = {"--size", size, "--msaa", msaa};
  const auto with = [&](std::vector<std::string> head, const std::vector<std::string>& tail) {
    head.insert(head.end(), tail.begin(), tail.end());
    return head;
  };
  /// One row: N alternating runs of the cooked, Assimp and floor children; medians printed.
  const auto row = [&](const std::string& label, const std::vector<std::string>& cooked_cmd,
                       const std::vector<std::string>& assimp_cmd) {
    std::vector<double> cooked, assimp, floor;
    uint64_t cooked_tex = 0, assimp_tex = 0;
    for (int r = 0; r < runs; ++r) {
      const auto c = time_child(cooked_cmd);
      const auto s = time_child(assimp_cmd);
      const auto e = time_child(with({self, "--empty-child"}, frame_args));
      if (!c || !s || !e) {
        std::fprintf(stderr, "ossa-bench-first-frame: %s: a run failed\n", label.c_str());
        status = 1;
        return;
      }
      cooked.push_back(c->ms);
      assimp.push_back(s->ms);
      floor.push_back(e->ms);
      cooked_tex = c->texture_bytes;
      assimp_tex = s->texture_bytes;
    }
    const double mc = median(cooked), ms = median(assimp), mf = median(floor);
    const double oc = mc - mf, os = ms - mf;
    // Within the floor's noise (one run, a busy machine) a ratio over it means nothing: "-".
    char over_ratio[32] = "-";
    if (oc >= 1.0 && os >= 1.0) std::snprintf(over_ratio, sizeof over_ratio, "%.2fx", os / oc);
    char tex_ratio[32] = "-";
    if (assimp_tex > 0)
      std::snprintf(tex_ratio, sizeof tex_ratio, "%.3f",
                    static_cast<double>(cooked_tex) / static_cast<double>(assimp_tex));
    std::printf("%-20s %9.1f %9.1f %9.1f %6.2fx %9.1f %9.1f %7s %10.2f %10.2f %6s\n", label.c_str(), mc, ms, mf,
                ms / mc, oc, os, over_ratio, mib(cooked_tex), mib(assimp_tex), tex_ratio);
    std::fflush(stdout);
  };
  for (const Asset& a : assets)
    row(a.label, with({viewer, a.cooked.string(), "--frames", "1", "--first-frame-time", "--no-grid"}, frame_args),
        with({self, "--assimp-child", a.source.string()}, frame_args));
  if (!all_sources.empty()) {
    std::vector<std::string> cooked_cmd = with({self, "--ossa-child"}, frame_args),
                             assimp_cmd = with({self, "--assimp-child"}, frame_args);
    for (const fs::path& p : all_cooked) cooked_cmd.push_back(p.string());
    for (const fs::path& p : all_sources) assimp_cmd.push_back(p.string());
    row("all " + std::to_string(all_sources.size()) + " shared", cooked_cmd, assimp_cmd);
  }
  std::error_code ec;
  fs::remove_all(tmp, ec);
  return status;
}
