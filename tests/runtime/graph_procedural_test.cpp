// graph_procedural_test.cpp — the graph's procedural nodes (two-bone IK, aim, foot placement, foot
// locking, spring chains) on Pab's real rig and clips, through the cooked format: each graph is
// written by the cooker's writer, opened by the verified loader and played by GraphInstance.
//
// What is measured is what a game sees: model-space joint positions rebuilt from the output local
// pose by local_to_model (forward kinematics), against the targets the parameters give. Pab is
// authored in centimetres, so the 1e-4-of-the-chain bound is about 0.01 cm on a leg.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <tuple>
#include <map>
#include <memory>
#include <vector>

#include "allocation_counter.h"
#include "cooker/model/graph_def.h"
#include "graph_fixture.h"
#include <glm/gtc/matrix_transform.hpp>
#include <ossa/anim/pose_ops.h>
#include <ossa/graph/graph.h>

namespace ossa {
namespace {

using namespace ossa::cook;
using test::PabRig;

using test::play;
using test::Played;

uint16_t vector_param(GraphDef& g, const std::string& name, glm::vec3 value = glm::vec3(0.0f), bool world = false) {
  const uint16_t p = test::add_param(g, name, ParamType::Vector);
  g.parameters[p].default_vector[0] = value.x;
  g.parameters[p].default_vector[1] = value.y;
  g.parameters[p].default_vector[2] = value.z;
  g.parameters[p].world = world;
  return p;
}

uint16_t joint(const PabRig& rig, const char* name) {
  const int j = rig.joint(name);
  EXPECT_GE(j, 0) << name;
  return static_cast<uint16_t>(j < 0 ? 0 : j);
}

float chain_length(const Played& p, int a, int b, int c) {
  return glm::length(p.position(b) - p.position(a)) + glm::length(p.position(c) - p.position(b));
}

/// A graph: input clip -> two-bone IK on the left leg towards "target" (weight parameter "w").
GraphDef leg_ik_graph(const PabRig& rig, uint16_t clip, float rate, bool world) {
  GraphDef g = test::pab_graph(rig);
  const uint16_t in = test::clip_node(g, clip, rate);
  TwoBoneIkDef t;
  t.input = in;
  t.start = joint(rig, "LeftUpLeg");
  t.mid = joint(rig, "LeftLeg");
  t.end = joint(rig, "LeftFoot");
  t.target_parameter = vector_param(g, "target", glm::vec3(0.0f), world);
  t.pole = {0.0f, 0.0f, 1.0f};  // knees forward
  t.weight_parameter = static_cast<int16_t>(test::add_param(g, "w", ParamType::Float, 1.0f));
  g.parameters.back().min_value = 0.0f;
  g.parameters.back().max_value = 1.0f;
  g.root = test::add_node(g, t, "leg_ik");
  return g;
}

TEST(GraphProcedural, TwoBoneIkReachesReachableTargetsAndSaysSo) {
  NEED_RIG();
  Played p = play(*rig, leg_ik_graph(*rig, test::kWalk, 1.0f, false));
  ASSERT_TRUE(p.inst);
  const int hip = rig->joint("LeftUpLeg"), knee = rig->joint("LeftLeg"), ankle = rig->joint("LeftFoot");
  const int target = p.param("target"), w = p.param("w");
  int reached = 0;
  for (int frame = 0; frame < 40; ++frame) {
    // The animated ankle, then a target moved 2..12 cm from it (reachable: the leg can bend).
    p.inst->set_float(w, 0.0f);
    p.inst->update(0.0f);
    const glm::vec3 animated = p.position(ankle);
    const float length = chain_length(p, hip, knee, ankle);
    const glm::vec3 offset(std::sin(frame * 0.7f) * 6.0f, 2.0f + (frame % 5) * 2.5f, std::cos(frame * 1.3f) * 6.0f);
    ASSERT_TRUE(p.inst->set_vector(target, animated + offset));
    p.inst->set_float(w, 1.0f);
    p.inst->update(0.0f);
    const glm::vec3 solved = p.position(ankle);
    EXPECT_LT(glm::length(solved - (animated + offset)), 1e-4f * length) << "frame " << frame;
    reached += p.inst->reached(1) ? 1 : 0;
    p.inst->update(1.0f / 30.0f);
  }
  EXPECT_EQ(reached, 40);
  // Out of reach: the leg points at the target, and the node says it did not reach.
  p.inst->update(0.0f);
  const glm::vec3 h = p.position(hip);
  p.inst->set_vector(target, h + glm::vec3(0.0f, -500.0f, 0.0f));
  p.inst->update(0.0f);
  EXPECT_FALSE(p.inst->reached(1));
  const glm::vec3 dir = glm::normalize(p.position(ankle) - p.position(hip));
  EXPECT_GT(glm::dot(dir, glm::vec3(0.0f, -1.0f, 0.0f)), 0.999f);
}

TEST(GraphProcedural, WorldSpaceTargetsGoThroughTheCharactersTransform) {
  NEED_RIG();
  Played model = play(*rig, leg_ik_graph(*rig, test::kWalk, 0.0f, false));
  Played world = play(*rig, leg_ik_graph(*rig, test::kWalk, 0.0f, true));
  ASSERT_TRUE(model.inst && world.inst);
  const int ankle = rig->joint("LeftFoot");
  model.inst->update(0.0f);
  const glm::vec3 target = model.position(ankle) + glm::vec3(3.0f, 8.0f, -4.0f);
  const glm::mat4 placed = glm::translate(glm::mat4(1.0f), glm::vec3(250.0f, 3.0f, -40.0f)) *
                           glm::mat4_cast(glm::angleAxis(1.1f, glm::vec3(0.0f, 1.0f, 0.0f)));
  ASSERT_TRUE(world.inst->set_transform(placed));
  EXPECT_FALSE(world.inst->set_transform(glm::mat4(0.0f)));  // singular: refused, the last one kept
  model.inst->set_vector(model.param("target"), target);
  world.inst->set_vector(world.param("target"), glm::vec3(placed * glm::vec4(target, 1.0f)));
  model.inst->update(0.0f);
  world.inst->update(0.0f);
  EXPECT_LT(glm::length(model.position(ankle) - target), 1e-3f);
  EXPECT_LT(glm::length(world.position(ankle) - target), 1e-3f);
}

/// Every procedural node at weight 0 gives its input's pose, bit for bit.
TEST(GraphProcedural, ZeroWeightPassesTheInputThroughUnchanged) {
  NEED_RIG();
  GraphDef g = test::pab_graph(*rig);
  const uint16_t w = test::add_param(g, "w", ParamType::Float, 0.0f);
  const uint16_t target = vector_param(g, "target", glm::vec3(20.0f, 100.0f, 50.0f));
  const uint16_t ground = test::add_param(g, "ground", ParamType::Float, 15.0f);
  uint16_t n = test::clip_node(g, test::kJog);
  TwoBoneIkDef t;
  t.input = n, t.start = joint(*rig, "LeftArm"), t.mid = joint(*rig, "LeftForeArm"), t.end = joint(*rig, "Lefthand");
  t.target_parameter = target, t.weight_parameter = static_cast<int16_t>(w);
  n = test::add_node(g, t);
  AimDef a;
  a.input = n, a.target_parameter = target, a.weight_parameter = static_cast<int16_t>(w);
  a.chain = {{joint(*rig, "Neck"), 0.5f, 1.0f}, {joint(*rig, "Head"), 1.0f, 1.0f}};
  n = test::add_node(g, a);
  FootLegDef leg;
  leg.hip = joint(*rig, "LeftUpLeg"), leg.knee = joint(*rig, "LeftLeg"), leg.ankle = joint(*rig, "LeftFoot");
  leg.ground_parameter = static_cast<int16_t>(ground);
  leg.planted_parameter = static_cast<int16_t>(ground);
  FootPlacementDef f;
  f.input = n, f.pelvis = joint(*rig, "Hips"), f.legs = {leg}, f.max_pelvis_drop = 30.0f;
  f.weight_parameter = static_cast<int16_t>(w);
  n = test::add_node(g, f);
  FootLockDef l;
  l.input = n, l.legs = {leg}, l.release_radius = 10.0f, l.blend_time = 0.0f,
  l.weight_parameter = static_cast<int16_t>(w);
  n = test::add_node(g, l);
  SpringDef s;
  s.input = n, s.weight_parameter = static_cast<int16_t>(w);
  s.chains = {SpringChainDef{
      {joint(*rig, "RightArm"), joint(*rig, "RightForeArm")}, 4.0f, 0.4f, {0.0f, -981.0f, 0.0f}, 2.0f, 20.0f}};
  n = test::add_node(g, s);
  g.root = n;
  GraphDef plain = test::pab_graph(*rig);
  plain.root = test::clip_node(plain, test::kJog);
  Played p = play(*rig, g), q = play(*rig, plain);
  ASSERT_TRUE(p.inst && q.inst);
  for (int frame = 0; frame < 20; ++frame) {
    p.inst->update(1.0f / 60.0f);
    q.inst->update(1.0f / 60.0f);
    const ConstPoseSpan a0 = p.inst->pose(), b0 = q.inst->pose();
    ASSERT_EQ(0, std::memcmp(a0.base, b0.base, sizeof(float) * kPoseComponents * a0.stride)) << "frame " << frame;
  }
  // And at weight 1 the same graph moves the pose (the check above can fail).
  p.inst->set_float(p.param("w"), 1.0f);
  p.inst->update(1.0f / 60.0f);
  q.inst->update(1.0f / 60.0f);
  EXPECT_NE(0, std::memcmp(p.inst->pose().base, q.inst->pose().base,
                           sizeof(float) * kPoseComponents * p.inst->pose().stride));
}

TEST(GraphProcedural, AimChainTurnsTheHeadOntoTheTargetWithinItsLimits) {
  NEED_RIG();
  for (const float limit : {3.0f, 0.35f}) {
    GraphDef g = test::pab_graph(*rig);
    AimDef a;
    a.input = test::clip_node(g, test::kWalk, 0.0f);
    a.target_parameter = vector_param(g, "target");
    a.chain = {
        {joint(*rig, "Spine2"), 0.3f, limit}, {joint(*rig, "Neck"), 0.5f, limit}, {joint(*rig, "Head"), 1.0f, limit}};
    // The head's local axes at the bind pose: Pab faces +z, up +y (computed as the compiler does).
    glm::quat bind(1.0f, 0.0f, 0.0f, 0.0f);
    for (int j = rig->joint("Head"); j >= 0; j = rig->skeleton.joints[static_cast<size_t>(j)].parent)
      bind = rig->skeleton.joints[static_cast<size_t>(j)].rotation * bind;
    const glm::vec3 f = glm::conjugate(bind) * glm::vec3(0.0f, 0.0f, 1.0f),
                    u = glm::conjugate(bind) * glm::vec3(0.0f, 1.0f, 0.0f);
    a.forward = {f.x, f.y, f.z};
    a.up = {u.x, u.y, u.z};
    a.pole = {0.0f, 1.0f, 0.0f};
    g.root = test::add_node(g, a, "look");
    Played p = play(*rig, g);
    ASSERT_TRUE(p.inst);
    const int head = rig->joint("Head");
    p.inst->update(0.0f);
    const glm::vec3 eye = p.position(head);
    const glm::mat3 before(p.model()[static_cast<size_t>(head)]);
    const glm::vec3 forward_before = glm::normalize(before * f);
    int faced = 0;
    for (int k = 0; k < 12; ++k) {
      // Targets around the front half: up to ~70 degrees aside, some above and below.
      const float yaw = -1.2f + 0.2f * k, pitch = 0.3f * std::sin(k * 1.7f);
      const glm::vec3 dir(std::sin(yaw) * std::cos(pitch), std::sin(pitch), std::cos(yaw) * std::cos(pitch));
      const glm::vec3 target = eye + 150.0f * dir;
      p.inst->set_vector(p.param("target"), target);
      p.inst->update(0.0f);
      const glm::mat3 m(p.model()[static_cast<size_t>(head)]);
      const glm::vec3 forward = glm::normalize(m * f);
      const glm::vec3 to_target = glm::normalize(target - p.position(head));
      const float error = std::acos(std::min(1.0f, glm::dot(forward, to_target)));
      const float turned = std::acos(std::min(1.0f, glm::dot(forward, forward_before)));
      if (limit >= 3.0f) {
        EXPECT_LT(error, 2e-3f) << "target " << k;
        EXPECT_TRUE(p.inst->reached(static_cast<size_t>(g.root)));
      } else {
        EXPECT_LE(turned, 3.0f * limit + 1e-3f) << "three joints of " << limit << " rad each";
      }
      faced += error < 2e-3f ? 1 : 0;
    }
    if (limit < 3.0f) {
      EXPECT_LT(faced, 12);  // the limit bit on the wide targets
    }
  }
}

/// Left leg, right leg, pelvis "Hips": foot placement with per-foot ground heights and one normal.
GraphDef feet_graph(const PabRig& rig, uint16_t clip) {
  GraphDef g = test::pab_graph(rig);
  FootPlacementDef f;
  f.input = test::clip_node(g, clip, 0.0f);
  f.pelvis = joint(rig, "Hips");
  f.max_pelvis_drop = 40.0f;
  const uint16_t left = test::add_param(g, "left", ParamType::Float),
                 right = test::add_param(g, "right", ParamType::Float);
  g.parameters[left].min_value = g.parameters[right].min_value = -100.0f;
  g.parameters[left].max_value = g.parameters[right].max_value = 100.0f;
  const uint16_t normal = vector_param(g, "normal", glm::vec3(0.0f, 1.0f, 0.0f));
  for (const auto& [hip, knee, ankle, ground] : {std::tuple{"LeftUpLeg", "LeftLeg", "LeftFoot", left},
                                                 std::tuple{"RightUpLeg", "RightLeg", "RightFoot", right}}) {
    FootLegDef leg;
    leg.hip = joint(rig, hip), leg.knee = joint(rig, knee), leg.ankle = joint(rig, ankle);
    leg.ground_parameter = static_cast<int16_t>(ground);
    leg.normal_parameter = static_cast<int16_t>(normal);
    f.legs.push_back(leg);
  }
  g.root = test::add_node(g, f, "feet");
  return g;
}

TEST(GraphProcedural, FootPlacementPutsEachFootOnItsGroundAndLowersThePelvisToReach) {
  NEED_RIG();
  Played p = play(*rig, feet_graph(*rig, test::kWalk));
  GraphDef plain = test::pab_graph(*rig);
  plain.root = test::clip_node(plain, test::kWalk, 0.0f);
  Played q = play(*rig, plain);
  ASSERT_TRUE(p.inst && q.inst);
  const int la = rig->joint("LeftFoot"), ra = rig->joint("RightFoot"), hips = rig->joint("Hips");
  q.inst->update(0.0f);
  p.inst->update(0.0f);
  // Flat ground at 0: the clip's own pose (within float noise of the identity corrections).
  EXPECT_LT(glm::length(p.position(la) - q.position(la)), 1e-3f);
  EXPECT_LT(glm::length(p.position(hips) - q.position(hips)), 1e-4f);
  // A 6 cm step under the left foot: it rises 6 cm, the right stays, the pelvis stays.
  p.inst->set_float(p.param("left"), 6.0f);
  p.inst->update(0.0f);
  EXPECT_NEAR(p.position(la).y, q.position(la).y + 6.0f, 1e-2f);
  EXPECT_LT(glm::length(p.position(ra) - q.position(ra)), 1e-2f);
  EXPECT_NEAR(p.position(hips).y, q.position(hips).y, 1e-3f);
  // A 25 cm hole under the right foot: the leg cannot reach, so the pelvis drops, and both feet land.
  p.inst->set_float(p.param("left"), 0.0f);
  p.inst->set_float(p.param("right"), -25.0f);
  p.inst->update(0.0f);
  EXPECT_LT(p.position(hips).y, q.position(hips).y - 5.0f);
  EXPECT_GT(p.position(hips).y, q.position(hips).y - 40.0f - 1e-3f);
  EXPECT_NEAR(p.position(ra).y, q.position(ra).y - 25.0f, 1e-2f);
  EXPECT_NEAR(p.position(la).y, q.position(la).y, 1e-2f);
  // A slope: each ankle turns by the slope's angle (its up axis follows the normal).
  const float angle = 0.25f;
  const glm::vec3 normal(0.0f, std::cos(angle), std::sin(angle));
  p.inst->set_float(p.param("right"), 0.0f);
  p.inst->set_vector(p.param("normal"), normal);
  p.inst->update(0.0f);
  const glm::mat3 animated(q.model()[static_cast<size_t>(la)]), placed(p.model()[static_cast<size_t>(la)]);
  const glm::quat turn =
      glm::normalize(glm::quat_cast(placed)) * glm::conjugate(glm::normalize(glm::quat_cast(animated)));
  EXPECT_NEAR(glm::angle(turn), angle, 2e-3f);
}

TEST(GraphProcedural, FootLockHoldsAPlantedFootInTheWorldAndReleasesIt) {
  NEED_RIG();
  GraphDef g = test::pab_graph(*rig);
  const uint16_t planted = test::add_param(g, "planted", ParamType::Bool);
  FootLockDef l;
  l.input = test::clip_node(g, test::kWalk, 0.0f);  // a held pose: only the character moves
  FootLegDef leg;
  leg.hip = joint(*rig, "LeftUpLeg"), leg.knee = joint(*rig, "LeftLeg"), leg.ankle = joint(*rig, "LeftFoot");
  leg.planted_parameter = static_cast<int16_t>(planted);
  l.legs = {leg};
  l.release_radius = 12.0f;
  l.blend_time = 0.1f;
  g.root = test::add_node(g, l, "lock");
  Played p = play(*rig, g);
  ASSERT_TRUE(p.inst);
  const int ankle = rig->joint("LeftFoot");
  p.inst->update(0.0f);
  const glm::vec3 animated = p.position(ankle);
  p.inst->set_bool(p.param("planted"), true);
  p.inst->update(1.0f / 60.0f);
  const glm::vec3 locked_world = animated;  // identity transform at the plant
  // The character slides 1 cm per frame along x: the foot stays put in the world (after the blend in).
  for (int frame = 1; frame <= 8; ++frame) {
    const glm::mat4 t = glm::translate(glm::mat4(1.0f), glm::vec3(1.0f * frame, 0.0f, 0.0f));
    p.inst->set_transform(t);
    p.inst->update(1.0f / 60.0f);
    const glm::vec3 world(t * glm::vec4(p.position(ankle), 1.0f));
    if (frame >= 6) {
      EXPECT_LT(glm::length(world - locked_world), 1e-2f) << "frame " << frame;
    }
  }
  // Lifting releases: after the blend time the foot is the clip's again (model space).
  p.inst->set_bool(p.param("planted"), false);
  for (int frame = 0; frame < 8; ++frame) p.inst->update(1.0f / 60.0f);
  EXPECT_LT(glm::length(p.position(ankle) - animated), 1e-3f);
  // Straying past the radius releases too: plant, then move the character 20 cm at once.
  p.inst->set_bool(p.param("planted"), true);
  p.inst->update(1.0f / 60.0f);
  p.inst->set_transform(glm::translate(glm::mat4(1.0f), glm::vec3(28.0f, 0.0f, 0.0f)));
  for (int frame = 0; frame < 8; ++frame) p.inst->update(1.0f / 60.0f);
  EXPECT_LT(glm::length(p.position(ankle) - animated), 1e-3f);
}

/// Pab's right arm as a spring chain on a held pose, the character swinging along x.
GraphDef arm_spring_graph(const PabRig& rig, float teleport) {
  GraphDef g = test::pab_graph(rig);
  SpringDef s;
  s.input = test::clip_node(g, test::kWalk, 0.0f);
  s.chains = {SpringChainDef{{joint(rig, "RightArm"), joint(rig, "RightForeArm"), joint(rig, "RightHand")},
                             3.0f,
                             0.2f,
                             {0.0f, -981.0f, 0.0f},
                             3.0f,
                             15.0f}};
  s.colliders = {SpringColliderDef{joint(rig, "Spine2"), {0.0f, 0.0f, 0.0f}, {0.0f, 20.0f, 0.0f}, 14.0f}};
  s.teleport_distance = teleport;
  g.root = test::add_node(g, s, "arm");
  return g;
}

glm::mat4 swing(double t) {
  return glm::translate(glm::mat4(1.0f),
                        glm::vec3(static_cast<float>(40.0 * std::sin(2.0 * 3.14159265358979 * 0.7 * t)), 0.0f, 0.0f));
}

TEST(GraphProcedural, SpringChainGivesTheSameMotionAtAnyFrameRate) {
  NEED_RIG();
  const int hand = rig->joint("RightHand");
  std::vector<glm::vec3> ends;
  for (const int hz : {30, 60, 144}) {
    Played p = play(*rig, arm_spring_graph(*rig, 0.0f));
    ASSERT_TRUE(p.inst);
    const int frames = 2 * hz;
    for (int f = 1; f <= frames; ++f) {
      p.inst->set_transform(swing(static_cast<double>(f) / hz));
      p.inst->update(1.0f / static_cast<float>(hz));
    }
    ends.push_back(p.position(hand));
  }
  EXPECT_LT(glm::length(ends[0] - ends[1]), 1.0f) << "30 vs 60 Hz, cm";
  EXPECT_LT(glm::length(ends[2] - ends[1]), 1.0f) << "144 vs 60 Hz, cm";
  // The chain did move: a held arm would be exactly where the clip has it.
  GraphDef plain = test::pab_graph(*rig);
  plain.root = test::clip_node(plain, test::kWalk, 0.0f);
  Played q = play(*rig, plain);
  q.inst->update(0.0f);
  EXPECT_GT(glm::length(ends[1] - q.position(hand)), 2.0f);
}

TEST(GraphProcedural, SpringChainResetsOnTeleportAndOnReset) {
  NEED_RIG();
  Played p = play(*rig, arm_spring_graph(*rig, 100.0f));
  ASSERT_TRUE(p.inst);
  GraphDef plain = test::pab_graph(*rig);
  plain.root = test::clip_node(plain, test::kWalk, 0.0f);
  Played q = play(*rig, plain);
  q.inst->update(0.0f);
  const int hand = rig->joint("RightHand");
  for (int f = 1; f <= 60; ++f) {
    p.inst->set_transform(swing(f / 60.0));
    p.inst->update(1.0f / 60.0f);
  }
  ASSERT_GT(glm::length(p.position(hand) - q.position(hand)), 1.0f);
  // A 10 m jump: the chain restarts on the animated pose instead of whipping across.
  p.inst->set_transform(glm::translate(glm::mat4(1.0f), glm::vec3(1000.0f, 0.0f, 0.0f)));
  p.inst->update(1.0f / 60.0f);
  EXPECT_LT(glm::length(p.position(hand) - q.position(hand)), 0.5f);
  // reset(): the same.
  for (int f = 1; f <= 30; ++f) {
    p.inst->set_transform(swing(f / 60.0));
    p.inst->update(1.0f / 60.0f);
  }
  p.inst->reset();
  p.inst->set_transform(glm::mat4(1.0f));
  p.inst->update(1.0f / 60.0f);
  EXPECT_LT(glm::length(p.position(hand) - q.position(hand)), 0.5f);
}

TEST(GraphProcedural, UpdatesAreDeterministicAndAllocationFree) {
  NEED_RIG();
  GraphDef g = arm_spring_graph(*rig, 0.0f);
  Played a = play(*rig, g), b = play(*rig, g);
  Played c = play(*rig, feet_graph(*rig, test::kJog));
  ASSERT_TRUE(a.inst && b.inst && c.inst);
  c.inst->set_float(c.param("left"), 10.0f);
  const size_t before = test::allocation_count();
  for (int f = 1; f <= 120; ++f) {
    a.inst->set_transform(swing(f / 60.0));
    b.inst->set_transform(swing(f / 60.0));
    a.inst->update(1.0f / 60.0f);
    b.inst->update(1.0f / 60.0f);
    c.inst->update(1.0f / 60.0f);
  }
  EXPECT_EQ(test::allocation_count(), before);
  EXPECT_EQ(0, std::memcmp(a.inst->pose().base, b.inst->pose().base,
                           sizeof(float) * kPoseComponents * a.inst->pose().stride));
}

TEST(GraphProcedural, ChainsThatAreNotChainsAreRefusedWhenBound) {
  NEED_RIG();
  GraphDef g = leg_ik_graph(*rig, test::kWalk, 1.0f, false);
  auto& t = std::get<TwoBoneIkDef>(g.nodes[g.root].kind);
  t.mid = joint(*rig, "RightLeg");  // not below LeftUpLeg
  auto asset = test::make_graph_file(*rig, {g});
  ASSERT_TRUE(asset.ok()) << asset.error().message;  // indices are in range: the file is valid
  auto def = GraphDefinition::create(*asset, g.name);
  ASSERT_FALSE(def.ok());
  EXPECT_NE(def.error().message.find("'LeftUpLeg' is not an ancestor of 'RightLeg'"), std::string::npos)
      << def.error().message;
  // A joint index past the rig is refused by the loader.
  t.mid = 500;
  auto bad = test::make_graph_file(*rig, {g});
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("mid joint 500 is out of range"), std::string::npos) << bad.error().message;
}

/// Values the loader refuses in procedural nodes, each named in the message.
TEST(GraphProcedural, OutOfRangeSettingsAreRefusedByTheLoader) {
  NEED_RIG();
  const auto refused = [&](GraphDef g, const std::string& expected) {
    auto asset = test::make_graph_file(*rig, {g});
    ASSERT_FALSE(asset.ok()) << "accepted; expected: " << expected;
    EXPECT_NE(asset.error().message.find(expected), std::string::npos) << asset.error().message;
  };
  GraphDef ik = leg_ik_graph(*rig, test::kWalk, 1.0f, false);
  std::get<TwoBoneIkDef>(ik.nodes[ik.root].kind).soften = 0.0f;
  refused(ik, "soften must be within (0, 1]");
  ik = leg_ik_graph(*rig, test::kWalk, 1.0f, false);
  std::get<TwoBoneIkDef>(ik.nodes[ik.root].kind).weight = 2.0f;
  refused(ik, "weight must be within [0, 1]");
  ik = leg_ik_graph(*rig, test::kWalk, 1.0f, false);
  std::get<TwoBoneIkDef>(ik.nodes[ik.root].kind).target_parameter =
      static_cast<uint16_t>(std::get<TwoBoneIkDef>(ik.nodes[ik.root].kind).weight_parameter);
  refused(ik, "has type Float, which cannot be used here");
  GraphDef spring = arm_spring_graph(*rig, 0.0f);
  auto& chain = std::get<SpringDef>(spring.nodes[spring.root].kind).chains[0];
  chain.joints.assign(65, chain.joints[0]);
  refused(spring, "65 joints; a chain needs 1 to 64");
  spring = arm_spring_graph(*rig, 0.0f);
  std::get<SpringDef>(spring.nodes[spring.root].kind).chains[0].drag = 1.5f;
  refused(spring, "drag within [0, 1]");
  spring = arm_spring_graph(*rig, 0.0f);
  std::get<SpringDef>(spring.nodes[spring.root].kind).step = 0.0f;
  refused(spring, "step must be within [1e-4, 1] s");
  GraphDef feet = feet_graph(*rig, test::kWalk);
  std::get<FootPlacementDef>(feet.nodes[feet.root].kind)
      .legs.resize(9, std::get<FootPlacementDef>(feet.nodes[feet.root].kind).legs[0]);
  refused(feet, "9 legs; a foot node needs 1 to 8");
  feet = feet_graph(*rig, test::kWalk);
  std::get<FootPlacementDef>(feet.nodes[feet.root].kind).legs[0].normal_parameter = 0;  // not a vector
  refused(feet, "normal: parameter 0");
}

}  // namespace
}  // namespace ossa
