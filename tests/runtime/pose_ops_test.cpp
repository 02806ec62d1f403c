// pose_ops_test.cpp — Pose storage and the pose operations (pose.h, pose_ops.h): the identities a
// blend tree relies on, shortest-arc rotation blending, joint + depth masks, additive round trips,
// and local_to_model against a double-precision reference.
//
// Poses are built directly (seeded random joints) so the arithmetic is tested independently of
// the sampler; joint counts are deliberately not multiples of kPoseLanes so every test also
// covers a partial last lane block and its padding. Skeletons come from the synthetic file
// (test_files.h) and from the cooked Pab rig (67 joints, tests/fixtures/Pab/skeleton.ossa): a real
// parents array and a real bind pose.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <optional>
#include <random>
#include <set>
#include <span>
#include <stdexcept>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include <ossa/loader/asset.h>
#include <ossa/anim/pose.h>
#include <ossa/anim/pose_ops.h>
#include <ossa/anim/vector_isa.h>
#include "test_files.h"

namespace {

namespace fs = std::filesystem;
using ossa::ConstPoseSpan;
using ossa::Pose;
using ossa::PoseSpan;
using ossa::Transform;

constexpr uint32_t kJoints = 13;  // two lane blocks, the second partial

// ---------------------------------------------------------------------------------------------
// Helpers

struct Rng {
  std::mt19937 gen;
  explicit Rng(uint32_t seed) : gen(seed) {}
  float uniform(float lo, float hi) { return std::uniform_real_distribution<float>(lo, hi)(gen); }
  glm::quat rotation() {
    glm::quat q(uniform(-1, 1), uniform(-1, 1), uniform(-1, 1), uniform(-1, 1));
    return glm::normalize(q);
  }
  Transform transform() {
    Transform t;
    t.translation = {uniform(-2, 2), uniform(-2, 2), uniform(-2, 2)};
    t.rotation = rotation();
    t.scale = {uniform(0.5f, 2), uniform(0.5f, 2), uniform(0.5f, 2)};
    return t;
  }
};

Pose random_pose(uint32_t joints, uint32_t seed) {
  Pose p(joints);
  Rng rng(seed);
  for (uint32_t j = 0; j < joints; ++j) ossa::set_transform(p, j, rng.transform());
  return p;
}

void expect_padding_identity(ConstPoseSpan p) {
  for (uint32_t j = p.joint_count; j < p.stride; ++j) {
    for (uint32_t k = ossa::kTx; k <= ossa::kRz; ++k) EXPECT_EQ(p[ossa::PoseComponent(k)][j], 0.0f) << j;
    EXPECT_EQ(p[ossa::kRw][j], 1.0f) << j;
    for (uint32_t k = ossa::kSx; k <= ossa::kSz; ++k) EXPECT_EQ(p[ossa::PoseComponent(k)][j], 1.0f) << j;
  }
}

void expect_pose_eq(ConstPoseSpan a, ConstPoseSpan b) {
  ASSERT_EQ(a.joint_count, b.joint_count);
  for (uint32_t k = 0; k < ossa::kPoseComponents; ++k)
    for (uint32_t j = 0; j < a.joint_count; ++j)
      EXPECT_EQ(a[ossa::PoseComponent(k)][j], b[ossa::PoseComponent(k)][j]) << "component " << k << " joint " << j;
}

/// Component-wise within tol, except that a rotation may come out negated (the same rotation).
void expect_pose_near(ConstPoseSpan a, ConstPoseSpan b, float tol) {
  ASSERT_EQ(a.joint_count, b.joint_count);
  for (uint32_t j = 0; j < a.joint_count; ++j) {
    const Transform ta = ossa::get_transform(a, j), tb = ossa::get_transform(b, j);
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(ta.translation[c], tb.translation[c], tol) << "joint " << j;
      EXPECT_NEAR(ta.scale[c], tb.scale[c], tol) << "joint " << j;
    }
    const float sign = glm::dot(ta.rotation, tb.rotation) < 0 ? -1.0f : 1.0f;
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(ta.rotation[c], sign * tb.rotation[c], tol) << "joint " << j;
  }
}

/// A rotation of `degrees` about z.
glm::quat about_z(float degrees) { return glm::angleAxis(glm::radians(degrees), glm::vec3(0, 0, 1)); }

/// The joint + depth mask computed the slow, obvious way: walk up from every joint.
std::vector<float> reference_mask(std::span<const int16_t> parents, int joint, int depth) {
  std::vector<float> out(parents.size(), 0.0f);
  for (size_t i = 0; i < parents.size(); ++i) {
    int level = 0;
    for (int j = int(i); j >= 0; j = parents[size_t(j)], ++level) {
      if (j == joint) {
        if (depth < 0 || level <= depth) out[i] = 1.0f;
        break;
      }
    }
  }
  return out;
}

glm::dmat4 reference_trs(const Transform& t) {
  const glm::dquat r(double(t.rotation.w), double(t.rotation.x), double(t.rotation.y), double(t.rotation.z));
  return glm::translate(glm::dmat4(1.0), glm::dvec3(t.translation)) * glm::mat4_cast(r) *
         glm::scale(glm::dmat4(1.0), glm::dvec3(t.scale));
}

