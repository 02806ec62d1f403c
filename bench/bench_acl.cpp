// bench_acl.cpp — ossa-bench-acl: ossa's clip compression and playback against ACL's, clip by clip,
// on the same raw keys, judged by one error measure, timed in one process.
//
//   ossa-bench-acl [--assets DIR] [--runs N] [--min-poses N] [--no-timing] [--filter TEXT]
//                  [--metres-per-unit M] [SOURCE[@RIG_SOURCE]...]
//
// Built only when CMake is pointed at a local ACL checkout (-DOSSA_ACL_SOURCE_DIR, with RTM from
// -DOSSA_RTM_SOURCE_DIR or ACL's external/rtm): nothing is fetched, and CI does not build it.
// Without SOURCEs it runs every clip of the shared assets (--assets, default ../shared/assets):
// CMU 01_03 (BVH, read at --metres-per-unit, default CMU's 0.056444 m), Pab's six clips against
// Pab's rig, Pab's own clip, Fox, CesiumMan, RobotExpressive, RiggedSimple, the Quaternius
// characters and two Khronos samples: 110 clips. SOURCE@RIG_SOURCE cooks a clip-only source
// against RIG_SOURCE's cooked skeleton, as `ossa-cook --skeleton` does.
//
// Per clip:
//  - Raw keys: the source imported and sampled on its frame grid exactly as ossa-cook does
//    (import_scene, reference_samples). Both codecs get these floats and nothing else.
//  - ossa: compress_clip with the default options (0.1 mm at 10 cm), written and loaded as a file,
//    played with ossa::sample.
//  - ACL (acl_codec.h): the raw keys, the bind pose as default values, ossa's probe measure as its
//    error metric, default settings; its precision starts at the same 0.1 mm and is lowered (at
//    most 8 rounds) until the error measured below is within the bound, as ossa's cooker
//    guarantees: the two are compared at equal error. A clip ACL cannot bring within the bound
//    keeps its closest round and is flagged (acl_reached 0).
//  - Error, one measure for both (measure_clip below): the raw keys played as the runtime plays
//    them (ossa's interpolation between consecutive raw frames) against each candidate sampled at
//    the same times, every frame and three points between each pair of frames, both poses taken to
//    model space in double and compared with ossa::probe_error (<ossa/anim/pose_error.h>), the
//    measure ossa-cook reports. _frames columns: at the frames only.
//  - Bytes: ossa's cooked_bytes (the clip's stored vectors, as ossa-bench-compression counts them);
//    ACL's compressed_tracks::get_size() (its whole buffer).
//  - Time, in ns per whole pose, median over --runs interleaved runs (block order rotated each
//    run, warm caches): forward playback at 60 Hz through the clip, looping, and random seeks (the
//    same random times for both); ossa::sample into an SoA pose, ACL seek + decompress_tracks into
//    an rtm::qvvf array.
// Ratios are ossa / ACL (below 1: ossa smaller or faster). The last lines sum up the bytes and give
// the worst clips of each column.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <map>
#include <random>
#include <string>
#include <vector>

#include "bench/acl_codec.h"
#include "bench/clip_side_by_side.h"
#include "bench/cooked_rig.h"
#include "bench/machine.h"
#include "cooker/import/import_scene.h"

namespace fs = std::filesystem;
using namespace ossa;
using namespace ossa::bench;

