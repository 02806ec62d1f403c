// bench_vs_ozz.cpp — ossa-bench-vs-ozz: ossa and ozz-animation 0.16.0 side by side, in one process,
// on the same character, and the ratios ossa / ozz.
//
//   ossa-bench-vs-ozz [--rounds N] [--media DIR] [--clone baseline|avx2|avx512]
//
// Built only when CMake is given a local ozz-animation checkout (-DOSSA_OZZ_SOURCE_DIR=...,
// bench/ozz/CMakeLists.txt); nothing is fetched. ozz runs twice: as its own build makes it (-O3, its
// SSE2 math) and built with -O3 -mavx2 -mfma (ozz_side.h). ossa runs its default build's code with
// its run-time dispatch (the machine line names the copies that ran).
//
// Data. ossa cooks assets/Pab (skeleton, walk, jog, run, arnaud: bench_fixture.h) with default
// options; ozz loads its own media of the same FBX files (pab_*.ozz, arnaud_mesh.ozz from
// <ozz>/media/bin). Both skeletons have 67 joints; ozz splits arnaud into parts by influence
// count, ossa welds and orders it by influence class, so vertex counts differ and the skinning
// ratios are per vertex. Sampling walks the same times (60 Hz forward playback, looping; the seek
// workload's times from seek_fraction), pose workloads use the same nudges of each side's rest
// pose (nudge()).
//
// Method. Every round times one batch of each workload on each side, the sides' order rotating
// round by round, so a neighbour's burst hits all three alike; a batch lasts ~100 us. Printed per
// workload: the median over rounds of ns per call (and the minimum), ns per joint or vertex, and
// ossa / ozz per joint or vertex against both builds and the faster one. Rows with a target
// (ossa <= 0.75x the faster ozz build) say whether it is met. Only ratios from one run mean
// anything: the first line names the CPU.
#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "bench/bench_fixture.h"
#include "bench/machine.h"
#include "bench/ozz/ozz_side.h"
#include <ossa/anim/pose.h>
#include <ossa/anim/pose_ops.h>
#include <ossa/anim/sample.h>
#include <ossa/skinning/skinning.h>

#ifndef OSSA_OZZ_MEDIA_DIR
#define OSSA_OZZ_MEDIA_DIR ""
#endif

namespace {

using Clock = std::chrono::steady_clock;
using ossa::bench::AnchorCall;
using ossa::bench::AnchorSide;

constexpr size_t kTimes = 4096;

[[noreturn]] void die(const std::string& what) {
  std::fprintf(stderr, "ossa-bench-vs-ozz: %s\n", what.c_str());
  std::exit(1);
}

ossa::SamplingCache cache_or_die(const ossa::ClipView& clip, const ossa::SkeletonView& skeleton) {
  auto cache = ossa::make_sampling_cache(clip, skeleton);
  if (!cache) die(cache.error().message);
  return std::move(*cache);
}

/// ossa's bind pose with nudge(seed, j) applied to every joint (ozz_side.h); rotation only unless `trs`.
ossa::Pose nudged_bind_pose(const ossa::SkeletonView& skeleton, uint32_t seed, bool trs) {
  ossa::Pose pose(uint32_t(skeleton.joint_count()));
  ossa::set_bind_pose(skeleton, pose);
  for (uint32_t j = 0; j < pose.joint_count(); ++j) {
    ossa::Transform t = ossa::get_transform(pose, j);
    const ossa::bench::Nudge n = ossa::bench::nudge(seed, j);
    const glm::vec3 axis = glm::normalize(glm::vec3(n.axis[0], n.axis[1], n.axis[2]));
    t.rotation = glm::normalize(t.rotation * glm::angleAxis(n.angle, axis));
    if (trs) {
      t.translation += glm::vec3(n.move[0], n.move[1], n.move[2]) * (0.01f * (1.0f + glm::length(t.translation)));
      t.scale *= 1.0f + 0.02f * n.scale;
    }
    ossa::set_transform(pose, j, t);
  }
  return pose;
}

/// ossa's side of every workload; the calls point into this object, which outlives them.
struct OssaSide {
  const ossa::bench::BenchData& data = ossa::bench::bench_data();
  ossa::SkeletonView skeleton = data.skeleton.skeleton();
  uint32_t joints = uint32_t(skeleton.joint_count());
  ossa::ClipView clips[3] = {data.walk.clip(0), data.jog.clip(0), data.run.clip(0)};
  ossa::MeshView mesh = data.arnaud.mesh(0);

