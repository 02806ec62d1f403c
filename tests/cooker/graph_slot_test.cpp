// graph_slot_test.cpp — the slot node and what montages do to the character (graph_slot.cpp,
// graph_montage.cpp) on Pab's real clips: with no montage, or at weight 0, a slot's output is its
// input bit for bit; a masked slot changes only the masked joints (and sets them to the montage's
// pose); an additive slot leaves unmasked joints alone; root motion from a montage moves the character
// by the clip's own displacement (within 1 mm) without sinking it; updates and host calls allocate
// nothing; and the Pab sample plays its upper-body montage over locomotion, looping until told.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <random>
#include <string>
#include <vector>

#include "allocation_counter.h"
#include "cooker/clip/clip_compress.h"
#include "cooker/clip/root_motion.h"
#include "cooker/cook.h"
#include "cooker/import/import_scene.h"
#include "graph_fixture.h"
#include "test_files.h"
#include <ossa/anim/pose_ops.h>
#include <ossa/anim/sample.h>
#include <ossa/graph/graph.h>

namespace ossa {
namespace {

using namespace ossa::cook;
using test::PabRig;
using test::play;
using test::Played;

bool same_bits(ConstPoseSpan a, ConstPoseSpan b) {
  return std::memcmp(a.base, b.base, sizeof(float) * kPoseComponents * a.stride) == 0;
}

/// Whether joint j of a and b is equal bit for bit (all ten components).
bool same_joint(ConstPoseSpan a, ConstPoseSpan b, uint32_t j) {
  for (uint32_t k = 0; k < kPoseComponents; ++k)
    if (std::memcmp(&a[PoseComponent(k)][j], &b[PoseComponent(k)][j], sizeof(float)) != 0) return false;
  return true;
}

/// walk under a slot (group "actions"; mask below `mask_joint` when >= 0).
GraphDef slot_graph(const PabRig& rig, int mask_joint = -1, bool additive = false, bool mesh_space = false) {
  GraphDef g = test::pab_graph(rig);
  SlotDef s;
  s.input = test::clip_node(g, test::kWalk);
  s.slot = "body";
  s.group = "actions";
  if (mask_joint >= 0) s.mask.push_back({static_cast<uint16_t>(mask_joint), -1});
  s.additive = additive;
  s.mesh_space_rotation = mesh_space;
  test::add_node(g, s, "slot");
  MontageDef m;
  m.name = "arms";
  m.group = "actions";
  m.tracks.push_back({"body", {{test::kCrossarms, 0.0f, 8.0f, 1.0f}}});
  m.sections = {{"all", 0.0f, -1}};
  m.blend_in = m.blend_out = 0.25f;
  g.montages.push_back(m);
  return g;
}

TEST(Slot, NoMontageOrWeightZeroIsTheInputBitForBit) {
  NEED_RIG();
  GraphDef plain = test::pab_graph(*rig);
  test::clip_node(plain, test::kWalk);
  Played ref = play(*rig, plain);
  ASSERT_TRUE(ref.inst);
  for (int mask : {-1, rig->joint("Spine1")}) {
    for (bool additive : {false, true}) {
      Played p = play(*rig, slot_graph(*rig, mask, additive, mask >= 0 && !additive));
      ASSERT_TRUE(p.inst);
      ref.inst->reset();
      std::mt19937 rng(11);
      std::uniform_real_distribution<float> u(0.001f, 0.05f);
      for (int f = 0; f < 300; ++f) {
        if (f == 100) {  // played and stopped at once: it never has weight
          ASSERT_TRUE(p.inst->play_montage("arms"));
          ASSERT_TRUE(p.inst->stop_montage("arms", 0.0f));
        }
        const float dt = u(rng);
        p.inst->update(dt);
        ref.inst->update(dt);
        ASSERT_TRUE(same_bits(p.inst->pose(), ref.inst->pose()))
            << "mask " << mask << " additive " << additive << " frame " << f;
        EXPECT_EQ(p.inst->montage_status(0).slot_weight, 0.0f);
      }
      // After a masked or additive montage has played and ended, the input (which never stopped) shows again.
      if (mask < 0 && !additive) continue;  // a full-body montage pauses its input (no weight, not evaluated)
      p.inst->play_montage("arms");
      for (int f = 0; f < 120; ++f) {
        if (f == 60) p.inst->stop_montage("arms");
        p.inst->update(1.0f / 60.0f);
        ref.inst->update(1.0f / 60.0f);
      }
      EXPECT_FALSE(p.inst->montage_playing(0));
      EXPECT_TRUE(same_bits(p.inst->pose(), ref.inst->pose())) << "mask " << mask << " additive " << additive;
    }
  }
}

TEST(Slot, MaskedSlotChangesOnlyTheMaskedJoints) {
  NEED_RIG();
  const int spine1 = rig->joint("Spine1");
  ASSERT_GE(spine1, 0);
  GraphDef plain = test::pab_graph(*rig);
  test::clip_node(plain, test::kWalk);
  for (int mode = 0; mode < 3; ++mode) {  // override, override in mesh space, additive
    Played p = play(*rig, slot_graph(*rig, spine1, mode == 2, mode == 1));
    Played ref = play(*rig, plain);
    ASSERT_TRUE(p.inst && ref.inst);
    p.inst->play_montage("arms");
    std::vector<float> mask(p.def->joint_count(), 0.0f);
    build_joint_mask(p.def->skeleton().parents(), spine1, -1, mask);
    const ClipView arms = p.def->clip(test::kCrossarms);
    auto cache = make_sampling_cache(arms, p.def->skeleton());
    Pose expected(p.def->joint_count());
    int changed = 0;
    for (int f = 0; f < 90; ++f) {
      p.inst->update(1.0f / 60.0f);
      ref.inst->update(1.0f / 60.0f);
      const float weight = p.inst->montage_status(0).weight;
      if (mode == 0 && weight >= 1.0f) {
        SampleOptions options;
        options.loop = false;
        sample(arms, p.inst->montage_status(0).position, options, *cache, expected);
      }
      for (uint32_t j = 0; j < p.def->joint_count(); ++j) {
        if (mask[j] == 0.0f) {
          ASSERT_TRUE(same_joint(p.inst->pose(), ref.inst->pose(), j)) << "unmasked joint " << j << " mode " << mode;
          continue;
        }
        changed += !same_joint(p.inst->pose(), ref.inst->pose(), j);
        if (mode == 0 && weight >= 1.0f) {  // at full weight a masked joint is the montage's pose
          for (uint32_t k = 0; k < kPoseComponents; ++k)
            ASSERT_NEAR(p.inst->pose()[PoseComponent(k)][j], expected.span()[PoseComponent(k)][j], 1e-5f) << j;
        }
      }
    }
    EXPECT_GT(changed, 0) << "the montage changed the masked joints, mode " << mode;
  }
}

TEST(Slot, MachineUnderACoveringSlotReplaysItsHistoryWhole) {
  // Under a slot covering Spine1's subtree at full weight, a machine's states layer crossarms on that
  // subtree. The machine evaluates the slot's shown lanes only, and keeps its last outputs for an
  // inertialization: the montage is stopped and the machine inertializes in the same update, which
  // replays the two updates before on every joint, and once the montage has ended the pose is bit for
  // bit the one of a character that never played it (without the replay, update 14 differs).
  NEED_RIG();
  const int spine1 = rig->joint("Spine1");
  ASSERT_GE(spine1, 0);
  GraphDef g = test::pab_graph(*rig);
  const uint16_t go = test::add_param(g, "go", ParamType::Trigger);
  uint16_t states[2];
  for (int k = 0; k < 2; ++k) {
    LayeredDef layered;
    layered.base = test::clip_node(g, k == 0 ? test::kWalk : test::kJog);
    LayerDef layer;
    layer.node = test::clip_node(g, test::kCrossarms, k == 0 ? 1.0f : 0.5f);
    layer.mask.push_back({static_cast<uint16_t>(spine1), -1});
    layer.mesh_space_rotation = k == 1;
    layered.layers.push_back(layer);
    states[k] = test::add_node(g, layered);
  }
  StateMachineDef sm;
  sm.name = "m";
  sm.states = {{"a", states[0], true}, {"b", states[1], true}};
  sm.transitions.push_back({0, 1, {{CondOp::Trigger, go, 0.0f}}, -1.0f, 1.0f, TransitionModeDef::Inertialize});
  g.machines.push_back(sm);
  GraphDef with_slot = slot_graph(*rig, spine1, false, true);  // its slot and montage, over the machine
  SlotDef slot = std::get<SlotDef>(with_slot.nodes.back().kind);
  slot.input = test::add_node(g, StateMachineRefDef{0}, "m");
  test::add_node(g, slot, "slot");
  g.montages = with_slot.montages;
  Played p = play(*rig, g), ref = play(*rig, g);
  ASSERT_TRUE(p.inst && ref.inst);
  ASSERT_TRUE(p.inst->play_montage("arms"));
  for (int f = 0; f < 60; ++f) {
    p.inst->update(1.0f / 60.0f);
    ref.inst->update(1.0f / 60.0f);
  }
  ASSERT_GE(p.inst->montage_status(0).weight, 1.0f);
  // The machine's states are pure (clips and layers), so under the montage it evaluates only the
  // lanes the slot shows: Spine1's subtree fills 6 of Pab's 9 blocks of 8 joints.
  EXPECT_EQ(p.inst->machine_status(0).skipped_joints, 48u);
  EXPECT_EQ(ref.inst->machine_status(0).skipped_joints, 0u);
  ASSERT_TRUE(p.inst->stop_montage("arms"));
  p.inst->set_trigger(go);
  ref.inst->set_trigger(go);
  int compared = 0;
  for (int f = 0; f < 40; ++f) {
    p.inst->update(1.0f / 60.0f);
    ref.inst->update(1.0f / 60.0f);
    if (p.inst->montage_playing(0)) continue;
    ASSERT_GT(p.inst->machine_status(0).inertial_remaining, 0.0f);
    ASSERT_TRUE(same_bits(p.inst->pose(), ref.inst->pose())) << "update " << f << " after the stop";
    ++compared;
  }
  EXPECT_GT(compared, 10);
}

/// Pab's walk with its root motion taken out (as `ossa-cook --root-motion` does), and as authored.
struct RootMotionClips {
  PabRig rig;  // the fixture's, with "walk_rm" added as clip 4
  CompressedClip original;
};
const RootMotionClips* root_motion_clips() {
  static const std::unique_ptr<RootMotionClips> out = []() -> std::unique_ptr<RootMotionClips> {
    const PabRig* base = test::pab_rig();
    if (!base) return nullptr;
    auto r = std::make_unique<RootMotionClips>();
    r->rig = *base;
    ImportOptions options;
    options.reference = &r->rig.skeleton;
    auto scene = import_scene((test::source_dir() / "assets" / "Pab" / "walk.fbx").string(), options);
    if (!scene || scene->clips.empty()) return nullptr;
    SourceClip clip = scene->clips[0];
    if (!extract_root_motion(clip, r->rig.skeleton, 1)) return nullptr;
    auto compressed = compress_clip(clip, r->rig.skeleton, r->rig.metres_per_unit, ClipCompressionOptions{});
    if (!compressed) return nullptr;
    compressed->name = "walk_rm";
    r->rig.clips.push_back(std::move(*compressed));
    r->original = r->rig.clips[test::kWalk];
    return r;
  }();
  return out.get();
}

TEST(SlotRootMotion, MovesTheCharacterByTheClipsOwnDisplacementWithoutSinking) {
  const RootMotionClips* clips = root_motion_clips();
  if (!clips) GTEST_SKIP() << "assets/Pab not found or did not import";
  const PabRig& rig = clips->rig;
  const float d = rig.clips[4].grid.duration();
  // The authored walk's root: how far it travels over the montage (ground plane, rig units).
  GraphDef probe = test::pab_graph(rig);
  test::clip_node(probe, test::kWalk);
  Played authored = play(rig, probe);
  ASSERT_TRUE(authored.inst);
  const ClipView walk = authored.def->clip(test::kWalk);
  auto cache = make_sampling_cache(walk, authored.def->skeleton());
  Pose pose(authored.def->joint_count());
  const auto root_at = [&](float t) {
    SampleOptions o;
    o.loop = false;
    sample(walk, t, o, *cache, pose);
    std::vector<glm::mat4> model(authored.def->joint_count());
    local_to_model(authored.def->skeleton().parents(), pose, model);
    return glm::vec3(model[0][3]);
  };
  const glm::vec3 cycle = root_at(d) - root_at(0.0f);
  const float mm = 0.001f / rig.metres_per_unit;

  for (bool root_motion : {true, false}) {
    for (float rate : {1.0f, 2.0f}) {
      GraphDef g = test::pab_graph(rig);
      SlotDef s;
      s.input = test::clip_node(g, test::kCrossarms);
      s.slot = "body";
      s.group = "actions";
      test::add_node(g, s, "slot");
      MontageDef m;
      m.name = "stride";
      m.group = "actions";
      m.tracks.push_back({"body", {{4, 0.0f, d, 1.0f}}});
      m.sections = {{"step", 0.0f, -1}};
      m.blend_in = m.blend_out = 0.2f;
      m.root_motion = root_motion;
      g.montages.push_back(m);
      Played p = play(rig, g);
      ASSERT_TRUE(p.inst);
      p.inst->play_montage("stride", rate);
      glm::vec3 position(0.0f);
      float yaw = 0.0f;
      float sink = 0.0f;
      const ClipView in_place = p.def->clip(4);
      auto in_place_cache = make_sampling_cache(in_place, p.def->skeleton());
      Pose expected(p.def->joint_count());
      for (int f = 0; f < 240 && p.inst->montage_playing(0); ++f) {
        p.inst->update(1.0f / 60.0f);
        const RootMotionDelta delta = p.inst->root_motion();
        position += glm::angleAxis(yaw, glm::vec3(0.0f, 1.0f, 0.0f)) * delta.translation;  // as a host would
        yaw += delta.yaw;
        if (p.inst->montage_status(0).weight >= 1.0f) {  // at full weight the root is the in-place clip's
          SampleOptions o;
          o.loop = false;
          sample(in_place, p.inst->montage_status(0).position, o, *in_place_cache, expected);
          sink = std::max(sink, std::fabs(p.inst->pose()[kTy][0] - expected.span()[kTy][0]));
        }
      }
      EXPECT_FALSE(p.inst->montage_playing(0));
      EXPECT_LT(sink, 1e-4f) << "the root keeps the clip's height";
      if (root_motion) {
        EXPECT_LT(glm::length(position - glm::vec3(cycle.x, 0.0f, cycle.z)), mm)
            << "moved " << position.x << " " << position.z << ", the clip " << cycle.x << " " << cycle.z << ", rate "
            << rate;
        EXPECT_GT(glm::length(position), 100.0f * mm) << "it did move";
      } else {
        EXPECT_EQ(position, glm::vec3(0.0f)) << "root motion off: the host moves the character itself";
      }
    }
  }
}

TEST(Slot, UpdatesAndHostCallsAllocateNothing) {
  NEED_RIG();
  GraphDef g = slot_graph(*rig, rig->joint("Spine1"), false, true);
  MontageDef& m = g.montages[0];
  m.sections = {{"start", 0.0f, 1}, {"loop", 1.0f, 1}, {"end", 2.0f, -1}};
  m.blend_in_curve = MontageCurveDef::Inertialize;  // the slot keeps its history and captures offsets too
  m.notifies = {{"hit", 0.5f, 0.0f, MontageNotifyKindDef::Instant},
                {"top", 1.0f, 0.0f, MontageNotifyKindDef::BranchingPoint},
                {"swing", 1.2f, 0.5f, MontageNotifyKindDef::Window}};
  MontageDef other = m;
  other.name = "other";
  g.montages.push_back(other);
  Played p = play(*rig, g);
  ASSERT_TRUE(p.inst);
  int heard = 0;
  p.inst->set_montage_listener(
      [](GraphInstance& inst, const MontageEvent& e, void* user) {
        ++*static_cast<int*>(user);
        if (e.type == MontageEventType::BranchingPoint) inst.set_next_section(e.montage, 1, 2);
      },
      &heard);
  const auto drive = [&](int frames) {
    for (int f = 0; f < frames; ++f) {
      if (f % 97 == 0) p.inst->play_montage(f % 2 ? "other" : "arms", 1.0f + 0.1f * static_cast<float>(f % 5));
      if (f % 53 == 0) p.inst->jump_to_section(0, 1);
      if (f % 71 == 0) p.inst->set_montage_rate(1, 1.5f);
      if (f % 151 == 0) p.inst->stop_montage();
      p.inst->update(f % 200 == 0 ? 0.5f : 1.0f / 60.0f);
      (void)p.inst->montage_events();
    }
  };
  drive(200);  // warm up
  const size_t before = test::allocation_count();
  drive(2000);
  EXPECT_EQ(test::allocation_count(), before) << "montage updates or host calls allocated";
  EXPECT_GT(heard, 100);
}

/// The Pab sample graph (assets/Pab/pab.graph.json) cooked by the real cooker, once per process.
const Asset* pab_sample() {
  static const std::unique_ptr<Asset> asset = []() -> std::unique_ptr<Asset> {
    const std::filesystem::path source = test::source_dir() / "assets" / "Pab" / "pab.graph.json";
    if (!std::filesystem::exists(source)) return nullptr;
    const std::filesystem::path out = test::make_temp_dir("graph_slot") / "pab.ossa";
    const CookRecord r = cook_file(source, out, CookOptions{});
    EXPECT_TRUE(r.ok) << r.error;
    auto a = Asset::open(out.string());
    return a.ok() ? std::make_unique<Asset>(std::move(*a)) : nullptr;
  }();
  return asset.get();
}

TEST(Slot, PabSamplePlaysItsUpperBodyMontageOverLocomotion) {
  const Asset* sample = pab_sample();
  if (!sample) GTEST_SKIP() << "assets/Pab/pab.graph.json not found or did not cook";
  auto def = GraphDefinition::create(*sample, "pab");
  ASSERT_TRUE(def.ok()) << def.error().message;
  const int montage = def->find_montage("cross_arms");
  ASSERT_GE(montage, 0);
  EXPECT_EQ(def->section_count(static_cast<size_t>(montage)), 3u);
  std::vector<float> mask(def->joint_count(), 0.0f);
  build_joint_mask(def->skeleton().parents(), def->skeleton().find_joint("Spine1"), -1, mask);
  // With the crossed_arms layer on too: its mask is the slot's, so under the montage at full weight
  // only its blend's renormalization of the legs is seen, and that must stay bit for bit.
  for (const bool crossed : {false, true}) {
    auto with = GraphInstance::create(*def), without = GraphInstance::create(*def);
    ASSERT_TRUE(with.ok() && without.ok());
    for (GraphInstance* inst : {&*with, &*without}) {
      for (const char* off : {"foot_lock", "feet_on_ground"}) inst->set_float(def->find_parameter(off), 0.0f);
      inst->set_float(def->find_parameter("speed"), 1.07f);
      inst->set_bool(def->find_parameter("crossed_arms"), crossed);
    }
    ASSERT_TRUE(with->play_montage("cross_arms"));
    int changed = 0;
    for (int f = 0; f < 60 * 6; ++f) {
      with->update(1.0f / 60.0f);
      without->update(1.0f / 60.0f);
      for (uint32_t j = 0; j < def->joint_count(); ++j) {
        if (mask[j] == 0.0f)
          ASSERT_TRUE(same_joint(with->pose(), without->pose(), j))
              << "the legs walk on, joint " << j << " " << crossed;
        else changed += !same_joint(with->pose(), without->pose(), j);
      }
      const MontageStatus st = with->montage_status(montage);
      ASSERT_TRUE(st.playing && !st.blending_out) << "the loop holds until told, frame " << f;
      if (f > 120) {
        EXPECT_EQ(st.section, def->find_section(static_cast<size_t>(montage), "loop"));
      }
    }
    EXPECT_GT(changed, 1000);
    ASSERT_TRUE(with->set_next_section("cross_arms", "loop", "end"));
    bool ended = false;
    for (int f = 0; f < 60 * 5 && !ended; ++f) {
      with->update(1.0f / 60.0f);
      without->update(1.0f / 60.0f);
      for (const MontageEvent& e : with->montage_events()) ended |= e.type == MontageEventType::Ended && !e.interrupted;
    }
    EXPECT_TRUE(ended);
    EXPECT_TRUE(same_bits(with->pose(), without->pose())) << "after the montage the graph's own pose is back";
  }
}

TEST(Slot, PabLocomotionUnderTheMontageSkipsHiddenJointsAndStaysExact) {
  // The Pab sample's locomotion machine (blend space, sprint, pose; inertializations and crossfades)
  // under its upper-body slot: two characters get one random schedule of speeds, triggers and the
  // crossed_arms layer, and one of them plays, stops and replays the montage at random (some stops
  // in the update a transition fires). At every update the joints the slot leaves out are bit for
  // bit the other's, and whenever no montage plays the whole pose is; meanwhile the machine skipped
  // the hidden joints, and transitions fired right after it had (without the replay of its history
  // for their inertializations, the whole poses differ).
  const Asset* sample = pab_sample();
  if (!sample) GTEST_SKIP() << "assets/Pab/pab.graph.json not found or did not cook";
  auto def = GraphDefinition::create(*sample, "pab");
  ASSERT_TRUE(def.ok()) << def.error().message;
  std::vector<float> mask(def->joint_count(), 0.0f);
  build_joint_mask(def->skeleton().parents(), def->skeleton().find_joint("Spine1"), -1, mask);
  auto with = GraphInstance::create(*def), without = GraphInstance::create(*def);
  ASSERT_TRUE(with.ok() && without.ok());
  const int speed = def->find_parameter("speed"), strike = def->find_parameter("strike_pose"),
            crossed = def->find_parameter("crossed_arms");
  for (GraphInstance* inst : {&*with, &*without})
    for (const char* off : {"foot_lock", "feet_on_ground"}) inst->set_float(def->find_parameter(off), 0.0f);
  std::mt19937 rng(2026);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  int skipped = 0, after_skipping = 0, whole = 0;
  bool was_skipping = false;
  for (int f = 0; f < 60 * 60; ++f) {
    const float r = u(rng);
    const bool change = r < 0.05f;
    const float v = u(rng) < 0.15f ? 0.0f : 7.0f * u(rng);
    const bool trigger = u(rng) < 0.01f, toggle = u(rng) < 0.01f, layer_on = u(rng) < 0.5f;
    for (GraphInstance* inst : {&*with, &*without}) {
      if (change) inst->set_float(speed, v);
      if (trigger) inst->set_trigger(strike);
      if (toggle) inst->set_bool(crossed, layer_on);
    }
    const bool playing = with->montage_playing(0);
    const int transition_before = with->machine_status(0).transition;
    if (!playing && u(rng) < 0.02f) {
      ASSERT_TRUE(with->play_montage("cross_arms"));
    }
    if (playing && !with->montage_status(0).blending_out && (u(rng) < 0.01f || (change && u(rng) < 0.2f))) {
      ASSERT_TRUE(with->stop_montage("cross_arms", u(rng) < 0.3f ? 0.0f : -1.0f));
    }
    const float dt = u(rng) < 0.02f ? 0.3f : 1.0f / 60.0f;  // now and then a long frame
    with->update(dt);
    without->update(dt);
    const MachineStatus st = with->machine_status(0);
    const bool fired = st.transition != transition_before && st.transition >= 0 && st.elapsed <= dt;
    skipped += st.skipped_joints > 0;
    after_skipping += was_skipping && fired;  // an inertialization then replays the updates before
    was_skipping = st.skipped_joints > 0;
    for (uint32_t j = 0; j < def->joint_count(); ++j) {
      if (mask[j] == 0.0f) {
        ASSERT_TRUE(same_joint(with->pose(), without->pose(), j)) << "joint " << j << " update " << f;
      }
    }
    if (!with->montage_playing(0)) {
      ASSERT_TRUE(same_bits(with->pose(), without->pose())) << "no montage, update " << f;
      ++whole;
    }
  }
  EXPECT_GT(skipped, 600);
  EXPECT_GT(after_skipping, 5);
  EXPECT_GT(whole, 600);
  std::printf("updates skipping hidden joints %d, transitions fired right after one %d, whole poses compared %d\n",
              skipped, after_skipping, whole);
}

}  // namespace
}  // namespace ossa
