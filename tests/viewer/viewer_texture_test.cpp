// viewer_texture_test.cpp — cooked textures in the viewer: BC and RGBA8 mip chains uploaded as
// they are (no decode, no mipmap generation) look like the source image decoded at load, on both
// skinning paths, and take the GPU memory the file says.
//
// viewer_cook.cmake cooks CesiumMan and the Fox three ways: BC (the default, quantized/), RGBA8
// chains (rgba8-textures/) and the source's PNG / JPEG bytes (source-textures/, which the viewer
// decodes with stb_image and mips with glGenerateMipmap, in sRGB like the others). Differences
// between them are the block compression's error and the two mip filters' (the cooker's area
// filter in linear light against the driver's box filter), small against what a texture left out
// or sampled wrongly (un-flipped rows, sRGB decoded twice) does to the image. A generated quad
// with flat and tilted normal maps checks the BC5 path (x, y stored; z rebuilt by the shader),
// which no sample has.
#include <cstdio>
#include <string>
#include <vector>

#include <ossa/loader/asset.h>

#include "viewer_test_common.h"

namespace ossa::test {
namespace {

namespace fs = std::filesystem;

struct Textured {
  const char* name;
  const char* file;
  uint64_t bc_bytes;     // the BC1 chain of its 1024 x 1024 texture
  uint64_t rgba8_bytes;  // an RGBA8 chain of the same
};
const Textured kTextured[] = {{"CesiumMan", "CesiumMan/CesiumMan.ossa", 699064, 5592404},
                              {"Fox", "Fox/Fox.ossa", 699064, 5592404}};

// Measured (256 x 256, MSAA 4, llvmpipe, Mesa 22.3, both skinning paths alike): BC vs source
// differ on 0.055 % (CesiumMan) and 0.005 % (Fox) of the pixels by more than 24 / 255, mean
// |difference| 0.17 and 0.064; RGBA8 vs source on none, mean 0.0065 and 0.0008. The bounds leave
// a 3-5x margin.
constexpr double kMaxDifferingBc = 0.003, kMaxMeanBc = 0.6;
constexpr double kMaxDifferingRgba8 = 0.001, kMaxMeanRgba8 = 0.05;

void PrintTo(const Textured& t, std::ostream* os) { *os << t.name; }

class ViewerTexture : public ::testing::TestWithParam<Textured> {
 protected:
  void SetUp() override {
    std::string why;
    if (!test_display(&why)) GTEST_FAIL() << "no display for the viewer: " << why;
    dir_ = make_temp_dir(std::string("viewer-texture-") + GetParam().name);
  }
  Image render(const char* layout, const std::string& tag, const std::string& extra) {
    const fs::path png = dir_ / (tag + ".png");
    const std::string args = quote((viewer_cooked_dir() / layout / GetParam().file).string()) +
                             " --size 256x256 --no-grid --time 0.4 --screenshot " + quote(png.string()) + " " + extra;
    const CommandResult r = run_viewer(args + " -v");
    EXPECT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.err.find("left out"), std::string::npos) << "a texture was not shown: " << r.err;
    Image image = load_png(png);
    EXPECT_FALSE(image.empty());
    return image;
  }
  fs::path dir_;
};

TEST_P(ViewerTexture, CompressedChainsLookLikeTheSourceOnBothSkinningPaths) {
  for (const char* path : {"", "--cpu-skinning"}) {
    const Image source = render("source-textures", std::string("source") + path, path);
    const Image bc = render("quantized", std::string("bc") + path, path);
    const Image rgba8 = render("rgba8-textures", std::string("rgba8") + path, path);
    const ImageDiff d_bc = compare(source, bc, kPixelThreshold);
    const ImageDiff d_rgba8 = compare(source, rgba8, kPixelThreshold);
    std::printf("%s %s: BC vs source %.5f differ, mean %.4f; RGBA8 vs source %.5f differ, mean %.4f\n", GetParam().name,
                *path ? path : "GPU skinning", d_bc.differing, d_bc.mean_abs, d_rgba8.differing, d_rgba8.mean_abs);
    EXPECT_LT(d_bc.differing, kMaxDifferingBc);
    EXPECT_LT(d_bc.mean_abs, kMaxMeanBc);
    EXPECT_LT(d_rgba8.differing, kMaxDifferingRgba8);
    EXPECT_LT(d_rgba8.mean_abs, kMaxMeanRgba8);
    EXPECT_GT(coverage(bc), 0.02);  // a character is there at all
  }
}

TEST_P(ViewerTexture, GpuMemoryIsTheFilesChains) {
  // --first-frame-time prints what the textures took on the GPU: the cooked chain's bytes as they
  // are in the file, against the RGBA8 chain a decoded source image needs (8x more for BC1).
  const auto bytes_of = [&](const char* layout) -> uint64_t {
    const std::string args = quote((viewer_cooked_dir() / layout / GetParam().file).string()) +
                             " --size 64x64 --frames 1 --first-frame-time";
    const CommandResult r = run_viewer(args);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    const size_t at = r.out.find("texture-bytes ");
    if (at == std::string::npos) {
      ADD_FAILURE() << "no texture-bytes line: " << r.out;
      return 0;
    }
    return std::stoull(r.out.substr(at + 14));
  };
  EXPECT_EQ(bytes_of("quantized"), GetParam().bc_bytes);
  EXPECT_EQ(bytes_of("rgba8-textures"), GetParam().rgba8_bytes);
  EXPECT_EQ(bytes_of("source-textures"), GetParam().rgba8_bytes);
}

/// The quad's document with a grey material and, when `normal_map` is given, that image as its
/// normal texture.
std::string quad_with_normal_map(const std::string& normal_map) {
  if (normal_map.empty())
    return quad_gltf(R"("materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.6, 0.6, 0.6, 1]}}])");
  return quad_gltf(R"("images": [{"uri": ")" + normal_map + R"("}], "textures": [{"source": 0}],
    "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.6, 0.6, 0.6, 1]}, "normalTexture": {"index": 0}}])");
}

