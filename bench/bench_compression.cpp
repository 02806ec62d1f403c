// bench_compression.cpp — ossa-bench-compression: what clip compression achieves, one row per clip.
//
//   ossa-bench-compression [--skeleton REF_SOURCE] [--clip-tolerance MM] [--metres-per-unit M]
//                          [--breakdown] ASSET...
//
// Each ASSET is imported and its clips compressed in-process, exactly as ossa-cook does it
// (import_scene, then compress_clip with the file's metres_per_unit), at the default tolerance and,
// when --clip-tolerance is given, again at that one. --metres-per-unit overrides the file's unit as
// `ossa-cook --metres-per-unit` does (BVH states none and is read as 1 m; CMU's mocap unit is
// 1/0.45 inch = 0.056444 m): the tolerance is in millimetres, so the unit decides how many source
// units it spans, and a clip measured in the wrong unit is measured at the wrong tolerance.
// --skeleton cooks REF_SOURCE first (cook_file, into a temporary directory) and reads the skeleton
// back from the cooked file (load_reference_skeleton), so clip-only files such as Pab/walk.fbx are
// measured against the same rig, with the same floats, as `ossa-cook --skeleton REF.ossa` would
// cook them.
//
// Output: tab-separated on stdout, header
//   asset clip joints unit_m raw_bytes cooked_bytes ratio max_error_mm mean_error_mm tolerance_mm
// unit_m is the metres per source unit the clip was measured in (the file's, or --metres-per-unit),
// so a row says which unit its ratio holds for. The tolerance_mm column is always there (not only
// with --clip-tolerance) so the table has one shape whatever the options. raw_bytes is 10 floats
// per joint per frame; cooked_bytes is the sum of the clip's vectors' bytes (constants, animated,
// key_frames, key_values with its padding), table overhead excluded (CompressedClip::cooked_bytes).
// Errors are in millimetres through the file's metres_per_unit. Exit status 1 when any asset fails
// (its error on stderr), 2 on usage.
//
// --breakdown follows each row with comment lines (starting "# ", so the rows stay one table for
// whatever reads it) saying where the clip's cooked_bytes go, which is what choosing the next
// compression change needs: the four stored vectors (constants, channel records, key_frames,
// key_values: they sum to cooked_bytes); the animated channels keyed at every frame (their key
// frames are one shared run) against those with keys removed (values and key-frame bytes apart);
// and how many channels of each kind use each bit count (32: raw floats).
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <set>
#include <string>
#include <vector>

#include "cooker/clip/clip_compress.h"
#include "cooker/cook.h"
#include "cooker/import/import_scene.h"
#include "bench/cooked_rig.h"
#include "bench/machine.h"
#include <ossa/format/clip_codec.h>
#include <ossa/format/ossa_generated.h>

namespace fs = std::filesystem;
using namespace ossa::cook;

namespace {

int usage() {
  std::fprintf(stderr,
               "usage: ossa-bench-compression [--skeleton REF_SOURCE] [--clip-tolerance MM] [--metres-per-unit M] "
               "[--breakdown] ASSET...\n");
  return 2;
}

/// Bits of one channel's keys in key_values (raw floats start byte-aligned: up to 7 bits more each).
uint64_t value_bits(const CompressedAnimated& a) { return a.key_count * a.bits.total(); }

/// --breakdown: where cooked_bytes go (see the header comment).
void print_breakdown(const CompressedClip& c) {
  const char* name = c.name.c_str();
  const size_t constant_bytes = c.constants.size() * sizeof(ossa::fb::ConstantChannel);
  const size_t record_bytes = c.animated.size() * sizeof(ossa::fb::AnimatedChannel);
  const size_t frame_bytes = c.key_frames.size() * sizeof(uint16_t);
  std::printf(
      "# %s: constants %zu x %zu = %zu B + channel records %zu x %zu = %zu B + key_frames %zu x 2 = %zu B"
      " + key_values %zu B = %zu B\n",
      name, c.constants.size(), sizeof(ossa::fb::ConstantChannel), constant_bytes, c.animated.size(),
      sizeof(ossa::fb::AnimatedChannel), record_bytes, c.key_frames.size(), frame_bytes, c.key_values.size(),
      constant_bytes + record_bytes + frame_bytes + c.key_values.size());
  const uint32_t frames = c.grid.frame_count;
  size_t every_channels = 0, reduced_channels = 0;
  uint64_t every_keys = 0, reduced_keys = 0, every_bits = 0, reduced_bits = 0;
  std::set<uint32_t> reduced_runs;  // first_key of the key-frame runs the reduced channels read
  uint64_t reduced_run_frames = 0;
  std::map<uint32_t, uint32_t> bits_used[3];  // per channel kind: bits per key -> channels
  for (const CompressedAnimated& a : c.animated) {
    if (a.key_count == frames) {
      ++every_channels;
      every_keys += a.key_count;
      every_bits += value_bits(a);
    } else {
      ++reduced_channels;
      reduced_keys += a.key_count;
      reduced_bits += value_bits(a);
      if (reduced_runs.insert(a.first_key).second) reduced_run_frames += a.key_count;
    }
    if (a.channel < 3) ++bits_used[a.channel][static_cast<uint32_t>(a.bits.total())];
  }
  std::printf(
      "# %s: keyed at every frame: %zu channels, %llu keys, %.0f B of values (no key frames stored, %u frames);"
      " keys removed: %zu channels, %llu of %llu frames kept, %.0f B of values, %llu B of key frames"
      " (%zu runs)\n",
      name, every_channels, static_cast<unsigned long long>(every_keys), static_cast<double>(every_bits) / 8.0, frames,
      reduced_channels, static_cast<unsigned long long>(reduced_keys),
      static_cast<unsigned long long>(reduced_channels) * frames, static_cast<double>(reduced_bits) / 8.0,
      static_cast<unsigned long long>(reduced_run_frames * sizeof(uint16_t)), reduced_runs.size());
  static const char* const kKinds[3] = {"translation", "rotation", "scale"};
  std::printf("# %s: bits per key (bits:channels):", name);
  for (int k = 0; k < 3; ++k) {
    std::printf(" %s", kKinds[k]);
    if (bits_used[k].empty()) std::printf(" -");
    for (const auto& [bits, count] : bits_used[k]) std::printf(" %u:%u", bits, count);
    std::printf(k < 2 ? ";" : "\n");
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> assets;
  std::string skeleton_source;
  double extra_tolerance_mm = 0.0;
  double metres_per_unit = 0.0;  // 0: the file's
  bool breakdown = false;
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
    } else if (arg == "--breakdown") {
      breakdown = true;
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
    auto loaded = ossa::bench::cooked_rig(skeleton_source);
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
  std::printf(
      "asset\tclip\tjoints\tunit_m\traw_bytes\tcooked_bytes\tratio\tmax_error_mm\tmean_error_mm"
      "\ttolerance_mm\n");
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
                    c.name.c_str(), scene->skeleton.joints.size(), static_cast<double>(scene->metres_per_unit),
                    c.raw_bytes, c.cooked_bytes,
                    c.cooked_bytes ? static_cast<double>(c.raw_bytes) / c.cooked_bytes : 0.0, c.max_error * mm_per_unit,
                    c.mean_error * mm_per_unit, static_cast<double>(options.tolerance_metres) * 1000.0);
        if (breakdown) print_breakdown(c);
      }
    }
  }
  return status;
}