  struct Sampler {
    ossa::ClipView clip;
    ossa::SamplingCache cache;
    ossa::Pose pose;
    std::vector<float> times;
    size_t next = 0;
  };
  Sampler forward{clips[0], cache_or_die(clips[0], skeleton), ossa::Pose(joints), {}};
  Sampler seek{clips[0], cache_or_die(clips[0], skeleton), ossa::Pose(joints), {}};

  ossa::Pose inputs[3] = {nudged_bind_pose(skeleton, 17, true), nudged_bind_pose(skeleton, 18, true),
                          nudged_bind_pose(skeleton, 19, true)};
  ossa::Pose blended{joints};
  std::vector<glm::mat4> model = std::vector<glm::mat4>(joints);

  ossa::SamplingCache frame_caches[3] = {cache_or_die(clips[0], skeleton), cache_or_die(clips[1], skeleton),
                                         cache_or_die(clips[2], skeleton)};
  ossa::Pose frame_poses[3] = {ossa::Pose(joints), ossa::Pose(joints), ossa::Pose(joints)};
  ossa::Pose frame_blended{joints};
  std::vector<glm::mat4> frame_model = std::vector<glm::mat4>(joints);
  std::vector<glm::mat4> bind, palette;
  std::vector<float> phase;
  size_t frame_next = 0;

  std::vector<glm::mat4> skin_palette;
  std::vector<float> positions, normals;
  ossa::SkinnedStreams positions_only, with_normals, with_normals_raw;

  OssaSide() {
    float t = 0.0f;
    forward.times.resize(kTimes);
    for (float& x : forward.times) {
      x = t;
      t = ossa::advance_time(t, 1.0f / 60.0f, 1.0f, clips[0].duration(), true);
    }
    seek.times.resize(kTimes);
    for (size_t i = 0; i < kTimes; ++i) seek.times[i] = ossa::bench::seek_fraction(uint32_t(i)) * clips[0].duration();

    const size_t slots = std::max<size_t>(1, mesh.joints().size());
    bind.resize(slots);
    palette.resize(slots);
    ossa::prepare_bind_matrices(mesh, bind);  // once, at load, as a game would
    phase.resize(kTimes);
    for (size_t i = 0; i < kTimes; ++i) {
      const float p = float(i) / 60.0f / clips[0].duration();
      phase[i] = p - float(int(p));
    }

    const ossa::Pose nudged = nudged_bind_pose(skeleton, 29, false);
    std::vector<glm::mat4> m(joints);
    ossa::local_to_model(skeleton.parents(), nudged, m);
    skin_palette.resize(slots);
    ossa::skinning_matrices(mesh, m, skin_palette);
    positions.resize(3 * size_t(mesh.vertex_count()));
    normals.resize(positions.size());
    positions_only = {positions, {}, {}};
    with_normals = {positions, normals, {}};
    with_normals_raw = {positions, normals, {}};
    with_normals_raw.renormalize = false;
  }