// A BC5 normal map holds x and y only; the shader rebuilds z. A flat map (0, 0, 1) must then light
// the quad exactly as no map does, and a tilted one as its source image decoded at load does.
// Measured (128 x 128, facing the quad): centre pixel 189 plain, 189 flat (BC and source), 100
// tilted (BC and source).
TEST_F(Viewer, Bc5NormalMapsRebuildZ) {
  const fs::path src = dir_ / "src";
  fs::create_directories(src);
  ASSERT_TRUE(write_quad_bin(src));
  ASSERT_TRUE(write_file(src / "flat.png", solid_png(128, 128, 255)));
  ASSERT_TRUE(write_file(src / "tilt.png", solid_png(128, 38, 218)));  // about 45 degrees away from the light
  ASSERT_TRUE(write_file(src / "plain.gltf", quad_with_normal_map("")));
  ASSERT_TRUE(write_file(src / "flat.gltf", quad_with_normal_map("flat.png")));
  ASSERT_TRUE(write_file(src / "tilt.gltf", quad_with_normal_map("tilt.png")));
  const std::string cook = quote((bin_dir() / "ossa-cook").string());
  const auto bc = run_command(cook + " -q " + quote(src.string()) + " -o " + quote((dir_ / "bc").string()));
  ASSERT_EQ(bc.exit_code, 0) << bc.err;
  const auto source = run_command(cook + " -q --texture-format source " + quote(src.string()) + " -o " +
                                  quote((dir_ / "source").string()));
  ASSERT_EQ(source.exit_code, 0) << source.err;
  auto tilt_asset = Asset::open((dir_ / "bc" / "tilt.ossa").string());
  ASSERT_TRUE(tilt_asset.ok()) << tilt_asset.error().message;
  ASSERT_EQ(tilt_asset->material(0).textures()->Get(0)->encoding(), fb::TextureEncoding::Bc5);
  const auto shot = [&](const char* layout, const char* name) {
    const fs::path png = dir_ / (std::string(layout) + "-" + name + ".png");
    return screenshot(quote((dir_ / layout / (std::string(name) + ".ossa")).string()) +
                          " -q --no-grid --size 128x128 --yaw 0 --pitch 0 --screenshot " + quote(png.string()),
                      png);
  };
  const Image plain = shot("bc", "plain");
  const ImageDiff flat = compare(plain, shot("bc", "flat"), kPixelThreshold);
  const ImageDiff flat_source = compare(plain, shot("source", "flat"), kPixelThreshold);
  const Image tilt_bc = shot("bc", "tilt");
  const ImageDiff tilted = compare(plain, tilt_bc, kPixelThreshold);
  const ImageDiff tilt_vs_source = compare(tilt_bc, shot("source", "tilt"), kPixelThreshold);
  std::printf(
      "flat BC5 vs no map: %.4f differ, mean %.3f; flat source: %.4f, %.3f; tilted vs no map: %.4f, %.3f; "
      "tilted BC5 vs source: %.4f, %.3f\n",
      flat.differing, flat.mean_abs, flat_source.differing, flat_source.mean_abs, tilted.differing, tilted.mean_abs,
      tilt_vs_source.differing, tilt_vs_source.mean_abs);
  EXPECT_LT(flat.differing, 0.002);
  EXPECT_LT(flat.mean_abs, 0.5);
  EXPECT_LT(flat_source.mean_abs, 0.5);
  EXPECT_GT(tilted.differing, 0.3) << "the tilted normal map does not change the lighting";
  EXPECT_LT(tilt_vs_source.differing, 0.002);
  EXPECT_LT(tilt_vs_source.mean_abs, 0.5);
}

std::string textured_name(const ::testing::TestParamInfo<Textured>& i) { return i.param.name; }
INSTANTIATE_TEST_SUITE_P(Samples, ViewerTexture, ::testing::ValuesIn(kTextured), textured_name);

}  // namespace
}  // namespace ossa::test
