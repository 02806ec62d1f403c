// ik_test.cpp — two_bone_ik and aim_ik (ossa/anim/ik.h), tested the way ozz tests its IK jobs: analytic cases
// against known rotations, then forward kinematics rebuilding the chain from the corrected local
// pose (local_to_model, the runtime's own) for seeded random chains, targets, poles, twists,
// softening and weights, and degenerate chains that must stay finite.
//
// The chain is a small skeleton: root (0) > start (1) > twist bone (2) > mid (3) > end (4). The
// twist bone between start and mid checks that the job works on model-space matrices and needs no
// direct parent links; the root carries an arbitrary placement (rotation, translation, uniform
// scale) so corrections are checked in local space under a transformed parent.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <random>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include <ossa/anim/ik.h>
#include <ossa/anim/pose.h>
#include <ossa/anim/pose_ops.h>
#include "allocation_counter.h"

namespace {

using ossa::Transform;

constexpr uint32_t kStart = 1, kTwist = 2, kMid = 3, kEnd = 4;
const std::array<int16_t, 5> kParents{-1, 0, 1, 2, 3};

struct Chain {
  ossa::Pose local{5};
  std::vector<glm::mat4> model = std::vector<glm::mat4>(5);

  void update() { ossa::local_to_model(kParents, local, model); }
  glm::vec3 at(uint32_t j) const { return glm::vec3(model[j][3]); }
  float length() const { return glm::length(at(kMid) - at(kStart)) + glm::length(at(kEnd) - at(kMid)); }