std::vector<glm::dmat4> reference_model(std::span<const int16_t> parents, ConstPoseSpan local) {
  std::vector<glm::dmat4> model(parents.size());
  for (size_t i = 0; i < parents.size(); ++i) {
    const glm::dmat4 l = reference_trs(ossa::get_transform(local, uint32_t(i)));
    model[i] = parents[i] < 0 ? l : model[size_t(parents[i])] * l;
  }
  return model;
}

/// Every element within rel * (1 + the largest magnitude in its column) of the reference: a
/// relative bound that stays meaningful for elements near zero.
void expect_matrix_near(const glm::mat4& m, const glm::dmat4& ref, double rel, const std::string& what) {
  for (int c = 0; c < 4; ++c) {
    double scale = 1.0;
    for (int r = 0; r < 4; ++r) scale = std::max(scale, std::abs(ref[c][r]));
    for (int r = 0; r < 4; ++r)
      EXPECT_NEAR(double(m[c][r]), ref[c][r], rel * scale) << what << " [" << c << "][" << r << "]";
  }
}

glm::dmat4 to_dmat4(const ossa::fb::Mat4& m) {
  glm::dmat4 out;
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) out[c][r] = double(m.m()->Get(flatbuffers::uoffset_t(c * 4 + r)));
  return out;
}

/// The synthetic file's skeleton (root -> spine -> {head, arm}).
struct SyntheticRig {
  ossa::Asset asset;
  static SyntheticRig make() {
    const std::vector<uint8_t> bytes = ossa::test::make_valid_file();
    auto a = ossa::Asset::from_bytes(bytes, "synthetic");
    if (!a) throw std::runtime_error(a.error().message);
    return SyntheticRig{std::move(*a)};
  }
};

/// The cooked Pab skeleton (67 joints): the committed fixture ossa-cook made (tests/fixtures/Pab),
/// opened once per test run; nullopt (after a failure naming the file) when it cannot be opened.
const std::optional<ossa::Asset>& pab() {
  static const std::optional<ossa::Asset> asset = []() -> std::optional<ossa::Asset> {
    auto a = ossa::Asset::open((ossa::test::fixtures_dir() / "Pab" / "skeleton.ossa").string());
    if (!a) {
      ADD_FAILURE() << a.error().message;
      return std::nullopt;
    }
    return std::move(*a);
  }();
  return asset;
}

#define REQUIRE_PAB() ASSERT_TRUE(pab()) << "tests/fixtures/Pab/skeleton.ossa could not be opened"

// ---------------------------------------------------------------------------------------------
// Pose storage

TEST(Pose, StorageIsAlignedPaddedAndIdentity) {
  Pose p(kJoints);
  const PoseSpan s = p.span();
  EXPECT_EQ(s.joint_count, kJoints);
  EXPECT_EQ(s.stride, 16u);
  EXPECT_EQ(reinterpret_cast<uintptr_t>(s.base) % 32, 0u);
  for (uint32_t k = 0; k < ossa::kPoseComponents; ++k)
    EXPECT_EQ(reinterpret_cast<uintptr_t>(s[ossa::PoseComponent(k)]) % 32, 0u) << "component " << k;
  for (uint32_t j = 0; j < s.stride; ++j) {
    const Transform t = ossa::get_transform(p, j);
    EXPECT_EQ(t.translation, glm::vec3(0.0f));
    EXPECT_EQ(t.rotation, glm::quat(1, 0, 0, 0));
    EXPECT_EQ(t.scale, glm::vec3(1.0f));
  }
  EXPECT_EQ(ossa::pose_stride(0), 0u);
  EXPECT_EQ(ossa::pose_stride(8), 8u);
  EXPECT_EQ(ossa::pose_stride(67), 72u);
}

TEST(Pose, MoveTransfersStorage) {
  Pose a = random_pose(kJoints, 1);
  const float* storage = a.span().base;
  Pose b(std::move(a));
  EXPECT_EQ(b.span().base, storage);
  EXPECT_EQ(b.joint_count(), kJoints);
  EXPECT_EQ(a.joint_count(), 0u);  // NOLINT(bugprone-use-after-move): the moved-from state is API
  EXPECT_EQ(a.span().base, nullptr);

  Pose c(3);
  c = std::move(b);
  EXPECT_EQ(c.span().base, storage);
  EXPECT_EQ(c.joint_count(), kJoints);
  EXPECT_EQ(b.span().base, nullptr);
  Pose& self = c;
  c = std::move(self);
  EXPECT_EQ(c.span().base, storage) << "self-move keeps the storage";

  Pose empty;
  EXPECT_EQ(empty.joint_count(), 0u);
  ossa::set_identity(empty);  // no lanes: must not touch memory
}

