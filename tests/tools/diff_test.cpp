// diff_test.cpp — ossa-diff's comparison (tools/diff/diff.h) and the probe-point measure
// behind it (<ossa/anim/pose_error.h>), on synthetic files where the one change is known exactly.
//
// Each test builds a pair of files from SyntheticSpec (tests/support/test_files.h) that differ in one
// field and checks that the report names exactly that item with the expected figure: the point of
// ossa-diff is that a regression is named precisely, and a test that only checked "differs" would
// pass for a tool that reports the wrong joint.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <string>

#include <glm/gtc/quaternion.hpp>

#include <ossa/anim/pose_error.h>
#include "tools/diff/diff.h"
#include "tools/diff/report.h"
#include "test_files.h"

namespace {

using ossa::diff::Difference;
using ossa::diff::DiffReport;
using ossa::test::SyntheticSpec;

ossa::Asset open_spec(const SyntheticSpec& spec, const char* name) {
  auto a = ossa::Asset::from_bytes(ossa::test::make_valid_file(spec), name);
  EXPECT_TRUE(a.ok()) << (a.ok() ? "" : a.error().message);
  return std::move(a).value();
}

DiffReport diff(const SyntheticSpec& old_spec, const SyntheticSpec& new_spec, double tolerance_mm = 0.1) {
  const ossa::Asset a = open_spec(old_spec, "old.ossa"), b = open_spec(new_spec, "new.ossa");
  ossa::diff::Options options;
  options.tolerance_mm = tolerance_mm;
  auto r = ossa::diff::diff_assets(a, b, options);
  EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
  return std::move(r).value();
}

std::string all_lines(const DiffReport& r) {
  std::string out;
  for (const Difference& d : r.differences) out += ossa::diff::difference_line(d) + "\n";
  return out;
}

// ---- the measure ------------------------------------------------------------------------------

TEST(PoseError, TranslationIsItsOwnError) {
  const ossa::ModelAffine a, b{glm::dmat3(1.0), glm::dvec3(0.0, 0.003, 0.004)};
  EXPECT_NEAR(ossa::probe_error(a, b, 0.1), 0.005, 1e-12);
}

TEST(PoseError, RotationMovesTheProbePointsAndTheChildren) {
  // Two joints: a root and a child 1 unit along x. Turning the root by theta about z moves the
  // root's x and y probe points by 2 p sin(theta / 2), and the child's furthest point (at 1 + p
  // from the root) by 2 (1 + p) sin(theta / 2): the error accumulates down the chain.
  const double theta = 0.01, p = 0.1;
  const int16_t parents[] = {-1, 0};
  ossa::Pose a(2), b(2);
  ossa::set_transform(a, 1, {glm::vec3(1, 0, 0), glm::quat(1, 0, 0, 0), glm::vec3(1)});
  ossa::set_transform(b, 1, {glm::vec3(1, 0, 0), glm::quat(1, 0, 0, 0), glm::vec3(1)});
  ossa::set_transform(b, 0,
                      {glm::vec3(0), glm::angleAxis(static_cast<float>(theta), glm::vec3(0, 0, 1)), glm::vec3(1)});
  ossa::ModelAffine scratch[4];
  const ossa::PoseError e = ossa::pose_error(parents, a, b, p, scratch);
  EXPECT_EQ(e.joint, 1);
  EXPECT_NEAR(e.max, 2.0 * (1.0 + p) * std::sin(theta / 2.0), 1e-6);
  const ossa::PoseError root_only = ossa::model_pose_error(std::span(scratch, 1), std::span(scratch + 2, 1), p);
  EXPECT_EQ(root_only.joint, 0);
  EXPECT_NEAR(root_only.max, 2.0 * p * std::sin(theta / 2.0), 1e-7);
}

TEST(PoseError, ScaleScalesTheProbePoints) {
  const ossa::ModelAffine a = ossa::affine_from_trs(glm::vec3(0), glm::quat(1, 0, 0, 0), glm::vec3(1));
  const ossa::ModelAffine b = ossa::affine_from_trs(glm::vec3(0), glm::quat(1, 0, 0, 0), glm::vec3(1, 1.5f, 1));
  EXPECT_NEAR(ossa::probe_error(a, b, 0.1), 0.05, 1e-9);
}

// ---- the comparison ---------------------------------------------------------------------------

TEST(Diff, IdenticalFilesAreTheSame) {
  SyntheticSpec spec;
  spec.graph = true;
  const DiffReport r = diff(spec, spec);
  EXPECT_TRUE(r.same()) << all_lines(r);
  ASSERT_EQ(r.clips.items.size(), 1u);
  EXPECT_TRUE(r.clips.items[0].sampled);
  EXPECT_EQ(r.clips.items[0].max_error_mm, 0.0);
  EXPECT_EQ(r.clips.items[0].joints_compared, 4u);
  // 31 frames at 30 Hz over 1 s and three points between each pair of frames: 31 + 30 * 3.
  EXPECT_EQ(r.clips.items[0].times, 121u);
  ASSERT_EQ(r.meshes.items.size(), 1u);
  EXPECT_EQ(r.meshes.items[0].max_displacement_mm, 0.0);
  ASSERT_EQ(r.graphs.items.size(), 1u);
  EXPECT_TRUE(r.graphs.items[0].same);
}

TEST(Diff, MovedBindJointIsNamedWithItsDistance) {
  SyntheticSpec moved;
  moved.skeleton->translations[3] = ossa::fb::Vec3(0.5f + 0.005f, 0.5f, 0.0f);  // 'arm', 5 mm in x (metres)
  const DiffReport r = diff(SyntheticSpec{}, moved);
  ASSERT_EQ(r.differences.size(), 1u) << all_lines(r);
  const Difference& d = r.differences[0];
  EXPECT_EQ(d.section, "skeleton");
  EXPECT_EQ(d.item, "arm");
  EXPECT_EQ(d.what, "bind pose");
  ASSERT_TRUE(d.value.has_value());
  EXPECT_NEAR(*d.value, 5.0, 1e-3);
  EXPECT_EQ(d.unit, "mm");
  EXPECT_NEAR(r.skeleton.max_bind_mm, 5.0, 1e-3);
  EXPECT_EQ(r.skeleton.worst_joint, "arm");
  // Within a looser tolerance it is the same.
  EXPECT_TRUE(diff(SyntheticSpec{}, moved, 6.0).same());
}

TEST(Diff, MovedBindJointInCentimetreFileIsConvertedToMillimetres) {
  SyntheticSpec a, b;
  a.metres_per_unit = b.metres_per_unit = 0.01f;
  b.skeleton->translations[2] = ossa::fb::Vec3(0.0f, 1.0f + 0.5f, 0.0f);  // 'head', 0.5 cm
  const DiffReport r = diff(a, b);
  EXPECT_NEAR(r.skeleton.max_bind_mm, 5.0, 1e-3);
  EXPECT_EQ(r.skeleton.worst_joint, "head");
}

TEST(Diff, MovedVertexIsNamedWithItsDisplacement) {
  SyntheticSpec moved;
  auto& v = moved.meshes[0].vertices[2].position;  // (-0.5, 1, 0.1): inside the bounds
  v = ossa::fb::Vec3(v.x(), v.y() + 0.002f, v.z());
  const DiffReport r = diff(SyntheticSpec{}, moved);
  ASSERT_EQ(r.differences.size(), 1u) << all_lines(r);
  const Difference& d = r.differences[0];
  EXPECT_EQ(d.section, "meshes");
  EXPECT_EQ(d.item, "body");
  EXPECT_EQ(d.what, "vertex displacement");
  // 2 mm, give or take one unorm16 step of the 2 m high bounds (0.03 mm).
  ASSERT_TRUE(d.value.has_value());
  EXPECT_NEAR(*d.value, 2.0, 0.031);
  EXPECT_EQ(d.detail, "vertex 2");
  EXPECT_EQ(r.meshes.items[0].worst_vertex, 2u);
}

TEST(Diff, FloatAndQuantizedLayoutsCompareByPosition) {
  using S = ossa::fb::VertexSemantic;
  using F = ossa::fb::VertexFormat;
  SyntheticSpec floats;
  floats.meshes[0].layout = {{S::Position, F::Float32x3, 0},
                             {S::Normal, F::Float32x3, 12},
                             {S::TexCoord0, F::Float32x2, 24},
                             {S::Joints, F::Uint16x4, 32},
                             {S::Weights, F::Unorm8x4, 40}};
  floats.meshes[0].vertex_stride = 44;
  const DiffReport r = diff(SyntheticSpec{}, floats);
  ASSERT_EQ(r.meshes.items.size(), 1u);
  const auto& m = r.meshes.items[0];
  EXPECT_TRUE(m.topology_same);
  EXPECT_FALSE(m.layout_same);
  ASSERT_TRUE(m.max_displacement_mm.has_value());
  // The quantized side is off by at most half a unorm16 step per axis of the 1 x 2 x 0.2 m bounds.
  const double half_step = 0.5 * 1000.0 * std::sqrt(1.0 + 4.0 + 0.04) / 65535.0;
  EXPECT_GT(*m.max_displacement_mm, 0.0);
  EXPECT_LE(*m.max_displacement_mm, half_step * 1.001);
  ASSERT_EQ(r.differences.size(), 1u) << all_lines(r);
  EXPECT_EQ(r.differences[0].what, "layout");
}

TEST(Diff, ChangedTopologySkipsDisplacement) {
  SyntheticSpec changed;
  changed.meshes[0].indices = {0, 2, 1, 1, 2, 3, 2, 3, 4, 3, 5, 4};
  const DiffReport r = diff(SyntheticSpec{}, changed);
  ASSERT_EQ(r.meshes.items.size(), 1u);
  EXPECT_FALSE(r.meshes.items[0].topology_same);
  EXPECT_FALSE(r.meshes.items[0].max_displacement_mm.has_value());
  ASSERT_EQ(r.differences.size(), 1u) << all_lines(r);
  EXPECT_EQ(r.differences[0].what, "topology");
  EXPECT_EQ(r.differences[0].text, "index data changed");
}

TEST(Diff, RenamedAndRemovedClipsAreNamed) {
  SyntheticSpec two;
  two.clips.push_back(two.clips[0]);
  two.clips[1].name = "run";
  SyntheticSpec renamed = two;
  renamed.clips[0].name = "stroll";
  renamed.clips.pop_back();  // 'run' removed
  const DiffReport r = diff(two, renamed);
  const std::string lines = all_lines(r);
  EXPECT_EQ(r.differences.size(), 3u) << lines;
  EXPECT_NE(lines.find("clips 'walk': removed"), std::string::npos) << lines;
  EXPECT_NE(lines.find("clips 'run': removed"), std::string::npos) << lines;
  EXPECT_NE(lines.find("clips 'stroll': added"), std::string::npos) << lines;
  EXPECT_EQ(r.clips.removed, (std::vector<std::string>{"walk", "run"}));
  EXPECT_EQ(r.clips.added, (std::vector<std::string>{"stroll"}));
}

TEST(Diff, RenamedJointIsNamedAndClipsStillCompare) {
  SyntheticSpec renamed;
  renamed.skeleton->names[3] = "left_arm";
  const DiffReport r = diff(SyntheticSpec{}, renamed);
  ASSERT_EQ(r.skeleton.renamed.size(), 1u);
  EXPECT_EQ(r.skeleton.renamed[0], (std::pair<std::string, std::string>{"arm", "left_arm"}));
  const std::string lines = all_lines(r);
  EXPECT_NE(lines.find("skeleton 'arm': renamed: 'arm' -> 'left_arm'"), std::string::npos) << lines;
  EXPECT_NE(lines.find("skeleton: hash:"), std::string::npos) << "a different rig is a difference: " << lines;
  EXPECT_EQ(r.differences.size(), 2u) << lines;
  // The clips bind to different rigs; joints pair by name (and the rename), so all 4 compare.
  ASSERT_EQ(r.clips.items.size(), 1u);
  EXPECT_TRUE(r.clips.items[0].sampled);
  EXPECT_EQ(r.clips.items[0].joints_compared, 4u);
  EXPECT_EQ(r.clips.items[0].max_error_mm, 0.0);
}

TEST(Diff, RemovedJointIsNamedAndSkippedInClips) {
  SyntheticSpec fewer;
  auto& s = *fewer.skeleton;
  s.names.pop_back();  // 'arm'
  s.parents.pop_back();
  s.translations.pop_back();
  s.rotations.pop_back();
  s.scales.pop_back();
  fewer.meshes[0].joints = {1, 2, 2};
  fewer.clips[0].animated.erase(fewer.clips[0].animated.begin() + 1, fewer.clips[0].animated.end());  // arm's channels
  const DiffReport r = diff(SyntheticSpec{}, fewer);
  EXPECT_EQ(r.skeleton.removed, (std::vector<std::string>{"arm"}));
  ASSERT_EQ(r.clips.items.size(), 1u);
  EXPECT_EQ(r.clips.items[0].joints_compared, 3u);
  EXPECT_EQ(r.clips.items[0].joints_skipped, 1u);
  EXPECT_NE(all_lines(r).find("skeleton 'arm': removed"), std::string::npos) << all_lines(r);
}

TEST(Diff, ClipKeyChangeIsMeasuredAtTheWorstJointAndTime) {
  SyntheticSpec changed;
  // spine rotation keys: identity, 45 degrees about y, identity. Raise the middle key to 46 degrees.
  auto& rot = changed.clips[0].animated[0];
  ASSERT_EQ(rot.joint, 1);
  const double half = 46.0 * std::numbers::pi / 360.0;
  rot.values[1] = {0.0f, static_cast<float>(std::sin(half)), 0.0f};
  const DiffReport r = diff(SyntheticSpec{}, changed);
  ASSERT_EQ(r.clips.items.size(), 1u);
  const auto& c = r.clips.items[0];
  // The spine turns 1 degree more at frame 15 (0.5 s); its children carry it further out.
  EXPECT_NEAR(c.worst_time_s, 0.5, 1e-6);
  EXPECT_TRUE(c.worst_joint == "head" || c.worst_joint == "arm") << c.worst_joint;
  EXPECT_GT(c.max_error_mm, 2.0 * 100.0 * std::sin(std::numbers::pi / 360.0));  // more than the spine's own probe
  ASSERT_EQ(r.differences.size(), 1u) << all_lines(r);
  EXPECT_EQ(r.differences[0].what, "joint error");
}

TEST(Diff, EventsDurationAndRootMotionAreCompared) {
  SyntheticSpec a, b;
  a.clips[0].events = {{"foot_left", 0.25f}, {"foot_right", 0.75f}};
  b.clips[0].events = {{"foot_left", 0.25f}, {"foot_right", 0.8f}};
  b.clips[0].root_motion = ossa::test::SyntheticRootMotion{std::vector<ossa::fb::Vec3>(31, ossa::fb::Vec3(0, 0, 0)),
                                                           std::vector<float>(31, 0.0f), 1};
  const std::string lines = all_lines(diff(a, b));
  EXPECT_NE(lines.find("clips 'walk': event: 'foot_right' at 0.75 s -> 'foot_right' at 0.8 s"), std::string::npos)
      << lines;
  EXPECT_NE(lines.find("clips 'walk': root motion: added"), std::string::npos) << lines;
}

TEST(Diff, MaterialTextureBytesAreCompared) {
  SyntheticSpec changed;
  (*changed.materials[0].textures[0].data)[40] ^= 0x01;
  const DiffReport r = diff(SyntheticSpec{}, changed);
  ASSERT_EQ(r.differences.size(), 1u) << all_lines(r);
  EXPECT_EQ(r.differences[0].section, "materials");
  EXPECT_EQ(r.differences[0].what, "texture 0 (Diffuse) data");
}

TEST(Diff, RemovedGraphIsNamed) {
  SyntheticSpec with_graph;
  with_graph.graph = true;
  const DiffReport r = diff(with_graph, SyntheticSpec{});
  EXPECT_EQ(r.graphs.removed, (std::vector<std::string>{"g"}));
  EXPECT_FALSE(r.same());
}

TEST(Diff, ClipOnlyFileNeedsASkeleton) {
  const ossa::Asset rig = open_spec(SyntheticSpec{}, "rig.ossa");
  SyntheticSpec clip_only;
  clip_only.skeleton.reset();
  clip_only.meshes.clear();
  clip_only.clips[0].skeleton_hash = rig.skeleton().hash();
  clip_only.clips[0].joint_count = 4;
  const ossa::Asset a = open_spec(clip_only, "clips.ossa");
  const auto no_rig = ossa::diff::diff_assets(a, a, {});
  ASSERT_FALSE(no_rig.ok());
  EXPECT_NE(no_rig.error().message.find("clips.ossa"), std::string::npos) << no_rig.error().message;
  EXPECT_NE(no_rig.error().message.find("--skeleton"), std::string::npos) << no_rig.error().message;
  const auto with_rig = ossa::diff::diff_assets(a, a, {}, &rig, &rig);
  ASSERT_TRUE(with_rig.ok()) << with_rig.error().message;
  EXPECT_TRUE(with_rig->same());
  ASSERT_EQ(with_rig->clips.items.size(), 1u);
  EXPECT_TRUE(with_rig->clips.items[0].sampled);
}

}  // namespace
