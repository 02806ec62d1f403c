// float_env_test.cpp — the runtime's float kernels run with flush-to-zero / denormals-are-zero and
// give the caller its floating-point environment back (runtime/internal/float_env.h).
//
// Why it matters: a rest value like 7.7e-34, interpolated or squared, makes subnormal floats that
// cost the CPU a microcode assist each (Pab's walk sampled 1.8-2.5x slower). The runtime cannot
// rely on the cooker having flushed them, so each kernel sets FTZ/DAZ for its own duration. What
// a caller can see of that: a subnormal input acts as zero, and MXCSR (mode bits and sticky flags)
// is what it was before the call, whatever the caller had set. Both are checked here, kernel by
// kernel, on synthetic files (test_files.h): sampling, blend, blend_n, blend_layered, add,
// local_to_model, skinning_matrices (both forms), skin_cpu on every skinning ISA the CPU has.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <string>
#include <vector>

#include "test_files.h"
#include <ossa/anim/pose.h>
#include <ossa/anim/pose_ops.h>
#include <ossa/anim/sample.h>
#include <ossa/loader/asset.h>
#include <ossa/skinning/skinning.h>

#if defined(__SSE__) || defined(_M_X64)
#include <xmmintrin.h>
#define OSSA_TEST_MXCSR 1
#else
#define OSSA_TEST_MXCSR 0
#endif