TEST(Pose, TransformRoundTripAndCopy) {
  Pose p(kJoints);
  Rng rng(2);
  std::vector<Transform> ts;
  for (uint32_t j = 0; j < kJoints; ++j) {
    ts.push_back(rng.transform());
    ossa::set_transform(p, j, ts.back());
  }
  for (uint32_t j = 0; j < kJoints; ++j) {
    const Transform t = ossa::get_transform(p, j);
    EXPECT_EQ(t.translation, ts[j].translation);
    EXPECT_EQ(t.rotation, ts[j].rotation);
    EXPECT_EQ(t.scale, ts[j].scale);
  }
  expect_padding_identity(p);
  Pose q(kJoints);
  ossa::copy_pose(p, q);
  expect_pose_eq(q, p);
  expect_padding_identity(q);
  ossa::set_identity(q);
  for (uint32_t j = 0; j < q.span().stride; ++j) EXPECT_EQ(q.span()[ossa::kRw][j], 1.0f);
}

TEST(Pose, BindPoseFromSkeleton) {
  const SyntheticRig rig = SyntheticRig::make();
  const ossa::SkeletonView sk = rig.asset.skeleton();
  const ossa::test::SyntheticSkeleton spec;
  Pose p(uint32_t(sk.joint_count()));
  ossa::set_bind_pose(sk, p);
  for (uint32_t j = 0; j < p.joint_count(); ++j) {
    const Transform t = ossa::get_transform(p, j);
    EXPECT_EQ(t.translation, glm::vec3(spec.translations[j].x(), spec.translations[j].y(), spec.translations[j].z()));
    EXPECT_EQ(t.rotation,
              glm::quat(spec.rotations[j].w(), spec.rotations[j].x(), spec.rotations[j].y(), spec.rotations[j].z()));
    EXPECT_EQ(t.scale, glm::vec3(spec.scales[j].x(), spec.scales[j].y(), spec.scales[j].z()));
  }
  expect_padding_identity(p);
}

// ---------------------------------------------------------------------------------------------
// blend

TEST(Blend, EndsAreExactAndSelfBlendIsIdentity) {
  const Pose a = random_pose(kJoints, 10), b = random_pose(kJoints, 11);
  Pose out(kJoints);
  ossa::blend(a, b, 0.0f, out);
  expect_pose_eq(out, a);
  ossa::blend(a, b, 1.0f, out);
  expect_pose_eq(out, b);
  ossa::blend(a, b, -3.0f, out);  // clamped
  expect_pose_eq(out, a);
  ossa::blend(a, b, 7.0f, out);
  expect_pose_eq(out, b);
  for (float alpha : {0.25f, 0.5f, 0.9f}) {
    ossa::blend(a, a, alpha, out);
    expect_pose_near(out, a, 1e-6f);
    expect_padding_identity(out);
  }
}

TEST(Blend, MatchesPerJointNlerpAndMayAliasItsInputs) {
  const Pose a = random_pose(kJoints, 12), b = random_pose(kJoints, 13);
  const float alpha = 0.3f;
  Pose out(kJoints);
  ossa::blend(a, b, alpha, out);
  for (uint32_t j = 0; j < kJoints; ++j) {
    const Transform ta = ossa::get_transform(a, j), tb = ossa::get_transform(b, j);
    const Transform to = ossa::get_transform(out, j);
    const glm::quat qb = glm::dot(ta.rotation, tb.rotation) < 0 ? -tb.rotation : tb.rotation;
    const glm::quat expect = glm::normalize(ta.rotation * (1 - alpha) + qb * alpha);
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(to.rotation[c], expect[c], 1e-6f) << j;
    for (int c = 0; c < 3; ++c) {
      EXPECT_NEAR(to.translation[c], glm::mix(ta.translation[c], tb.translation[c], alpha), 1e-6f) << j;
      EXPECT_NEAR(to.scale[c], glm::mix(ta.scale[c], tb.scale[c], alpha), 1e-6f) << j;
    }
  }
  expect_padding_identity(out);

  Pose in_place(kJoints);
  ossa::copy_pose(a, in_place);
  ossa::blend(in_place, b, alpha, in_place);
  expect_pose_eq(in_place, out);
  ossa::copy_pose(b, in_place);
  ossa::blend(a, in_place, alpha, in_place);
  expect_pose_eq(in_place, out);
}

