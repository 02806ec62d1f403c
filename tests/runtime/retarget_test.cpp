// retarget_test.cpp — the humanoid profile, mapping by name, retarget poses and the retarget job
// (ossa/retarget/*.h) on synthetic rigs (retarget_fixture.h): every naming convention the mapping
// claims, A-pose against T-pose, other proportions, units, up axes and random joint frames, a
// rig onto itself, planted feet, allocation-free frames. The same checks on the shared sample rigs
// and the cooker's --retarget-to are in retarget_cook_test.cpp.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <ossa/anim/ik.h>
#include <ossa/anim/pose_ops.h>
#include <ossa/retarget/foot_contacts.h>
#include <ossa/retarget/humanoid.h>
#include <ossa/retarget/retarget.h>
#include <ossa/retarget/retarget_measure.h>

#include "allocation_counter.h"
#include "retarget_fixture.h"

namespace {

using namespace ossa;
using ossa::test::HumanoidNames;
using ossa::test::RigShape;
using ossa::test::SyntheticRig;
using B = HumanoidBone;

std::vector<HumanoidNames> conventions() {
  return {test::mixamo_names(), test::unreal_names(), test::unity_names(),
          test::vroid_names(),  test::rigify_names(), test::metarig_names(),
          test::cmu_names(),    test::biped_names(),  test::quaternius_names()};
}

TEST(HumanoidProfile, NamesAndParents) {
  EXPECT_EQ(kHumanoidBoneCount, 52u);
  size_t required = 0;
  for (size_t b = 0; b < kHumanoidBoneCount; ++b) {
    const auto bone = static_cast<B>(b);
    EXPECT_EQ(find_humanoid_bone(humanoid_bone_name(bone)), bone);
    required += humanoid_bone_required(bone) ? 1 : 0;
    if (bone != B::Hips) {
      EXPECT_LT(static_cast<size_t>(humanoid_bone_parent(bone)), b) << humanoid_bone_name(bone);
    }
  }
  EXPECT_EQ(required, 15u);  // VRM 1.0's required bones
  EXPECT_EQ(find_humanoid_bone("LEFTUPPERARM"), B::LeftUpperArm);
  EXPECT_EQ(find_humanoid_bone("leftUpperArmX"), B::Count);
}

TEST(HumanoidMapping, EveryConventionByName) {
  for (const HumanoidNames& names : conventions()) {
    SCOPED_TRACE(names.convention);
    const SyntheticRig rig = test::make_humanoid(names, RigShape{.frame_seed = 7});
    const HumanoidMap map = map_humanoid(rig.views, rig.parents);
    for (const auto& [bone, joint] : names.expected) {
      const int j = map[bone];
      EXPECT_EQ(j >= 0 ? rig.names[static_cast<size_t>(j)] : std::string("-"), joint) << humanoid_bone_name(bone);
    }
    EXPECT_TRUE(check_humanoid(map, rig.parents, names.convention).ok());
    for (const auto& [extra, parent] : names.extras)
      for (int16_t j : map.joints) EXPECT_NE(j >= 0 ? rig.names[static_cast<size_t>(j)] : "", extra) << "helper mapped";
  }
}

TEST(HumanoidMapping, MissingBonesAreNamed) {
  HumanoidNames names = test::mixamo_names();
  names.hand = {"", ""};
  names.fingers = {};
  const SyntheticRig rig = test::make_humanoid(names, RigShape{});
  const HumanoidMap map = map_humanoid(rig.views, rig.parents);
  const Status st = check_humanoid(map, rig.parents, "handless.ossa");
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("handless.ossa: missing humanoid bones: leftHand, rightHand"), std::string::npos)
      << st.message();
  const SyntheticRig other = test::make_humanoid(test::unity_names(), RigShape{});
  RetargetRig source = rig.rig("handless.ossa");
  auto built = make_retarget_map(source, other.rig("unity.ossa"));
  ASSERT_FALSE(built.ok());
  EXPECT_NE(built.error().message.find("leftHand, rightHand"), std::string::npos) << built.error().message;
  // A rig whose names say nothing is not guessed at.
  std::vector<std::string_view> anonymous(rig.views.size(), "joint");
  EXPECT_EQ(missing_humanoid_bones(map_humanoid(anonymous, rig.parents)).size(), 15u);
}

