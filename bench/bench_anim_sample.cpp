// bench_anim_sample.cpp — clip sampling and a whole character frame on Pab (ossa-bench-anim;
// bench_fixture.h).
//
// The reference figures are ozz-animation's on the same assets: 4.8 ns per joint to
// sample a compressed clip and 1.44 us for a frame of three samples, a three-way blend,
// local-to-model and the skinning palette. These benchmarks do that work:
//   BM_Sample      forward playback of the walk at 60 Hz through one SamplingCache (the common
//                  case: keys are decoded only when playback passes them);
//   BM_SampleSeek  a random time per call (cursor searches and two decodes per channel that moved);
//   BM_SampleNoisyRest  BM_Sample on a copy of the skeleton whose bind pose carries +-7.7e-34 where
//                  it holds 0 (noisy_rest_copy: a rig cooked elsewhere, as Pab's FBX is before the
//                  cooker flushes it); with the runtime's flush-to-zero it costs what BM_Sample costs,
//                  without it 1.9x as much on a Zen 5 EPYC;
//   BM_Frame       walk, jog and run sampled at their own phase, blend_n of the three,
//                  local_to_model and the skinning palette for the arnaud mesh (its constant
//                  half prepared once, prepare_bind_matrices).
// Each reports `ns_per_joint` (time per call / joints). Time stepping is outside the measured
// region only where it costs nothing (a table of precomputed times), so the figure is the runtime's.
//
// Run: ossa-bench-anim --benchmark_repetitions=5 --benchmark_report_aggregates_only=true
//                      --benchmark_filter='BM_Sample|BM_Frame'
#include <benchmark/benchmark.h>

#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <random>
#include <vector>

#include <glm/glm.hpp>

#include "bench_fixture.h"
#include <ossa/anim/pose.h>
#include <ossa/anim/pose_ops.h>
#include <ossa/anim/sample.h>
#include <ossa/skinning/skinning.h>

