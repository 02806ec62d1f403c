// bench_load.cpp — ossa-bench-load: how much faster is opening a cooked file than importing its
// source with Assimp, the thesis's loader and its stated future-work bottleneck?
//
//   ossa-bench-load [--min-seconds S] ASSET...
//
// Each ASSET (a source file) is cooked in-process with default options into a temporary directory.
// Then, in this one process and one after the other, it times (a) Assimp::Importer::ReadFile with
// the cooker's import flags and settings, and (b) ossa::Asset::open = read (mmap past 4 MiB) + FlatBuffers verify +
// semantic checks (+ unmap), and (c) the physical limit of (b): a plain open + read + close of the
// same .ossa bytes into a buffer allocated once, outside the timing, and (d) the same with the
// fstat that a loader which learns the file's size from the file needs (Asset::open does; on the
// 2-core PVM VM the issue was measured on, each system call costs ~1.5 us, so (d) is 1.2-1.4x (c)
// on small files). (b), (c) and (d) run interleaved, one call of each per round, so a noisy
// neighbour slows all three alike. Assimp is repeated for at least --min-seconds and 5 runs, the
// three others together for at least --min-seconds and 200 rounds; medians are reported. Output:
// a tab-separated table with a header, one row per asset:
//   asset source_bytes cooked_bytes assimp_import_ms ossa_open_ms read_ms open_over_read
//   stat_read_ms open_over_stat_read speedup
// open_over_read is ossa_open_ms / read_ms (what opening costs over reading the bytes),
// open_over_stat_read is ossa_open_ms / stat_read_ms; speedup is assimp_import_ms / ossa_open_ms.
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <functional>
#include <memory>
#include <string>
#include <vector>

#include <fcntl.h>
#include <unistd.h>

#include <assimp/Importer.hpp>
#include <assimp/postprocess.h>
#include <assimp/config.h>
#include <assimp/scene.h>

#include "cooker/cook.h"
#include "cooker/import/import_scene.h"
#include <ossa/loader/asset.h>
#include "bench/machine.h"
#include "bench/plain_read.h"

namespace fs = std::filesystem;
using Clock = std::chrono::steady_clock;

namespace {

/// Median of run()'s duration over at least min_runs runs and min_seconds; setup() runs before
/// each run, untimed.
template <class S, class F>
double median_ms(double min_seconds, int min_runs, S&& setup, F&& run) {
  std::vector<double> samples;
  const auto start = Clock::now();
  while (static_cast<int>(samples.size()) < min_runs ||
         std::chrono::duration<double>(Clock::now() - start).count() < min_seconds) {
    setup();
    const auto t0 = Clock::now();
    if (!run()) return -1.0;
    samples.push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
    if (samples.size() >= 100000) break;
  }
  std::sort(samples.begin(), samples.end());
  return samples[samples.size() / 2];
}

/// Medians of each of runs' durations, the runs called in turn once per round, for at least
/// min_rounds rounds and min_seconds; an empty result when a run fails.
std::vector<double> interleaved_medians_ms(double min_seconds, int min_rounds,
                                           const std::vector<std::function<bool()>>& runs) {
  std::vector<std::vector<double>> samples(runs.size());
  const auto start = Clock::now();
  while (static_cast<int>(samples[0].size()) < min_rounds ||
         std::chrono::duration<double>(Clock::now() - start).count() < min_seconds) {
    for (size_t r = 0; r < runs.size(); ++r) {
      const auto t0 = Clock::now();
      if (!runs[r]()) return std::vector<double>(runs.size(), -1.0);
      samples[r].push_back(std::chrono::duration<double, std::milli>(Clock::now() - t0).count());
    }
    if (samples[0].size() >= 100000) break;
  }
  std::vector<double> medians;
  for (std::vector<double>& s : samples) {
    std::sort(s.begin(), s.end());
    medians.push_back(s[s.size() / 2]);
  }
  return medians;
}

}  // namespace

int main(int argc, char** argv) {
  double min_seconds = 1.0;
  std::vector<fs::path> assets;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    if (a == "--min-seconds" && i + 1 < argc) min_seconds = std::atof(argv[++i]);
    else if (a == "-h" || a == "--help") {
      std::printf("usage: ossa-bench-load [--min-seconds S] ASSET...\n");
      return 0;
    } else assets.emplace_back(a);
  }
  if (assets.empty()) {
    std::fprintf(stderr, "usage: ossa-bench-load [--min-seconds S] ASSET...\n");
    return 2;
  }
  const fs::path tmp = fs::temp_directory_path() / ("ossa-bench-load-" + std::to_string(::getpid()));
  int status = 0;
  std::printf("# %s\n", ossa::bench::machine_line().c_str());
  std::printf(
      "asset\tsource_bytes\tcooked_bytes\tassimp_import_ms\tossa_open_ms\tread_ms\topen_over_read\t"
      "stat_read_ms\topen_over_stat_read\tspeedup\n");
  for (size_t i = 0; i < assets.size(); ++i) {
    const fs::path& src = assets[i];
    const fs::path cooked = tmp / (std::to_string(i) + "-" + src.stem().string() + ".ossa");
    const ossa::cook::CookRecord rec = ossa::cook::cook_file(src, cooked, {});
    if (!rec.ok) {
      std::fprintf(stderr, "ossa-bench-load: %s\n", rec.error.c_str());
      status = 1;
      continue;
    }
    // A fresh importer per run, made outside the timed region: Assimp 5.2.5's BVH importer fails
    // on the second ReadFile of a reused Importer ("Unexpected end of file").
    // The cooker's flags plus the welding a runtime loading through Assimp would ask for.
    const unsigned flags = ossa::cook::assimp_import_flags() | aiProcess_JoinIdenticalVertices;
    std::unique_ptr<Assimp::Importer> importer;
    const double assimp_ms = median_ms(
        min_seconds, 5,
        [&] {
          importer = std::make_unique<Assimp::Importer>();
          importer->SetPropertyBool(AI_CONFIG_IMPORT_FBX_PRESERVE_PIVOTS, false);
        },
        [&] { return importer->ReadFile(src.string(), flags) != nullptr; });
    std::vector<char> buffer(static_cast<size_t>(rec.cooked_bytes));
    const std::vector<double> loads =
        interleaved_medians_ms(min_seconds, 200,
                               {[&] { return ossa::Asset::open(cooked.string()).ok(); },
                                [&] { return ossa::bench::read_whole(cooked, buffer); },
                                [&] { return ossa::bench::stat_read_whole(cooked, buffer); }});
    const double ossa_ms = loads[0], read_ms = loads[1], stat_read_ms = loads[2];
    if (assimp_ms < 0 || ossa_ms < 0 || read_ms < 0 || stat_read_ms < 0) {
      std::fprintf(stderr, "ossa-bench-load: %s: load failed during timing\n", src.string().c_str());
      status = 1;
      continue;
    }
    std::printf("%s\t%llu\t%llu\t%.3f\t%.4f\t%.4f\t%.2f\t%.4f\t%.2f\t%.0f\n", src.filename().string().c_str(),
                static_cast<unsigned long long>(rec.source_bytes), static_cast<unsigned long long>(rec.cooked_bytes),
                assimp_ms, ossa_ms, read_ms, ossa_ms / read_ms, stat_read_ms, ossa_ms / stat_read_ms,
                assimp_ms / ossa_ms);
    std::fflush(stdout);
  }
  std::error_code ec;
  fs::remove_all(tmp, ec);
  return status;
}
