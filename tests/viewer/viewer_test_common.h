// viewer_test_common.h — what the ossa-view end-to-end suites (viewer_test_*.cpp) share: the
// pixel tolerances, the screenshot runner and the Viewer fixture.
//
// The suites were one 1000-line file; they are split by subject (samples and rendering, graphs
// and procedural nodes, morph targets, failures and the command line, the window mode's panel,
// browser, cooking and timeline) so each stays readable. Everything here is inline so each suite
// is its own translation unit and the viewer_test target is just OSSA_VIEWER_TEST_SOURCES.
#pragma once
#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include <stb_image_write.h>

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
constexpr double kMaxDifferingSame = 0.002;  // GPU vs CPU, float vs quantized
constexpr double kMaxMeanSame = 0.15;
constexpr double kMinDifferingPosed = 0.01;  // a clip frame vs the bind pose

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

/// A flat 8 x 8 RGB PNG of one colour (the generated maps of the texture suites).
inline std::vector<uint8_t> solid_png(uint8_t r, uint8_t g, uint8_t b) {
  std::vector<uint8_t> texels;
  for (int i = 0; i < 64; ++i) texels.insert(texels.end(), {r, g, b});
  std::vector<uint8_t> out;
  stbi_write_png_to_func(
      [](void* ctx, void* data, int size) {
        auto* o = static_cast<std::vector<uint8_t>*>(ctx);
        o->insert(o->end(), static_cast<uint8_t*>(data), static_cast<uint8_t*>(data) + size);
      },
      &out, 8, 8, 3, texels.data(), 24);
  return out;
}

/// Writes `dir`/quad.bin, which quad_gltf's documents read: a 2 x 2 unit quad facing +Z
/// (positions, normals, texture coordinates, 6 indices; 140 bytes).
inline bool write_quad_bin(const std::filesystem::path& dir) {
  const float geometry[] = {-1, -1, 0, 1, -1, 0, 1, 1, 0, -1, 1, 0,  // positions
                            0,  0,  1, 0, 0,  1, 0, 0, 1, 0,  0, 1,  // normals
                            0,  1,  1, 1, 1,  0, 0, 0};              // texture coordinates
  const uint16_t indices[] = {0, 1, 2, 0, 2, 3};
  std::vector<uint8_t> bin(reinterpret_cast<const uint8_t*>(geometry),
                           reinterpret_cast<const uint8_t*>(geometry) + sizeof geometry);
  bin.insert(bin.end(), reinterpret_cast<const uint8_t*>(indices),
             reinterpret_cast<const uint8_t*>(indices) + sizeof indices);
  return bin.size() == 140 && write_file(dir / "quad.bin", bin);
}

/// A glTF document of that quad (its one primitive uses material 0); `tail` holds its
/// "materials" member (and "images", "textures" when it has maps), without the closing brace.
inline std::string quad_gltf(const std::string& tail) {
  return R"({"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}], "nodes": [{"mesh": 0}],
    "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3,
      "material": 0}]}],
    "buffers": [{"uri": "quad.bin", "byteLength": 140}],
    "bufferViews": [{"buffer": 0, "byteLength": 48}, {"buffer": 0, "byteOffset": 48, "byteLength": 48},
                    {"buffer": 0, "byteOffset": 96, "byteLength": 32}, {"buffer": 0, "byteOffset": 128,
                      "byteLength": 12}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-1, -1, 0], "max": [1,
      1, 0]},
                  {"bufferView": 1, "componentType": 5126, "count": 4, "type": "VEC3"},
                  {"bufferView": 2, "componentType": 5126, "count": 4, "type": "VEC2"},
                  {"bufferView": 3, "componentType": 5123, "count": 6, "type": "SCALAR"}],)" +
         tail + "}";
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