TEST(Blend, OppositeHemisphereTakesTheShortArc) {
  // b holds the same rotation as 40 degrees about z, written with the opposite sign. A naive
  // lerp would pass near zero and swing the long way; the short arc lands on 20 degrees.
  Pose a(1), b(1), out(1);
  ossa::set_transform(a, 0, {glm::vec3(0), about_z(0.0f), glm::vec3(1)});
  ossa::set_transform(b, 0, {glm::vec3(0), -about_z(40.0f), glm::vec3(1)});
  ossa::blend(a, b, 0.5f, out);
  const glm::quat r = ossa::get_transform(out, 0).rotation;
  EXPECT_GT(glm::dot(r, about_z(0.0f)), 0.0f) << "follows the first pose's hemisphere";
  EXPECT_NEAR(glm::degrees(glm::angle(r)), 20.0f, 1e-3f);
  EXPECT_NEAR(std::abs(glm::dot(r, about_z(20.0f))), 1.0f, 1e-6f);

  // The same through blend_n, with the first pose's sign negative and one more input.
  Pose c(1);
  ossa::set_transform(a, 0, {glm::vec3(0), -about_z(10.0f), glm::vec3(1)});
  ossa::set_transform(b, 0, {glm::vec3(0), about_z(30.0f), glm::vec3(1)});
  ossa::set_transform(c, 0, {glm::vec3(0), -about_z(50.0f), glm::vec3(1)});
  const ConstPoseSpan poses[] = {a, b, c};
  const float weights[] = {1, 1, 1};
  ossa::blend_n(poses, weights, out);
  const glm::quat rn = ossa::get_transform(out, 0).rotation;
  EXPECT_NEAR(std::abs(glm::dot(rn, about_z(30.0f))), 1.0f, 1e-6f) << "mean of 10, 30, 50 degrees";
  EXPECT_LT(rn.w, 0.0f) << "sign of the first pose";
}

// ---------------------------------------------------------------------------------------------
// blend_n

TEST(BlendN, OneWeightIsThatPose) {
  const Pose a = random_pose(kJoints, 20), b = random_pose(kJoints, 21), c = random_pose(kJoints, 22);
  const ConstPoseSpan poses[] = {a, b, c};
  Pose out(kJoints);
  const float only_b[] = {0, 2.5f, 0};
  ossa::blend_n(poses, only_b, out);
  expect_pose_near(out, b, 1e-6f);
  const float only_a[] = {0.1f, 0, 0};
  ossa::blend_n(poses, only_a, out);
  expect_pose_near(out, a, 1e-6f);
  ossa::blend_n(std::span<const ConstPoseSpan>(poses, 1), std::span<const float>(only_a, 1), out);
  expect_pose_near(out, a, 1e-6f);
  expect_padding_identity(out);
}

TEST(BlendN, WeightsAreNormalized) {
  const Pose a = random_pose(kJoints, 23), b = random_pose(kJoints, 24), c = random_pose(kJoints, 25);
  const ConstPoseSpan poses[] = {a, b, c};
  Pose out1(kJoints), out2(kJoints), out3(kJoints);
  const float w1[] = {0.2f, 0.3f, 0.5f};
  const float w2[] = {2.0f, 3.0f, 5.0f};
  const float w3[] = {0.06f, 0.09f, 0.15f};
  ossa::blend_n(poses, w1, out1);
  ossa::blend_n(poses, w2, out2);
  ossa::blend_n(poses, w3, out3);
  expect_pose_near(out2, out1, 1e-6f);
  expect_pose_near(out3, out1, 1e-6f);
  expect_padding_identity(out1);
  expect_padding_identity(out3);

  // Two poses: the same as blend.
  Pose pair(kJoints), single(kJoints);
  const float w[] = {0.7f, 0.3f};
  ossa::blend_n(std::span<const ConstPoseSpan>(poses, 2), w, pair);
  ossa::blend(a, b, 0.3f, single);
  expect_pose_near(pair, single, 1e-6f);

  // No usable weights: the first pose, not NaNs.
  const float zero[] = {0, 0, 0};
  ossa::blend_n(poses, zero, out1);
  expect_pose_eq(out1, a);
}

TEST(BlendN, ManyPosesMatchPerJointReference) {
  // More than three inputs take several passes over the pose (groups of three, the last one
  // partial); zero weights are skipped. Compare with the definition, joint by joint.
  constexpr size_t kCount = 8;
  std::vector<Pose> inputs;
  for (size_t i = 0; i < kCount; ++i) inputs.push_back(random_pose(kJoints, uint32_t(80 + i)));
  std::vector<ConstPoseSpan> poses(inputs.begin(), inputs.end());
  for (const std::vector<float>& weights :
       {std::vector<float>{1, 2, 3, 4, 5, 6, 7, 8}, std::vector<float>{0, 0.5f, 0, 1, 2, 0, 0.25f, 0},
        std::vector<float>{3, 1, 4, 1, 5, 9, 2}}) {
    const size_t n = std::min(poses.size(), weights.size());
    Pose out(kJoints);
    ossa::blend_n(std::span(poses.data(), n), std::span(weights.data(), n), out);
    expect_padding_identity(out);
    double total = 0;
    for (size_t i = 0; i < n; ++i) total += weights[i];
    size_t first = 0;
    while (weights[first] == 0) ++first;
    for (uint32_t j = 0; j < kJoints; ++j) {
      const glm::quat ref = ossa::get_transform(poses[first], j).rotation;
      glm::dvec3 t(0), s(0);
      glm::dquat q(0, 0, 0, 0);
      for (size_t i = 0; i < n; ++i) {
        const Transform ti = ossa::get_transform(poses[i], j);
        const double w = weights[i] / total;
        t += w * glm::dvec3(ti.translation);
        s += w * glm::dvec3(ti.scale);
        const glm::dquat qi(ti.rotation.w, ti.rotation.x, ti.rotation.y, ti.rotation.z);
        q = q + (glm::dot(ref, ti.rotation) < 0 ? -w : w) * qi;
      }
      q = glm::normalize(q);
      const Transform to = ossa::get_transform(out, j);
      for (int c = 0; c < 3; ++c) {
        EXPECT_NEAR(to.translation[c], t[c], 1e-5) << "joint " << j;
        EXPECT_NEAR(to.scale[c], s[c], 1e-5) << "joint " << j;
      }
      EXPECT_NEAR(to.rotation.x, q.x, 1e-5) << "joint " << j;
      EXPECT_NEAR(to.rotation.y, q.y, 1e-5) << "joint " << j;
      EXPECT_NEAR(to.rotation.z, q.z, 1e-5) << "joint " << j;
      EXPECT_NEAR(to.rotation.w, q.w, 1e-5) << "joint " << j;
    }
  }
}