namespace {

ossa::SamplingCache cache_or_die(const ossa::ClipView& clip, const ossa::SkeletonView& skeleton) {
  auto cache = ossa::make_sampling_cache(clip, skeleton);
  if (!cache) {
    std::fprintf(stderr, "bench: %s\n", cache.error().message.c_str());
    std::exit(1);
  }
  return std::move(*cache);
}

/// `n` times of forward playback at 60 Hz, looping (precomputed, so the loop measures sampling).
std::vector<float> playback_times(const ossa::ClipView& clip, size_t n, float start = 0.0f) {
  std::vector<float> times(n);
  float t = start;
  for (float& x : times) {
    x = t;
    t = ossa::advance_time(t, 1.0f / 60.0f, 1.0f, clip.duration(), true);
  }
  return times;
}

void per_joint_counter(benchmark::State& state, uint32_t joints) {
  // Iteration-invariant rate, inverted: seconds per iteration / joints, shown in ns.
  state.counters["ns_per_joint"] = benchmark::Counter(
      static_cast<double>(joints) * 1e-9, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void BM_Sample(benchmark::State& state) {
  const auto& data = ossa::bench::bench_data();
  const ossa::SkeletonView skeleton = data.skeleton.skeleton();
  const ossa::ClipView clip = data.walk.clip(0);
  ossa::SamplingCache cache = cache_or_die(clip, skeleton);
  ossa::Pose pose(static_cast<uint32_t>(skeleton.joint_count()));
  // A whole number of loops' worth of 60 Hz times, replayed: the wrap back to the start is part
  // of forward playback too.
  const std::vector<float> times = playback_times(clip, 4096);
  size_t i = 0;
  for (auto _ : state) {
    ossa::sample(clip, times[i], {}, cache, pose);
    benchmark::DoNotOptimize(pose.span().base);
    benchmark::ClobberMemory();
    i = (i + 1) & (times.size() - 1);
  }
  per_joint_counter(state, pose.joint_count());
}
BENCHMARK(BM_Sample);

void BM_SampleNoisyRest(benchmark::State& state) {
  const auto& data = ossa::bench::bench_data();
  static size_t noisy = 0;
  static const std::vector<uint8_t> bytes = ossa::bench::noisy_rest_copy(data.skeleton, &noisy);
  auto rig = ossa::Asset::from_bytes(bytes, "skeleton-noisy");
  if (!rig) {
    state.SkipWithError(rig.error().message.c_str());
    return;
  }
  const ossa::SkeletonView skeleton = rig->skeleton();
  const ossa::ClipView clip = data.walk.clip(0);
  ossa::SamplingCache cache = cache_or_die(clip, skeleton);
  ossa::Pose pose(static_cast<uint32_t>(skeleton.joint_count()));
  const std::vector<float> times = playback_times(clip, 4096);
  size_t i = 0;
  for (auto _ : state) {
    ossa::sample(clip, times[i], {}, cache, pose);
    benchmark::DoNotOptimize(pose.span().base);
    benchmark::ClobberMemory();
    i = (i + 1) & (times.size() - 1);
  }
  per_joint_counter(state, pose.joint_count());
  state.counters["noisy_values"] = static_cast<double>(noisy);
}
BENCHMARK(BM_SampleNoisyRest);

void BM_SampleSeek(benchmark::State& state) {
  const auto& data = ossa::bench::bench_data();
  const ossa::SkeletonView skeleton = data.skeleton.skeleton();
  const ossa::ClipView clip = data.walk.clip(0);
  ossa::SamplingCache cache = cache_or_die(clip, skeleton);
  ossa::Pose pose(static_cast<uint32_t>(skeleton.joint_count()));
  std::mt19937 rng(42);
  std::uniform_real_distribution<float> u(0.0f, clip.duration());
  std::vector<float> times(4096);
  for (float& t : times) t = u(rng);
  size_t i = 0;
  for (auto _ : state) {
    ossa::sample(clip, times[i], {}, cache, pose);
    benchmark::DoNotOptimize(pose.span().base);
    benchmark::ClobberMemory();
    i = (i + 1) & (times.size() - 1);
  }
  per_joint_counter(state, pose.joint_count());
}
BENCHMARK(BM_SampleSeek);

/// One character frame: three locomotion clips sampled at their own (synchronised) phase, a
/// three-way blend, model space, and the skinning palette of the arnaud mesh.
void BM_Frame(benchmark::State& state) {
  const auto& data = ossa::bench::bench_data();
  const ossa::SkeletonView skeleton = data.skeleton.skeleton();
  const auto joints = static_cast<uint32_t>(skeleton.joint_count());
  const ossa::ClipView clips[3] = {data.walk.clip(0), data.jog.clip(0), data.run.clip(0)};
  ossa::SamplingCache caches[3] = {cache_or_die(clips[0], skeleton), cache_or_die(clips[1], skeleton),
                                   cache_or_die(clips[2], skeleton)};
  ossa::Pose poses[3] = {ossa::Pose(joints), ossa::Pose(joints), ossa::Pose(joints)};
  ossa::Pose blended(joints);
  const ossa::ConstPoseSpan inputs[3] = {poses[0], poses[1], poses[2]};
  const float weights[3] = {0.2f, 0.5f, 0.3f};
  std::vector<glm::mat4> model(joints);
  const ossa::MeshView mesh = data.arnaud.mesh(0);
  std::vector<glm::mat4> palette(mesh.joints().empty() ? 1 : mesh.joints().size());
  // The mesh's constant palette half (inverse bind * de-quantization) is made once, at load, as a
  // game would; per frame only model * bind remains.
  std::vector<glm::mat4> bind(palette.size());
  ossa::prepare_bind_matrices(mesh, bind);
  // Normalized phase advancing at 60 Hz of the walk's cycle; each clip plays at that phase.
  const size_t steps = 4096;
  std::vector<float> phase(steps);
  for (size_t i = 0; i < steps; ++i) {
    const float p = static_cast<float>(i) / 60.0f / clips[0].duration();
    phase[i] = p - static_cast<float>(static_cast<int>(p));
  }
  size_t i = 0;
  for (auto _ : state) {
    for (int c = 0; c < 3; ++c) ossa::sample(clips[c], phase[i] * clips[c].duration(), {}, caches[c], poses[c]);
    ossa::blend_n(inputs, weights, blended);
    ossa::local_to_model(skeleton.parents(), blended, model);
    ossa::skinning_matrices(mesh.joints(), bind, model, palette);
    benchmark::DoNotOptimize(palette.data());
    benchmark::ClobberMemory();
    i = (i + 1) & (steps - 1);
  }
  per_joint_counter(state, joints);
  state.counters["palette"] = static_cast<double>(palette.size());
}
BENCHMARK(BM_Frame);

}  // namespace
