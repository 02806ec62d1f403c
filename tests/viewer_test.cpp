// viewer_test.cpp — ossa-view end to end: headless renders of every sample, checked by measure.
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
//  - morph targets: a held weight (--morph) moves the silhouette where the deltas say and nothing
//    else, the GPU morph matches the CPU reference (apply_morphs) on both layouts and in a crowd;
//  - failures exit non-zero with a message naming the file.
// Tolerances were measured on llvmpipe (Mesa 22.3, Debian 12); see the constants below.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include <ossa/loader/asset.h>

#include "blend_shape_fbx.h"
#include "test_files.h"
#include "viewer_harness.h"

namespace fs = std::filesystem;
using namespace ossa::test;

namespace {

// Measured (256 x 256, MSAA 4, llvmpipe, Mesa 22.3): GPU vs CPU skinning differ on at most
// 0.003 % of the pixels by more than 24 / 255, mean |difference| <= 0.019 (CesiumMan; the others
// are ~10x closer); float32 vs quantized cooks: 0.015 % of the pixels, mean 0.034 (CesiumMan). The
// differing pixels sit on silhouette edges that float rounding moves by a sub-pixel. The bounds
// below leave a 5-10x margin and stay far below what a real skinning mistake gives: leaving out
// the shader's per-mesh normal correction (1 / position_scale) was tried and gives 1.7-6 % of
// the pixels and a mean of 1.3-3.0 on four of the five samples (RiggedSimple's scale is nearly
// uniform, so it cannot tell); a wrong palette moves whole limbs. A clip frame vs the bind pose differs on
// 6.5 % (Pab walk) to 11 % of the pixels.
constexpr int kPixelThreshold = 24;
constexpr double kMaxDifferingSame = 0.002;   // GPU vs CPU, float vs quantized
constexpr double kMaxMeanSame = 0.15;
constexpr double kMinDifferingPosed = 0.01;   // a clip frame vs the bind pose

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

/// Runs ossa-view with `args` (which write a screenshot to `png`); fails the test on a non-zero
/// exit or any GL error message, and returns the image.
Image screenshot(const std::string& args, const fs::path& png) {
  const CommandResult r = run_viewer(args);
  EXPECT_EQ(r.exit_code, 0) << "ossa-view " << args << "\n" << r.err;
  EXPECT_EQ(r.err.find("GL error"), std::string::npos) << r.err;
  Image image = load_png(png);
  EXPECT_FALSE(image.empty()) << "no image at " << png;
  return image;
}

/// Renders `sample` with extra options into a PNG in `dir` (see screenshot).
Image render(const Sample& sample, const fs::path& dir, const std::string& tag, const std::string& extra,
             const char* layout = "quantized") {
  const fs::path png = dir / (tag + ".png");
  std::string args = files_of(sample, layout) + "--size 256x256 --no-grid --screenshot " + quote(png.string()) + " " + extra;
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

// ---------------------------------------------------------------------------------------------

class Viewer : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string why;
    if (!test_display(&why)) GTEST_FAIL() << "no display for the viewer: " << why;
    dir_ = make_temp_dir("viewer");
  }
  fs::path cooked(const char* rel) const { return viewer_cooked_dir() / "quantized" / rel; }
  fs::path dir_;
};

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
                            " " + quote(cooked("Pab/run.ossa").string()) + " " + quote(cooked("Pab/crossarms.ossa").string());
  std::vector<Image> images;
  for (const char* clip : {"walk", "run", "crossarms"}) {
    const fs::path png = dir_ / (std::string(clip) + ".png");
    const CommandResult r = run_viewer(files + " --no-grid --size 192x192 --time 0.5 --clip " + clip +
                                       " --screenshot " + quote(png.string()));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    images.push_back(load_png(png));
  }
  EXPECT_GT(compare(images[0], images[1], kPixelThreshold).differing, kMinDifferingPosed) << "walk and run look the same";
  EXPECT_GT(compare(images[0], images[2], kPixelThreshold).differing, kMinDifferingPosed) << "walk and crossarms look the same";
}

TEST_F(Viewer, OverlaysChangeTheImage) {
  const std::string base = quote(cooked("CesiumMan/CesiumMan.ossa").string()) + " --size 192x192 --time 0.4 --no-grid";
  const CommandResult plain = run_viewer(base + " --screenshot " + quote((dir_ / "plain.png").string()));
  const CommandResult skeleton = run_viewer(base + " --skeleton --screenshot " + quote((dir_ / "skeleton.png").string()));
  const CommandResult wire = run_viewer(base + " --wireframe --screenshot " + quote((dir_ / "wire.png").string()));
  const CommandResult grid = run_viewer(quote(cooked("CesiumMan/CesiumMan.ossa").string()) +
                                        " --size 192x192 --time 0.4 --screenshot " + quote((dir_ / "grid.png").string()));
  ASSERT_EQ(plain.exit_code + skeleton.exit_code + wire.exit_code + grid.exit_code, 0) << plain.err << skeleton.err << wire.err << grid.err;
  const Image p = load_png(dir_ / "plain.png");
  EXPECT_GT(compare(p, load_png(dir_ / "skeleton.png"), kPixelThreshold).differing, 0.002);
  EXPECT_GT(compare(p, load_png(dir_ / "wire.png"), kPixelThreshold).differing, 0.01);
  EXPECT_GT(coverage(load_png(dir_ / "grid.png")), coverage(p) + 0.02) << "the grid adds lines around the character";
}