namespace {

using ossa::Pose;
using ossa::Transform;

constexpr float kSubnormal = 1e-40f;

/// The synthetic rig with a subnormal bind translation on its root: the clip animates the arm's
/// translation, and the root shares the arm's 8-joint block, so sampling interpolates the root's
/// fixed value too (k0 == k1 == 1e-40) instead of copying it.
std::vector<uint8_t> rig_with_subnormal_rest() {
  ossa::test::SyntheticSpec spec;
  spec.skeleton->translations[0] = {kSubnormal, -kSubnormal, 0.0f};
  return ossa::test::make_valid_file(spec);
}

struct Fixture {
  std::vector<uint8_t> bytes = rig_with_subnormal_rest();
  ossa::Asset asset = [this] {
    auto a = ossa::Asset::from_bytes(bytes, "synthetic");
    if (!a) ADD_FAILURE() << a.error().message;
    return std::move(*a);
  }();
  ossa::SkeletonView skeleton = asset.skeleton();
  uint32_t joints = uint32_t(skeleton.joint_count());
};

/// Every guarded entry point, each called once on inputs holding subnormal values.
std::vector<std::pair<std::string, std::function<void()>>> kernels(Fixture& f) {
  std::vector<std::pair<std::string, std::function<void()>>> out;
  auto pose = std::make_shared<Pose>(f.joints);
  auto other = std::make_shared<Pose>(f.joints);
  auto result = std::make_shared<Pose>(f.joints);
  ossa::set_bind_pose(f.skeleton, *pose);
  ossa::set_bind_pose(f.skeleton, *other);
  auto model = std::make_shared<std::vector<glm::mat4>>(f.joints);
  const ossa::ClipView clip = f.asset.clip(0);
  auto made = ossa::make_sampling_cache(clip, f.skeleton);
  EXPECT_TRUE(made) << made.error().message;
  auto cache = std::make_shared<ossa::SamplingCache>(std::move(*made));
  const ossa::SkeletonView skeleton = f.skeleton;
  const ossa::MeshView mesh = f.asset.mesh(0);
  const size_t slots = std::max<size_t>(1, mesh.joints().size());
  auto palette = std::make_shared<std::vector<glm::mat4>>(slots, glm::mat4(1.0f));
  auto bind = std::make_shared<std::vector<glm::mat4>>(slots);
  ossa::prepare_bind_matrices(mesh, *bind);
  auto positions = std::make_shared<std::vector<float>>(3 * size_t(mesh.vertex_count()));
  auto normals = std::make_shared<std::vector<float>>(3 * size_t(mesh.vertex_count()));
  auto mask = std::make_shared<std::vector<float>>(f.joints, 0.5f);
  out.emplace_back("sample", [=] { ossa::sample(clip, 0.3f * clip.duration(), {}, *cache, *pose); });
  out.emplace_back("blend", [=] { ossa::blend(*pose, *other, 0.5f, *result); });
  out.emplace_back("blend_n", [=] {
    const ossa::ConstPoseSpan in[2] = {*pose, *other};
    const float w[2] = {0.25f, 0.75f};
    ossa::blend_n(in, w, *result);
  });
  out.emplace_back("blend_layered", [=] { ossa::blend_layered(*pose, *other, *mask, 1.0f, *result); });
  out.emplace_back("make_additive", [=] { ossa::make_additive(*pose, *other, *result); });
  out.emplace_back("add", [=] { ossa::add(*pose, *other, 0.5f, *result); });
  out.emplace_back("local_to_model", [=] { ossa::local_to_model(skeleton.parents(), *pose, *model); });
  out.emplace_back("skinning_matrices(mesh)", [=] { ossa::skinning_matrices(mesh, *model, *palette); });
  out.emplace_back("skinning_matrices(bind)", [=] { ossa::skinning_matrices(mesh.joints(), *bind, *model, *palette); });
  for (ossa::SkinningIsa isa : {ossa::SkinningIsa::Portable, ossa::SkinningIsa::Avx2, ossa::SkinningIsa::Avx512}) {
    out.emplace_back("skin_cpu isa " + std::to_string(int(isa)), [=] {
      const ossa::SkinningIsa before = ossa::skinning_isa();
      if (!ossa::set_skinning_isa(isa)) return;  // not on this CPU
      ossa::skin_cpu(mesh, *palette, ossa::SkinningMethod::Linear, {*positions, *normals, {}});
      ossa::set_skinning_isa(before);
    });
  }
  return out;
}

#if OSSA_TEST_MXCSR
TEST(FloatEnvironment, CallersMxcsrIsRestored) {
  Fixture f;
  const unsigned original = _mm_getcsr();
  // IEEE (the default), FTZ/DAZ already set, one of them only, and round-toward-zero with the
  // sticky flags raised: each control bit must come back as it was. (The sticky exception flags,
  // bits 0-5, may gain what any float arithmetic raises, as after any other function.)
  for (const unsigned csr : {0x1f80u, 0x9fc0u, 0x9f80u, 0x1fc0u, 0x7f80u | 0x3fu}) {
    for (auto& [name, run] : kernels(f)) {
      _mm_setcsr(csr);
      run();
      const unsigned after = _mm_getcsr();
      _mm_setcsr(original);
      EXPECT_EQ(after & ~0x3fu, csr & ~0x3fu)
          << name << " changed MXCSR's controls " << std::hex << csr << " to " << after;
    }
  }
}
#endif

TEST(FloatEnvironment, SubnormalInputsActAsZero) {
  Fixture f;
#if OSSA_TEST_MXCSR
  const unsigned original = _mm_getcsr();
  _mm_setcsr(original & ~0x8040u);  // the caller runs IEEE arithmetic
#endif
  // Sampling: the root's fixed translation is interpolated with the arm's animated one.
  Pose pose(f.joints);
  const ossa::ClipView clip = f.asset.clip(0);
  auto cache = ossa::make_sampling_cache(clip, f.skeleton);
  ASSERT_TRUE(cache) << cache.error().message;
  ossa::sample(clip, 0.3f * clip.duration(), {}, *cache, pose);
  EXPECT_EQ(ossa::get_transform(pose, 0).translation, glm::vec3(0.0f));
  // The arm's animated translation is unaffected (a normal value).
  EXPECT_NE(ossa::get_transform(pose, 3).translation, glm::vec3(0.0f));

  // Pose operations over a pose holding subnormal translations and scales.
  Pose a(f.joints), b(f.joints), out(f.joints);
  ossa::set_bind_pose(f.skeleton, a);
  ossa::set_bind_pose(f.skeleton, b);
  Transform t = ossa::get_transform(b, 0);
  t.translation = glm::vec3(3 * kSubnormal, 0.0f, -2 * kSubnormal);
  ossa::set_transform(b, 0, t);
  ossa::blend(a, b, 0.5f, out);
  EXPECT_EQ(ossa::get_transform(out, 0).translation, glm::vec3(0.0f));
  {
    const ossa::ConstPoseSpan in[2] = {a, b};
    const float w[2] = {0.5f, 0.5f};
    ossa::blend_n(in, w, out);
    EXPECT_EQ(ossa::get_transform(out, 0).translation, glm::vec3(0.0f));
  }
  ossa::add(a, b, 1.0f, out);
  EXPECT_EQ(ossa::get_transform(out, 0).translation, glm::vec3(0.0f));

  // Model space: a subnormal local translation on the root.
  std::vector<glm::mat4> model(f.joints);
  ossa::local_to_model(f.skeleton.parents(), b, model);
  EXPECT_EQ(glm::vec3(model[0][3]), glm::vec3(0.0f));

  // Skinning: a palette whose translations are subnormal moves no vertex off the origin's line.
  const ossa::MeshView mesh = f.asset.mesh(0);
  std::vector<glm::mat4> palette(std::max<size_t>(1, mesh.joints().size()), glm::mat4(0.0f));
  for (glm::mat4& m : palette) m[3] = glm::vec4(kSubnormal, kSubnormal, -kSubnormal, 1.0f);
  std::vector<float> positions(3 * size_t(mesh.vertex_count()), 1.0f);
  ossa::skin_cpu(mesh, palette, ossa::SkinningMethod::Linear, {positions, {}, {}});
  for (float p : positions) EXPECT_EQ(p, 0.0f);
#if OSSA_TEST_MXCSR
  _mm_setcsr(original);
#endif
}

}  // namespace
