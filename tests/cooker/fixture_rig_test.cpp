// fixture_rig_test.cpp — the graph suites' rig (tests/support/graph_fixture.h) is what the cooker
// makes of assets/Pab.
//
// The runtime's graph suites read Pab's skeleton and clips back from the committed fixtures
// (tests/fixtures/Pab, cooked by ossa-cook) so that they build without the cooker. This suite
// imports and compresses the same sources in process, as the graph fixture once did itself, and
// requires every field the writer stores to come back equal: the read-back is exact and the
// fixtures hold what the cooker makes today (the fixtures_test CTest test checks their bytes).
#include <gtest/gtest.h>

#include <cstring>
#include <string>

#include "cooker/clip/clip_compress.h"
#include "cooker/import/import_scene.h"
#include "graph_fixture.h"
#include "test_files.h"

namespace ossa::cook {
namespace {

void expect_same_skeleton(const SourceSkeleton& got, const SourceSkeleton& want) {
  ASSERT_EQ(got.joints.size(), want.joints.size());
  for (size_t i = 0; i < want.joints.size(); ++i) {
    const SourceJoint &a = got.joints[i], &b = want.joints[i];
    SCOPED_TRACE("joint " + std::to_string(i) + " '" + b.name + "'");
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.parent, b.parent);
    EXPECT_EQ(a.translation, b.translation);
    EXPECT_EQ(a.rotation, b.rotation);
    EXPECT_EQ(a.scale, b.scale);
    EXPECT_EQ(a.inverse_bind, b.inverse_bind);
  }
}

/// Every field the writer stores (events are left to the tests, cooked_bytes is not stored).
void expect_same_clip(const CompressedClip& got, const CompressedClip& want) {
  EXPECT_EQ(got.grid.sample_rate, want.grid.sample_rate);
  EXPECT_EQ(got.grid.frame_count, want.grid.frame_count);
  ASSERT_EQ(got.constants.size(), want.constants.size());
  for (size_t i = 0; i < want.constants.size(); ++i) {
    EXPECT_EQ(got.constants[i].joint, want.constants[i].joint) << i;
    EXPECT_EQ(got.constants[i].channel, want.constants[i].channel) << i;
    EXPECT_EQ(std::memcmp(got.constants[i].value, want.constants[i].value, sizeof want.constants[i].value), 0) << i;
  }
  ASSERT_EQ(got.animated.size(), want.animated.size());
  for (size_t i = 0; i < want.animated.size(); ++i) {
    const CompressedAnimated &a = got.animated[i], &b = want.animated[i];
    EXPECT_EQ(a.joint, b.joint) << i;
    EXPECT_EQ(a.channel, b.channel) << i;
    EXPECT_EQ(a.bits, b.bits) << i;
    EXPECT_EQ(a.dropped, b.dropped) << i;
    EXPECT_EQ(a.first_key, b.first_key) << i;
    EXPECT_EQ(a.key_count, b.key_count) << i;
    EXPECT_EQ(a.bit_offset, b.bit_offset) << i;
    EXPECT_EQ(std::memcmp(a.range_min, b.range_min, sizeof a.range_min), 0) << i;
    EXPECT_EQ(std::memcmp(a.range_extent, b.range_extent, sizeof a.range_extent), 0) << i;
  }
  EXPECT_EQ(got.key_frames, want.key_frames);
  EXPECT_EQ(got.key_values, want.key_values);
  EXPECT_EQ(got.tolerance, want.tolerance);
  EXPECT_EQ(got.probe_distance, want.probe_distance);
  EXPECT_EQ(got.max_error, want.max_error);
  EXPECT_EQ(got.mean_error, want.mean_error);
  EXPECT_EQ(got.worst_joint, want.worst_joint);
  EXPECT_EQ(got.raw_bytes, want.raw_bytes);
  EXPECT_EQ(got.has_root_motion, want.has_root_motion);
  EXPECT_EQ(got.morph_weights.size(), want.morph_weights.size());
}

TEST(FixtureRig, ReadBackEqualsImportAndCompress) {
  const test::PabRig* rig = test::pab_rig();
  ASSERT_NE(rig, nullptr);
  const std::filesystem::path dir = test::source_dir() / "assets" / "Pab";
  auto rig_scene = import_scene((dir / "skeleton.fbx").string());
  ASSERT_TRUE(rig_scene) << rig_scene.error().message;
  expect_same_skeleton(rig->skeleton, rig_scene->skeleton);
  EXPECT_EQ(rig->metres_per_unit, rig_scene->metres_per_unit);
  ImportOptions options;
  options.reference = &rig_scene->skeleton;
  ASSERT_EQ(rig->clips.size(), 4u);
  size_t i = 0;
  for (const char* name : {"walk", "jog", "run", "crossarms"}) {
    SCOPED_TRACE(name);
    auto scene = import_scene((dir / (std::string(name) + ".fbx")).string(), options);
    ASSERT_TRUE(scene) << scene.error().message;
    ASSERT_FALSE(scene->clips.empty());
    auto clip =
        compress_clip(scene->clips[0], rig_scene->skeleton, rig_scene->metres_per_unit, ClipCompressionOptions{});
    ASSERT_TRUE(clip) << clip.error().message;
    EXPECT_EQ(rig->clips[i].name, name);
    EXPECT_TRUE(rig->clips[i].events.empty()) << "the fixture's events are the tests' to add";
    expect_same_clip(rig->clips[i], *clip);
    ++i;
  }
}

}  // namespace
}  // namespace ossa::cook
