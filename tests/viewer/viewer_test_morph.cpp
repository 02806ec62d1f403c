// viewer_test_morph.cpp — ossa-view's morph targets end to end: a held weight (--morph) moves the
// silhouette where the deltas say and nothing else, the GPU morph matches the CPU reference
// (apply_morphs) on both layouts and in a crowd, a weights-only clip plays on a face without
// joints, and bad --morph values are errors. Split from viewer_test.cpp by subject; helpers in
// viewer_test_common.h.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <ossa/loader/asset.h>

#include "blend_shape_fbx.h"
#include "test_files.h"
#include "viewer_test_common.h"

namespace fs = std::filesystem;
using namespace ossa::test;

namespace {

// ---------------------------------------------------------------------------------------------
// Morph targets, on synthetic files (tests/support/test_files.h): the 2 x 3 grid (x in +-0.5, rows at
// y = 0, 1, 2, skinned to spine / head) with target "smile" moving the head row (vertices 4, 5)
// +0.4 in x and tilting its normals, and "frown" moving the middle row (2, 3) -0.1 in x (default
// weight 0.25). The clip drives smile from 0 to 1 over its one second.

SyntheticSpec morph_spec() {
  SyntheticSpec spec;
  SyntheticMorphTarget smile;                        // vertices {4, 5}
  smile.position_deltas = {4000, 0, 0, 4000, 0, 0};  // x 0.0001 per step: +0.4
  smile.normal_deltas = {6000, 0, 0, 6000, 0, 0};
  smile.normal_step = {0.0001f, 0.0001f, 0.0001f};  // +0.6 in x: the normals tilt about 31 degrees
  SyntheticMorphTarget frown;
  frown.name = "frown";
  frown.vertices = {2, 3};
  frown.position_deltas = {-1000, 0, 0, -1000, 0, 0};
  frown.default_weight = 0.25f;
  spec.meshes[0].morph_targets = {smile, frown};
  spec.clips[0].morph_weights = {SyntheticMorphTrack{}};  // smile: 0 at frame 0, 1 at frame 30
  return spec;
}

/// The same file with float32 vertices (the "float32-layout" variant's layout).
SyntheticSpec morph_spec_float() {
  SyntheticSpec spec = morph_spec();
  for (const auto& [name, variant] : valid_variants()) {
    if (name != "float32-layout") continue;
    spec.meshes[0].layout = variant.meshes[0].layout;
    spec.meshes[0].vertex_stride = variant.meshes[0].vertex_stride;
  }
  return spec;
}

/// Foreground columns of one image row (colour off the top-left corner's by more than 18).
struct RowSpan {
  int left = 0, right = -1;
  bool empty() const { return right < left; }
  double centre() const { return 0.5 * (left + right); }
};
RowSpan row_span(const Image& img, int y) {
  const uint8_t* bg = img.at(0, 0);
  RowSpan s{img.width, -1};
  for (int x = 0; x < img.width; ++x) {
    const uint8_t* p = img.at(x, y);
    if (std::abs(p[0] - bg[0]) + std::abs(p[1] - bg[1]) + std::abs(p[2] - bg[2]) <= 18) continue;
    s.left = std::min(s.left, x);
    s.right = std::max(s.right, x);
  }
  return s;
}

class ViewerMorph : public Viewer {
 protected:
  fs::path write_spec(const std::string& name, const SyntheticSpec& spec) {
    const fs::path file = dir_ / (name + ".ossa");
    EXPECT_TRUE(write_file(file, make_valid_file(spec)));
    return file;
  }
  Image shot(const fs::path& file, const std::string& tag, const std::string& extra) {
    const fs::path png = dir_ / (tag + ".png");
    const std::string args =
        quote(file.string()) + " -q --no-grid --size 256x256 --screenshot " + quote(png.string()) + " " + extra;
    return screenshot(args, png);
  }
};

// --morph holds a weight: at smile = 1 the head row's silhouette sits 0.4 units to the right of
// where it is at smile = 0 (measured against the grid's own width in pixels), and below the
// middle row, which no target moves, not one pixel changes. Front view, bind pose, so the grid is
// drawn as authored; the framing is the unmorphed character's in both runs.
TEST_F(ViewerMorph, HeldWeightMovesTheHeadRowWhereItsDeltasSay) {
  const fs::path file = write_spec("morph", morph_spec());
  const std::string view = "--bind-pose --yaw 0 --pitch 0";
  const Image plain = shot(file, "plain", view);
  const Image rest = shot(file, "rest", view + " --morph smile=0 --morph frown=0");
  const Image smile = shot(file, "smile", view + " --morph smile=1 --morph frown=0");
  ASSERT_FALSE(rest.empty() || smile.empty() || plain.empty());

  int top = -1, bottom = -1;
  for (int y = 0; y < rest.height; ++y) {
    if (row_span(rest, y).empty()) continue;
    if (top < 0) top = y;
    bottom = y;
  }
  ASSERT_GT(bottom - top, 100) << "the grid fills most of the image height";
  const int middle = (top + bottom) / 2;                       // model y = 1: the camera looks level at the box centre
  const RowSpan base = row_span(rest, (middle + bottom) / 2);  // the edges at the top and bottom slant
  const double pixels_per_unit = base.right - base.left + 1;   // the grid is one unit wide

  // The lower half: not moved, not re-lit.
  int changed_below = 0;
  for (int y = middle + 3; y < rest.height; ++y)
    for (int x = 0; x < rest.width; ++x)
      for (int c = 0; c < 3; ++c)
        changed_below += std::abs(rest.at(x, y)[c] - smile.at(x, y)[c]) > kPixelThreshold ? 1 : 0;
  EXPECT_EQ(changed_below, 0) << "pixels below the middle row changed";

  // The upper half: each row shifted by 0.4 units times how far up the half it is.
  for (const int y : {top + 3, (top + middle) / 2}) {
    const RowSpan a = row_span(rest, y), b = row_span(smile, y);
    ASSERT_FALSE(a.empty() || b.empty()) << "row " << y;
    const double expected = 0.4 * pixels_per_unit * (middle - y) / static_cast<double>(middle - top);
    const double moved = b.centre() - a.centre();
    std::printf("row %d: moved %.1f px, expected %.1f px (%.1f px per unit)\n", y, moved, expected, pixels_per_unit);
    EXPECT_NEAR(moved, expected, 0.15 * expected + 2.0) << "row " << y;
    EXPECT_NEAR(b.right - b.left, a.right - a.left, 3) << "the row moves, it does not stretch";
  }
  const ImageDiff d = compare(rest, smile, kPixelThreshold);
  EXPECT_GT(d.differing, 0.01);
  // The default weights (smile 0, frown 0.25) vs frown held at 0: frown moves the middle row.
  EXPECT_GT(compare(plain, rest, kPixelThreshold).differing, 0.002) << "frown's default weight is not drawn";
}

// The GPU path (entry lists in texture buffers, weights per instance) and the CPU reference
// (apply_morphs, then skinning) draw the same morphing frames: the clip at t = 0.5 drives smile at
// 0.5 while it bends the spine, frown stays at its default; quantized and float32 layouts, the
// test_files "morph" variant (normal deltas, a constant track), and a crowd whose members play the
// clip at their own phases, hence with their own weights.
TEST_F(ViewerMorph, GpuMatchesCpuOnMorphingFrames) {
  // smile also moves the head row down and back here (y and z are the axes whose position_scale
  // is not 1: a delta not divided by it in the shader lands elsewhere).
  std::vector<std::pair<std::string, SyntheticSpec>> specs = {{"quantized", morph_spec()},
                                                              {"float", morph_spec_float()}};
  for (auto& [name, spec] : specs)
    spec.meshes[0].morph_targets[0].position_deltas = {4000, -3000, 1000, 4000, -3000, 1000};
  for (const auto& [name, spec] : valid_variants())
    if (name == "morph") specs.emplace_back("variant", spec);
  ASSERT_EQ(specs.size(), 3u);
  for (const auto& [name, spec] : specs) {
    const fs::path file = write_spec(name, spec);
    const Image gpu = shot(file, name + "-gpu", "--time 0.5");
    const Image cpu = shot(file, name + "-cpu", "--time 0.5 --cpu-skinning");
    const Image still = shot(file, name + "-still", "--time 0.5 --morph smile=0 --morph frown=0");
    const ImageDiff d = compare(gpu, cpu, kPixelThreshold);
    const ImageDiff shown = compare(gpu, still, kPixelThreshold);
    std::printf("%s: GPU vs CPU morphing: %.5f of pixels differ, mean %.4f; morph vs none: %.4f differ\n", name.c_str(),
                d.differing, d.mean_abs, shown.differing);
    EXPECT_LT(d.differing, kMaxDifferingSame) << name;
    EXPECT_LT(d.mean_abs, kMaxMeanSame) << name;
    EXPECT_GT(shown.differing, 0.002) << name << ": the morph does not show at this frame";
  }

  const fs::path file = write_spec("crowd", specs.front().second);
  const std::string crowd = "--crowd 4 --pitch 60 --yaw 0 --time 0.3";
  const Image gpu = shot(file, "crowd-gpu", crowd);
  const Image cpu = shot(file, "crowd-cpu", crowd + " --cpu-skinning");
  const Image held = shot(file, "crowd-held", crowd + " --morph smile=0");
  const ImageDiff d = compare(gpu, cpu, kPixelThreshold);
  std::printf("crowd: GPU vs CPU morphing: %.5f of pixels differ, mean %.4f\n", d.differing, d.mean_abs);
  EXPECT_LT(d.differing, kMaxDifferingSame) << "per-instance weights differ between the paths";
  EXPECT_GT(compare(gpu, held, kPixelThreshold).differing, 0.002);
}

// RobotExpressive (shared assets, glTF): its face targets (Angry, Surprised, Sad) cooked into the
// file; holding Surprised at 1 changes the face, and only the head: every changed pixel lies in
// the top of the silhouette, where the head is (the head is about the top 45 % of the robot in
// this view). The GPU and CPU paths agree on the surprised face.
TEST_F(ViewerMorph, RobotExpressiveSurprisedChangesTheFaceOnly) {
  const fs::path glb = shared_assets() / "RobotExpressive" / "RobotExpressive.glb";
  if (!fs::exists(glb)) GTEST_SKIP() << glb << " not found (set OSSA_SHARED_ASSETS)";
  const CommandResult cooked_robot = run_command(quote((bin_dir() / "ossa-cook").string()) + " " + quote(glb.string()) +
                                                 " -o " + quote(dir_.string()) + " -q");
  ASSERT_EQ(cooked_robot.exit_code, 0) << cooked_robot.err;
  const fs::path file = dir_ / "RobotExpressive.ossa";
  auto robot = ossa::Asset::open(file.string());
  ASSERT_TRUE(robot.ok()) << robot.error().message;
  size_t listed = 0;
  for (size_t m = 0; m < robot->mesh_count(); ++m) {
    const int t = robot->mesh(m).find_morph_target("Surprised");
    if (t >= 0) listed += robot->mesh(m).morph_target(static_cast<size_t>(t)).vertices()->size();
  }
  ASSERT_GT(listed, 0u) << "no vertex moved by a target named Surprised in " << file;

  const std::string view = "--clip Idle --time 0 --yaw 15 --pitch 5";
  const Image neutral = shot(file, "neutral", view + " --morph Surprised=0");
  const Image surprised = shot(file, "surprised", view + " --morph Surprised=1");
  const Image cpu = shot(file, "surprised-cpu", view + " --morph Surprised=1 --cpu-skinning");
  ASSERT_FALSE(neutral.empty() || surprised.empty() || cpu.empty());

  int top = -1, bottom = -1;
  for (int y = 0; y < neutral.height; ++y) {
    if (row_span(neutral, y).empty()) continue;
    if (top < 0) top = y;
    bottom = y;
  }
  ASSERT_GT(bottom - top, 100);
  const int head_bottom = top + static_cast<int>(0.45 * (bottom - top));
  int changed = 0, changed_below_head = 0;
  for (int y = 0; y < neutral.height; ++y)
    for (int x = 0; x < neutral.width; ++x) {
      bool differs = false;
      for (int c = 0; c < 3; ++c)
        differs = differs || std::abs(neutral.at(x, y)[c] - surprised.at(x, y)[c]) > kPixelThreshold;
      changed += differs ? 1 : 0;
      changed_below_head += differs && y > head_bottom ? 1 : 0;
    }
  const double area = static_cast<double>(neutral.width) * neutral.height;
  std::printf("RobotExpressive: Surprised 0 vs 1: %d pixels changed (%.4f), %d below the head; %zu vertices listed\n",
              changed, changed / area, changed_below_head, listed);
  EXPECT_GT(changed / area, 0.003) << "Surprised does not change the face";
  EXPECT_EQ(changed_below_head, 0) << "pixels below the head changed";

  const ImageDiff paths = compare(surprised, cpu, kPixelThreshold);
  std::printf("RobotExpressive surprised: GPU vs CPU: %.5f differ, mean %.4f\n", paths.differing, paths.mean_abs);
  EXPECT_LT(paths.differing, kMaxDifferingSame);
  EXPECT_LT(paths.mean_abs, kMaxMeanSame);
}

// A blend-shape face without joints (tests/support/blend_shape_fbx.h): its weights-only clip plays on the
// targets. At 1 s "smile" is at 1 (corners 1 and 3 moved), at 0 s at 0; GPU and CPU paths agree.
TEST_F(ViewerMorph, AWeightsOnlyClipPlaysOnAFaceWithoutJoints) {
  ASSERT_TRUE(write_file(dir_ / "face.fbx", std::string(kBlendShapeFbx)));
  const CommandResult cooked = run_command(quote((bin_dir() / "ossa-cook").string()) + " " +
                                           quote((dir_ / "face.fbx").string()) + " -o " + quote(dir_.string()) + " -q");
  ASSERT_EQ(cooked.exit_code, 0) << cooked.err;
  const fs::path file = dir_ / "face.ossa";
  const std::string view = "--clip talk --yaw 0 --pitch 0";
  const Image rest = shot(file, "face-0", view + " --time 0");
  const Image smiling = shot(file, "face-1", view + " --time 1");
  const Image cpu = shot(file, "face-1-cpu", view + " --time 1 --cpu-skinning");
  ASSERT_FALSE(rest.empty() || smiling.empty() || cpu.empty());
  const ImageDiff moved = compare(rest, smiling, kPixelThreshold);
  std::printf("face without joints: 0 s vs 1 s: %.4f differ\n", moved.differing);
  EXPECT_GT(moved.differing, 0.01) << "the clip's smile weight does not move the quad";
  const ImageDiff paths = compare(smiling, cpu, kPixelThreshold);
  EXPECT_LT(paths.differing, kMaxDifferingSame);
  EXPECT_LT(paths.mean_abs, kMaxMeanSame);
}

TEST_F(ViewerMorph, UnknownOrMalformedMorphIsAnError) {
  const fs::path file = write_spec("morph", morph_spec());
  const CommandResult unknown = run_viewer(quote(file.string()) + " -q --morph grin=1 --frames 1");
  EXPECT_EQ(unknown.exit_code, 1);
  EXPECT_NE(unknown.err.find("morph.ossa: no morph target named 'grin' (morph targets: 'smile', 'frown')"),
            std::string::npos)
      << unknown.err;

  const fs::path plain = dir_ / "plain.ossa";
  ASSERT_TRUE(write_file(plain, make_valid_file()));
  const CommandResult none = run_viewer(quote(plain.string()) + " -q --morph smile=1 --frames 1");
  EXPECT_EQ(none.exit_code, 1);
  EXPECT_NE(none.err.find("(morph targets: none)"), std::string::npos) << none.err;

  for (const char* bad : {"smile", "smile=", "=1", "smile=lots", "smile=inf", "smile=1e9"}) {
    const CommandResult r = run_viewer(quote(file.string()) + " --morph " + quote(bad) + " --frames 1");
    EXPECT_EQ(r.exit_code, 2) << bad;
    EXPECT_NE(r.err.find("--morph: expected NAME=WEIGHT"), std::string::npos) << bad << ": " << r.err;
  }
}

TEST_F(ViewerMorph, WindowModeShowsTheMorphPanel) {
  const fs::path file = write_spec("morph", morph_spec());
  const fs::path png = dir_ / "window.png";
  const CommandResult r =
      run_viewer(quote(file.string()) + " -q --morph frown=1 --size 480x320 --window-frames 3 --screenshot " +
                 quote(png.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(load_png(png).width, 480);
}

}  // namespace
