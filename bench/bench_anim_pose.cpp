// bench_anim_pose.cpp — pose operations on Pab's 67-joint rig (ossa-bench-anim; bench_fixture.h).
//
// The reference figures are ozz-animation's: 205 ns for a three-layer blend of Pab's 67
// joints and 5.5 ns per joint for local-to-model. BM_Blend3 and BM_LocalToModel measure the same
// work; the others cover the remaining pose operations and, as a yardstick, local-to-model done
// the obvious way with GLM (mat4 from TRS, generic mat4 product).
//
// Inputs are the bind pose plus a seeded perturbation of every joint (a few degrees of rotation,
// a little translation and scale), so the benchmark does not depend on the sampler and the blend
// inputs differ from joint to joint as sampled poses do. Every benchmark reports `ns_per_joint`
// (nanoseconds per joint per call, from CPU time, like the rates Google Benchmark computes); the
// time columns are per call. The console prints an inverted rate with an "s" suffix
// ("ns_per_joint=1.9s"): the number is nanoseconds, as the counter is scaled by 1e-9 (set_ns_per_joint).
//
// Run: ossa-bench-anim --benchmark_repetitions=5 --benchmark_filter='BM_Blend3|BM_LocalToModel'
#include <benchmark/benchmark.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <random>
#include <span>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include "bench_fixture.h"
#include <ossa/anim/pose.h>
#include <ossa/anim/ik.h>
#include <ossa/anim/pose_ops.h>
#include <ossa/anim/spring.h>