TEST(HumanoidMapping, StructureIsChecked) {
  const SyntheticRig rig = test::make_humanoid(test::mixamo_names(), RigShape{});
  HumanoidMap map = map_humanoid(rig.views, rig.parents);
  std::swap(map[B::LeftLowerArm], map[B::RightLowerArm]);
  const Status st = check_humanoid(map, rig.parents, "crossed");
  ASSERT_FALSE(st.ok());
  EXPECT_NE(st.message().find("leftLowerArm is not below leftUpperArm"), std::string::npos) << st.message();
  map = map_humanoid(rig.views, rig.parents);
  map[B::Head] = map[B::Neck];
  EXPECT_NE(check_humanoid(map, rig.parents, "twice").message().find("name the same joint"), std::string::npos);
}

/// Retargets `frames` of synthetic motion and returns the worst measures.
struct Worst {
  float limb = 0.0f, hand = 0.0f, foot = 0.0f;
  int crossings = 0;
  int adjusted_frames = 0;
};

Worst run(const SyntheticRig& source, const SyntheticRig& target, const RetargetRig& sr, const RetargetRig& tr,
          uint32_t frames, float degrees) {
  auto map = make_retarget_map(sr, tr);
  EXPECT_TRUE(map.ok()) << (map.ok() ? "" : map.error().message);
  Worst w;
  if (!map.ok()) return w;
  RetargetScratch scratch = make_retarget_scratch(*map);
  Pose in(static_cast<uint32_t>(source.names.size())), out(static_cast<uint32_t>(target.names.size()));
  for (uint32_t f = 0; f < frames; ++f) {
    test::synthetic_motion(source, f, degrees, in);
    RetargetInput input;
    input.source = in;
    EXPECT_TRUE(retarget(*map, input, scratch, out));
    RetargetMeasure m;
    measure_retarget(*map, scratch, &m);
    w.adjusted_frames += scratch.adjusted != 0 ? 1 : 0;
    for (float d : m.limb_degrees) w.limb = std::max(w.limb, d);
    for (float d : m.hand_degrees) w.hand = std::max(w.hand, d);
    for (float d : m.foot_degrees) w.foot = std::max(w.foot, d);
    for (int p : {kLeftHandPoint, kRightHandPoint, kLeftFootPoint, kRightFootPoint}) {
      const float side = p % 2 == 0 ? 1.0f : -1.0f;
      if (side * m.source_side[static_cast<size_t>(p)] > 0.05f && side * m.target_side[static_cast<size_t>(p)] < 0.0f)
        ++w.crossings;
    }
  }
  return w;
}

TEST(Retarget, APoseRigMeetsTPoseRig) {
  // Mixamo T-pose, Y-up, metres -> an Unreal A-pose rig, Z-up, centimetres, other proportions,
  // every joint frame turned at random; and back.
  const SyntheticRig t_pose = test::make_humanoid(test::mixamo_names(), RigShape{.frame_seed = 3});
  RigShape a_shape{.arm_down_degrees = 45.0f,
                   .thigh = 0.5f,
                   .shin = 0.47f,
                   .upper_arm = 0.31f,
                   .forearm = 0.27f,
                   .orientation = glm::angleAxis(glm::radians(90.0f), glm::vec3(1, 0, 0)),
                   .units_per_metre = 100.0f,
                   .frame_seed = 11};
  const SyntheticRig a_pose = test::make_humanoid(test::unreal_names(), a_shape);
  for (int direction = 0; direction < 2; ++direction) {
    SCOPED_TRACE(direction == 0 ? "T to A" : "A to T");
    const SyntheticRig& s = direction == 0 ? t_pose : a_pose;
    const SyntheticRig& t = direction == 0 ? a_pose : t_pose;
    const Worst w = run(s, t, s.rig("source"), t.rig("target"), 90, 25.0f);
    EXPECT_LT(w.limb, 0.5f);
    EXPECT_LT(w.hand, 0.5f);
    EXPECT_LT(w.foot, 0.5f);
    EXPECT_EQ(w.crossings, 0);
    // Without straightening the A-pose rig, its arms are 45 degrees off: what the test would see
    // if rest poses were not aligned (the classic A/T retarget bug).
    RetargetRig unaligned = a_pose.rig("a-pose as bound");
    unaligned.rest = RestPose::Bind;
    const Worst bad = direction == 0 ? run(s, t, s.rig("source"), unaligned, 30, 25.0f)
                                     : run(s, t, unaligned, t.rig("target"), 30, 25.0f);
    EXPECT_GT(bad.limb, 30.0f);
  }
}

