// viewer_test_render.cpp — ossa-view end to end: headless renders of every sample, checked by measure.
//
// Each test runs the real binary (headless: hidden window, offscreen framebuffer, PNG out) on the
// samples cooked by the viewer_cook.cmake fixture, on a private Xvfb with Mesa's llvmpipe
// (viewer_harness.h), and measures the PNGs:
//  - the character covers a plausible part of the image (not empty, not a full-screen smear);
//  - a frame of a clip differs from the bind pose (the clip really drives the mesh);
//  - GPU skinning (quantized layout decoded in the shader, palette in a texture buffer) and the
//    runtime's skin_cpu reference draw the same image within a small tolerance, for the quantized
//    and the float32 layouts, and float32 and quantized cooks of one asset look the same;
//  - a crowd draws its instances (counted as separate silhouettes from above);
//  - overlays change the image; the window mode runs and captures.
// Graphs, morph targets and failures have files of their own (viewer_test_graph.cpp, _morph, _cli).
// Tolerances were measured on llvmpipe (Mesa 22.3, Debian 12); see the constants below.
// (Split from the one viewer_test.cpp by subject; shared helpers in viewer_test_common.h.)
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include "test_files.h"
#include "viewer_test_common.h"

namespace fs = std::filesystem;
using namespace ossa::test;

