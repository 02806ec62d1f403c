// main.cpp — the ossa-cook command line: parse options, plan, cook in parallel, report.
// Inputs are sources (FBX, glTF, ...) and animation graph files (`*.graph.json`, docs/GRAPH.md).
//
//   ossa-cook INPUT... -o OUTDIR [--root DIR] [--jobs N] [--report FILE.json]
//             [--skeleton REF.ossa] [--float-vertices] [--clip-tolerance MM] [--no-clip-compression]
//             [--root-motion] [--up-axis x|y|z] [--quiet]
//
// Exit status: 0 when every input cooked, 1 when any failed (the rest are still cooked), 2 for a
// usage error or a plan that cannot be carried out (nothing is written then).
#include <unistd.h>

#include <cstdio>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include <CLI/CLI.hpp>

#include "cooker/batch.h"
#include "cooker/cook.h"
#include "format/version.h"

namespace fs = std::filesystem;
using namespace ossa::cook;

namespace {

std::string human_bytes(uint64_t n) {
  char buf[32];
  if (n >= 1u << 20) std::snprintf(buf, sizeof buf, "%.2f MiB", static_cast<double>(n) / (1 << 20));
  else if (n >= 1u << 10) std::snprintf(buf, sizeof buf, "%.1f KiB", static_cast<double>(n) / (1 << 10));
  else std::snprintf(buf, sizeof buf, "%llu B", static_cast<unsigned long long>(n));
  return buf;
}

void print_summary(const std::vector<CookRecord>& records) {
  std::printf("%-40s %7s %7s %9s %6s %12s %12s\n", "output", "joints", "meshes", "vertices", "clips", "source",
              "cooked");
  for (const CookRecord& r : records) {
    if (!r.ok) continue;
    std::printf("%-40s %7u %7u %9u %6u %12s %12s\n", r.output.c_str(), r.joints, r.meshes, r.vertices, r.clips,
                human_bytes(r.source_bytes).c_str(), human_bytes(r.cooked_bytes).c_str());
  }
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{"ossa-cook: cook FBX / glTF / GLB / Collada / BVH sources and animation graph files (*.graph.json) "
               "into .ossa files"};
  std::vector<std::string> inputs;
  std::string out_dir, root, report_path, skeleton_path;
  unsigned jobs = std::max(1u, std::thread::hardware_concurrency());
  bool float_vertices = false, quiet = false, lossless_clips = false, root_motion = false;
  double clip_tolerance_mm = 0.1;
  std::string up_axis = "y";
  app.add_option("inputs", inputs, "source files, graph files (X.graph.json -> X.ossa) or directories (searched recursively)")
      ->required();
  app.add_option("-o,--output", out_dir, "output directory")->required();
  app.add_option("--root", root, "mirror inputs' paths relative to this directory under the output directory");
  app.add_option("-j,--jobs", jobs, "cook this many files in parallel")->check(CLI::Range(1u, 256u));
  app.add_option("--report", report_path, "write a JSON record per input to this file");
  app.add_option("--skeleton", skeleton_path, "cook clip-only files against this cooked skeleton (.ossa)");
  app.add_flag("--float-vertices", float_vertices, "store vertices as float32 instead of quantized");
  app.add_option("--clip-tolerance", clip_tolerance_mm,
                 "largest model-space error of any joint, in millimetres at 10 cm from it (default 0.1)")
      ->check(CLI::Range(1e-6, 1e4));
  app.add_flag("--no-clip-compression", lossless_clips, "keep every clip key exact (raw floats at every frame)");
  app.add_flag("--root-motion", root_motion, "extract root translation and yaw from clips into a root-motion track");
  app.add_option("--up-axis", up_axis, "up axis for --root-motion")->check(CLI::IsMember({"x", "y", "z"}));
  app.add_flag("-q,--quiet", quiet, "print only failures");
  app.set_version_flag("--version", std::string(ossa::kCookerVersion));
  CLI11_PARSE(app, argc, argv);

  CookOptions options;
  options.float_vertices = float_vertices;
  options.clips.enabled = !lossless_clips;
  options.clips.tolerance_metres = static_cast<float>(clip_tolerance_mm / 1000.0);
  options.root_motion = root_motion;
  options.up_axis = static_cast<uint8_t>(up_axis == "x" ? 0 : up_axis == "z" ? 2 : 1);
  SourceSkeleton reference;
  if (!skeleton_path.empty()) {
    auto loaded = load_reference_skeleton(skeleton_path);
    if (!loaded) {
      std::fprintf(stderr, "ossa-cook: --skeleton %s\n", loaded.error().message.c_str());
      return 2;
    }
    reference = std::move(*loaded);
    options.reference = &reference;
    options.reference_name = fs::path(skeleton_path).filename().string();
  }

  std::vector<fs::path> input_paths(inputs.begin(), inputs.end());
  auto plan = plan_batch(input_paths, out_dir, root);
  if (!plan) {
    std::fprintf(stderr, "ossa-cook: %s\n", plan.error().message.c_str());
    return 2;
  }
  if (plan->empty()) {
    std::fprintf(stderr, "ossa-cook: no source files found in the inputs given\n");
    return 2;
  }

  const bool tty = ::isatty(STDERR_FILENO) != 0;
  auto progress = [&](size_t done, size_t total, const CookRecord& r) {
    if (!r.ok) {
      std::fprintf(stderr, "%s[%zu/%zu] FAILED %s\n", tty ? "\r\033[K" : "", done, total, r.error.c_str());
    } else if (!quiet) {
      if (tty) std::fprintf(stderr, "\r\033[K[%zu/%zu] %s (%.0f ms)", done, total, r.input.c_str(), r.seconds * 1e3);
      else std::fprintf(stderr, "[%zu/%zu] %s -> %s (%.0f ms)\n", done, total, r.input.c_str(), r.output.c_str(),
                        r.seconds * 1e3);
    }
    for (const std::string& w : r.warnings)
      if (!quiet) std::fprintf(stderr, "%swarning: %s: %s\n", tty ? "\r\033[K" : "", r.input.c_str(), w.c_str());
    if (tty && done == total && !quiet) std::fprintf(stderr, "\n");
    std::fflush(stderr);
  };
  const std::vector<CookRecord> records = run_batch(*plan, options, jobs, progress);

  size_t failed = 0;
  for (const CookRecord& r : records) failed += r.ok ? 0 : 1;
  if (!report_path.empty()) {
    const std::string text = report_json(records, options).dump(2) + "\n";
    if (ossa::Status st = write_file_atomic(report_path, std::vector<uint8_t>(text.begin(), text.end())); !st) {
      std::fprintf(stderr, "ossa-cook: report: %s\n", st.message().c_str());
      return 1;
    }
  }
  if (!quiet) print_summary(records);
  if (failed > 0) {
    std::fprintf(stderr, "ossa-cook: %zu of %zu inputs failed:\n", failed, records.size());
    for (const CookRecord& r : records) {
      if (r.ok) continue;
      std::string indented = r.error;  // graph files report one problem per line
      for (size_t at = indented.find('\n'); at != std::string::npos; at = indented.find('\n', at + 3))
        indented.replace(at, 1, "\n  ");
      std::fprintf(stderr, "  %s\n", indented.c_str());
    }
    return 1;
  }
  return 0;
}
