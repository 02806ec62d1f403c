// bench_compression.cpp — ossa-bench-compression: what clip compression achieves, one row per clip.
//
//   ossa-bench-compression [--skeleton REF_SOURCE] [--clip-tolerance MM] [--metres-per-unit M] ASSET...
//
// Each ASSET is imported and its clips compressed in-process, exactly as ossa-cook does it
// (import_scene, then compress_clip with the file's metres_per_unit), at the default tolerance and,
// when --clip-tolerance is given, again at that one. --metres-per-unit overrides the file's unit as
// `ossa-cook --metres-per-unit` does (BVH states none and is read as 1 m; CMU's mocap unit is
// 1/0.45 inch = 0.056444 m): the tolerance is in millimetres, so the unit decides how many source
// units it spans, and a clip measured in the wrong unit is measured at the wrong tolerance. --skeleton cooks REF_SOURCE first (cook_file,
// into a temporary directory) and reads the skeleton back from the cooked file
// (load_reference_skeleton), so clip-only files such as Pab/walk.fbx are measured against the
// same rig, with the same floats, as `ossa-cook --skeleton REF.ossa` would cook them.
//
// Output: tab-separated on stdout, header
//   asset clip joints unit_m raw_bytes cooked_bytes ratio max_error_mm mean_error_mm tolerance_mm
// unit_m is the metres per source unit the clip was measured in (the file's, or --metres-per-unit),
// so a row says which unit its ratio holds for. The tolerance_mm column is always there (not only
// with --clip-tolerance) so the table has one shape whatever the options. raw_bytes is 10 floats per joint per frame; cooked_bytes is the sum
// of the clip's vectors' bytes (constants, animated, key_frames, key_values with its padding),
// table overhead excluded (CompressedClip::cooked_bytes). Errors are in millimetres through the
// file's metres_per_unit. Exit status 1 when any asset fails (its error on stderr), 2 on usage.
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "cooker/clip/clip_compress.h"
#include "cooker/cook.h"
#include "cooker/import/import_scene.h"
#include "bench/machine.h"

namespace fs = std::filesystem;
using namespace ossa::cook;

namespace {

int usage() {
  std::fprintf(stderr, "usage: ossa-bench-compression [--skeleton REF_SOURCE] [--clip-tolerance MM] [--metres-per-unit M] "
                       "ASSET...\n");
  return 2;
}

/// Cooks `source` into a scratch directory and loads its skeleton back, as --skeleton REF.ossa does.
ossa::Result<SourceSkeleton> cooked_reference(const fs::path& source) {
  const fs::path dir = fs::temp_directory_path() / ("ossa-bench-compression-" + std::to_string(::getpid()));
  const fs::path out = dir / (source.stem().string() + ".ossa");
  const CookRecord record = cook_file(source, out, CookOptions{});
  ossa::Result<SourceSkeleton> skeleton = record.ok ? load_reference_skeleton(out)
                                                    : ossa::Result<SourceSkeleton>(ossa::Error{record.error});
  std::error_code ec;
  fs::remove_all(dir, ec);
  return skeleton;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> assets;
  std::string skeleton_source;
  double extra_tolerance_mm = 0.0;
  double metres_per_unit = 0.0;  // 0: the file's
  for (int i = 1; i < argc; ++i) {
    const std::string arg = argv[i];
    if (arg == "--skeleton" && i + 1 < argc) {
      skeleton_source = argv[++i];
    } else if (arg == "--clip-tolerance" && i + 1 < argc) {
      char* end = nullptr;
      extra_tolerance_mm = std::strtod(argv[++i], &end);
      if (*end != '\0' || !(extra_tolerance_mm > 0.0)) return usage();
    } else if (arg == "--metres-per-unit" && i + 1 < argc) {
      char* end = nullptr;
      metres_per_unit = std::strtod(argv[++i], &end);
      // ossa-cook's range (cooker/cli/main.cpp)
      if (*end != '\0' || !(metres_per_unit >= 1e-6 && metres_per_unit <= 1e6)) return usage();
    } else if (arg == "-h" || arg == "--help" || (!arg.empty() && arg[0] == '-')) {
      return usage();
    } else {
      assets.push_back(arg);
    }
  }
  if (assets.empty()) return usage();

  ImportOptions import_options;
  import_options.metres_per_unit = static_cast<float>(metres_per_unit);
  SourceSkeleton reference;
  if (!skeleton_source.empty()) {
    auto loaded = cooked_reference(skeleton_source);
    if (!loaded) {
      std::fprintf(stderr, "ossa-bench-compression: --skeleton %s\n", loaded.error().message.c_str());
      return 1;
    }
    reference = std::move(*loaded);
    import_options.reference = &reference;
  }

  std::vector<ClipCompressionOptions> settings(1);  // the default tolerance first
  if (extra_tolerance_mm > 0.0) {
    settings.emplace_back();
    settings.back().tolerance_metres = static_cast<float>(extra_tolerance_mm / 1000.0);
  }

  std::printf("# %s\n", ossa::bench::machine_line().c_str());
  std::printf("asset\tclip\tjoints\tunit_m\traw_bytes\tcooked_bytes\tratio\tmax_error_mm\tmean_error_mm\ttolerance_mm\n");
  int status = 0;
  for (const std::string& asset : assets) {
    auto scene = import_scene(asset, import_options);
    if (!scene) {
      std::fprintf(stderr, "ossa-bench-compression: %s\n", scene.error().message.c_str());
      status = 1;
      continue;
    }
    const double mm_per_unit = static_cast<double>(scene->metres_per_unit) * 1000.0;
    for (const ClipCompressionOptions& options : settings) {
      for (const SourceClip& clip : scene->clips) {
        auto compressed = compress_clip(clip, scene->skeleton, scene->metres_per_unit, options);
        if (!compressed) {
          std::fprintf(stderr, "ossa-bench-compression: %s: %s\n", asset.c_str(), compressed.error().message.c_str());
          status = 1;
          continue;
        }
        const CompressedClip& c = *compressed;
        std::printf("%s\t%s\t%zu\t%g\t%u\t%u\t%.2f\t%.4f\t%.4f\t%g\n", fs::path(asset).filename().string().c_str(),
                    c.name.c_str(), scene->skeleton.joints.size(), static_cast<double>(scene->metres_per_unit), c.raw_bytes, c.cooked_bytes,
                    c.cooked_bytes ? static_cast<double>(c.raw_bytes) / c.cooked_bytes : 0.0,
                    c.max_error * mm_per_unit, c.mean_error * mm_per_unit,
                    static_cast<double>(options.tolerance_metres) * 1000.0);
      }
    }
  }
  return status;
}
