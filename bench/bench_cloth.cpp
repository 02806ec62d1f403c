// bench_cloth.cpp — ossa-bench-cloth: the cloth solver's cost per character and frame
// (ossa/anim/cloth.h), the two rows issue 29 asks for.
//
// - BM_ClothCape: a 40 x 25 cape (1,000 particles, its top row pinned) with 3 capsule colliders
//   (a torso and two swinging legs) updated at 60 Hz with the solver's default substep (1/240 s:
//   4 substeps per frame) and one constraint pass per substep, while the character walks in a
//   circle, so the cloth never settles. Time per update = per character per frame, one core.
// - BM_ClothCrowd: the same cape on N characters, split over 2 threads, one frame each per
//   iteration; the `caped_per_16_7ms` counter is how many caped characters 2 threads update in
//   16.7 ms at that rate.
// The cape is tests/support/cloth_grid.h's (what the cooker makes for a grid), so the bench needs no
// cooked file. The machine line names the CPU.
#include <cmath>
#include <cstdio>
#include <string>
#include <thread>
#include <vector>

#include <benchmark/benchmark.h>
#include <glm/gtc/matrix_transform.hpp>

#include <ossa/anim/cloth.h>
#include "cloth_grid.h"

namespace {

constexpr float kHz = 60.0f;

struct Caped {
  ossa::test::GridCloth grid;
  ossa::ClothInstance cloth;
  std::vector<glm::vec3> skinned, normals;
  std::vector<glm::mat4> model = std::vector<glm::mat4>(4, glm::mat4(1.0f));
  double time = 0.0;

  Caped() : grid(ossa::test::make_grid_cloth(40, 25, 0.025f, 1.5f, -0.2f)) {
    grid.colliders.emplace_back(1, ossa::fb::Vec3(0, -0.6f, 0), ossa::fb::Vec3(0, 0.4f, 0), 0.15f);  // torso
    for (uint16_t j = 2; j <= 3; ++j)
      grid.colliders.emplace_back(j, ossa::fb::Vec3(0, 0, 0), ossa::fb::Vec3(0, -0.8f, 0), 0.07f);  // legs
    auto c = ossa::make_cloth_instance(grid.source(), static_cast<uint32_t>(grid.rest.size()), model.size());
    if (!c) {
      std::fprintf(stderr, "ossa-bench-cloth: %s\n", c.error().message.c_str());
      std::exit(1);
    }
    cloth = std::move(*c);
    skinned = grid.rest;
    normals.assign(grid.rest.size(), glm::vec3(0.0f, 0.0f, -1.0f));
    model[1] = glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, 1.0f, 0.0f));
  }

  /// One 60 Hz frame: legs swing, the character walks a circle of 3 m radius at 1.5 m/s.
  void frame() {
    time += 1.0 / kHz;
    const float t = static_cast<float>(time), swing = 0.6f * std::sin(2.0f * 3.14159265f * t);
    for (int side = 0; side < 2; ++side) {
      glm::mat4 m = glm::translate(glm::mat4(1.0f), glm::vec3(side == 0 ? 0.1f : -0.1f, 0.9f, 0.0f));
      model[static_cast<size_t>(2 + side)] = glm::rotate(m, side == 0 ? swing : -swing, glm::vec3(1, 0, 0));
    }
    const float angle = 0.5f * t;
    glm::mat4 world = glm::rotate(glm::mat4(1.0f), angle, glm::vec3(0, 1, 0));
    world[3] = glm::vec4(3.0f * std::sin(angle), 0.0f, 3.0f * std::cos(angle), 1.0f);
    ossa::ClothInput in;
    in.skinned_positions = skinned;
    in.skinned_normals = normals;
    in.model = model;
    in.model_to_world = world;
    in.dt = 1.0f / kHz;
    if (!ossa::update_cloth(cloth, in)) std::exit(1);
  }
};

void BM_ClothCape(benchmark::State& state) {
  Caped c;
  for (int k = 0; k < 120; ++k) c.frame();  // past the start, swinging
  for (auto _ : state) {
    c.frame();
    benchmark::DoNotOptimize(c.cloth.positions().data());
  }
  state.counters["particles"] = static_cast<double>(c.cloth.particle_count());
  state.counters["colliders"] = static_cast<double>(c.grid.colliders.size());
  state.counters["substeps_per_frame"] = std::round(1.0 / (kHz * c.cloth.settings.substep));
  state.counters["iterations"] = c.cloth.settings.iterations;
}
BENCHMARK(BM_ClothCape)->Unit(benchmark::kMicrosecond);

void BM_ClothCrowd(benchmark::State& state) {
  const auto n = static_cast<size_t>(state.range(0));
  std::vector<Caped> crowd(n);
  for (auto& c : crowd)
    for (int k = 0; k < 60; ++k) c.frame();
  for (auto _ : state) {
    std::thread other([&] {
      for (size_t i = 0; i < n / 2; ++i) crowd[i].frame();
    });
    for (size_t i = n / 2; i < n; ++i) crowd[i].frame();
    other.join();
  }
  state.counters["characters"] = static_cast<double>(n);
  state.counters["caped_per_16_7ms"] =
      benchmark::Counter(static_cast<double>(n) * 0.0167, benchmark::Counter::kIsIterationInvariantRate);
}
BENCHMARK(BM_ClothCrowd)->Arg(64)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