  void sample(Sampler& s) {
    ossa::sample(s.clip, s.times[s.next], {}, s.cache, s.pose);
    s.next = (s.next + 1) & (kTimes - 1);
  }
  void blend3() {
    const ossa::ConstPoseSpan in[3] = {inputs[0], inputs[1], inputs[2]};
    const float w[3] = {0.5f, 0.3f, 0.2f};
    ossa::blend_n(in, w, blended);
  }
  void to_model() { ossa::local_to_model(skeleton.parents(), inputs[0], model); }
  void frame() {
    const float p = phase[frame_next];
    frame_next = (frame_next + 1) & (kTimes - 1);
    for (int c = 0; c < 3; ++c) ossa::sample(clips[c], p * clips[c].duration(), {}, frame_caches[c], frame_poses[c]);
    const ossa::ConstPoseSpan in[3] = {frame_poses[0], frame_poses[1], frame_poses[2]};
    const float w[3] = {0.2f, 0.5f, 0.3f};
    ossa::blend_n(in, w, frame_blended);
    ossa::local_to_model(skeleton.parents(), frame_blended, frame_model);
    ossa::skinning_matrices(mesh.joints(), bind, frame_model, palette);
  }
  void skin(const ossa::SkinnedStreams& out) { ossa::skin_cpu(mesh, skin_palette, ossa::SkinningMethod::Linear, out); }
};

template <class F>
AnchorCall call_of(F* f) {
  return {[](void* p) { (*static_cast<F*>(p))(); }, f};
}

struct Row {
  const char* name;
  ossa::bench::AnchorWorkload anchor;
  bool per_vertex;
  bool target;  // ossa <= 0.75x the faster ozz build
};

double median(std::vector<double> v) {
  std::sort(v.begin(), v.end());
  const size_t n = v.size();
  return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

}  // namespace

int main(int argc, char** argv) {
  std::string error;
  if (!ossa::bench::apply_clone(argc, argv, &error)) die(error);
  int rounds = 101;
  std::string media = OSSA_OZZ_MEDIA_DIR;
  for (int i = 1; i < argc; ++i) {
    if (std::strcmp(argv[i], "--rounds") == 0 && i + 1 < argc) {
      rounds = std::max(3, std::atoi(argv[++i]));
    } else if (std::strcmp(argv[i], "--media") == 0 && i + 1 < argc) {
      media = argv[++i];
    } else {
      std::fprintf(stderr, "usage: ossa-bench-vs-ozz [--rounds N] [--media DIR] [--clone baseline|avx2|avx512]\n");
      return 2;
    }
  }
  std::printf("# %s\n", ossa::bench::machine_line().c_str());

  // The sides: ossa, ozz -O3, ozz -O3 -mavx2 -mfma (where the CPU has AVX2 and FMA).
  AnchorSide sides[3];
  const char* names[3] = {"ossa", "ozz -O3", "ozz avx2"};
  OssaSide ossa_side;
  auto forward = [&] { ossa_side.sample(ossa_side.forward); };
  auto seek = [&] { ossa_side.sample(ossa_side.seek); };
  auto blend3 = [&] { ossa_side.blend3(); };
  auto to_model = [&] { ossa_side.to_model(); };
  auto frame = [&] { ossa_side.frame(); };
  auto skin_p = [&] { ossa_side.skin(ossa_side.positions_only); };
  auto skin_n = [&] { ossa_side.skin(ossa_side.with_normals); };
  auto skin_raw = [&] { ossa_side.skin(ossa_side.with_normals_raw); };
  sides[0].joints = ossa_side.joints;
  sides[0].vertices = ossa_side.mesh.vertex_count();
  sides[0].palette = uint32_t(ossa_side.palette.size());
  AnchorCall ossa_calls[8] = {call_of(&forward), call_of(&seek),   call_of(&blend3), call_of(&to_model),
                              call_of(&frame),   call_of(&skin_p), call_of(&skin_n), call_of(&skin_raw)};
  if (!ossa::bench::ozz_side_o3(media.c_str(), &sides[1])) die(sides[1].error);
  __builtin_cpu_init();
  const bool avx2 = __builtin_cpu_supports("avx2") && __builtin_cpu_supports("fma");
  if (avx2 && !ossa::bench::ozz_side_avx2(media.c_str(), &sides[2])) die(sides[2].error);
  const int side_count = avx2 ? 3 : 2;
  for (int s = 0; s < side_count; ++s)
    std::printf("# %-8s joints %u, arnaud vertices %u, palette %u\n", names[s], sides[s].joints, sides[s].vertices,
                sides[s].palette);

  const Row rows[] = {
      {"sample forward", ossa::bench::kSampleForward, false, true},
      {"sample seek", ossa::bench::kSampleSeek, false, false},
      {"blend 3", ossa::bench::kBlend3, false, false},
      {"local-to-model", ossa::bench::kLocalToModel, false, false},
      {"frame", ossa::bench::kFrame, false, true},
      {"skin positions", ossa::bench::kSkinPositions, true, true},
      {"skin pos+normals", ossa::bench::kSkinNormals, true, true},
      {"skin pos+nrm raw", ossa::bench::kSkinNormals, true, false},  // ossa not renormalizing, as ozz never does
  };
  constexpr size_t kRows = sizeof rows / sizeof rows[0];
  const auto call = [&](size_t row, int side) {
    return side == 0 ? ossa_calls[row] : sides[side].run[rows[row].anchor];
  };

  // Batch sizes: ~100 us of the slowest side, measured once after a warm-up.
  int reps[kRows];
  for (size_t r = 0; r < kRows; ++r) {
    double slowest = 0.0;
    for (int s = 0; s < side_count; ++s) {
      const AnchorCall c = call(r, s);
      for (int i = 0; i < 64; ++i) c.fn(c.state);
      const auto start = Clock::now();
      for (int i = 0; i < 64; ++i) c.fn(c.state);
      slowest = std::max(slowest, std::chrono::duration<double>(Clock::now() - start).count() / 64);
    }
    reps[r] = std::max(1, int(100e-6 / std::max(slowest, 1e-9)));
  }
  std::vector<double> ns[kRows][3];
  for (int round = 0; round < rounds; ++round) {
    for (size_t r = 0; r < kRows; ++r) {
      for (int k = 0; k < side_count; ++k) {
        const int s = (round + k) % side_count;
        const AnchorCall c = call(r, s);
        const auto start = Clock::now();
        for (int i = 0; i < reps[r]; ++i) c.fn(c.state);
        ns[r][s].push_back(std::chrono::duration<double, std::nano>(Clock::now() - start).count() / reps[r]);
      }
    }
  }

  std::printf(
      "# %d rounds; ns per call: median (min); ratios of medians per joint or vertex; "
      "target: ossa <= 0.75x the faster ozz build\n",
      rounds);
  std::printf("%-17s %-8s %17s %17s %17s %9s %9s %9s  %s\n", "workload", "unit", "ossa", "ozz -O3", "ozz avx2",
              "ossa/O3", "ossa/avx2", "ossa/best", "target");
  for (size_t r = 0; r < kRows; ++r) {
    double per_unit[3] = {0, 0, 0};
    std::printf("%-17s %-8s", rows[r].name, rows[r].per_vertex ? "vertex" : "joint");
    for (int s = 0; s < 3; ++s) {
      if (s >= side_count) {
        std::printf(" %17s", "-");
        continue;
      }
      const double med = median(ns[r][s]);
      const double low = *std::min_element(ns[r][s].begin(), ns[r][s].end());
      per_unit[s] = med / double(rows[r].per_vertex ? sides[s].vertices : sides[s].joints);
      char cell[64];
      std::snprintf(cell, sizeof cell, "%.0f (%.0f)", med, low);
      std::printf(" %17s", cell);
    }
    const double best = side_count == 3 ? std::min(per_unit[1], per_unit[2]) : per_unit[1];
    std::printf(" %9.2f", per_unit[0] / per_unit[1]);
    if (side_count == 3) std::printf(" %9.2f", per_unit[0] / per_unit[2]);
    else std::printf(" %9s", "-");
    std::printf(" %9.2f  %s\n", per_unit[0] / best,
                rows[r].target ? (per_unit[0] / best <= 0.75 ? "met" : "NOT MET") : "-");
  }
  return 0;
}
