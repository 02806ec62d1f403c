// viewer_test_pbr.cpp — a PBR source's material (format v11) cooked and shown: glTF's occlusion,
// metallic-roughness and emissive maps and factors reach the .ossa file by role (occlusion BC4,
// metallic-roughness BC5, emissive sRGB colour), ossa-inspect reports them, and the viewer uses
// what Phong can (occlusion scales the ambient term, emission is added) and names what it cannot
// (metallic-roughness). The inputs are generated quads with flat maps (viewer_test_common.h), so
// each term's effect on the centre pixel is known.
#include <cstdio>
#include <string>

#include <ossa/loader/asset.h>

#include "viewer_test_common.h"

namespace ossa::test {
namespace {

namespace fs = std::filesystem;

/// The quad's document with one material: grey base colour, metallic and roughness factors, and
/// `extra` material members (maps, emissive factor) over images occlusion.png (0), orm.png (1)
/// and glow.png (2).
std::string pbr_quad(float metallic, const std::string& extra) {
  return quad_gltf(R"("images": [{"uri": "occlusion.png"}, {"uri": "orm.png"}, {"uri": "glow.png"}],
    "textures": [{"source": 0}, {"source": 1}, {"source": 2}],
    "materials": [{"pbrMetallicRoughness": {"baseColorFactor": [0.6, 0.6, 0.6, 1], "metallicFactor": )" +
                   std::to_string(metallic) + R"(, "roughnessFactor": 0.75)" + extra + "}}]");
}

const uint8_t* centre(const Image& image) { return image.at(image.width / 2, image.height / 2); }

TEST_F(Viewer, PbrMaterialsCookByRoleAndShowWhatPhongCan) {
  const fs::path src = dir_ / "src";
  fs::create_directories(src);
  ASSERT_TRUE(write_quad_bin(src));
  ASSERT_TRUE(write_file(src / "occlusion.png", solid_png(0, 255, 255)));  // R: no ambient light reaches it
  ASSERT_TRUE(write_file(src / "orm.png", solid_png(255, 200, 60)));       // G roughness, B metallic
  ASSERT_TRUE(write_file(src / "glow.png", solid_png(255, 0, 0)));
  ASSERT_TRUE(write_file(src / "plain.gltf", pbr_quad(0.0f, "")));
  ASSERT_TRUE(write_file(src / "occluded.gltf", pbr_quad(0.0f, R"(}, "occlusionTexture": {"index": 0)")));
  ASSERT_TRUE(write_file(src / "metal.gltf", pbr_quad(0.25f, R"(, "metallicRoughnessTexture": {"index": 1})")));
  ASSERT_TRUE(write_file(src / "glowing.gltf",
                         pbr_quad(0.0f, R"(}, "emissiveFactor": [1, 1, 1], "emissiveTexture": {"index": 2)")));
  const std::string cook = quote((bin_dir() / "ossa-cook").string());
  const auto cooked = run_command(cook + " -q " + quote(src.string()) + " -o " + quote((dir_ / "out").string()));
  ASSERT_EQ(cooked.exit_code, 0) << cooked.err;

  const auto material_of = [&](const char* name) {
    auto asset = Asset::open((dir_ / "out" / (std::string(name) + ".ossa")).string());
    EXPECT_TRUE(asset.ok()) << name << ": " << (asset.ok() ? "" : asset.error().message);
    return asset;
  };
  auto metal = material_of("metal");
  ASSERT_TRUE(metal.ok());
  const fb::Material& m = metal->material(0);
  ASSERT_NE(m.pbr(), nullptr);
  EXPECT_FLOAT_EQ(m.pbr()->metallic(), 0.25f);
  EXPECT_FLOAT_EQ(m.pbr()->roughness(), 0.75f);
  ASSERT_EQ(m.textures()->size(), 1u);
  EXPECT_EQ(m.textures()->Get(0)->role(), fb::TextureRole::MetallicRoughness);
  EXPECT_EQ(m.textures()->Get(0)->encoding(), fb::TextureEncoding::Bc5);
  auto occluded = material_of("occluded");
  ASSERT_TRUE(occluded.ok());
  ASSERT_EQ(occluded->material(0).textures()->size(), 1u);
  EXPECT_EQ(occluded->material(0).textures()->Get(0)->role(), fb::TextureRole::Occlusion);
  EXPECT_EQ(occluded->material(0).textures()->Get(0)->encoding(), fb::TextureEncoding::Bc4);
  auto glowing = material_of("glowing");
  ASSERT_TRUE(glowing.ok());
  ASSERT_NE(glowing->material(0).emissive(), nullptr);
  EXPECT_FLOAT_EQ(glowing->material(0).emissive()->x(), 1.0f);
  ASSERT_EQ(glowing->material(0).textures()->size(), 1u);
  EXPECT_EQ(glowing->material(0).textures()->Get(0)->role(), fb::TextureRole::Emissive);
  EXPECT_TRUE(glowing->material(0).textures()->Get(0)->srgb());

  const auto inspect = run_command(quote((bin_dir() / "ossa-inspect").string()) + " --json " +
                                   quote((dir_ / "out" / "metal.ossa").string()));
  ASSERT_EQ(inspect.exit_code, 0) << inspect.err;
  std::string compact;  // the JSON without its layout
  for (const char c : inspect.out)
    if (c != ' ' && c != '\n') compact += c;
  EXPECT_NE(compact.find(R"("pbr":{"metallic":0.25,"roughness":0.75})"), std::string::npos) << inspect.out;

  const auto shot = [&](const char* name, std::string* err = nullptr) {
    const fs::path png = dir_ / (std::string(name) + ".png");
    const std::string args = quote((dir_ / "out" / (std::string(name) + ".ossa")).string()) +
                             " --no-grid --size 128x128 --yaw 0 --pitch 0 --screenshot " + quote(png.string());
    const CommandResult r = run_viewer(args);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    if (err) *err = r.err;
    return load_png(png);
  };
  std::string plain_err, metal_err;
  const Image plain = shot("plain", &plain_err), dark = shot("occluded"), red = shot("glowing");
  shot("metal", &metal_err);
  ASSERT_FALSE(plain.empty());
  ASSERT_FALSE(dark.empty());
  ASSERT_FALSE(red.empty());
  std::printf("centre pixel: plain %d %d %d, occluded %d %d %d, emissive red %d %d %d\n", centre(plain)[0],
              centre(plain)[1], centre(plain)[2], centre(dark)[0], centre(dark)[1], centre(dark)[2], centre(red)[0],
              centre(red)[1], centre(red)[2]);
  for (int c = 0; c < 3; ++c) EXPECT_LT(centre(dark)[c] + 5, centre(plain)[c]) << "occlusion removes the ambient term";
  EXPECT_GT(centre(red)[0], centre(plain)[0] + 20) << "emission adds red";
  for (int c = 1; c < 3; ++c) EXPECT_NEAR(centre(red)[c], centre(plain)[c], 2) << "and nothing else";
  EXPECT_NE(metal_err.find("metallic-roughness of material"), std::string::npos) << metal_err;
  EXPECT_EQ(plain_err.find("metallic-roughness"), std::string::npos) << "a non-metal without a map: " << plain_err;
}

}  // namespace
}  // namespace ossa::test