namespace {

struct Source {
  std::string path;  // relative to --assets unless absolute
  std::string rig;   // "" or the rig's source, for clip-only files
};

std::vector<Source> default_sources() {
  std::vector<Source> s = {{"CMU_BVH/01_03.bvh", ""}};
  for (const char* clip : {"walk", "jog", "run", "crossarms", "atlas", "crackhead"})
    s.push_back({std::string("Pab/") + clip + ".fbx", "Pab/skeleton.fbx"});
  for (const char* main :
       {"Pab/skeleton.fbx", "Fox/Fox.glb", "CesiumMan/CesiumMan.glb", "RobotExpressive/RobotExpressive.glb",
        "RiggedSimple/RiggedSimple.glb", "Quaternius_Alien/Alien.fbx", "Quaternius_Cowboy/Cowboy.fbx",
        "Quaternius_Eagle/Eagle.fbx", "Quaternius_Male/Smooth_Male_Casual.fbx", "Quaternius_Robot/Robot.fbx",
        "Quaternius_Spider/Spider.fbx", "Quaternius_Trex/Trex.fbx", "Khronos_embedded/interpolation_test.gltf",
        "Khronos_embedded/box_animated.gltf"})
    s.push_back({main, ""});
  return s;
}

int usage() {
  std::fprintf(stderr,
               "usage: ossa-bench-acl [--assets DIR] [--runs N] [--min-poses N] [--no-timing] [--filter TEXT]\n"
               "                      [--metres-per-unit M] [SOURCE[@RIG_SOURCE]...]\n");
  return 2;
}

double median(std::vector<double> v) {
  if (v.empty()) return 0.0;
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

struct Row {
  std::string asset, clip;
  uint32_t joints = 0, frames = 0;
  uint32_t ossa_bytes = 0, acl_bytes = 0;
  ClipMeasure ossa_err, acl_err;
  double acl_precision = 0.0;  // in metres
  bool acl_reached = false;
  uint32_t acl_segments = 0;
  double ossa_fwd = 0, acl_fwd = 0, ossa_rand = 0, acl_rand = 0;
};

/// ACL at equal error: the precision lowered until the measured error is within `tolerance`.
std::unique_ptr<AclClip> acl_within(const SideBySideClip& c, double tolerance, Row& row, std::string* error) {
  double precision = tolerance;
  std::unique_ptr<AclClip> best;
  for (int round = 0; round < 9; ++round) {
    std::unique_ptr<AclClip> acl = AclClip::compress(c.raw, precision, c.shell, error);
    if (!acl) return nullptr;
    const ClipMeasure m = measure_clip(c, [&](float t, PoseSpan out) { acl->sample(t, out); });
    const bool better = !best || m.max() < row.acl_err.max();
    if (better) {
      row.acl_err = m;
      row.acl_precision = precision * c.metres_per_unit;
      best = std::move(acl);
    }
    if (m.max() <= tolerance) {
      row.acl_reached = true;
      break;
    }
    precision *= std::min(0.9, tolerance / m.max() * 0.97);
  }
  return best;
}

void time_clip(SideBySideClip& c, AclClip& acl, int runs, uint32_t min_poses, Row& row) {
  const float duration = c.clip.duration();
  std::vector<float> forward;
  for (uint32_t k = 0; forward.size() < min_poses; ++k) {
    const float t = static_cast<float>(k) / 60.0f;
    forward.push_back(duration > 0.0f ? std::fmod(t, duration) : 0.0f);
  }
  std::vector<float> random(forward.size());
  std::mt19937 rng(12345);
  std::uniform_real_distribution<float> unit(0.0f, 1.0f);
  for (float& t : random) t = std::min(unit(rng) * duration, std::nextafter(duration, 0.0f));
  if (!(duration > 0.0f)) std::fill(random.begin(), random.end(), 0.0f);

  auto block = [&](int b) {
    switch (b) {
      case 0: return time_ossa(c, c.forward_cache, forward);
      case 1: return time_ossa(c, c.random_cache, random);
      case 2: return acl.time_poses(forward);
      default: return acl.time_poses(random);
    }
  };
  std::vector<double> t[4];
  for (int b = 0; b < 4; ++b) block(b);  // warm-up
  for (int r = 0; r < runs; ++r)
    for (int i = 0; i < 4; ++i) t[(i + r) % 4].push_back(block((i + r) % 4));
  row.ossa_fwd = median(t[0]);
  row.ossa_rand = median(t[1]);
  row.acl_fwd = median(t[2]);
  row.acl_rand = median(t[3]);
}

double ratio(double a, double b) { return b > 0.0 ? a / b : 0.0; }

void print_row(const Row& r, double mm) {
  std::printf(
      "%s\t%s\t%u\t%u\t%u\t%u\t%.3f\t%.4f\t%.4f\t%.4f\t%.4f\t%.5f\t%d\t%u\t%.1f\t%.1f\t%.2f\t%.1f\t%.1f\t%.2f\n",
      r.asset.c_str(), r.clip.c_str(), r.joints, r.frames, r.ossa_bytes, r.acl_bytes, ratio(r.ossa_bytes, r.acl_bytes),
      r.ossa_err.max() * mm, r.acl_err.max() * mm, r.ossa_err.at_frames * mm, r.acl_err.at_frames * mm,
      r.acl_precision * 1000.0, r.acl_reached ? 1 : 0, r.acl_segments, r.ossa_fwd, r.acl_fwd,
      ratio(r.ossa_fwd, r.acl_fwd), r.ossa_rand, r.acl_rand, ratio(r.ossa_rand, r.acl_rand));
  std::printf("# %s/%s: worst joint ossa %u at frame %.2f, ACL %u at frame %.2f\n", r.asset.c_str(), r.clip.c_str(),
              r.ossa_err.worst_joint, static_cast<double>(r.ossa_err.worst_frame), r.acl_err.worst_joint,
              static_cast<double>(r.acl_err.worst_frame));
  std::fflush(stdout);
}

/// The closing lines: byte totals, clips over ACL or over the bound, and each ratio's worst clips.
void print_summary(const std::vector<Row>& rows, const std::vector<double>& mm, double tolerance_mm, bool timing) {
  uint64_t ossa = 0, acl = 0;
  size_t larger = 0, over = 0, acl_over = 0;
  for (size_t i = 0; i < rows.size(); ++i) {
    ossa += rows[i].ossa_bytes;
    acl += rows[i].acl_bytes;
    larger += rows[i].ossa_bytes > rows[i].acl_bytes;
    over += rows[i].ossa_err.max() * mm[i] > tolerance_mm;
    acl_over += !rows[i].acl_reached;
  }
  std::printf(
      "# clips %zu: bytes ossa %llu, ACL %llu, ratio %.3f; ossa larger than ACL on %zu clips; ossa over "
      "%.4g mm on %zu clips (ACL not brought within it on %zu)\n",
      rows.size(), static_cast<unsigned long long>(ossa), static_cast<unsigned long long>(acl),
      ratio(static_cast<double>(ossa), static_cast<double>(acl)), larger, tolerance_mm, over, acl_over);
  const auto worst = [&](const char* what, auto key) {
    std::vector<size_t> order(rows.size());
    for (size_t i = 0; i < order.size(); ++i) order[i] = i;
    std::stable_sort(order.begin(), order.end(), [&](size_t a, size_t b) { return key(a) > key(b); });
    double sum_log = 0.0;
    for (size_t i = 0; i < rows.size(); ++i) sum_log += std::log(std::max(key(i), 1e-9));
    std::printf("# %s: geometric mean %.3f; worst:", what, std::exp(sum_log / std::max<size_t>(1, rows.size())));
    for (size_t k = 0; k < std::min<size_t>(6, order.size()); ++k)
      std::printf(" %s/%s %.3f;", rows[order[k]].asset.c_str(), rows[order[k]].clip.c_str(), key(order[k]));
    std::printf("\n");
  };
  worst("bytes ossa/ACL", [&](size_t i) { return ratio(rows[i].ossa_bytes, rows[i].acl_bytes); });
  worst("error ossa mm", [&](size_t i) { return rows[i].ossa_err.max() * mm[i]; });
  if (!timing) return;
  worst("forward ns ossa/ACL", [&](size_t i) { return ratio(rows[i].ossa_fwd, rows[i].acl_fwd); });
  worst("random access ns ossa/ACL", [&](size_t i) { return ratio(rows[i].ossa_rand, rows[i].acl_rand); });
  double fwd[2] = {0, 0}, rnd[2] = {0, 0};
  for (const Row& r : rows) {
    fwd[0] += r.ossa_fwd / r.joints, fwd[1] += r.acl_fwd / r.joints;
    rnd[0] += r.ossa_rand / r.joints, rnd[1] += r.acl_rand / r.joints;
  }
  const double n = static_cast<double>(std::max<size_t>(1, rows.size()));
  std::printf("# mean ns per joint: forward ossa %.2f, ACL %.2f (%.3f); random access ossa %.2f, ACL %.2f (%.3f)\n",
              fwd[0] / n, fwd[1] / n, ratio(fwd[0], fwd[1]), rnd[0] / n, rnd[1] / n, ratio(rnd[0], rnd[1]));
}

}  // namespace

int main(int argc, char** argv) {
  std::string assets = OSSA_BENCH_SHARED_ASSETS, filter;
  int runs = 7;
  uint32_t min_poses = 2048;
  bool timing = true;
  float bvh_unit = 0.056444f;  // CMU's mocap unit (1/0.45 inch), as the shared assets' README states
  std::vector<Source> sources;
  for (int i = 1; i < argc; ++i) {
    const std::string a = argv[i];
    const bool more = i + 1 < argc;
    if (a == "--assets" && more) assets = argv[++i];
    else if (a == "--runs" && more) runs = std::max(1, std::atoi(argv[++i]));
    else if (a == "--min-poses" && more) min_poses = static_cast<uint32_t>(std::max(1, std::atoi(argv[++i])));
    else if (a == "--no-timing") timing = false;
    else if (a == "--filter" && more) filter = argv[++i];
    else if (a == "--metres-per-unit" && more) bvh_unit = std::strtof(argv[++i], nullptr);
    else if (!a.empty() && a[0] == '-') return usage();
    else if (const size_t at = a.find('@'); at != std::string::npos)
      sources.push_back({a.substr(0, at), a.substr(at + 1)});
    else sources.push_back({a, ""});
  }
  if (!(bvh_unit > 0.0f)) return usage();
  if (sources.empty()) sources = default_sources();
  const auto resolve = [&](const std::string& p) {
    return fs::path(p).is_absolute() ? fs::path(p) : fs::path(assets) / p;
  };

  std::printf("# %s\n# %s, built %s; ossa-cook's defaults (%.4g mm at %.4g cm probes)\n", machine_line().c_str(),
              acl_version().c_str(), OSSA_BENCH_BUILD, kToleranceMetres * 1000.0, kProbeMetres * 100.0);
  std::printf(
      "# bytes: ossa cooked_bytes / ACL get_size(); errors in mm, the larger of frames and between frames "
      "(_frames: frames only); times in ns per pose, median of %d runs\n",
      runs);
  std::printf(
      "asset\tclip\tjoints\tframes\tossa_bytes\tacl_bytes\tbytes_ratio\tossa_mm\tacl_mm\tossa_frames_mm"
      "\tacl_frames_mm\tacl_precision_mm\tacl_reached\tacl_segments\tossa_fwd_ns\tacl_fwd_ns\tfwd_ratio"
      "\tossa_rand_ns\tacl_rand_ns\trand_ratio\n");
  std::map<std::string, cook::SourceSkeleton> rigs;
  std::vector<Row> rows;
  std::vector<double> mm_per_unit;
  int status = 0;
  for (const Source& s : sources) {
    cook::ImportOptions options;
    options.metres_per_unit = fs::path(s.path).extension() == ".bvh" ? bvh_unit : 0.0f;
    if (!s.rig.empty()) {
      if (!rigs.count(s.rig)) {
        auto rig = cooked_rig(resolve(s.rig));
        if (!rig) {
          std::fprintf(stderr, "ossa-bench-acl: %s\n", rig.error().message.c_str());
          status = 1;
          continue;
        }
        rigs.emplace(s.rig, std::move(*rig));
      }
      options.reference = &rigs.at(s.rig);
    }
    auto file = cook_side_by_side(resolve(s.path).string(), options);
    if (!file) {
      std::fprintf(stderr, "ossa-bench-acl: %s\n", file.error().message.c_str());
      status = 1;
      continue;
    }
    for (SideBySideClip& c : file->clips) {
      Row row;
      row.asset = s.path;
      row.clip = std::string(c.clip.name());
      if (!filter.empty() && (row.asset + "/" + row.clip).find(filter) == std::string::npos) continue;
      row.joints = c.raw.joints;
      row.frames = c.raw.frames;
      row.ossa_bytes = c.ossa_bytes;
      row.ossa_err = measure_clip(c, [&](float t, PoseSpan out) { sample_ossa(c, t, out); });
      std::string error;
      const double tolerance = kToleranceMetres / c.metres_per_unit;
      std::unique_ptr<AclClip> acl = acl_within(c, tolerance, row, &error);
      if (!acl) {
        std::fprintf(stderr, "ossa-bench-acl: %s: clip '%s': ACL: %s\n", s.path.c_str(), row.clip.c_str(),
                     error.c_str());
        status = 1;
        continue;
      }
      row.acl_bytes = acl->bytes();
      row.acl_segments = acl->segments();
      if (timing) time_clip(c, *acl, runs, min_poses, row);
      print_row(row, c.metres_per_unit * 1000.0);
      rows.push_back(row);
      mm_per_unit.push_back(c.metres_per_unit * 1000.0);
    }
  }
  print_summary(rows, mm_per_unit, kToleranceMetres * 1000.0, timing);
  return status;
}