TEST(Retarget, AcrossConventionsChainsAndIkFeet) {
  // Spines of 3, 1 and 5 joints, necks of 1 and 2, a Quaternius rig whose feet hang from the root.
  HumanoidNames one = test::unity_names();
  one.spine = {"Spine"};
  HumanoidNames five = test::unreal_names();
  five.spine = {"spine_01", "spine_02", "spine_03", "spine_04", "spine_05"};
  const std::vector<std::pair<HumanoidNames, RigShape>> rigs = {
      {test::mixamo_names(), RigShape{.frame_seed = 1}},
      {one, RigShape{.thigh = 0.38f, .shin = 0.40f, .frame_seed = 2}},
      {five, RigShape{.arm_down_degrees = 30.0f, .frame_seed = 3}},
      {test::cmu_names(), RigShape{.units_per_metre = 39.37f, .frame_seed = 4}},
      {test::quaternius_names(),
       RigShape{.thigh = 0.33f, .shin = 0.5f, .hip_width = 0.12f, .frame_seed = 5, .ik_feet = true}},
  };
  for (size_t a = 0; a < rigs.size(); ++a) {
    for (size_t b = 0; b < rigs.size(); ++b) {
      if (a == b) continue;
      SCOPED_TRACE(rigs[a].first.convention + " -> " + rigs[b].first.convention);
      const SyntheticRig s = test::make_humanoid(rigs[a].first, rigs[a].second);
      const SyntheticRig t = test::make_humanoid(rigs[b].first, rigs[b].second);
      const Worst w = run(s, t, s.rig("source"), t.rig("target"), 60, 20.0f);
      EXPECT_EQ(w.crossings, 0);
      // Limbs follow exactly unless the mid-plane guard had to swing one back to its side.
      if (w.adjusted_frames == 0) {
        EXPECT_LT(w.limb, 0.5f);
      }
      EXPECT_LT(w.limb, 15.0f);
      EXPECT_LT(w.hand, 0.5f);
    }
  }
}

TEST(Retarget, RigOntoItselfIsTheSource) {
  for (const auto& [names, shape] : std::vector<std::pair<HumanoidNames, RigShape>>{
           {test::mixamo_names(), RigShape{.frame_seed = 9}},
           {test::quaternius_names(), RigShape{.units_per_metre = 100.0f, .frame_seed = 10, .ik_feet = true}},
           {test::cmu_names(),
            RigShape{.orientation = glm::angleAxis(3.14159265f, glm::vec3(0, 1, 0)), .frame_seed = 12}}}) {
    SCOPED_TRACE(names.convention);
    const SyntheticRig rig = test::make_humanoid(names, shape);
    auto map = make_retarget_map(rig.rig("self"), rig.rig("self"));
    ASSERT_TRUE(map.ok()) << map.error().message;
    RetargetScratch scratch = make_retarget_scratch(*map);
    const auto n = static_cast<uint32_t>(rig.names.size());
    Pose in(n), out(n);
    std::vector<glm::mat4> expected(n), got(n);
    float worst = 0.0f;
    for (uint32_t f = 0; f < 40; ++f) {
      test::synthetic_motion(rig, f, 30.0f, in);
      RetargetInput input;
      input.source = in;
      ASSERT_TRUE(retarget(*map, input, scratch, out));
      local_to_model(rig.parents, in, expected);
      local_to_model(rig.parents, out, got);
      for (uint32_t j = 0; j < n; ++j)
        for (int c = 0; c < 4; ++c) worst = std::max(worst, glm::length(glm::vec3(got[j][c] - expected[j][c])));
    }
    EXPECT_LT(worst, 1e-4f * shape.units_per_metre);  // 0.1 mm
  }
}

TEST(Retarget, HipsTravelScaledByHipsHeight) {
  const SyntheticRig s = test::make_humanoid(test::mixamo_names(), RigShape{});
  const SyntheticRig t = test::make_humanoid(test::unity_names(), RigShape{.thigh = 0.6f, .shin = 0.6f});
  auto map = make_retarget_map(s.rig("s"), t.rig("t"));
  ASSERT_TRUE(map.ok());
  EXPECT_NEAR(map->scale, (0.6f + 0.6f) / (0.43f + 0.42f), 1e-3f);  // pelvis over the ankles
  RetargetScratch scratch = make_retarget_scratch(*map);
  Pose in(static_cast<uint32_t>(s.names.size())), out(static_cast<uint32_t>(t.names.size()));
  test::bind_pose(s, in);
  RetargetInput input;
  input.source = in;
  auto hips_at = [&](float forward) {
    Transform root = s.bind[0];
    root.translation += glm::vec3(0.0f, 0.0f, forward);
    set_transform(in, 0, root);
    EXPECT_TRUE(retarget(*map, input, scratch, out));
    return glm::vec3(scratch.target_model[static_cast<size_t>(t.joint("Hips"))][3]);
  };
  const glm::vec3 start = hips_at(0.0f), end = hips_at(1.0f);
  EXPECT_NEAR(end.z - start.z, map->scale, 1e-4f);
  EXPECT_NEAR(end.y, start.y, 1e-5f);
}