TEST(BlendN, ZeroWeightPosesDoNotMatter) {
  // A zero-weight first pose in the opposite hemisphere must neither flip nor skew the result.
  Pose a(kJoints), b = random_pose(kJoints, 90), c = random_pose(kJoints, 91);
  for (uint32_t j = 0; j < kJoints; ++j) {
    Transform t = ossa::get_transform(b, j);
    t.rotation = -t.rotation;
    ossa::set_transform(a, j, t);
  }
  const ConstPoseSpan with_zero[] = {a, b, c}, without[] = {b, c};
  const float w3[] = {0, 0.4f, 0.6f}, w2[] = {0.4f, 0.6f};
  Pose out3(kJoints), out2(kJoints);
  ossa::blend_n(with_zero, w3, out3);
  ossa::blend_n(without, w2, out2);
  expect_pose_eq(out3, out2);
}

// ---------------------------------------------------------------------------------------------
// Joint masks and blend_layered

TEST(JointMask, SyntheticTree) {
  const std::vector<int16_t> parents = ossa::test::SyntheticSkeleton{}.parents;  // root spine head arm
  auto mask = [&](int joint, int depth) {
    std::vector<float> m(parents.size(), 0.0f);
    ossa::build_joint_mask(parents, joint, depth, m);
    return m;
  };
  EXPECT_EQ(mask(1, 0), (std::vector<float>{0, 1, 0, 0}));
  EXPECT_EQ(mask(1, 1), (std::vector<float>{0, 1, 1, 1}));
  EXPECT_EQ(mask(1, -1), (std::vector<float>{0, 1, 1, 1}));
  EXPECT_EQ(mask(0, 1), (std::vector<float>{1, 1, 0, 0}));
  EXPECT_EQ(mask(0, -1), (std::vector<float>{1, 1, 1, 1}));
  EXPECT_EQ(mask(3, 5), (std::vector<float>{0, 0, 0, 1}));
  EXPECT_EQ(mask(4, -1), (std::vector<float>{0, 0, 0, 0})) << "out-of-range joint: nothing";
  EXPECT_EQ(mask(-1, -1), (std::vector<float>{0, 0, 0, 0}));

  // Calls max-combine: head and arm separately make one mask; partial weights are kept where
  // no call covers them and raised to 1 where one does.
  std::vector<float> m = {0.5f, 0.25f, 0.0f, 0.75f};
  ossa::build_joint_mask(parents, 2, 0, m);
  ossa::build_joint_mask(parents, 3, 0, m);
  EXPECT_EQ(m, (std::vector<float>{0.5f, 0.25f, 1.0f, 1.0f}));
}

TEST(JointMask, MatchesWalkingUpParents) {
  // A random bushy tree: parents before children, but subtrees not contiguous, so the mask must
  // not rely on depth-first layout.
  std::vector<int16_t> parents = {-1};
  Rng rng(30);
  for (int i = 1; i < 90; ++i) parents.push_back(int16_t(std::min(i - 1, int(rng.uniform(0, 1) * float(i)))));
  parents.push_back(-1);  // a second root
  parents.push_back(int16_t(parents.size() - 1));
  for (int joint = 0; joint < int(parents.size()); ++joint)
    for (int depth : {-1, 0, 1, 2, 3}) {
      std::vector<float> m(parents.size(), 0.0f);
      ossa::build_joint_mask(parents, joint, depth, m);
      ASSERT_EQ(m, reference_mask(parents, joint, depth)) << "joint " << joint << " depth " << depth;
    }
}