namespace {

struct Sample {
  const char* name;
  std::vector<const char*> files;  // under the fixture's quantized/ (and float/ for kFloatSamples)
  const char* clip;                // "" = the first clip
};

// Every sample with a mesh, as scripts/demo.sh cooks them. Pab's skeleton.ossa has a mesh but
// its only clip holds 7 constant rotations, so it is not among the animated ones.
const Sample kCesiumMan{"CesiumMan", {"CesiumMan/CesiumMan.ossa"}, ""};
const Sample kFox{"Fox", {"Fox/Fox.ossa"}, "Walk"};
const Sample kRiggedSimple{"RiggedSimple", {"RiggedSimple/RiggedSimple.ossa"}, ""};
const Sample kPabSkeleton{"PabSkeleton", {"Pab/skeleton.ossa"}, ""};
const Sample kPabArnaudWalk{"PabArnaudWalk", {"Pab/arnaud.ossa", "Pab/walk.ossa"}, "walk"};
const Sample kSamples[] = {kCesiumMan, kFox, kRiggedSimple, kPabSkeleton, kPabArnaudWalk};
const Sample kAnimatedSamples[] = {kCesiumMan, kFox, kRiggedSimple, kPabArnaudWalk};
const Sample kFloatSamples[] = {kCesiumMan, kFox, kRiggedSimple};  // viewer_cook.cmake's float/ cooks

constexpr const char* kTime = "0.4";

void PrintTo(const Sample& s, std::ostream* os) { *os << s.name; }

std::string files_of(const Sample& s, const char* layout) {
  std::string out;
  for (const char* f : s.files) out += quote((viewer_cooked_dir() / layout / f).string()) + " ";
  return out;
}

/// Renders `sample` with extra options into a PNG in `dir` (see screenshot).
Image render(const Sample& sample, const fs::path& dir, const std::string& tag, const std::string& extra,
             const char* layout = "quantized") {
  const fs::path png = dir / (tag + ".png");
  std::string args =
      files_of(sample, layout) + "--size 256x256 --no-grid --screenshot " + quote(png.string()) + " " + extra;
  if (*sample.clip) args += std::string(" --clip ") + quote(sample.clip);
  return screenshot(args, png);
}

class ViewerSample : public ::testing::TestWithParam<Sample> {
 protected:
  void SetUp() override {
    std::string why;
    if (!test_display(&why)) GTEST_FAIL() << "no display for the viewer: " << why;
    dir_ = make_temp_dir(std::string("viewer-") + GetParam().name);
  }
  fs::path dir_;
};

TEST_P(ViewerSample, RendersAPlausibleCharacter) {
  const Image image = render(GetParam(), dir_, "frame", std::string("--time ") + kTime);
  const double c = coverage(image);
  std::printf("%s: coverage %.3f\n", GetParam().name, c);
  EXPECT_GT(c, 0.02) << "the character is (nearly) invisible";
  EXPECT_LT(c, 0.60) << "the character fills the image: framing or geometry is wrong";
}

class ViewerAnimatedSample : public ViewerSample {};
class ViewerFloatSample : public ViewerSample {};

TEST_P(ViewerAnimatedSample, ClipFrameDiffersFromBindPose) {
  const Image bind = render(GetParam(), dir_, "bind", "--bind-pose");
  const Image posed = render(GetParam(), dir_, "posed", std::string("--time ") + kTime);
  const ImageDiff d = compare(bind, posed, kPixelThreshold);
  std::printf("%s: bind vs t=%s: %.4f of pixels differ, mean %.3f\n", GetParam().name, kTime, d.differing, d.mean_abs);
  EXPECT_GT(d.differing, kMinDifferingPosed) << "the clip does not move the mesh";
}

TEST_P(ViewerSample, GpuSkinningMatchesCpuSkinning) {
  const std::string t = std::string("--time ") + kTime;
  const Image gpu = render(GetParam(), dir_, "gpu", t);
  const Image cpu = render(GetParam(), dir_, "cpu", t + " --cpu-skinning");
  const ImageDiff d = compare(gpu, cpu, kPixelThreshold);
  std::printf("%s: GPU vs CPU skinning: %.5f of pixels differ by > %d, mean %.4f, max %d\n", GetParam().name,
              d.differing, kPixelThreshold, d.mean_abs, d.max_channel);
  EXPECT_LT(d.differing, kMaxDifferingSame);
  EXPECT_LT(d.mean_abs, kMaxMeanSame);
}

TEST_P(ViewerFloatSample, FloatLayoutMatchesQuantizedAndCpu) {
  const std::string t = std::string("--time ") + kTime;
  const Image quantized = render(GetParam(), dir_, "quantized", t);
  const Image gpu = render(GetParam(), dir_, "float-gpu", t, "float");
  const Image cpu = render(GetParam(), dir_, "float-cpu", t + " --cpu-skinning", "float");
  const ImageDiff layouts = compare(quantized, gpu, kPixelThreshold);
  const ImageDiff paths = compare(gpu, cpu, kPixelThreshold);
  std::printf("%s: float vs quantized: %.5f differ, mean %.4f; float GPU vs CPU: %.5f differ, mean %.4f\n",
              GetParam().name, layouts.differing, layouts.mean_abs, paths.differing, paths.mean_abs);
  EXPECT_LT(layouts.differing, kMaxDifferingSame);
  EXPECT_LT(layouts.mean_abs, kMaxMeanSame);
  EXPECT_LT(paths.differing, kMaxDifferingSame);
  EXPECT_LT(paths.mean_abs, kMaxMeanSame);
}

std::string sample_name(const ::testing::TestParamInfo<Sample>& i) { return i.param.name; }
INSTANTIATE_TEST_SUITE_P(Samples, ViewerSample, ::testing::ValuesIn(kSamples), sample_name);
INSTANTIATE_TEST_SUITE_P(Samples, ViewerAnimatedSample, ::testing::ValuesIn(kAnimatedSamples), sample_name);
INSTANTIATE_TEST_SUITE_P(Samples, ViewerFloatSample, ::testing::ValuesIn(kFloatSamples), sample_name);
/// Separate silhouettes (4-connected non-background regions of at least `min_pixels`).
int count_blobs(const Image& image, size_t min_pixels) {
  const int w = image.width, h = image.height;
  const auto bg = image.at(0, 0);
  std::vector<uint8_t> seen(static_cast<size_t>(w) * h, 0);
  const auto fg = [&](int x, int y) {
    const uint8_t* p = image.at(x, y);
    return std::abs(p[0] - bg[0]) > 6 || std::abs(p[1] - bg[1]) > 6 || std::abs(p[2] - bg[2]) > 6;
  };
  int blobs = 0;
  std::vector<std::pair<int, int>> stack;
  for (int y = 0; y < h; ++y) {
    for (int x = 0; x < w; ++x) {
      if (seen[static_cast<size_t>(y) * w + x] || !fg(x, y)) continue;
      size_t size = 0;
      stack.assign(1, {x, y});
      seen[static_cast<size_t>(y) * w + x] = 1;
      while (!stack.empty()) {
        const auto [cx, cy] = stack.back();
        stack.pop_back();
        ++size;
        const int nx[] = {cx + 1, cx - 1, cx, cx}, ny[] = {cy, cy, cy + 1, cy - 1};
        for (int k = 0; k < 4; ++k) {
          if (nx[k] < 0 || ny[k] < 0 || nx[k] >= w || ny[k] >= h) continue;
          uint8_t& s = seen[static_cast<size_t>(ny[k]) * w + nx[k]];
          if (!s && fg(nx[k], ny[k])) {
            s = 1;
            stack.push_back({nx[k], ny[k]});
          }
        }
      }
      blobs += size >= min_pixels ? 1 : 0;
    }
  }
  return blobs;
}

TEST_F(Viewer, CrowdDrawsEveryInstanceOnBothSkinningPaths) {
  // From above, so instances on the crowd grid do not hide one another; each plays the walk at
  // its own phase from its own palette region.
  const std::string base = quote(cooked("Pab/arnaud.ossa").string()) + " " + quote(cooked("Pab/walk.ossa").string()) +
                           " --crowd 4 --pitch 75 --yaw 0 --no-grid --size 256x256 --time 0.3";
  const CommandResult gpu = run_viewer(base + " --screenshot " + quote((dir_ / "gpu.png").string()));
  ASSERT_EQ(gpu.exit_code, 0) << gpu.err;
  const CommandResult cpu = run_viewer(base + " --cpu-skinning --screenshot " + quote((dir_ / "cpu.png").string()));
  ASSERT_EQ(cpu.exit_code, 0) << cpu.err;
  const Image g = load_png(dir_ / "gpu.png"), c = load_png(dir_ / "cpu.png");
  EXPECT_EQ(count_blobs(g, 30), 4);
  const ImageDiff d = compare(g, c, kPixelThreshold);
  EXPECT_LT(d.differing, kMaxDifferingSame) << "per-instance palettes differ between GPU and CPU paths";
}

TEST_F(Viewer, ClipsFromSeparateFilesPlayOnTheCharacter) {
  const std::string files = quote(cooked("Pab/arnaud.ossa").string()) + " " + quote(cooked("Pab/walk.ossa").string()) +
                            " " + quote(cooked("Pab/run.ossa").string()) + " " +
                            quote(cooked("Pab/crossarms.ossa").string());
  std::vector<Image> images;
  for (const char* clip : {"walk", "run", "crossarms"}) {
    const fs::path png = dir_ / (std::string(clip) + ".png");
    const CommandResult r = run_viewer(files + " --no-grid --size 192x192 --time 0.5 --clip " + clip +
                                       " --screenshot " + quote(png.string()));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    images.push_back(load_png(png));
  }
  EXPECT_GT(compare(images[0], images[1], kPixelThreshold).differing, kMinDifferingPosed)
      << "walk and run look the same";
  EXPECT_GT(compare(images[0], images[2], kPixelThreshold).differing, kMinDifferingPosed)
      << "walk and crossarms look the same";
}

TEST_F(Viewer, OverlaysChangeTheImage) {
  const std::string base = quote(cooked("CesiumMan/CesiumMan.ossa").string()) + " --size 192x192 --time 0.4 --no-grid";
  const CommandResult plain = run_viewer(base + " --screenshot " + quote((dir_ / "plain.png").string()));
  const CommandResult skeleton =
      run_viewer(base + " --skeleton --screenshot " + quote((dir_ / "skeleton.png").string()));
  const CommandResult wire = run_viewer(base + " --wireframe --screenshot " + quote((dir_ / "wire.png").string()));
  const CommandResult grid =
      run_viewer(quote(cooked("CesiumMan/CesiumMan.ossa").string()) + " --size 192x192 --time 0.4 --screenshot " +
                 quote((dir_ / "grid.png").string()));
  ASSERT_EQ(plain.exit_code + skeleton.exit_code + wire.exit_code + grid.exit_code, 0)
      << plain.err << skeleton.err << wire.err << grid.err;
  const Image p = load_png(dir_ / "plain.png");
  EXPECT_GT(compare(p, load_png(dir_ / "skeleton.png"), kPixelThreshold).differing, 0.002);
  EXPECT_GT(compare(p, load_png(dir_ / "wire.png"), kPixelThreshold).differing, 0.01);
  EXPECT_GT(coverage(load_png(dir_ / "grid.png")), coverage(p) + 0.02) << "the grid adds lines around the character";
}

TEST_F(Viewer, WindowModeWithPanelRunsAndCaptures) {
  const fs::path png = dir_ / "window.png";
  const CommandResult r = run_viewer(quote(cooked("Fox/Fox.ossa").string()) +
                                     " --size 480x320 --window-frames 3 --screenshot " + quote(png.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Image image = load_png(png);
  ASSERT_EQ(image.width, 480);
  ASSERT_EQ(image.height, 320);
  EXPECT_GT(coverage(image), 0.1) << "expected the panel and the fox";
}

}  // namespace
