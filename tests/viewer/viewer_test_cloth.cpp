// viewer_test_cloth.cpp — ossa-view's cloth end to end on the bundled sample (assets/CapedMan, cooked
// by viewer_cook.cmake): the simulated cape changes the image against --cloth off, the GPU setting
// (every mesh skinned in the shader, the cape's cloth vertices read from the particles' texture
// buffer there) draws what the CPU reference (skin_cpu, particles written over its streams)
// draws, alone and in a crowd, the overlay shows, and bad options are errors.
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

/// --stats's "cloth particles from the vertex shader P  meshes skinned on the CPU M" line.
struct ClothRoute {
  double shader_particles = -1, cpu_meshes = -1;
};
ClothRoute cloth_route(const std::string& out) {
  ClothRoute r;
  const size_t at = out.find("cloth particles from the vertex shader");
  if (at != std::string::npos)
    std::sscanf(out.c_str() + at, "cloth particles from the vertex shader %lf  meshes skinned on the CPU %lf",
                &r.shader_particles, &r.cpu_meshes);
  return r;
}

TEST_F(ViewerCloth, GpuPathReadsTheParticlesInItsVertexShader) {
  const std::string file = quote(cooked("CapedMan/CapedMan.ossa").string());
  const std::string png = quote((dir_ / "route.png").string());
  const auto route = [&](const std::string& args) {
    const CommandResult r = run_viewer(file + " --size 64x64 --stats --screenshot " + png + " " + args);
    EXPECT_EQ(r.exit_code, 0) << args << "\n" << r.err;
    return cloth_route(r.out);
  };
  const ClothRoute one = route("--time 0.5"), crowd = route("--time 0.5 --crowd 4");
  const ClothRoute cpu = route("--time 0.5 --cpu-skinning"), cpu_crowd = route("--time 0.5 --crowd 4 --cpu-skinning");
  const ClothRoute off = route("--time 0.5 --cloth off");
  std::printf("shader particles: 1 character %.0f, 4 %.0f; CPU-skinned meshes: GPU %.0f, CPU %.0f, CPU x4 %.0f\n",
              one.shader_particles, crowd.shader_particles, one.cpu_meshes, cpu.cpu_meshes, cpu_crowd.cpu_meshes);
  EXPECT_GT(one.shader_particles, 100.0) << "the cape is not read by the vertex shader";
  EXPECT_EQ(crowd.shader_particles, 4.0 * one.shader_particles);
  EXPECT_EQ(one.cpu_meshes, 0.0) << "the GPU path skinned the cloth mesh on the CPU";
  EXPECT_EQ(crowd.cpu_meshes, 0.0);
  EXPECT_EQ(cpu.shader_particles, 0.0);
  EXPECT_EQ(cpu_crowd.shader_particles, 0.0);
  EXPECT_GE(cpu.cpu_meshes, 1.0);
  EXPECT_EQ(cpu_crowd.cpu_meshes, 4.0 * cpu.cpu_meshes) << "--cpu-skinning skins every instance's meshes";
  EXPECT_EQ(off.shader_particles, 0.0);
  EXPECT_EQ(off.cpu_meshes, 0.0);
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