TEST(JointMask, PabUpperBody) {
  REQUIRE_PAB();
  const ossa::SkeletonView sk = pab()->skeleton();
  const std::span<const int16_t> parents = sk.parents();
  ASSERT_EQ(sk.joint_count(), 67u);
  for (int joint = 0; joint < int(parents.size()); ++joint)
    for (int depth : {-1, 0, 1, 2}) {
      std::vector<float> m(parents.size(), 0.0f);
      ossa::build_joint_mask(parents, joint, depth, m);
      ASSERT_EQ(m, reference_mask(parents, joint, depth)) << sk.joint_name(size_t(joint)) << " depth " << depth;
    }

  // The upper body of the example (crossarms over walk). Pab's legs hang from Spine,
  // not Hips, so the upper body starts at Spine1: chest, arms, hands, neck and head, and nothing
  // of the hips or legs.
  const int spine1 = sk.find_joint("Spine1");
  ASSERT_GE(spine1, 0);
  std::vector<float> m(parents.size(), 0.0f);
  ossa::build_joint_mask(parents, spine1, -1, m);
  std::set<std::string> masked;
  for (size_t j = 0; j < m.size(); ++j)
    if (m[j] == 1.0f) masked.insert(std::string(sk.joint_name(j)));
  for (const char* name : {"Spine1", "Spine3", "Head", "LeftArm", "Lefthand", "LeftHandIndex3", "RightArm", "RightHand",
                           "RightHandPinky3"})
    EXPECT_TRUE(masked.count(name)) << name;
  for (const char* name : {"Hips", "Pelvis", "Spine", "LeftUpLeg", "LeftFoot", "RightUpLeg", "RightFoot"})
    EXPECT_FALSE(masked.count(name)) << name;
  EXPECT_EQ(masked.size(), 54u) << "67 joints less Hips, Pelvis, Spine and the two 5-joint legs";
  // Depth 2 from Spine1: Spine1, Spine2, Spine3 and nothing else.
  std::fill(m.begin(), m.end(), 0.0f);
  ossa::build_joint_mask(parents, spine1, 2, m);
  masked.clear();
  for (size_t j = 0; j < m.size(); ++j)
    if (m[j] == 1.0f) masked.insert(std::string(sk.joint_name(j)));
  EXPECT_EQ(masked, (std::set<std::string>{"Spine1", "Spine2", "Spine3"}));
}

TEST(BlendLayered, MaskSelectsBaseOrLayer) {
  const Pose base = random_pose(kJoints, 40), layer = random_pose(kJoints, 41);
  Pose out(kJoints);
  std::vector<float> zeros(kJoints, 0.0f), ones(kJoints, 1.0f);
  ossa::blend_layered(base, layer, zeros, 1.0f, out);
  expect_pose_near(out, base, 1e-6f);
  ossa::blend_layered(base, layer, ones, 1.0f, out);
  expect_pose_near(out, layer, 1e-6f);
  ossa::blend_layered(base, layer, ones, 0.0f, out);
  expect_pose_near(out, base, 1e-6f);
  expect_padding_identity(out);

  // Mixed weights: each joint is blend() of that joint at weight * mask.
  std::vector<float> mask(kJoints);
  for (uint32_t j = 0; j < kJoints; ++j) mask[j] = float(j % 5) / 4.0f;
  ossa::blend_layered(base, layer, mask, 0.8f, out);
  Pose single(kJoints);
  for (uint32_t j = 0; j < kJoints; ++j) {
    ossa::blend(base, layer, 0.8f * mask[j], single);
    const Transform to = ossa::get_transform(out, j), ts = ossa::get_transform(single, j);
    for (int c = 0; c < 4; ++c) EXPECT_NEAR(to.rotation[c], ts.rotation[c], 1e-6f) << j;
    for (int c = 0; c < 3; ++c) EXPECT_NEAR(to.translation[c], ts.translation[c], 1e-6f) << j;
  }

  // In place over the base, and a short mask (joints past it keep the base).
  Pose in_place(kJoints);
  ossa::copy_pose(base, in_place);
  ossa::blend_layered(in_place, layer, mask, 0.8f, in_place);
  expect_pose_eq(in_place, out);
  ossa::blend_layered(base, layer, std::span<const float>(ones.data(), 3), 1.0f, out);
  for (uint32_t j = 0; j < kJoints; ++j) {
    const Transform to = ossa::get_transform(out, j);
    const Transform te = ossa::get_transform(j < 3 ? ConstPoseSpan(layer) : ConstPoseSpan(base), j);
    EXPECT_NEAR(to.translation.x, te.translation.x, 1e-6f) << j;
  }
}

// ---------------------------------------------------------------------------------------------
// Additive

TEST(Additive, RoundTripAndWeights) {
  const Pose pose = random_pose(kJoints, 50), reference = random_pose(kJoints, 51);
  Pose delta(kJoints), out(kJoints);
  ossa::make_additive(pose, reference, delta);
  expect_padding_identity(delta);
  ossa::add(reference, delta, 1.0f, out);
  expect_pose_near(out, pose, 1e-5f);
  expect_padding_identity(out);
  ossa::add(reference, delta, 0.0f, out);
  expect_pose_near(out, reference, 1e-6f);

  // A pose against itself is no change.
  ossa::make_additive(reference, reference, delta);
  for (uint32_t j = 0; j < kJoints; ++j) {
    const Transform t = ossa::get_transform(delta, j);
    EXPECT_NEAR(glm::length(t.translation), 0.0f, 1e-6f);
    EXPECT_NEAR(std::abs(t.rotation.w), 1.0f, 1e-6f);
    EXPECT_NEAR(glm::length(t.scale - glm::vec3(1)), 0.0f, 1e-6f);
  }

  // Half weight: half the rotation angle, half the translation, in place over the base.
  Pose base(1), d(1), half(1);
  ossa::set_transform(base, 0, {glm::vec3(1, 2, 3), about_z(10.0f), glm::vec3(2)});
  ossa::set_transform(d, 0, {glm::vec3(4, 0, 0), about_z(60.0f), glm::vec3(3)});
  ossa::copy_pose(base, half);
  ossa::add(half, d, 0.5f, half);
  const Transform th = ossa::get_transform(half, 0);
  EXPECT_NEAR(std::abs(glm::dot(th.rotation, about_z(40.0f))), 1.0f, 1e-6f);
  EXPECT_NEAR(th.translation.x, 3.0f, 1e-6f);
  EXPECT_NEAR(th.scale.x, 4.0f, 1e-6f);  // 2 * lerp(1, 3, 0.5)
}