TEST_F(Viewer, WindowModeWithPanelRunsAndCaptures) {
  const fs::path png = dir_ / "window.png";
  const CommandResult r = run_viewer(quote(cooked("Fox/Fox.ossa").string()) + " --size 480x320 --window-frames 3 --screenshot " +
                                     quote(png.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Image image = load_png(png);
  ASSERT_EQ(image.width, 480);
  ASSERT_EQ(image.height, 320);
  EXPECT_GT(coverage(image), 0.1) << "expected the panel and the fox";
}

// ---------------------------------------------------------------------------------------------
// --graph: the Pab sample graph, cooked from assets/Pab/pab.graph.json into Pab/pab.ossa (rig,
// meshes, clips with events, graph 'pab': speed 0..7 over walk 1.07 / jog 3.13 / run 5.02, sprint
// above 5.5, a crossarms pose below 0.05 or on strike_pose, crossed_arms layering the arms).

class ViewerGraph : public Viewer {
 protected:
  std::string files() const { return quote(cooked("Pab/pab.ossa").string()); }
  Image render_graph(const std::string& tag, const std::string& extra) {
    const fs::path png = dir_ / (tag + ".png");
    const CommandResult r = run_viewer(files() + " --graph pab --no-grid --size 192x192 --time 2 --screenshot " +
                                       quote(png.string()) + " " + extra);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return load_png(png);
  }
};

TEST_F(ViewerGraph, ParametersChangeThePose) {
  const Image walk = render_graph("walk", "");  // speed's default, 1.07: the walk sample
  const Image sprint = render_graph("sprint", "--set speed=6.5");  // past 5.5: the sprint state
  const Image arms = render_graph("arms", "--set crossed_arms=true");  // the crossarms layer
  const Image stop = render_graph("stop", "--set strike_pose");  // trigger: the pose state
  const Image bind = render_graph("bind", "--bind-pose");
  EXPECT_GT(coverage(walk), 0.02);
  EXPECT_GT(compare(walk, bind, kPixelThreshold).differing, kMinDifferingPosed) << "the graph does not move the mesh";
  EXPECT_GT(compare(walk, sprint, kPixelThreshold).differing, kMinDifferingPosed) << "speed does not reach the pose";
  EXPECT_GT(compare(walk, arms, kPixelThreshold).differing, kMinDifferingPosed) << "crossed_arms does not layer";
  EXPECT_GT(compare(walk, stop, kPixelThreshold).differing, kMinDifferingPosed) << "strike_pose does not change state";
}

TEST_F(ViewerGraph, RendersDeterministicallyAndAgreesWithCpuSkinning) {
  const Image a = render_graph("a", "--set speed=3");
  const Image b = render_graph("b", "--set speed=3");
  const Image cpu = render_graph("cpu", "--set speed=3 --cpu-skinning");
  EXPECT_EQ(compare(a, b, 0).max_channel, 0) << "the same graph inputs gave another image";
  EXPECT_LT(compare(a, cpu, kPixelThreshold).differing, kMaxDifferingSame);
}

TEST_F(ViewerGraph, UnknownGraphOrParameterIsNamed) {
  const CommandResult graph = run_viewer(files() + " --graph walkies --frames 1");
  EXPECT_NE(graph.exit_code, 0);
  EXPECT_NE(graph.err.find("walkies"), std::string::npos) << graph.err;
  EXPECT_NE(graph.err.find("'pab' (pab.ossa)"), std::string::npos) << graph.err;

  const CommandResult parameter = run_viewer(files() + " --graph pab --set sped=2 --frames 1");
  EXPECT_NE(parameter.exit_code, 0);
  EXPECT_NE(parameter.err.find("sped"), std::string::npos) << parameter.err;
  EXPECT_NE(parameter.err.find("speed, crossed_arms, strike_pose"), std::string::npos) << parameter.err;

  const CommandResult value = run_viewer(files() + " --graph pab --set speed=fast --frames 1");
  EXPECT_NE(value.exit_code, 0);
  EXPECT_NE(value.err.find("fast"), std::string::npos) << value.err;

  const CommandResult no_graph = run_viewer(quote(cooked("Fox/Fox.ossa").string()) + " --graph pab --frames 1");
  EXPECT_NE(no_graph.exit_code, 0);
  EXPECT_NE(no_graph.err.find("graphs: none"), std::string::npos) << no_graph.err;
}

TEST_F(ViewerGraph, WindowModeShowsTheGraphPanel) {
  const fs::path png = dir_ / "window.png";
  const CommandResult r = run_viewer(files() + " --graph pab --crowd 3 --size 640x400 --window-frames 3 --screenshot " +
                                     quote(png.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(load_png(png).width, 640);
}

// ---------------------------------------------------------------------------------------------
// Procedural nodes (format v6): Pab's graph looks at look_target (an aim over spine, neck and
// head, weighted by look_weight) and places its feet on per-foot ground (ground_left / _right
// heights, ground_normal); the Fox graph (assets/Fox/fox_tail.graph.json, cooked here: the fixture
// does not cook it) springs its tail. Vector parameters are set with --param NAME=X,Y,Z. Pab
// stands in the crossed-arms pose (speed 0) seen from the front (yaw 0: its left is the image's
// right), so a change shows where it happens and little elsewhere.

/// Fraction of pixels in rows [y0, y1) differing by more than kPixelThreshold.
double differing_rows(const Image& a, const Image& b, int y0, int y1) {
  if (a.width != b.width || a.height != b.height || a.empty() || y1 <= y0) return 1.0;
  size_t n = 0;
  for (int y = y0; y < y1; ++y) {
    for (int x = 0; x < a.width; ++x) {
      const uint8_t *p = a.at(x, y), *q = b.at(x, y);
      int worst = 0;
      for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(int(p[c]) - int(q[c])));
      n += worst > kPixelThreshold ? 1 : 0;
    }
  }
  return static_cast<double>(n) / (static_cast<double>(y1 - y0) * a.width);
}

bool foreground(const Image& image, int x, int y) {
  const uint8_t *p = image.at(x, y), *bg = image.at(0, 0);
  return std::abs(p[0] - bg[0]) > 6 || std::abs(p[1] - bg[1]) > 6 || std::abs(p[2] - bg[2]) > 6;
}

/// The lowest row holding a silhouette pixel in columns [x0, x1), or -1.
int lowest_row(const Image& image, int x0, int x1) {
  for (int y = image.height - 1; y >= 0; --y) {
    for (int x = std::max(x0, 0); x < std::min(x1, image.width); ++x)
      if (foreground(image, x, y)) return y;
  }
  return -1;
}

/// The middle column of the silhouette's lowest `rows` rows (between the feet).
int feet_middle(const Image& image, int rows) {
  const int bottom = lowest_row(image, 0, image.width);
  int lo = image.width, hi = -1;
  for (int y = std::max(bottom - rows, 0); y <= bottom; ++y) {
    for (int x = 0; x < image.width; ++x) {
      if (!foreground(image, x, y)) continue;
      lo = std::min(lo, x);
      hi = std::max(hi, x);
    }
  }
  return hi < lo ? image.width / 2 : (lo + hi) / 2;
}

class ViewerProcedural : public Viewer {
 protected:
  std::string pab() const { return quote(cooked("Pab/pab.ossa").string()); }
  /// Pab standing (speed 0: the crossed-arms pose), 2 s in, from the front.
  Image render_pab(const std::string& tag, const std::string& extra) {
    return render_file(pab() + " --graph pab --param speed=0 --yaw 0 --pitch 0 --time 2", tag, extra);
  }
  Image render_file(const std::string& base, const std::string& tag, const std::string& extra) {
    const fs::path png = dir_ / (tag + ".png");
    return screenshot(base + " --no-grid --size 256x256 --screenshot " + quote(png.string()) + " " + extra, png);
  }
  /// assets/Fox/fox_tail.graph.json cooked into this test's folder (mesh, clips and graph 'fox').
  fs::path cook_fox() {
    const fs::path assets = source_dir() / "assets";
    const CommandResult r = run_command(quote((bin_dir() / "ossa-cook").string()) + " --quiet " +
                                        quote((assets / "Fox" / "fox_tail.graph.json").string()) + " --root " +
                                        quote(assets.string()) + " -o " + quote((dir_ / "cooked").string()));
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return dir_ / "cooked" / "Fox" / "fox_tail.ossa";
  }
};

TEST_F(ViewerProcedural, LookTargetTurnsTheHeadOnly) {
  const Image ahead = render_pab("ahead", "--param look_target=150,160,100");  // look_weight 0: no aim
  const Image side = render_pab("side", "--param look_weight=1 --param look_target=150,160,100");
  const int h = ahead.height;
  const double upper = differing_rows(ahead, side, 0, h * 3 / 10);
  const double lower = differing_rows(ahead, side, h / 2, h);
  std::printf("look: upper 30%% %.4f of pixels differ, lower half %.4f\n", upper, lower);
  // The camera frames the pose as shown, so a turned head moves the framing by a pixel or so: the
  // legs differ on their edges (about 1 %), the head and chest several times more.
  EXPECT_GT(upper, 0.02) << "look_weight 1 does not turn the head towards the side target";
  EXPECT_LT(lower, upper / 3.0) << "looking aside moved the legs as much as the head";
}

TEST_F(ViewerProcedural, MalformedVectorIsNamed) {
  for (const char* bad : {"1,2", "1,2,3,4", "1,x,3", "nan,1,1", "1;2;3", ""}) {
    const CommandResult r = run_viewer(pab() + " --graph pab --param 'look_target=" + bad + "' --frames 1 --size 32x32");
    EXPECT_EQ(r.exit_code, 1) << bad << ": " << r.err;
    EXPECT_NE(r.err.find("look_target"), std::string::npos) << bad << ": " << r.err;
    EXPECT_NE(r.err.find("three finite numbers"), std::string::npos) << bad << ": " << r.err;
  }
  const CommandResult ok = run_viewer(pab() + " --graph pab --param look_target=-1.5,2e2,0 --frames 1 --size 32x32");
  EXPECT_EQ(ok.exit_code, 0) << ok.err;
}

TEST_F(ViewerProcedural, RaisedGroundLiftsTheLeftFoot) {
  const Image flat = render_pab("flat", "");
  const Image raised = render_pab("raised", "--param ground_left=20");  // 20 cm up under the left foot
  const int middle = feet_middle(flat, flat.height / 20);
  // From the front the character's left foot is on the image's right.
  const int left_flat = lowest_row(flat, middle, flat.width), left_raised = lowest_row(raised, middle, raised.width);
  const int right_flat = lowest_row(flat, 0, middle), right_raised = lowest_row(raised, 0, middle);
  std::printf("ground: split at x %d; left foot bottom %d -> %d, right foot %d -> %d\n", middle, left_flat, left_raised,
              right_flat, right_raised);
  // The framing follows the pose (a bent knee widens it), so the feet are compared with each other
  // too: measured 256 px high, the left foot rises 28 px, 24 px more than the right one.
  EXPECT_LT(left_raised, left_flat - 8) << "the left foot did not go up with its ground";
  EXPECT_GT((right_raised - left_raised) - (right_flat - left_flat), 8) << "the left foot did not rise above the right";
  EXPECT_NEAR(right_raised, right_flat, 6) << "the right foot moved";
}

TEST_F(ViewerProcedural, TiltedGroundIsDrawnUnderTheFeet) {
  const std::string tilt = "--param ground_normal=0,0.9659,0.2588 --param ground_left=10";
  const Image plain = render_pab("plain", tilt);
  const Image shown = render_pab("shown", tilt + " --show-procedural");
  const int h = plain.height;
  const double feet = differing_rows(plain, shown, h * 8 / 10, h);
  const double upper_half = differing_rows(plain, shown, 0, h / 2);
  std::printf("ground overlay: bottom fifth %.4f of pixels differ, upper half %.4f\n", feet, upper_half);
  EXPECT_GT(feet, 0.01) << "no ground drawn under the feet";
  EXPECT_LT(upper_half, feet) << "the ground patches are not under the feet";
}

TEST_F(ViewerProcedural, SpringMovesTheTailAndIsDrawn) {
  const fs::path fox = cook_fox();
  const std::string base = quote(fox.string()) + " --graph fox --time 1.5";
  const Image spring = render_file(base, "spring", "--param tail_spring=1");
  const Image stiff = render_file(base, "stiff", "--param tail_spring=0");
  const Image overlay = render_file(base, "overlay", "--param tail_spring=1 --show-procedural");
  // Seen at yaw 30 the fox faces left: its head is in the image's left third, its tail right.
  const ImageDiff d = compare(spring, stiff, kPixelThreshold);
  size_t head_differs = 0;
  for (int y = 0; y < spring.height; ++y) {
    for (int x = 0; x < spring.width / 3; ++x) {
      int worst = 0;
      for (int c = 0; c < 3; ++c) worst = std::max(worst, std::abs(int(spring.at(x, y)[c]) - int(stiff.at(x, y)[c])));
      head_differs += worst > kPixelThreshold ? 1 : 0;
    }
  }
  const double overlay_differs = compare(spring, overlay, kPixelThreshold).differing;
  std::printf("spring: %.4f of pixels differ (left third: %zu pixels); overlay %.4f\n", d.differing, head_differs,
              overlay_differs);
  EXPECT_GT(d.differing, 0.001) << "tail_spring does not move the tail";
  EXPECT_EQ(head_differs, 0u) << "the spring moved more than the tail";
  EXPECT_GT(overlay_differs, 0.003) << "--show-procedural drew no chain or colliders";
}

// ---------------------------------------------------------------------------------------------
// Morph targets, on synthetic files (tests/test_files.h): the 2 x 3 grid (x in +-0.5, rows at
// y = 0, 1, 2, skinned to spine / head) with target "smile" moving the head row (vertices 4, 5)
// +0.4 in x and tilting its normals, and "frown" moving the middle row (2, 3) -0.1 in x (default
// weight 0.25). The clip drives smile from 0 to 1 over its one second.

SyntheticSpec morph_spec() {
  SyntheticSpec spec;
  SyntheticMorphTarget smile;  // vertices {4, 5}
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
    const std::string args = quote(file.string()) + " -q --no-grid --size 256x256 --screenshot " + quote(png.string()) + " " + extra;
    const CommandResult r = run_viewer(args);
    EXPECT_EQ(r.exit_code, 0) << "ossa-view " << args << "\n" << r.err;
    EXPECT_EQ(r.err.find("GL error"), std::string::npos) << r.err;
    Image image = load_png(png);
    EXPECT_FALSE(image.empty()) << "no image at " << png;
    return image;
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
  const int middle = (top + bottom) / 2;  // model y = 1: the camera looks level at the box centre
  const RowSpan base = row_span(rest, (middle + bottom) / 2);  // the edges at the top and bottom slant
  const double pixels_per_unit = base.right - base.left + 1;  // the grid is one unit wide

  // The lower half: not moved, not re-lit.
  int changed_below = 0;
  for (int y = middle + 3; y < rest.height; ++y)
    for (int x = 0; x < rest.width; ++x)
      for (int c = 0; c < 3; ++c) changed_below += std::abs(rest.at(x, y)[c] - smile.at(x, y)[c]) > kPixelThreshold ? 1 : 0;
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
  std::vector<std::pair<std::string, SyntheticSpec>> specs = {{"quantized", morph_spec()}, {"float", morph_spec_float()}};
  for (auto& [name, spec] : specs) spec.meshes[0].morph_targets[0].position_deltas = {4000, -3000, 1000, 4000, -3000, 1000};
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
      for (int c = 0; c < 3; ++c) differs = differs || std::abs(neutral.at(x, y)[c] - surprised.at(x, y)[c]) > kPixelThreshold;
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

// A blend-shape face without joints (tests/blend_shape_fbx.h): its weights-only clip plays on the
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
  EXPECT_NE(unknown.err.find("morph.ossa: no morph target named 'grin' (morph targets: 'smile', 'frown')"), std::string::npos)
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
  const CommandResult r = run_viewer(quote(file.string()) + " -q --morph frown=1 --size 480x320 --window-frames 3 --screenshot " +
                                     quote(png.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(load_png(png).width, 480);
}

// ---------------------------------------------------------------------------------------------
// Failures: non-zero exit, and a message naming the file.

TEST_F(Viewer, CorruptFileIsRefusedByName) {
  const fs::path bad = dir_ / "garbage.ossa";
  ASSERT_TRUE(write_file(bad, std::string(4096, 'x')));
  const CommandResult r = run_viewer(quote(bad.string()) + " --screenshot " + quote((dir_ / "x.png").string()));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find(bad.string()), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "x.png"));
}

TEST_F(Viewer, TruncatedFileIsRefusedByName) {
  const auto bytes = read_file(cooked("Fox/Fox.ossa"));
  ASSERT_TRUE(bytes.has_value());
  const fs::path bad = dir_ / "truncated.ossa";
  ASSERT_TRUE(write_file(bad, std::span<const uint8_t>(bytes->data(), bytes->size() / 2)));
  const CommandResult r = run_viewer(quote(bad.string()) + " --screenshot " + quote((dir_ / "x.png").string()));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find(bad.string()), std::string::npos) << r.err;
}

TEST_F(Viewer, MissingFileIsNamed) {
  const fs::path missing = dir_ / "no-such-file.ossa";
  const CommandResult r = run_viewer(quote(missing.string()) + " --frames 1");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find(missing.string()), std::string::npos) << r.err;
}

TEST_F(Viewer, ClipOnlyFileAloneHasNoMesh) {
  const CommandResult r = run_viewer(quote(cooked("Pab/walk.ossa").string()) + " --frames 1");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("walk.ossa"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("no mesh"), std::string::npos) << r.err;
}

// A file with a skeleton and no mesh (mocap) is shown as its bones, with its clip playing.
TEST_F(Viewer, SkeletonOnlyFileIsShownAsBones) {
  const std::string bvh =
      "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation "
      "Yrotation\n  JOINT Spine\n  {\n    OFFSET 0 0.5 0\n    CHANNELS 3 Zrotation Xrotation Yrotation\n    JOINT Head\n"
      "    {\n      OFFSET 0 0.5 0\n      CHANNELS 3 Zrotation Xrotation Yrotation\n      End Site\n      {\n"
      "        OFFSET 0 0.2 0\n      }\n    }\n  }\n}\nMOTION\nFrames: 3\nFrame Time: 0.5\n"
      "0 1 0 0 0 0 0 0 0 0 0 0\n0 1 0 0 0 0 40 0 0 0 0 0\n0 1 0 0 0 0 80 0 0 0 0 0\n";
  ASSERT_TRUE(ossa::test::write_file(dir_ / "mocap.bvh", bvh));
  const CommandResult cooked_bvh = ossa::test::run_command(quote((ossa::test::bin_dir() / "ossa-cook").string()) + " " +
                                                           quote((dir_ / "mocap.bvh").string()) + " -o " +
                                                           quote(dir_.string()) + " -q");
  ASSERT_EQ(cooked_bvh.exit_code, 0) << cooked_bvh.err;
  const std::string base = quote((dir_ / "mocap.ossa").string()) + " --size 192x192 --no-grid";
  const CommandResult start = run_viewer(base + " --time 0 --screenshot " + quote((dir_ / "bones0.png").string()));
  const CommandResult bent = run_viewer(base + " --time 0.5 --screenshot " + quote((dir_ / "bones1.png").string()));
  ASSERT_EQ(start.exit_code + bent.exit_code, 0) << start.err << bent.err;
  const Image a = load_png(dir_ / "bones0.png"), b = load_png(dir_ / "bones1.png");
  EXPECT_GT(coverage(a), 0.002) << "bones drawn";
  EXPECT_LT(coverage(a), 0.3);
  EXPECT_GT(compare(a, b, kPixelThreshold).differing, 0.001) << "the clip bends the spine between t = 0 and t = 0.5";
}

// A model coloured only by its vertex colours (no texture, a grey default material) is drawn in
// those colours: the left half of the quad red, the right half blue.
TEST_F(Viewer, VertexColoursTintTheSurface) {
  ASSERT_TRUE(ossa::test::write_file(dir_ / "painted.obj",
                                     std::string("v -1 0 0 1 0 0\nv 0 0 0 1 0 0\nv 0 2 0 1 0 0\nv -1 2 0 1 0 0\n"
                                                 "v 0 0 0 0 0 1\nv 1 0 0 0 0 1\nv 1 2 0 0 0 1\nv 0 2 0 0 0 1\n"
                                                 "vn 0 0 1\nf 1//1 2//1 3//1\nf 1//1 3//1 4//1\nf 5//1 6//1 7//1\nf 5//1 7//1 8//1\n")));
  const CommandResult cooked_obj = ossa::test::run_command(quote((ossa::test::bin_dir() / "ossa-cook").string()) + " " +
                                                           quote((dir_ / "painted.obj").string()) + " -o " +
                                                           quote(dir_.string()) + " -q");
  ASSERT_EQ(cooked_obj.exit_code, 0) << cooked_obj.err;
  const CommandResult r = run_viewer(quote((dir_ / "painted.ossa").string()) + " --size 128x128 --no-grid --yaw 0 --pitch 0 " +
                                     "--screenshot " + quote((dir_ / "painted.png").string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Image img = load_png(dir_ / "painted.png");
  ASSERT_FALSE(img.empty());
  // Mean colour of the left and right thirds' non-background pixels.
  const uint8_t* bg = img.at(0, 0);
  glm::dvec3 left(0.0), right(0.0);
  double nl = 0, nr = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const uint8_t* p = img.at(x, y);
      if (std::abs(p[0] - bg[0]) + std::abs(p[1] - bg[1]) + std::abs(p[2] - bg[2]) < 30) continue;
      const glm::dvec3 c(p[0], p[1], p[2]);
      if (x < img.width / 3) { left += c; ++nl; }
      if (x >= 2 * img.width / 3) { right += c; ++nr; }
    }
  ASSERT_GT(nl, 20.0);
  ASSERT_GT(nr, 20.0);
  left /= nl;
  right /= nr;
  EXPECT_GT(left.r, 3.0 * std::max(left.g, left.b) + 10.0) << "red half: " << left.r << " " << left.g << " " << left.b;
  EXPECT_GT(right.b, 3.0 * std::max(right.r, right.g) + 10.0) << "blue half: " << right.r << " " << right.g << " " << right.b;
}

// A prop far larger than its rig (a 4 m plank held by a 0.2 m two-joint rig) is framed whole:
// the camera frames the skinned vertices, not the joints plus a margin, so no edge of the plank
// touches the image border.
TEST_F(Viewer, APropLargerThanItsSkeletonIsFramedWhole) {
  const std::string dae = R"(<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="meter" meter="1"/><up_axis>Y_UP</up_axis></asset>
  <library_geometries>
    <geometry id="plank-mesh" name="plank">
      <mesh>
        <source id="plank-pos">
          <float_array id="plank-pos-array" count="12">-2 0.95 0  2 0.95 0  2 1.45 0  -2 1.45 0</float_array>
          <technique_common><accessor source="#plank-pos-array" count="4" stride="3">
            <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/></accessor></technique_common>
        </source>
        <vertices id="plank-verts"><input semantic="POSITION" source="#plank-pos"/></vertices>
        <triangles count="2"><input semantic="VERTEX" source="#plank-verts" offset="0"/><p>0 1 2 0 2 3</p></triangles>
      </mesh>
    </geometry>
  </library_geometries>
  <library_controllers>
    <controller id="plank-skin">
      <skin source="#plank-mesh">
        <bind_shape_matrix>1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1</bind_shape_matrix>
        <source id="plank-joints"><Name_array id="plank-joints-array" count="2">Hips Hand</Name_array>
          <technique_common><accessor source="#plank-joints-array" count="2" stride="1"><param name="JOINT" type="name"/></accessor></technique_common></source>
        <source id="plank-ibm"><float_array id="plank-ibm-array" count="32">1 0 0 0 0 1 0 -1 0 0 1 0 0 0 0 1  1 0 0 0 0 1 0 -1.2 0 0 1 0 0 0 0 1</float_array>
          <technique_common><accessor source="#plank-ibm-array" count="2" stride="16"><param name="TRANSFORM" type="float4x4"/></accessor></technique_common></source>
        <source id="plank-weights"><float_array id="plank-weights-array" count="1">1</float_array>
          <technique_common><accessor source="#plank-weights-array" count="1" stride="1"><param name="WEIGHT" type="float"/></accessor></technique_common></source>
        <joints><input semantic="JOINT" source="#plank-joints"/><input semantic="INV_BIND_MATRIX" source="#plank-ibm"/></joints>
        <vertex_weights count="4">
          <input semantic="JOINT" source="#plank-joints" offset="0"/><input semantic="WEIGHT" source="#plank-weights" offset="1"/>
          <vcount>1 1 1 1</vcount>
          <v>1 0 1 0 1 0 1 0</v>
        </vertex_weights>
      </skin>
    </controller>
  </library_controllers>
  <library_visual_scenes>
    <visual_scene id="Scene" name="Scene">
      <node id="Hips" name="Hips" sid="Hips" type="JOINT">
        <matrix sid="transform">1 0 0 0 0 1 0 1 0 0 1 0 0 0 0 1</matrix>
        <node id="Hand" name="Hand" sid="Hand" type="JOINT">
          <matrix sid="transform">1 0 0 0 0 1 0 0.2 0 0 1 0 0 0 0 1</matrix>
        </node>
      </node>
      <node id="plank" name="plank">
        <instance_controller url="#plank-skin"><skeleton>#Hips</skeleton></instance_controller>
      </node>
    </visual_scene>
  </library_visual_scenes>
  <scene><instance_visual_scene url="#Scene"/></scene>
</COLLADA>
)";
  ASSERT_TRUE(ossa::test::write_file(dir_ / "plank.dae", dae));
  const CommandResult cooked_dae = ossa::test::run_command(quote((ossa::test::bin_dir() / "ossa-cook").string()) + " " +
                                                           quote((dir_ / "plank.dae").string()) + " -o " +
                                                           quote(dir_.string()) + " -q");
  ASSERT_EQ(cooked_dae.exit_code, 0) << cooked_dae.err;
  auto plank = ossa::Asset::open((dir_ / "plank.ossa").string());
  ASSERT_TRUE(plank.ok()) << plank.error().message;
  ASSERT_EQ(plank->skeleton().joint_count(), 2u) << "the plank is skinned to a rig, not baked";
  const CommandResult r = run_viewer(quote((dir_ / "plank.ossa").string()) + " --size 160x120 --no-grid --yaw 0 --pitch 0 " +
                                     "--screenshot " + quote((dir_ / "plank.png").string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Image img = load_png(dir_ / "plank.png");
  ASSERT_FALSE(img.empty());
  const uint8_t* bg = img.at(0, 0);
  const auto foreground = [&](int x, int y) {
    const uint8_t* p = img.at(x, y);
    return std::abs(p[0] - bg[0]) + std::abs(p[1] - bg[1]) + std::abs(p[2] - bg[2]) > 18;
  };
  int left = img.width, right = -1;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      if (foreground(x, y)) {
        left = std::min(left, x);
        right = std::max(right, x);
      }
  ASSERT_GE(right, 0) << "the plank is drawn";
  EXPECT_GT(left, 0) << "the plank's left end is cut off";
  EXPECT_LT(right, img.width - 1) << "the plank's right end is cut off";
  EXPECT_GT(right - left, img.width / 2) << "and it is framed, not lost in the distance";
}

TEST_F(Viewer, ClipOfAnotherSkeletonIsRefused) {
  const CommandResult r = run_viewer(quote(cooked("Fox/Fox.ossa").string()) + " " + quote(cooked("Pab/walk.ossa").string()) +
                                     " --frames 1");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("walk.ossa"), std::string::npos) << r.err;
}

TEST_F(Viewer, UnknownClipNameListsTheClips) {
  const CommandResult r = run_viewer(quote(cooked("Fox/Fox.ossa").string()) + " --clip Gallop --frames 1");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("Gallop"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("'Survey', 'Walk', 'Run'"), std::string::npos) << r.err;
}

TEST_F(Viewer, UnwritableScreenshotIsNamed) {
  const fs::path out = dir_ / "missing-dir" / "out.png";
  const CommandResult r = run_viewer(quote(cooked("Fox/Fox.ossa").string()) + " --size 64x64 --screenshot " + quote(out.string()));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find(out.string()), std::string::npos) << r.err;
}

TEST_F(Viewer, BadSizeIsAUsageError) {
  const CommandResult r = run_viewer(quote(cooked("Fox/Fox.ossa").string()) + " --size 640by480 --frames 1");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--size"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("run 'ossa-view --help'"), std::string::npos) << r.err;
}

// -q / -v (runtime/tools/cli/cli.h) on a rendered scene. The synthetic file's normal map is a path
// that does not exist, so a plain run warns that it was left out.
TEST_F(Viewer, QuietHidesWarningsVerboseNamesTheContext) {
  const fs::path file = dir_ / "synthetic.ossa";
  ASSERT_TRUE(write_file(file, make_valid_file()));
  const std::string args = quote(file.string()) + " --size 64x64 --frames 1";

  const CommandResult normal = run_viewer(args);
  ASSERT_EQ(normal.exit_code, 0) << normal.err;
  EXPECT_NE(normal.err.find("warning: "), std::string::npos) << normal.err;
  EXPECT_NE(normal.err.find("left out"), std::string::npos) << normal.err;

  const CommandResult quiet = run_viewer(args + " -q");
  ASSERT_EQ(quiet.exit_code, 0) << quiet.err;
  EXPECT_TRUE(quiet.err.empty()) << quiet.err;
  EXPECT_TRUE(quiet.out.empty()) << quiet.out;

  const CommandResult verbose = run_viewer(args + " --verbose");
  ASSERT_EQ(verbose.exit_code, 0) << verbose.err;
  EXPECT_NE(verbose.err.find("OpenGL "), std::string::npos) << verbose.err;
  EXPECT_NE(verbose.err.find("4 joints, 1 meshes"), std::string::npos) << verbose.err;
  EXPECT_NE(verbose.err.find("left out"), std::string::npos) << "-v keeps the warnings: " << verbose.err;
}

// The viewer trusts the loader, so whatever a loadable file names must be safe to show: texture
// paths that leave the file's folder, a directory, a FIFO or /dev/zero as a texture, and an
// embedded PNG claiming 16384 x 16384 pixels are each left out with a warning naming why, in
// bounded time and memory; --time beyond an hour is a usage error rather than a long hang.
TEST_F(Viewer, HostileTexturesAreLeftOutByName) {
  ASSERT_EQ(::mkfifo((dir_ / "pipe.png").c_str(), 0644), 0);
  fs::create_directories(dir_ / "folder.png");
  const auto png = tiny_png();
  std::vector<uint8_t> bomb(png.begin(), png.end());
  for (int k = 0; k < 2; ++k) {  // IHDR width and height -> 16384
    bomb[16 + 4 * k] = 0;
    bomb[17 + 4 * k] = 0;
    bomb[18 + 4 * k] = 0x40;
    bomb[19 + 4 * k] = 0;
  }
  SyntheticSpec spec;
  spec.materials[0].textures = {
      {ossa::fb::TextureRole::Diffuse, "", "image/png", bomb},
      {ossa::fb::TextureRole::Normal, "../../../../../../etc/passwd", "", std::nullopt},
      {ossa::fb::TextureRole::Specular, "pipe.png", "", std::nullopt}};
  SyntheticMaterial second;
  second.textures = {{ossa::fb::TextureRole::Diffuse, "/dev/zero", "", std::nullopt},
                     {ossa::fb::TextureRole::Normal, "folder.png", "", std::nullopt}};
  spec.materials.push_back(second);
  const fs::path file = dir_ / "hostile.ossa";
  ASSERT_TRUE(write_file(file, make_valid_file(spec)));
  const auto start = std::chrono::steady_clock::now();
  const CommandResult r = run_viewer(quote(file.string()) + " --size 64x64 --frames 1");
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_LT(seconds, 20.0);
  EXPECT_NE(r.err.find("over the viewer's limit of 16384 per side and 67108864 pixels"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("passwd left out: it lies outside the file's folder"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("pipe.png left out: it is not a regular file"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("/dev/zero left out: a texture path must be relative to the file"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("folder.png left out: it is not a regular file"), std::string::npos) << r.err;

  const CommandResult forever = run_viewer(quote(cooked("Fox/Fox.ossa").string()) + " --time inf --frames 1");
  EXPECT_EQ(forever.exit_code, 2);
  EXPECT_NE(forever.err.find("--time: expected a finite number of seconds"), std::string::npos) << forever.err;
  const CommandResult long_one = run_viewer(quote(cooked("Fox/Fox.ossa").string()) + " --time 1e9 --frames 1");
  EXPECT_EQ(long_one.exit_code, 2) << long_one.err;
}

}  // namespace