namespace {

/// Pab's bind pose with every joint nudged: rotation by up to ~6 degrees about a random axis,
/// translation by up to 1% of the rig scale, scale by up to 2%.
ossa::Pose perturbed_bind_pose(const ossa::SkeletonView& skeleton, uint32_t seed) {
  ossa::Pose pose(uint32_t(skeleton.joint_count()));
  ossa::set_bind_pose(skeleton, pose);
  std::mt19937 gen(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  for (uint32_t j = 0; j < pose.joint_count(); ++j) {
    ossa::Transform t = ossa::get_transform(pose, j);
    const glm::vec3 axis = glm::normalize(glm::vec3(u(gen), u(gen), u(gen)) + glm::vec3(0, 0, 1e-3f));
    t.rotation = glm::normalize(t.rotation * glm::angleAxis(0.1f * u(gen), axis));
    t.translation += glm::vec3(u(gen), u(gen), u(gen)) * (0.01f * (1.0f + glm::length(t.translation)));
    t.scale *= 1.0f + 0.02f * u(gen);
    ossa::set_transform(pose, j, t);
  }
  return pose;
}

struct PoseBench {
  ossa::SkeletonView skeleton;
  uint32_t joints = 0;
  ossa::Pose inputs[3];
  ossa::Pose out;
  std::vector<float> upper_body;  // crossarms-over-walk style mask: Spine1 and everything below
  std::vector<glm::mat4> model;
};

const PoseBench& pose_bench() {
  static const PoseBench bench = [] {
    PoseBench b;
    b.skeleton = ossa::bench::bench_data().skeleton.skeleton();
    b.joints = uint32_t(b.skeleton.joint_count());
    for (uint32_t i = 0; i < 3; ++i) b.inputs[i] = perturbed_bind_pose(b.skeleton, 17 + i);
    b.out = ossa::Pose(b.joints);
    b.upper_body.assign(b.joints, 0.0f);
    const int spine1 = b.skeleton.find_joint("Spine1");  // Pab's legs hang from Spine
    ossa::build_joint_mask(b.skeleton.parents(), spine1 >= 0 ? spine1 : 0, -1, b.upper_body);
    b.model.resize(b.joints);
    return b;
  }();
  return bench;
}

/// ns per joint per call: the rate of (joints * 1e-9) per iteration, inverted.
void set_ns_per_joint(benchmark::State& state, uint32_t joints) {
  state.counters["ns_per_joint"] = benchmark::Counter(
      double(joints) * 1e-9, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

void BM_Blend2(benchmark::State& state) {
  const PoseBench& b = pose_bench();
  ossa::Pose out(b.joints);
  for (auto _ : state) {
    ossa::blend(b.inputs[0], b.inputs[1], 0.3f, out);
    benchmark::DoNotOptimize(out.span().base);
    benchmark::ClobberMemory();
  }
  set_ns_per_joint(state, b.joints);
}
BENCHMARK(BM_Blend2);

void BM_Blend3(benchmark::State& state) {
  const PoseBench& b = pose_bench();
  ossa::Pose out(b.joints);
  const ossa::ConstPoseSpan poses[] = {b.inputs[0], b.inputs[1], b.inputs[2]};
  const float weights[] = {0.5f, 0.3f, 0.2f};
  for (auto _ : state) {
    ossa::blend_n(poses, weights, out);
    benchmark::DoNotOptimize(out.span().base);
    benchmark::ClobberMemory();
  }
  set_ns_per_joint(state, b.joints);
}
BENCHMARK(BM_Blend3);

void BM_BlendLayered(benchmark::State& state) {
  const PoseBench& b = pose_bench();
  ossa::Pose out(b.joints);
  for (auto _ : state) {
    ossa::blend_layered(b.inputs[0], b.inputs[1], b.upper_body, 0.8f, out);
    benchmark::DoNotOptimize(out.span().base);
    benchmark::ClobberMemory();
  }
  set_ns_per_joint(state, b.joints);
}
BENCHMARK(BM_BlendLayered);

void BM_Add(benchmark::State& state) {
  const PoseBench& b = pose_bench();
  ossa::Pose delta(b.joints), out(b.joints);
  ossa::make_additive(b.inputs[1], b.inputs[2], delta);
  for (auto _ : state) {
    ossa::add(b.inputs[0], delta, 0.5f, out);
    benchmark::DoNotOptimize(out.span().base);
    benchmark::ClobberMemory();
  }
  set_ns_per_joint(state, b.joints);
}
BENCHMARK(BM_Add);

void BM_LocalToModel(benchmark::State& state) {
  const PoseBench& b = pose_bench();
  std::vector<glm::mat4> model(b.joints);
  for (auto _ : state) {
    ossa::local_to_model(b.skeleton.parents(), b.inputs[0], model);
    benchmark::DoNotOptimize(model.data());
    benchmark::ClobberMemory();
  }
  set_ns_per_joint(state, b.joints);
}
BENCHMARK(BM_LocalToModel);

// One two-bone IK job on Pab's left arm (LeftArm > LeftForeArm > Lefthand) in a sampled pose,
// the target swept around the hand with a pole and softening on: ns per job.
void BM_TwoBoneIk(benchmark::State& state) {
  const PoseBench& b = pose_bench();
  std::vector<glm::mat4> model(b.joints);
  ossa::local_to_model(b.skeleton.parents(), b.inputs[0], model);
  const int start = b.skeleton.find_joint("LeftArm"), mid = b.skeleton.find_joint("LeftForeArm"),
            end = b.skeleton.find_joint("Lefthand");
  if (start < 0 || mid < 0 || end < 0) {
    state.SkipWithError("Pab's skeleton has no LeftArm > LeftForeArm > Lefthand");
    return;
  }
  ossa::TwoBoneIkInput in;
  in.start = model[static_cast<size_t>(start)];
  in.mid = model[static_cast<size_t>(mid)];
  in.end = model[static_cast<size_t>(end)];
  in.pole = glm::vec3(0.0f, 0.0f, -1.0f);
  in.soften = 0.97f;
  const glm::vec3 hand(in.end[3]);
  ossa::TwoBoneIkOutput out;
  float phase = 0.0f;
  for (auto _ : state) {
    phase += 0.01f;
    in.target = hand + 10.0f * glm::vec3(std::sin(phase), std::cos(phase), 0.0f);
    benchmark::DoNotOptimize(ossa::two_bone_ik(in, &out));
    benchmark::DoNotOptimize(out);
  }
}
BENCHMARK(BM_TwoBoneIk);

// One aim job on Pab's head (local +z forward, +y up assumed), the target swept around it with a
// pole and a 70 degree limit: ns per joint of an aim chain.
void BM_AimIk(benchmark::State& state) {
  const PoseBench& b = pose_bench();
  std::vector<glm::mat4> model(b.joints);
  ossa::local_to_model(b.skeleton.parents(), b.inputs[0], model);
  const int head = b.skeleton.find_joint("Head");
  if (head < 0) {
    state.SkipWithError("Pab's skeleton has no Head");
    return;
  }
  ossa::AimIkInput in;
  in.joint = model[static_cast<size_t>(head)];
  in.pole = glm::vec3(0.0f, 1.0f, 0.0f);
  in.max_angle = 1.2f;
  const glm::vec3 at(in.joint[3]);
  ossa::AimIkOutput out;
  float phase = 0.0f;
  for (auto _ : state) {
    phase += 0.01f;
    in.target = at + 100.0f * glm::vec3(std::sin(phase), 0.1f, std::cos(phase));
    benchmark::DoNotOptimize(ossa::aim_ik(in, &out));
    benchmark::DoNotOptimize(out);
  }
}
BENCHMARK(BM_AimIk);

// A spring chain over Pab's left arm and hand (LeftArm > LeftForeArm > Lefthand) with one sphere
// collider on the spine, one fixed step per update: ns per spring joint per step (the pose
// pass that writes the result included).
void BM_SpringChain(benchmark::State& state) {
  const PoseBench& b = pose_bench();
  const int arm = b.skeleton.find_joint("LeftArm"), fore = b.skeleton.find_joint("LeftForeArm"),
            hand = b.skeleton.find_joint("Lefthand"), spine = b.skeleton.find_joint("Spine");
  if (arm < 0 || fore < 0 || hand < 0 || spine < 0) {
    state.SkipWithError("Pab's skeleton lacks LeftArm > LeftForeArm > Lefthand or Spine");
    return;
  }
  const std::array<uint16_t, 3> joints{static_cast<uint16_t>(arm), static_cast<uint16_t>(fore),
                                       static_cast<uint16_t>(hand)};
  ossa::SpringSettings settings;
  settings.gravity = glm::vec3(0.0f, -981.0f, 0.0f);  // Pab is in centimetres
  auto chain = ossa::make_spring_chain(b.skeleton.parents(), joints, settings);
  if (!chain.ok()) {
    state.SkipWithError(chain.error().message.c_str());
    return;
  }
  const std::array<ossa::SpringCollider, 1> colliders{
      ossa::SpringCollider{static_cast<uint16_t>(spine), glm::vec3(0.0f), glm::vec3(0.0f), 15.0f}};
  ossa::Pose local(b.joints);
  std::vector<glm::mat4> model(b.joints);
  ossa::copy_pose(b.inputs[0], local);
  ossa::local_to_model(b.skeleton.parents(), local, model);
  for (auto _ : state) {
    ossa::copy_pose(b.inputs[0], local);  // the animated pose, as each frame gives it
    ossa::update_spring_chain(*chain, settings.step, b.skeleton.parents(), local, model, colliders);
    benchmark::DoNotOptimize(model.data());
  }
  set_ns_per_joint(state, static_cast<uint32_t>(joints.size()));
}
BENCHMARK(BM_SpringChain);

// The yardstick: per joint, TRS -> mat4 with GLM's helpers and a generic mat4 product.
void BM_GlmLocalToModel(benchmark::State& state) {
  const PoseBench& b = pose_bench();
  const std::span<const int16_t> parents = b.skeleton.parents();
  std::vector<glm::mat4> model(b.joints);
  for (auto _ : state) {
    for (uint32_t j = 0; j < b.joints; ++j) {
      const ossa::Transform t = ossa::get_transform(b.inputs[0], j);
      const glm::mat4 local = glm::translate(glm::mat4(1.0f), t.translation) * glm::mat4_cast(t.rotation) *
                              glm::scale(glm::mat4(1.0f), t.scale);
      model[j] = parents[j] < 0 ? local : model[size_t(parents[j])] * local;
    }
    benchmark::DoNotOptimize(model.data());
    benchmark::ClobberMemory();
  }
  set_ns_per_joint(state, b.joints);
}
BENCHMARK(BM_GlmLocalToModel);

}  // namespace