TEST(Additive, TinyReferenceScalesAndDeepStacksStayFinite) {
  // A tiny reference scale (the loader accepts any scale within +-1e7, zero and denormals
  // included) has a ratio beyond float range; stacking additive layers multiplies scales again.
  // Every result must stay finite and within the loader's bound of 1e7. (Found by fuzz_load.)
  Pose pose(1), reference(1), delta(1), out(1);
  ossa::set_transform(pose, 0, {glm::vec3(1e7f, -1e7f, 0), about_z(30.0f), glm::vec3(1e7f, 1.0f, -1e7f)});
  ossa::set_transform(reference, 0, {glm::vec3(-1e7f, 1e7f, 0), about_z(0.0f), glm::vec3(2e-38f, 0.0f, 3e-38f)});
  ossa::make_additive(pose, reference, delta);
  const Transform td = ossa::get_transform(delta, 0);
  EXPECT_EQ(td.scale.x, 1e7f);   // clamped ratio
  EXPECT_EQ(td.scale.y, 1.0f);   // zero reference: no change
  EXPECT_EQ(td.scale.z, -1e7f);  // clamped, sign kept
  {
    // A subnormal reference scale is a zero one: the kernels run with denormals-are-zero
    // (runtime/internal/float_env.h), so it costs no assist and changes nothing.
    Pose denormal(1), d(1);
    ossa::set_transform(denormal, 0, {glm::vec3(0.0f), about_z(0.0f), glm::vec3(1e-40f, -1e-39f, 1e-45f)});
    ossa::make_additive(pose, denormal, d);
    const Transform t = ossa::get_transform(d, 0);
    EXPECT_EQ(t.scale, glm::vec3(1.0f));
  }
  ossa::copy_pose(pose, out);
  for (int layer = 0; layer < 40; ++layer) ossa::add(out, delta, 8.0f, out);
  const Transform t = ossa::get_transform(out, 0);
  for (int c = 0; c < 3; ++c) {
    EXPECT_TRUE(std::isfinite(t.translation[c]) && std::abs(t.translation[c]) <= 1e7f) << t.translation[c];
    EXPECT_TRUE(std::isfinite(t.scale[c]) && std::abs(t.scale[c]) <= 1e7f) << t.scale[c];
  }
  EXPECT_NEAR(glm::length(t.rotation), 1.0f, 1e-5f);
}

// ---------------------------------------------------------------------------------------------
// local_to_model

TEST(LocalToModel, MatchesDoublePrecisionReference) {
  // A random tree with two roots and chains deep enough for error to build up.
  constexpr uint32_t kCount = 43;
  std::vector<int16_t> parents = {-1};
  Rng rng(60);
  for (uint32_t i = 1; i < kCount; ++i)
    parents.push_back(i == 20 ? int16_t(-1) : int16_t(std::max(0, int(i) - 1 - int(rng.uniform(0, 3)))));
  const Pose local = random_pose(kCount, 61);
  std::vector<glm::mat4> model(kCount);
  ossa::local_to_model(parents, local, model);
  const std::vector<glm::dmat4> ref = reference_model(parents, local);
  for (uint32_t i = 0; i < kCount; ++i) expect_matrix_near(model[i], ref[i], 1e-5, "joint " + std::to_string(i));
}

TEST(LocalToModel, BindPoseReproducesInverseBind) {
  const SyntheticRig rig = SyntheticRig::make();
  const ossa::SkeletonView sk = rig.asset.skeleton();
  Pose bind(uint32_t(sk.joint_count()));
  ossa::set_bind_pose(sk, bind);
  std::vector<glm::mat4> model(sk.joint_count());
  ossa::local_to_model(sk.parents(), bind, model);
  for (size_t j = 0; j < model.size(); ++j)
    expect_matrix_near(model[j], glm::inverse(to_dmat4(sk.inverse_bind()[j])), 1e-5, std::string(sk.joint_name(j)));
}