  ossa::TwoBoneIkInput input(glm::vec3 target) const {
    ossa::TwoBoneIkInput in;
    in.start = model[kStart];
    in.mid = model[kMid];
    in.end = model[kEnd];
    in.target = target;
    return in;
  }
  /// Multiplies the corrections into the local pose and recomputes model space.
  void apply(const ossa::TwoBoneIkOutput& out) {
    for (const auto& [joint, correction] :
         {std::pair{kStart, out.start_correction}, std::pair{kMid, out.mid_correction}}) {
      Transform t = ossa::get_transform(local, joint);
      t.rotation = glm::normalize(t.rotation * correction);
      ossa::set_transform(local, joint, t);
    }
    update();
  }
};

Transform trs(glm::vec3 t, glm::quat r = glm::quat(1, 0, 0, 0), glm::vec3 s = glm::vec3(1.0f)) {
  Transform x;
  x.translation = t;
  x.rotation = r;
  x.scale = s;
  return x;
}

/// An arm along +x from the origin: upper 1 (start at 0, mid at 1), lower 1 (end at 2), bent
/// `bend` radians about +z at the mid joint.
Chain straight_arm(float bend = 0.0f) {
  Chain c;
  ossa::set_transform(c.local, 0, trs(glm::vec3(0.0f)));
  ossa::set_transform(c.local, kStart, trs(glm::vec3(0.0f)));
  ossa::set_transform(c.local, kTwist, trs(glm::vec3(0.5f, 0, 0)));
  ossa::set_transform(c.local, kMid, trs(glm::vec3(0.5f, 0, 0), glm::angleAxis(bend, glm::vec3(0, 0, 1))));
  ossa::set_transform(c.local, kEnd, trs(glm::vec3(1.0f, 0, 0)));
  c.update();
  return c;
}

glm::quat random_rotation(std::mt19937& rng) {
  std::normal_distribution<float> n(0.0f, 1.0f);
  return glm::normalize(glm::quat(n(rng), n(rng), n(rng), n(rng)));
}

/// A random chain: placed root (with uniform scale), random bone lengths and joint rotations.
Chain random_chain(std::mt19937& rng) {
  std::uniform_real_distribution<float> len(0.2f, 1.5f), pos(-2.0f, 2.0f), scale(0.5f, 2.0f);
  Chain c;
  ossa::set_transform(c.local, 0, trs({pos(rng), pos(rng), pos(rng)}, random_rotation(rng), glm::vec3(scale(rng))));
  ossa::set_transform(c.local, kStart, trs({pos(rng), pos(rng), pos(rng)}, random_rotation(rng)));
  const float upper = len(rng);
  ossa::set_transform(c.local, kTwist, trs({0.5f * upper, 0, 0}, random_rotation(rng)));
  // The twist bone's rotation turns the rest of the chain; the mid joint sits further along its x.
  ossa::set_transform(c.local, kMid, trs({0.5f * upper, 0, 0}, random_rotation(rng)));
  ossa::set_transform(c.local, kEnd, trs({len(rng), 0, 0}, random_rotation(rng)));
  c.update();
  return c;
}

bool unit_and_finite(const glm::quat& q) {
  return std::isfinite(q.x) && std::isfinite(q.y) && std::isfinite(q.z) && std::isfinite(q.w) &&
         std::fabs(glm::length(q) - 1.0f) < 1e-5f;
}

/// Signed side of the mid joint about the start-to-target axis, measured against the pole.
float pole_side(const Chain& c, glm::vec3 target, glm::vec3 pole) {
  const glm::vec3 k = glm::normalize(target - c.at(kStart));
  glm::vec3 m = c.at(kMid) - c.at(kStart);
  m -= k * glm::dot(m, k);
  glm::vec3 p = pole - k * glm::dot(pole, k);
  return glm::dot(glm::normalize(m), glm::normalize(p));
}

// ---------------------------------------------------------------------------------------------
// Analytic cases

TEST(TwoBoneIk, RightAngleReachIsTheKnownRotations) {
  // Arm along +x, bones of 1, slightly bent about +z. Of the two elbows that reach (1, 1, 0),
  // (1, 0, 0) and (0, 1, 0), the pole (1, -1, 0) picks the first: the upper bone keeps +x (the
  // start joint does not turn) and the mid joint's rotation becomes 90 degrees about z.
  Chain c = straight_arm(0.1f);  // a slight bend about +z: the elbow bends that way
  ossa::TwoBoneIkInput in = c.input({1, 1, 0});
  in.pole = glm::vec3(1, -1, 0);
  ossa::TwoBoneIkOutput out;
  ASSERT_TRUE(ossa::two_bone_ik(in, &out));
  EXPECT_TRUE(out.reached);
  c.apply(out);
  EXPECT_NEAR(glm::length(c.at(kMid) - glm::vec3(1, 0, 0)), 0.0f, 1e-5f);
  EXPECT_NEAR(glm::length(c.at(kEnd) - glm::vec3(1, 1, 0)), 0.0f, 1e-5f);
  // The start joint did not need to turn (upper bone stays on +x); the mid joint's total local
  // rotation is 90 degrees about z.
  const glm::quat start = ossa::get_transform(c.local, kStart).rotation;
  EXPECT_NEAR(std::fabs(start.w), 1.0f, 1e-5f);
  const glm::quat mid = ossa::get_transform(c.local, kMid).rotation;
  const glm::quat want = glm::angleAxis(glm::radians(90.0f), glm::vec3(0, 0, 1));
  EXPECT_NEAR(std::fabs(glm::dot(mid, want)), 1.0f, 1e-5f);
}

TEST(TwoBoneIk, StraightChainBendsAboutMidAxis) {
  // A straight chain has no bend to follow: it bends about the mid joint's local axis.
  Chain c = straight_arm(0.0f);
  ossa::TwoBoneIkInput in = c.input({1.5f, 0, 0});
  in.mid_axis = glm::vec3(0, 1, 0);
  ossa::TwoBoneIkOutput out;
  ASSERT_TRUE(ossa::two_bone_ik(in, &out));
  c.apply(out);
  EXPECT_NEAR(glm::length(c.at(kEnd) - glm::vec3(1.5f, 0, 0)), 0.0f, 1e-5f);
  EXPECT_NEAR(c.at(kMid).y, 0.0f, 1e-5f) << "bent about y: the elbow moves in the xz plane";
  EXPECT_GT(std::fabs(c.at(kMid).z), 0.1f);
}

TEST(TwoBoneIk, OutOfReachExtendsTowardsTheTarget) {
  Chain c = straight_arm(0.5f);
  const glm::vec3 target(0, 5, 0);
  ossa::TwoBoneIkOutput out;
  ASSERT_TRUE(ossa::two_bone_ik(c.input(target), &out));
  EXPECT_FALSE(out.reached);
  c.apply(out);
  EXPECT_NEAR(glm::length(c.at(kEnd) - glm::vec3(0, 2, 0)), 0.0f, 1e-5f) << "fully extended, pointing at it";
}

// ---------------------------------------------------------------------------------------------
// Forward kinematics over random chains

TEST(TwoBoneIk, RandomReachableTargetsAreReachedOnThePoleSide) {
  std::mt19937 rng(20261125);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f), fraction(0.05f, 0.98f), twist(-3.0f, 3.0f);
  int solved = 0;
  for (int i = 0; i < 2000; ++i) {
    Chain c = random_chain(rng);
    const float upper = glm::length(c.at(kMid) - c.at(kStart)), lower = glm::length(c.at(kEnd) - c.at(kMid));
    const float lo = std::fabs(upper - lower), hi = upper + lower;
    glm::vec3 dir(unit(rng), unit(rng), unit(rng));
    if (glm::length(dir) < 0.1f) continue;
    dir = glm::normalize(dir);
    const glm::vec3 target = c.at(kStart) + dir * (lo + fraction(rng) * (hi - lo));
    ossa::TwoBoneIkInput in = c.input(target);
    in.pole = glm::vec3(unit(rng), unit(rng), unit(rng));
    const bool with_twist = i % 3 == 0;
    if (with_twist) in.twist = twist(rng);
    ossa::TwoBoneIkOutput out;
    ASSERT_TRUE(ossa::two_bone_ik(in, &out)) << "case " << i;
    ASSERT_TRUE(unit_and_finite(out.start_correction) && unit_and_finite(out.mid_correction)) << "case " << i;
    EXPECT_TRUE(out.reached) << "case " << i;
    const glm::vec3 before_twist_pole = in.pole;
    c.apply(out);
    EXPECT_LT(glm::length(c.at(kEnd) - target), 1e-4f * c.length()) << "case " << i;
    // Bone lengths are kept (rotations only).
    EXPECT_NEAR(glm::length(c.at(kMid) - c.at(kStart)), upper, 1e-4f * hi);
    EXPECT_NEAR(glm::length(c.at(kEnd) - c.at(kMid)), lower, 1e-4f * hi);
    // Without twist, the mid joint lies in the half-plane of the pole (when both are off-axis).
    const glm::vec3 k = glm::normalize(target - c.at(kStart));
    const glm::vec3 p = before_twist_pole - k * glm::dot(before_twist_pole, k);
    glm::vec3 m = c.at(kMid) - c.at(kStart);
    m -= k * glm::dot(m, k);
    if (!with_twist && glm::length(p) > 0.05f && glm::length(m) > 1e-3f * hi) {
      EXPECT_GT(pole_side(c, target, before_twist_pole), 0.9999f) << "case " << i;
    }
    ++solved;
  }
  EXPECT_GT(solved, 1900);
}