/// A lunge: the hips travel forward and down while the left ankle stays where it stands (held by
/// two-bone IK on the source), the right leg swings.
void lunge(const SyntheticRig& rig, uint32_t frame, PoseSpan out) {
  test::bind_pose(rig, out);
  const float u = static_cast<float>(frame) / 60.0f;
  Transform hips = rig.bind[0];
  hips.translation += glm::vec3(0.0f, -0.08f * u, 0.25f * u);
  set_transform(out, 0, hips);
  std::vector<glm::mat4> rest(rig.names.size()), model(rig.names.size());
  Pose bind(static_cast<uint32_t>(rig.names.size()));
  test::bind_pose(rig, bind);
  local_to_model(rig.parents, bind, rest);
  // The right thigh lifts forward (a turn about the body's left axis, in model space).
  const int right = rig.joint("mixamorig:RightUpLeg");
  Transform swing = rig.bind[static_cast<size_t>(right)];
  const glm::quat m = glm::quat_cast(glm::mat3(rest[static_cast<size_t>(right)]));
  const glm::quat lift = glm::angleAxis(-0.5f - 0.3f * std::sin(3.0f * u), glm::vec3(1, 0, 0));
  swing.rotation = glm::normalize(swing.rotation * (glm::inverse(m) * lift * m));
  set_transform(out, static_cast<uint32_t>(right), swing);
  local_to_model(rig.parents, out, model);
  const int up = rig.joint("mixamorig:LeftUpLeg"), knee = rig.joint("mixamorig:LeftLeg"),
            foot = rig.joint("mixamorig:LeftFoot");
  TwoBoneIkInput ik;
  ik.start = model[static_cast<size_t>(up)];
  ik.mid = model[static_cast<size_t>(knee)];
  ik.end = model[static_cast<size_t>(foot)];
  ik.target = glm::vec3(rest[static_cast<size_t>(foot)][3]);
  ik.pole = glm::vec3(0.0f, 0.0f, 1.0f);
  TwoBoneIkOutput result;
  ASSERT_TRUE(two_bone_ik(ik, &result));
  for (const auto& [j, c] : {std::pair{up, result.start_correction}, std::pair{knee, result.mid_correction}}) {
    Transform x = get_transform(out, static_cast<uint32_t>(j));
    x.rotation = glm::normalize(x.rotation * c);
    set_transform(out, static_cast<uint32_t>(j), x);
  }
}

TEST(Retarget, PlantedFeetStayPlanted) {
  HumanoidNames mixamo = test::mixamo_names();
  const SyntheticRig s = test::make_humanoid(mixamo, RigShape{.frame_seed = 21});
  const SyntheticRig t = test::make_humanoid(
      test::quaternius_names(),
      RigShape{.thigh = 0.33f, .shin = 0.52f, .hip_width = 0.13f, .frame_seed = 22, .ik_feet = true});
  auto built = make_retarget_map(s.rig("lunge"), t.rig("quaternius"));
  ASSERT_TRUE(built.ok()) << built.error().message;
  const RetargetMap& map = *built;
  RetargetScratch scratch = make_retarget_scratch(map);
  const uint32_t frames = 61;
  std::vector<Pose> source;
  for (uint32_t f = 0; f < frames; ++f) {
    source.emplace_back(static_cast<uint32_t>(s.names.size()));
    lunge(s, f, source.back());
  }
  Pose out(static_cast<uint32_t>(t.names.size()));
  std::vector<ContactFrame> feet(frames);
  for (uint32_t f = 0; f < frames; ++f) {
    ASSERT_TRUE(pose_source(map, source[f], scratch));
    feet[f] = contact_frame(map, scratch);
  }
  const float floor = clip_floor(map, feet);
  EXPECT_EQ(floor, 0.0f);
  RetargetInput in;
  in.source_floor = floor;
  for (uint32_t f = 0; f < frames; ++f) {
    in.source = source[f];
    ASSERT_TRUE(retarget(map, in, scratch, out));
    feet[f].target_ankle = contact_frame(map, scratch).target_ankle;
  }
  const std::vector<ContactSpan> contacts = find_foot_contacts(map, feet, 30.0f, floor);
  ASSERT_FALSE(contacts.empty());
  EXPECT_EQ(contacts.front().foot, 0);
  EXPECT_EQ(contacts.front().first, 0u);
  EXPECT_GE(contacts.front().last, 50u);
  // Without the fix-up the target's ankle slides (its shins are longer than its thighs):
  glm::vec3 lo(1e9f), hi(-1e9f);
  for (uint32_t f = contacts.front().first; f <= contacts.front().last; ++f)
    lo = glm::min(lo, feet[f].target_ankle[0]), hi = glm::max(hi, feet[f].target_ankle[0]);
  const float h = map.target_pose.hips_height;
  EXPECT_GT(glm::length(hi - lo), 0.01f * h);
  // ... with it, the planted ankle stays within 1e-4 hips heights (0.1 mm on a 1 m leg).
  std::array<FootContact, 2> held{};
  in.contacts = held;
  float slide = 0.0f;
  glm::vec3 planted_lo(1e9f), planted_hi(-1e9f);
  for (uint32_t f = 0; f < frames; ++f) {
    foot_contacts_at(contacts, static_cast<float>(f), 30.0f, ContactSettings{}.blend_time, held);
    in.source = source[f];
    ASSERT_TRUE(retarget(map, in, scratch, out));
    if (f < contacts.front().first || f > contacts.front().last) continue;
    const glm::vec3 ankle(scratch.target_model[static_cast<size_t>(map.legs[0].foot)][3]);
    slide = std::max(slide, glm::length(ankle - held_ankle(map, scratch, 0, held[0], floor)));
    planted_lo = glm::min(planted_lo, ankle), planted_hi = glm::max(planted_hi, ankle);
    RetargetMeasure m;
    measure_retarget(map, scratch, &m);
    for (float d : m.limb_degrees) EXPECT_LT(d, 5.0f) << "frame " << f;
  }
  EXPECT_LT(slide, 1e-4f * h);
  EXPECT_LT(glm::length(planted_hi - planted_lo), 1e-4f * h);  // the source's foot is planted: so is the target's
}