TEST(LocalToModel, PabBindPoseReproducesInverseBind) {
  REQUIRE_PAB();
  const ossa::SkeletonView sk = pab()->skeleton();
  Pose bind(uint32_t(sk.joint_count()));
  ossa::set_bind_pose(sk, bind);
  expect_padding_identity(bind);
  std::vector<glm::mat4> model(sk.joint_count());
  ossa::local_to_model(sk.parents(), bind, model);
  const std::vector<glm::dmat4> ref = reference_model(sk.parents(), bind);
  for (size_t j = 0; j < model.size(); ++j) {
    const std::string name(sk.joint_name(j));
    expect_matrix_near(model[j], ref[j], 1e-5, name + " (double reference)");
    // The cooker inverted its double-precision bind matrices; the float bind TRS it stored
    // reproduces them to float precision of the rig's size (Pab is in centimetres).
    expect_matrix_near(model[j], glm::inverse(to_dmat4(sk.inverse_bind()[j])), 1e-5, name + " (inverse bind)");
  }
}

TEST(LocalToModel, BadParentsAreRootsAndShortSpansAreRespected) {
  const Pose local = random_pose(4, 70);
  const std::vector<int16_t> parents = {-1, 0, 5, 2};  // joint 2 names a later joint
  std::vector<glm::mat4> model(4, glm::mat4(0.0f));
  ossa::local_to_model(parents, local, model);
  const std::vector<int16_t> fixed = {-1, 0, -1, 2};
  const std::vector<glm::dmat4> ref = reference_model(fixed, local);
  for (size_t j = 0; j < 4; ++j) expect_matrix_near(model[j], ref[j], 1e-5, "joint " + std::to_string(j));

  std::vector<glm::mat4> two(2, glm::mat4(0.0f));
  ossa::local_to_model(parents, local, two);  // writes only what the span holds
  expect_matrix_near(two[1], ref[1], 1e-5, "joint 1");
}

}  // namespace

// ---------------------------------------------------------------------------------------------
// The two compiled copies of the per-joint loops (ossa/anim/vector_isa.h)

TEST(VectorIsa, BothCopiesGiveBitIdenticalPoses) {
  // The AVX2 and baseline copies use IEEE add / sub / mul / div only (no FMA), so every kernel
  // must agree bit for bit, whichever copy a benchmark or a CPU picks. On a CPU or build without
  // the AVX2 copy, set_vector_isa must refuse it and leave the baseline selected.
  if (ossa::best_vector_isa() != ossa::VectorIsa::Avx2) {
    EXPECT_FALSE(ossa::set_vector_isa(ossa::VectorIsa::Avx2));
    EXPECT_EQ(ossa::vector_isa(), ossa::VectorIsa::Baseline);
    GTEST_SKIP() << "no AVX2 copy on this CPU or build";
  }
  constexpr uint32_t kMany = 67;
  const Pose a = random_pose(kMany, 200), b = random_pose(kMany, 201), c = random_pose(kMany, 202);
  std::vector<int16_t> parents(kMany);
  for (uint32_t j = 0; j < kMany; ++j) parents[j] = static_cast<int16_t>(j == 0 ? -1 : (j - 1) / 2);
  std::vector<float> mask(kMany);
  for (uint32_t j = 0; j < kMany; ++j) mask[j] = static_cast<float>(j % 5) / 4.0f;
  struct Out {
    Pose blend{kMany}, blend_n{kMany}, layered{kMany}, additive{kMany}, added{kMany};
    std::vector<glm::mat4> model = std::vector<glm::mat4>(kMany);
  };
  const auto run = [&](ossa::VectorIsa isa, Out& o) {
    ASSERT_TRUE(ossa::set_vector_isa(isa));
    EXPECT_EQ(ossa::vector_isa(), isa);
    ossa::blend(a, b, 0.37f, o.blend);
    const ConstPoseSpan in[3] = {a, b, c};
    const float w[3] = {0.2f, 0.5f, 0.3f};
    ossa::blend_n(in, w, o.blend_n);
    ossa::blend_layered(a, b, mask, 0.8f, o.layered);
    ossa::make_additive(b, a, o.additive);
    ossa::add(c, o.additive, 0.6f, o.added);
    ossa::local_to_model(parents, o.added, o.model);
  };
  Out avx2, baseline;
  run(ossa::VectorIsa::Avx2, avx2);
  run(ossa::VectorIsa::Baseline, baseline);
  ossa::set_vector_isa(ossa::best_vector_isa());
  const auto same = [](const Pose& x, const Pose& y) {
    const ConstPoseSpan sx = x, sy = y;
    return std::memcmp(sx.base, sy.base, sizeof(float) * 10 * sx.stride) == 0;
  };
  EXPECT_TRUE(same(avx2.blend, baseline.blend));
  EXPECT_TRUE(same(avx2.blend_n, baseline.blend_n));
  EXPECT_TRUE(same(avx2.layered, baseline.layered));
  EXPECT_TRUE(same(avx2.additive, baseline.additive));
  EXPECT_TRUE(same(avx2.added, baseline.added));
  EXPECT_EQ(std::memcmp(avx2.model.data(), baseline.model.data(), sizeof(glm::mat4) * kMany), 0);
}