TEST(TwoBoneIk, NoPoleFlipWhenTheTargetCrossesTheChainsPlane) {
  // A target swept through the plane of the chain (z from -0.5 to 0.5) with a fixed pole: the
  // elbow stays on the pole's side the whole way and moves continuously.
  Chain rest = straight_arm(0.6f);
  const glm::vec3 pole(0, -1, 0);
  glm::vec3 previous_mid(NAN);
  for (int step = 0; step <= 100; ++step) {
    Chain c = straight_arm(0.6f);
    const glm::vec3 target(1.2f, 0.6f, -0.5f + 0.01f * static_cast<float>(step));
    ossa::TwoBoneIkInput in = c.input(target);
    in.pole = pole;
    ossa::TwoBoneIkOutput out;
    ASSERT_TRUE(ossa::two_bone_ik(in, &out));
    c.apply(out);
    EXPECT_LT(glm::length(c.at(kEnd) - target), 1e-4f * rest.length());
    EXPECT_GT(pole_side(c, target, pole), 0.99f) << "step " << step;
    if (step > 0) {
      EXPECT_LT(glm::length(c.at(kMid) - previous_mid), 0.05f) << "the elbow jumped at step " << step;
    }
    previous_mid = c.at(kMid);
  }
}

TEST(TwoBoneIk, WeightBlendsFromThePoseToTheSolution) {
  std::mt19937 rng(7);
  Chain base = random_chain(rng);
  const float upper = glm::length(base.at(kMid) - base.at(kStart)), lower = glm::length(base.at(kEnd) - base.at(kMid));
  const glm::vec3 dir = glm::normalize(base.at(kEnd) - base.at(kStart) + glm::vec3(0.3f, 0.5f, -0.2f));
  const glm::vec3 target = base.at(kStart) + dir * (0.5f * (std::fabs(upper - lower) + upper + lower));
  float last = INFINITY;
  for (const float w : {0.0f, 0.25f, 0.5f, 0.75f, 1.0f}) {
    std::mt19937 same(7);
    Chain c = random_chain(same);
    ossa::TwoBoneIkInput in = c.input(target);
    in.weight = w;
    ossa::TwoBoneIkOutput out;
    ASSERT_TRUE(ossa::two_bone_ik(in, &out));
    if (w == 0.0f) {
      EXPECT_EQ(out.start_correction, glm::quat(1, 0, 0, 0));
      EXPECT_EQ(out.mid_correction, glm::quat(1, 0, 0, 0));
    }
    EXPECT_EQ(out.reached, w == 1.0f);
    c.apply(out);
    const float miss = glm::length(c.at(kEnd) - target);
    EXPECT_LT(miss, last + 1e-5f) << "weight " << w << " moves the end closer";
    last = miss;
  }
  EXPECT_LT(last, 1e-4f * base.length());
}

