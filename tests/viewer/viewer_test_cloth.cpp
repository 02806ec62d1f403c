// viewer_test_cloth.cpp — ossa-view's cloth end to end on the bundled sample (assets/CapedMan, cooked
// by viewer_cook.cmake): the simulated cape changes the image against --cloth off, the GPU setting
// (cloth meshes from CPU-skinned streams, the rest skinned in the shader) draws what the CPU
// reference draws, alone and in a crowd, the overlay shows, and bad options are errors.
#include <gtest/gtest.h>

#include <cstdio>
#include <string>

#include "test_files.h"
#include "viewer_test_common.h"

namespace fs = std::filesystem;
using namespace ossa::test;

namespace {

class ViewerCloth : public Viewer {
 protected:
  Image shot(const std::string& name, const std::string& args) {
    const fs::path png = dir_ / (name + ".png");
    return screenshot(quote(cooked("CapedMan/CapedMan.ossa").string()) + " --size 256x256 --no-grid --yaw 150 " + args +
                          " --screenshot " + quote(png.string()),
                      png);
  }
};

TEST_F(ViewerCloth, SimulatedCapeShowsAndBothPathsAgree) {
  const Image gpu = shot("gpu", "--time 1.2");
  const Image cpu = shot("cpu", "--time 1.2 --cpu-skinning");
  const Image off = shot("off", "--time 1.2 --cloth off");
  const Image overlay = shot("overlay", "--time 1.2 --show-cloth");
  const ImageDiff same = compare(gpu, cpu, kPixelThreshold);
  const ImageDiff moved = compare(gpu, off, kPixelThreshold);
  std::printf("cape: GPU vs CPU %.5f of pixels differ (mean %.4f); simulated vs skinned %.4f; overlay %.4f\n",
              same.differing, same.mean_abs, moved.differing, compare(gpu, overlay, kPixelThreshold).differing);
  EXPECT_LT(same.differing, kMaxDifferingSame);
  EXPECT_LT(same.mean_abs, kMaxMeanSame);
  EXPECT_GT(moved.differing, 0.005) << "the simulated cape looks like the skinned one";
  EXPECT_GT(compare(gpu, overlay, kPixelThreshold).differing, 0.002) << "--show-cloth draws nothing";
}

TEST_F(ViewerCloth, CrowdSimulatesEveryInstance) {
  const std::string crowd = "--crowd 4 --pitch 40 --time 0.8";
  const Image gpu = shot("crowd-gpu", crowd);
  const Image cpu = shot("crowd-cpu", crowd + " --cpu-skinning");
  const Image off = shot("crowd-off", crowd + " --cloth off");
  const ImageDiff same = compare(gpu, cpu, kPixelThreshold);
  std::printf("crowd: GPU vs CPU %.5f differ; simulated vs skinned %.4f\n", same.differing,
              compare(gpu, off, kPixelThreshold).differing);
  EXPECT_LT(same.differing, kMaxDifferingSame);
  EXPECT_GT(compare(gpu, off, kPixelThreshold).differing, 0.005);
}

TEST_F(ViewerCloth, BadClothOptionsAreErrors) {
  const std::string file = quote(cooked("CapedMan/CapedMan.ossa").string());
  for (const std::string bad : {"--cloth maybe", "--wind 1,2", "--wind a,b,c"}) {
    const CommandResult r = run_viewer(file + " " + bad + " --screenshot " + quote((dir_ / "bad.png").string()));
    EXPECT_NE(r.exit_code, 0) << bad;
    EXPECT_FALSE(r.err.empty()) << bad;
  }
}

}  // namespace
