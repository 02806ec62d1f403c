// viewer_test_common.h — what the ossa-view end-to-end suites (viewer_test_*.cpp) share: the
// pixel tolerances, the screenshot runner and the Viewer fixture.
//
// The suites were one 1000-line file; they are split by subject (samples and rendering, graphs
// and procedural nodes, morph targets, failures and the command line, the window mode's panel,
// browser, cooking and timeline) so each stays readable. Everything here is inline so each suite
// is its own translation unit and the viewer_test target is just OSSA_VIEWER_TEST_SOURCES.
#pragma once
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "test_files.h"
#include "viewer_harness.h"

namespace ossa::test {

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

/// Runs ossa-view with `args` (which write a screenshot to `png`); fails the test on a non-zero
/// exit or any GL error message, and returns the image.
inline Image screenshot(const std::string& args, const std::filesystem::path& png) {
  const CommandResult r = run_viewer(args);
  EXPECT_EQ(r.exit_code, 0) << "ossa-view " << args << "\n" << r.err;
  EXPECT_EQ(r.err.find("GL error"), std::string::npos) << r.err;
  Image image = load_png(png);
  EXPECT_FALSE(image.empty()) << "no image at " << png;
  return image;
}


/// Whether (x, y) differs from the top-left corner's colour by more than 6 in a channel.
inline bool foreground(const Image& image, int x, int y) {
  const uint8_t *p = image.at(x, y), *bg = image.at(0, 0);
  return std::abs(p[0] - bg[0]) > 6 || std::abs(p[1] - bg[1]) > 6 || std::abs(p[2] - bg[2]) > 6;
}

class Viewer : public ::testing::Test {
 protected:
  void SetUp() override {
    std::string why;
    if (!test_display(&why)) GTEST_FAIL() << "no display for the viewer: " << why;
    dir_ = make_temp_dir("viewer");
  }
  std::filesystem::path cooked(const char* rel) const { return viewer_cooked_dir() / "quantized" / rel; }
  std::filesystem::path dir_;
};


}  // namespace ossa::test