TEST(TwoBoneIk, SofteningApproachesFullExtensionWithoutSnapping) {
  // The reach as a function of the target distance: continuous, below full extension while
  // softened, never above the target's distance, and equal to it well inside the soft zone.
  const float soften = 0.9f;
  float previous = 0.0f;
  for (int step = 0; step <= 300; ++step) {
    Chain c = straight_arm(0.4f);
    const float distance = 1.0f + 0.005f * static_cast<float>(step);  // 1 .. 2.5, chain 2
    const glm::vec3 target(0, distance, 0);
    ossa::TwoBoneIkInput in = c.input(target);
    in.soften = soften;
    ossa::TwoBoneIkOutput out;
    ASSERT_TRUE(ossa::two_bone_ik(in, &out));
    c.apply(out);
    const float reach = glm::length(c.at(kEnd) - c.at(kStart));
    EXPECT_LE(reach, distance + 1e-4f);
    EXPECT_LT(reach, 2.0f) << "never snaps to full extension";
    if (distance < soften * 2.0f - 1e-3f) {
      EXPECT_NEAR(reach, distance, 1e-4f);
      EXPECT_TRUE(out.reached);
    } else if (distance > soften * 2.0f + 0.02f) {
      EXPECT_FALSE(out.reached) << "softened by more than 1e-4 of the chain";
    }
    if (step > 0) {
      EXPECT_GE(reach, previous - 1e-5f) << "monotonic";
      EXPECT_LT(reach - previous, 0.0051f) << "continuous";
    }
    previous = reach;
  }
}

// ---------------------------------------------------------------------------------------------
// Degenerate and bad input

TEST(TwoBoneIk, DegenerateChainsGiveFinitePosesOrRefuse) {
  ossa::TwoBoneIkOutput out;
  // A target at the start joint: folded as far as the chain folds, finite.
  Chain c = straight_arm(0.3f);
  ASSERT_TRUE(ossa::two_bone_ik(c.input(c.at(kStart)), &out));
  EXPECT_TRUE(unit_and_finite(out.start_correction) && unit_and_finite(out.mid_correction));
  // Equal bones fold completely: the end comes back onto the start.
  c.apply(out);
  EXPECT_LT(glm::length(c.at(kEnd) - c.at(kStart)), 1e-4f);
  // Aligned joints and a target on their line, behind the start.
  Chain straight = straight_arm(0.0f);
  ASSERT_TRUE(ossa::two_bone_ik(straight.input({-1.0f, 0, 0}), &out));
  EXPECT_TRUE(unit_and_finite(out.start_correction) && unit_and_finite(out.mid_correction));
  straight.apply(out);
  EXPECT_LT(glm::length(straight.at(kEnd) - glm::vec3(-1, 0, 0)), 1e-4f);
  // A zero-length bone cannot be solved: refused, identity.
  Chain zero = straight_arm(0.0f);
  ossa::TwoBoneIkInput in = zero.input({1, 1, 0});
  in.mid = in.start;
  EXPECT_FALSE(ossa::two_bone_ik(in, &out));
  EXPECT_EQ(out.start_correction, glm::quat(1, 0, 0, 0));
  EXPECT_EQ(out.mid_correction, glm::quat(1, 0, 0, 0));
  // Non-finite input is refused.
  in = straight_arm(0.2f).input({NAN, 0, 0});
  EXPECT_FALSE(ossa::two_bone_ik(in, &out));
  in = straight_arm(0.2f).input({1, 1, 0});
  in.start[0][0] = INFINITY;
  EXPECT_FALSE(ossa::two_bone_ik(in, &out));
  // A zero-scale start matrix has no orientation: refused.
  in = straight_arm(0.2f).input({1, 1, 0});
  in.start[0] = glm::vec4(0.0f);
  EXPECT_FALSE(ossa::two_bone_ik(in, &out));
}

