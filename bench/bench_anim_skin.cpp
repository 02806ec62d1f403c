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
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <memory>
#include <optional>
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

/// BM_SkinFull without the final normalization (SkinnedStreams::renormalize = false): the work
/// ozz-animation's SkinningJob does, which never normalizes (a renderer normalizes in its shader).
void BM_SkinFullUnnormalized(benchmark::State& state) {
  SkinBench& b = skin_bench();
  const ossa::SkinnedStreams out{b.positions, b.normals, b.tangents, false};
  for (auto _ : state) {
    ossa::skin_cpu(b.mesh, b.palette, ossa::SkinningMethod::Linear, out);
    benchmark::DoNotOptimize(b.positions.data());
    benchmark::ClobberMemory();
  }
  set_ns_per_vertex(state, b.vertices);
}
BENCHMARK(BM_SkinFullUnnormalized);

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

/// Arnaud as cooked (its vertices ordered by influence class: skin_cpu runs one loop per class
/// range) and a copy whose classes are dealt out in turn, each class keeping its order (what a
/// file cooked before the ordering, or by another tool, looks like: skin_cpu classifies every
/// batch). Same vertices, same palette, one run: the ratio is what the ordering buys.
struct DealtArnaud {
  std::vector<uint8_t> bytes;
  std::optional<ossa::Asset> asset;
};

const ossa::MeshView& dealt_arnaud() {
  static const auto dealt = [] {
    const ossa::bench::BenchData& data = ossa::bench::bench_data();
    auto d = std::make_unique<DealtArnaud>();
    d->bytes = ossa::bench::dealt_copy(data.arnaud);
    auto a = ossa::Asset::from_bytes(d->bytes, "arnaud-dealt");
    if (!a) {
      std::fprintf(stderr, "bench: %s\n", a.error().message.c_str());
      std::exit(1);
    }
    d->asset.emplace(std::move(*a));
    return d;
  }();
  static const ossa::MeshView mesh = dealt->asset->mesh(0);
  return mesh;
}

/// Arg(ordered): 1 arnaud as cooked, 0 the dealt copy; Arg(full): normals too.
void BM_SkinOrder(benchmark::State& state) {
  SkinBench& b = skin_bench();
  const ossa::MeshView mesh = state.range(0) != 0 ? b.mesh : dealt_arnaud();
  const bool directions = state.range(1) != 0;
  const ossa::SkinnedStreams out{b.positions, directions ? std::span<float>(b.normals) : std::span<float>(),
                                 directions ? std::span<float>(b.tangents) : std::span<float>()};
  for (auto _ : state) {
    ossa::skin_cpu(mesh, b.palette, ossa::SkinningMethod::Linear, out);
    benchmark::DoNotOptimize(b.positions.data());
    benchmark::ClobberMemory();
  }
  set_ns_per_vertex(state, b.vertices);
}
BENCHMARK(BM_SkinOrder)->ArgNames({"ordered", "full"})->ArgsProduct({{0, 1}, {0, 1}});

void BM_SkinDualQuaternionFull(benchmark::State& state) {
  skin_loop(state, ossa::SkinningMethod::DualQuaternion, true);
}
BENCHMARK(BM_SkinDualQuaternionFull);

void BM_SkinningMatrices(benchmark::State& state) {
  SkinBench& b = skin_bench();
  for (auto _ : state) {
    ossa::skinning_matrices(b.mesh, b.model, b.palette);
    benchmark::DoNotOptimize(b.palette.data());
    benchmark::ClobberMemory();
  }
  state.counters["ns_per_slot"] = benchmark::Counter(
      double(b.palette.size()) * 1e-9, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_SkinningMatrices);

/// The per-frame palette a game builds: the constant half prepared once (prepare_bind_matrices),
/// then model * bind per slot, as BM_Frame does.
void BM_SkinningMatricesPrepared(benchmark::State& state) {
  SkinBench& b = skin_bench();
  std::vector<glm::mat4> bind(b.palette.size());
  ossa::prepare_bind_matrices(b.mesh, bind);
  for (auto _ : state) {
    ossa::skinning_matrices(b.mesh.joints(), bind, b.model, b.palette);
    benchmark::DoNotOptimize(b.palette.data());
    benchmark::ClobberMemory();
  }
  state.counters["ns_per_slot"] = benchmark::Counter(
      double(b.palette.size()) * 1e-9, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_SkinningMatricesPrepared);

}  // namespace