TEST(Retarget, FramesAllocateNothing) {
  const SyntheticRig s = test::make_humanoid(test::mixamo_names(), RigShape{.frame_seed = 1});
  const SyntheticRig t = test::make_humanoid(test::quaternius_names(), RigShape{.frame_seed = 2, .ik_feet = true});
  auto map = make_retarget_map(s.rig("s"), t.rig("t"));
  ASSERT_TRUE(map.ok());
  RetargetScratch scratch = make_retarget_scratch(*map);
  Pose in(static_cast<uint32_t>(s.names.size())), out(static_cast<uint32_t>(t.names.size())),
      base(static_cast<uint32_t>(t.names.size()));
  test::bind_pose(t, base);
  std::array<FootContact, 2> contacts{FootContact{1.0f, glm::vec3(0.01f, 0.0f, 0.0f), {}},
                                      FootContact{0.5f, glm::vec3(0.0f), glm::vec3(0.01f, 0.0f, 0.0f)}};
  RetargetInput input;
  input.source = in;
  input.target_base = base;
  input.contacts = contacts;
  test::synthetic_motion(s, 3, 20.0f, in);
  const size_t before = test::allocation_count();
  for (uint32_t f = 0; f < 20; ++f) {
    ASSERT_TRUE(retarget(*map, input, scratch, out));
    foot_contacts_at({}, static_cast<float>(f), 30.0f, 0.1f, contacts);
  }
  EXPECT_EQ(test::allocation_count(), before);
}

TEST(Retarget, RefusesSpansOfAnotherRig) {
  const SyntheticRig s = test::make_humanoid(test::mixamo_names(), RigShape{});
  const SyntheticRig t = test::make_humanoid(test::unity_names(), RigShape{});
  auto map = make_retarget_map(s.rig("s"), t.rig("t"));
  ASSERT_TRUE(map.ok());
  RetargetScratch scratch = make_retarget_scratch(*map);
  Pose in(static_cast<uint32_t>(s.names.size())), out(static_cast<uint32_t>(t.names.size()));
  Pose wrong(static_cast<uint32_t>(s.names.size()) + 1);
  test::bind_pose(s, in);
  set_identity(out);
  RetargetInput input;
  input.source = wrong;
  EXPECT_FALSE(retarget(*map, input, scratch, out));
  input.source = in;
  EXPECT_FALSE(retarget(*map, input, scratch, wrong));
  std::array<FootContact, 3> three{};
  input.contacts = three;
  EXPECT_FALSE(retarget(*map, input, scratch, out));
  EXPECT_EQ(get_transform(out, 0).translation, glm::vec3(0.0f));  // untouched
  RetargetScratch other;
  input.contacts = {};
  EXPECT_FALSE(retarget(*map, input, other, out));
}

}  // namespace