TEST(TwoBoneIk, IsAllocationFree) {
  Chain c = straight_arm(0.5f);
  ossa::TwoBoneIkInput in = c.input({1.0f, 1.0f, 0.3f});
  in.pole = glm::vec3(0, 0, 1);
  in.soften = 0.95f;
  ossa::TwoBoneIkOutput out;
  const size_t before = ossa::test::allocation_count();
  for (int i = 0; i < 100; ++i) {
    in.target.z = 0.01f * static_cast<float>(i);
    ASSERT_TRUE(ossa::two_bone_ik(in, &out));
  }
  EXPECT_EQ(ossa::test::allocation_count(), before);
}

// ---------------------------------------------------------------------------------------------
// Aim

/// root (0) > neck (1) > head (2), random placements; the head faces its local +z, up +y.
struct Head {
  ossa::Pose local{3};
  std::vector<glm::mat4> model = std::vector<glm::mat4>(3);
  static constexpr std::array<int16_t, 3> kHeadParents{-1, 0, 1};
  void update() { ossa::local_to_model(kHeadParents, local, model); }
  glm::vec3 axis(glm::vec3 local_axis) const {
    return glm::normalize(glm::vec3(model[2] * glm::vec4(local_axis, 0.0f)));
  }
  glm::vec3 position() const { return glm::vec3(model[2][3]); }
  void apply(const glm::quat& correction) {
    Transform t = ossa::get_transform(local, 2);
    t.rotation = glm::normalize(t.rotation * correction);
    ossa::set_transform(local, 2, t);
    update();
  }
};

Head random_head(std::mt19937& rng) {
  std::uniform_real_distribution<float> pos(-2.0f, 2.0f), scale(0.5f, 2.0f);
  Head h;
  ossa::set_transform(h.local, 0, trs({pos(rng), pos(rng), pos(rng)}, random_rotation(rng), glm::vec3(scale(rng))));
  ossa::set_transform(h.local, 1, trs({pos(rng), pos(rng), pos(rng)}, random_rotation(rng)));
  ossa::set_transform(h.local, 2, trs({0.0f, 0.3f, 0.0f}, random_rotation(rng)));
  h.update();
  return h;
}

float angle_between(glm::vec3 a, glm::vec3 b) {
  return std::acos(std::clamp(glm::dot(glm::normalize(a), glm::normalize(b)), -1.0f, 1.0f));
}

TEST(AimIk, RandomTargetsAreFacedWithUpTowardsThePole) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> unit(-1.0f, 1.0f);
  for (int i = 0; i < 2000; ++i) {
    Head h = random_head(rng);
    ossa::AimIkInput in;
    in.joint = h.model[2];
    in.target = h.position() + 3.0f * glm::vec3(unit(rng), unit(rng), unit(rng));
    in.pole = glm::vec3(unit(rng), unit(rng), unit(rng));
    if (glm::length(in.target - h.position()) < 0.05f) continue;
    ossa::AimIkOutput out;
    ASSERT_TRUE(ossa::aim_ik(in, &out));
    ASSERT_TRUE(unit_and_finite(out.correction));
    EXPECT_TRUE(out.reached);
    h.apply(out.correction);
    const glm::vec3 facing = h.axis({0, 0, 1});
    EXPECT_LT(angle_between(facing, in.target - h.position()), 1e-3f) << "case " << i;
    // Up leans towards the pole: their projections off the facing axis agree.
    const glm::vec3 up = h.axis({0, 1, 0});
    const glm::vec3 p = in.pole - facing * glm::dot(in.pole, facing);
    const glm::vec3 u = up - facing * glm::dot(up, facing);
    if (glm::length(p) > 0.05f) {
      EXPECT_LT(angle_between(u, p), 1e-3f) << "case " << i;
    }
  }
}

