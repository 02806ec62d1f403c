// bench_anim_skin.cpp — CPU skinning of Pab's arnaud mesh (ossa-bench-anim; bench_fixture.h).
//
// The reference figures are ozz-animation's on the same mesh and machine: 2.1 ns per
// vertex for positions only and 3.3 ns per vertex for positions + normals + tangents. BM_SkinPositions
// and BM_SkinFull measure the same work on ossa's cooked (quantized) arnaud: decoding included, and
// BM_SkinFull renormalizes what it transforms (arnaud has no tangents, so it is positions + normals;
// the streams the mesh has, as a renderer would ask for them). The ByIsa variants run one
// implementation each (0 portable, 1 AVX2, 2 AVX-512; skipped where the CPU lacks it), and the
// dual quaternion and palette benchmarks cover the rest of skinning.h.
//
// The palette comes from Pab's bind pose with every joint nudged (a few degrees, as sampled poses
// differ from bind): skinning costs the same whatever the pose. Every skinning benchmark reports
// `ns_per_vertex` (nanoseconds per vertex per call); the time column is per call.
//
// Run: ossa-bench-anim --benchmark_repetitions=5 --benchmark_filter='BM_Skin'
#include <benchmark/benchmark.h>

#include <cstdint>
#include <random>
#include <span>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "bench_fixture.h"
#include <ossa/anim/pose.h>
#include <ossa/anim/pose_ops.h>
#include <ossa/skinning/skinning.h>

namespace {

struct SkinBench {
  ossa::MeshView mesh;
  uint32_t vertices = 0;
  bool has_tangents = false;
  std::vector<glm::mat4> model;    // one per skeleton joint
  std::vector<glm::mat4> palette;  // one per mesh slot
  std::vector<float> positions, normals, tangents;
};

SkinBench& skin_bench() {
  static SkinBench bench = [] {
    const ossa::bench::BenchData& data = ossa::bench::bench_data();
    const ossa::SkeletonView skeleton = data.skeleton.skeleton();
    SkinBench b;
    b.mesh = data.arnaud.mesh(0);
    b.vertices = b.mesh.vertex_count();
    b.has_tangents = b.mesh.attribute(ossa::fb::VertexSemantic::Tangent) != nullptr;
    ossa::Pose pose(uint32_t(skeleton.joint_count()));
    ossa::set_bind_pose(skeleton, pose);
    std::mt19937 gen(29);
    std::uniform_real_distribution<float> u(-1.0f, 1.0f);
    for (uint32_t j = 0; j < pose.joint_count(); ++j) {
      ossa::Transform t = ossa::get_transform(pose, j);
      const glm::vec3 axis = glm::normalize(glm::vec3(u(gen), u(gen), u(gen)) + glm::vec3(0, 0, 1e-3f));
      t.rotation = glm::normalize(t.rotation * glm::angleAxis(0.1f * u(gen), axis));
      ossa::set_transform(pose, j, t);
    }
    b.model.resize(skeleton.joint_count());
    ossa::local_to_model(skeleton.parents(), pose, b.model);
    b.palette.resize(std::max<size_t>(1, b.mesh.joints().size()));
    ossa::skinning_matrices(b.mesh, b.model, b.palette);
    b.positions.resize(3 * size_t(b.vertices));
    b.normals.resize(3 * size_t(b.vertices));
    b.tangents.resize(b.has_tangents ? 4 * size_t(b.vertices) : 0);
    return b;
  }();
  return bench;
}

/// ns per vertex per call: the rate of (vertices * 1e-9) per iteration, inverted.
void set_ns_per_vertex(benchmark::State& state, uint32_t vertices) {
  state.counters["ns_per_vertex"] = benchmark::Counter(
      double(vertices) * 1e-9, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void skin_loop(benchmark::State& state, ossa::SkinningMethod method, bool directions) {
  SkinBench& b = skin_bench();
  const ossa::SkinnedStreams out{b.positions, directions ? std::span<float>(b.normals) : std::span<float>(),
                                 directions ? std::span<float>(b.tangents) : std::span<float>()};
  for (auto _ : state) {
    ossa::skin_cpu(b.mesh, b.palette, method, out);
    benchmark::DoNotOptimize(b.positions.data());
    benchmark::ClobberMemory();
  }
  set_ns_per_vertex(state, b.vertices);
}

void BM_SkinPositions(benchmark::State& state) { skin_loop(state, ossa::SkinningMethod::Linear, false); }
BENCHMARK(BM_SkinPositions);

void BM_SkinFull(benchmark::State& state) { skin_loop(state, ossa::SkinningMethod::Linear, true); }
BENCHMARK(BM_SkinFull);

/// One implementation: Arg(0) positions-only / Arg(1) full, Arg(isa).
void BM_SkinByIsa(benchmark::State& state) {
  const ossa::SkinningIsa previous = ossa::skinning_isa();
  if (!ossa::set_skinning_isa(static_cast<ossa::SkinningIsa>(state.range(1)))) {
    state.SkipWithError("the CPU lacks this instruction set");
    return;
  }
  skin_loop(state, ossa::SkinningMethod::Linear, state.range(0) != 0);
  ossa::set_skinning_isa(previous);
}
BENCHMARK(BM_SkinByIsa)->ArgNames({"full", "isa"})->ArgsProduct({{0, 1}, {0, 1, 2}});

void BM_SkinDualQuaternionFull(benchmark::State& state) { skin_loop(state, ossa::SkinningMethod::DualQuaternion, true); }
BENCHMARK(BM_SkinDualQuaternionFull);

void BM_SkinningMatrices(benchmark::State& state) {
  SkinBench& b = skin_bench();
  for (auto _ : state) {
    ossa::skinning_matrices(b.mesh, b.model, b.palette);
    benchmark::DoNotOptimize(b.palette.data());
    benchmark::ClobberMemory();
  }
  state.counters["ns_per_slot"] = benchmark::Counter(double(b.palette.size()) * 1e-9,
                                                     benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_SkinningMatrices);

}  // namespace