TEST(AimIk, MaxAngleLimitsTheTurn) {
  // A head facing +z asked to look straight behind (-z, slightly right) with a 60 degree neck.
  Head h;
  ossa::set_transform(h.local, 0, trs(glm::vec3(0.0f)));
  ossa::set_transform(h.local, 1, trs(glm::vec3(0.0f)));
  ossa::set_transform(h.local, 2, trs(glm::vec3(0.0f, 1.6f, 0.0f)));
  h.update();
  ossa::AimIkInput in;
  in.joint = h.model[2];
  in.target = glm::vec3(0.2f, 1.6f, -5.0f);
  in.max_angle = glm::radians(60.0f);
  ossa::AimIkOutput out;
  ASSERT_TRUE(ossa::aim_ik(in, &out));
  EXPECT_FALSE(out.reached);
  h.apply(out.correction);
  EXPECT_NEAR(angle_between(h.axis({0, 0, 1}), glm::vec3(0, 0, 1)), glm::radians(60.0f), 1e-4f);
  EXPECT_GT(h.axis({0, 0, 1}).x, 0.5f) << "turned towards the target's side";
}

TEST(AimIk, ChainSharesTheTurnAndTheLastJointFinishesIt) {
  // spine (1) > neck (2) > head (3) aimed at a point to the side: weights 0.3, 0.5, 1 from the
  // base, model matrices refreshed between joints. The head ends facing the target and each
  // joint takes part of the turn.
  ossa::Pose local(4);
  std::vector<glm::mat4> model(4);
  const std::array<int16_t, 4> parents{-1, 0, 1, 2};
  ossa::set_transform(local, 0, trs(glm::vec3(0.0f)));
  ossa::set_transform(local, 1, trs({0.0f, 1.0f, 0.0f}));
  ossa::set_transform(local, 2, trs({0.0f, 0.4f, 0.0f}));
  ossa::set_transform(local, 3, trs({0.0f, 0.2f, 0.0f}));
  ossa::local_to_model(parents, local, model);
  const glm::vec3 target(3.0f, 1.8f, 1.0f);
  const float weights[3] = {0.3f, 0.5f, 1.0f};
  float turned[3] = {};
  for (uint32_t j = 1; j <= 3; ++j) {
    ossa::AimIkInput in;
    in.joint = model[j];
    in.target = target;
    in.pole = glm::vec3(0, 1, 0);
    in.weight = weights[j - 1];
    ossa::AimIkOutput out;
    ASSERT_TRUE(ossa::aim_ik(in, &out));
    turned[j - 1] = 2.0f * std::acos(std::min(1.0f, std::fabs(out.correction.w)));
    Transform t = ossa::get_transform(local, j);
    t.rotation = glm::normalize(t.rotation * out.correction);
    ossa::set_transform(local, j, t);
    ossa::local_to_model(parents, local, model);
  }
  const glm::vec3 facing = glm::normalize(glm::vec3(model[3] * glm::vec4(0, 0, 1, 0)));
  EXPECT_LT(angle_between(facing, target - glm::vec3(model[3][3])), 1e-3f);
  for (const float a : turned) EXPECT_GT(a, 0.05f) << "every joint of the chain takes part";
}

TEST(AimIk, DegenerateInputIsFiniteOrRefused) {
  Head h;
  ossa::set_transform(h.local, 2, trs({0.0f, 1.0f, 0.0f}));
  h.update();
  ossa::AimIkInput in;
  in.joint = h.model[2];
  ossa::AimIkOutput out;
  in.target = h.position();  // the target at the joint: nothing to do
  ASSERT_TRUE(ossa::aim_ik(in, &out));
  EXPECT_EQ(out.correction, glm::quat(1, 0, 0, 0));
  in.target = h.position() - glm::vec3(0, 0, 2);  // straight behind: a half turn, finite
  ASSERT_TRUE(ossa::aim_ik(in, &out));
  EXPECT_TRUE(unit_and_finite(out.correction));
  h.apply(out.correction);
  EXPECT_LT(angle_between(h.axis({0, 0, 1}), glm::vec3(0, 0, -1)), 1e-3f);
  in.forward = glm::vec3(0.0f);
  EXPECT_FALSE(ossa::aim_ik(in, &out));
  in.forward = glm::vec3(0, 0, 1);
  in.target.x = NAN;
  EXPECT_FALSE(ossa::aim_ik(in, &out));
  EXPECT_EQ(out.correction, glm::quat(1, 0, 0, 0));
}

}  // namespace
