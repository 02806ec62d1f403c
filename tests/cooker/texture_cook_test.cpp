// texture_cook_test.cpp — the texture stage (cooker/texture): mip filtering by role, the block
// encoders and decoders, the format picked per role, sharing, the other source formats, and a
// real cook of the samples' textures checked through the loader's TextureView.
//
// Images are generated (gradients, checkers, noise, normal fields) so each property is tested on
// a class of inputs, and the real samples (CesiumMan, the Fox; AnimeBoy from ../shared when it is
// there) are cooked by the real cooker.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <random>

#include <stb_image_write.h>

#include <ossa/loader/asset.h>
#include <ossa/loader/texture.h>
#include "cooker/cook.h"
#include "cooker/import/image_check.h"
#include "cooker/texture/texture_cook.h"
#include "cooker/texture/texture_encode.h"
#include "cooker/texture/texture_mips.h"
#include "test_files.h"

namespace {

using namespace ossa;
using namespace ossa::cook;

Image make_image(uint32_t w, uint32_t h, auto&& texel) {
  Image img;
  img.width = w;
  img.height = h;
  img.rgba.resize(static_cast<size_t>(w) * h * 4);
  for (uint32_t y = 0; y < h; ++y)
    for (uint32_t x = 0; x < w; ++x) {
      const std::array<uint8_t, 4> t = texel(x, y);
      std::memcpy(&img.rgba[(static_cast<size_t>(y) * w + x) * 4], t.data(), 4);
    }
  return img;
}

double srgb_to_linear(double c) { return c <= 0.04045 ? c / 12.92 : std::pow((c + 0.055) / 1.055, 2.4); }

std::vector<uint8_t> png_of(const Image& img) {
  std::vector<uint8_t> out;
  stbi_write_png_to_func(
      [](void* ctx, void* data, int size) {
        auto* o = static_cast<std::vector<uint8_t>*>(ctx);
        o->insert(o->end(), static_cast<uint8_t*>(data), static_cast<uint8_t*>(data) + size);
      },
      &out, static_cast<int>(img.width), static_cast<int>(img.height), 4, img.rgba.data(),
      static_cast<int>(img.width) * 4);
  return out;
}

double psnr(const Image& a, const Image& b, int channels) {
  double sum = 0.0;
  size_t n = 0;
  for (size_t i = 0; i < a.rgba.size(); i += 4)
    for (int c = 0; c < channels; ++c) {
      const double d = double(a.rgba[i + c]) - b.rgba[i + c];
      sum += d * d;
      ++n;
    }
  return sum == 0.0 ? 99.0 : 10.0 * std::log10(255.0 * 255.0 / (sum / double(n)));
}

// ---- mips -----------------------------------------------------------------------------------

TEST(TextureMips, EveryLevelDownToOneByOneAtOddSizes) {
  for (const auto& [w, h] : {std::pair{5u, 3u}, {1u, 7u}, {16u, 16u}, {13u, 1u}, {1024u, 256u}}) {
    const Image img = make_image(w, h, [](uint32_t x, uint32_t y) {
      return std::array<uint8_t, 4>{uint8_t(x), uint8_t(y), 0, 255};
    });
    const std::vector<Image> mips = build_mips(img, TexelKind::Data);
    ASSERT_EQ(mips.size() + 1, texture_full_mip_count(w, h)) << w << "x" << h;
    for (size_t k = 0; k < mips.size(); ++k) {
      EXPECT_EQ(mips[k].width, std::max(1u, w >> (k + 1)));
      EXPECT_EQ(mips[k].height, std::max(1u, h >> (k + 1)));
    }
  }
}

TEST(TextureMips, AreaFilterKeepsTheMeanAtEveryLevel) {
  std::mt19937 rng(7);
  for (const auto& [w, h] : {std::pair{7u, 5u}, {64u, 32u}, {9u, 9u}}) {
    const Image img = make_image(w, h, [&](uint32_t, uint32_t) {
      return std::array<uint8_t, 4>{uint8_t(rng()), uint8_t(rng()), uint8_t(rng()), uint8_t(rng())};
    });
    double mean0[4] = {};
    for (size_t i = 0; i < img.rgba.size(); ++i) mean0[i % 4] += img.rgba[i];
    for (double& m : mean0) m /= double(w) * h;
    for (const Image& level : build_mips(img, TexelKind::Data)) {
      double mean[4] = {};
      for (size_t i = 0; i < level.rgba.size(); ++i) mean[i % 4] += level.rgba[i];
      for (int c = 0; c < 4; ++c)
        EXPECT_NEAR(mean[c] / (double(level.width) * level.height), mean0[c], 0.75) << w << "x" << h;
    }
  }
}

TEST(TextureMips, ColourIsAveragedInLinearLight) {
  // A black / white checker's next level is the grey it looks like: linear 0.5 = sRGB 188, not 128.
  const Image checker = make_image(8, 8, [](uint32_t x, uint32_t y) {
    const uint8_t v = ((x + y) & 1) ? 255 : 0;
    return std::array<uint8_t, 4>{v, v, v, 255};
  });
  const std::vector<Image> colour = build_mips(checker, TexelKind::Colour);
  for (size_t i = 0; i < colour[0].rgba.size(); i += 4) {
    EXPECT_NEAR(colour[0].rgba[i], 188, 1);
    EXPECT_NEAR(srgb_to_linear(colour[0].rgba[i] / 255.0), 0.5, 0.01);
  }
  EXPECT_NEAR(build_mips(checker, TexelKind::Data)[0].rgba[0], 128, 1);  // data maps average as stored
}

TEST(TextureMips, TransparentTexelsDoNotBleedTheirColour) {
  // Opaque blue beside fully transparent black: the next level is blue, half covered.
  const Image img = make_image(2, 2, [](uint32_t x, uint32_t) {
    return x == 0 ? std::array<uint8_t, 4>{0, 0, 255, 255} : std::array<uint8_t, 4>{0, 0, 0, 0};
  });
  const Image level = build_mips(img, TexelKind::Colour)[0];
  EXPECT_EQ(level.rgba[2], 255);
  EXPECT_NEAR(level.rgba[3], 128, 1);
  // Fully transparent everywhere: the plain average stays (no division by zero).
  const Image clear = make_image(2, 2, [](uint32_t, uint32_t) { return std::array<uint8_t, 4>{255, 0, 0, 0}; });
  EXPECT_EQ(build_mips(clear, TexelKind::Colour)[0].rgba[0], 255);
}

TEST(TextureMips, NormalLevelsStayUnitLength) {
  std::mt19937 rng(3);
  std::normal_distribution<float> tilt(0.0f, 0.6f);
  const Image normals = make_image(32, 32, [&](uint32_t, uint32_t) {
    float x = tilt(rng), y = tilt(rng), z = 1.0f;
    const float l = std::sqrt(x * x + y * y + z * z);
    return std::array<uint8_t, 4>{uint8_t(std::lround((x / l * 0.5f + 0.5f) * 255)),
                                  uint8_t(std::lround((y / l * 0.5f + 0.5f) * 255)),
                                  uint8_t(std::lround((z / l * 0.5f + 0.5f) * 255)), 255};
  });
  for (const Image& level : build_mips(normals, TexelKind::Normal))
    for (size_t i = 0; i < level.rgba.size(); i += 4) {
      double len = 0.0;
      for (int c = 0; c < 3; ++c) len += std::pow(level.rgba[i + c] / 127.5 - 1.0, 2.0);
      EXPECT_NEAR(std::sqrt(len), 1.0, 0.015);
    }
}

// ---- block encode / decode -------------------------------------------------------------------

TEST(TextureBlocks, DecodersFollowTheSpecification) {
  // BC1 with c0 <= c1: the 3-colour mode, index 3 is transparent black.
  const uint8_t bc1[8] = {0x00, 0x00, 0xFF, 0xFF,
                          0xE4, 0xE4, 0xE4, 0xE4};  // c0 black, c1 white; indices 0,1,2,3 per row
  const Image a = decode_level(bc1, fb::TextureEncoding::Bc1, 4, 4);
  EXPECT_EQ(a.rgba[0], 0);       // index 0: c0
  EXPECT_EQ(a.rgba[4], 255);     // index 1: c1
  EXPECT_EQ(a.rgba[8], 127);     // index 2: (c0 + c1) / 2
  EXPECT_EQ(a.rgba[12 + 3], 0);  // index 3: transparent
  // BC4 with v0 <= v1: six interpolated values, then 0 and 255.
  uint8_t bc4[8] = {10, 70, 0, 0, 0, 0, 0, 0};
  bc4[2] = 0x88;  // 3 bits per texel, little-endian: texel 0 -> 0b000, texel 1 -> 0b001, texel 2 -> 0b010
  bc4[7] = 0xF8;  // index bits 40..47: texel 14 -> 0b110, texel 15 -> 0b111
  const Image b = decode_level(bc4, fb::TextureEncoding::Bc4, 4, 4);
  EXPECT_EQ(b.rgba[0], 10);                 // index 0: v0
  EXPECT_EQ(b.rgba[4], 70);                 // index 1: v1
  EXPECT_EQ(b.rgba[8], (4 * 10 + 70) / 5);  // index 2: the first of four interpolated values
  EXPECT_EQ(b.rgba[14 * 4], 0);             // index 6: 0
  EXPECT_EQ(b.rgba[15 * 4], 255);           // index 7: 255
}

TEST(TextureBlocks, RoundTripQualityPerFormat) {
  std::mt19937 rng(11);
  // A smooth colour field with mild noise: what photos and painted textures look like to BC1.
  const Image colour = make_image(64, 64, [&](uint32_t x, uint32_t y) {
    const int n = int(rng() % 9) - 4;
    return std::array<uint8_t, 4>{uint8_t(std::clamp(int(x * 4) + n, 0, 255)),
                                  uint8_t(std::clamp(int(y * 4) + n, 0, 255)), uint8_t(std::clamp(128 + n, 0, 255)),
                                  uint8_t(std::clamp(int((x + y) * 2), 0, 255))};
  });
  for (const auto& [e, channels, floor] : {std::tuple{fb::TextureEncoding::Bc1, 3, 34.0},
                                           {fb::TextureEncoding::Bc3, 4, 34.0},
                                           {fb::TextureEncoding::Bc4, 1, 40.0},
                                           {fb::TextureEncoding::Bc5, 2, 40.0},
                                           {fb::TextureEncoding::Rgba8, 4, 99.0}}) {
    std::vector<uint8_t> bytes;
    encode_level(colour, e, bytes);
    ASSERT_EQ(bytes.size(), texture_level_bytes(e, 64, 64));
    EXPECT_GE(psnr(colour, decode_level(bytes, e, 64, 64), channels), floor) << fb::EnumNameTextureEncoding(e);
  }
  // A level smaller than a block (and not a multiple of 4) is padded, and decodes to itself
  // (a black and white checker: both are exact 565 endpoints).
  const Image tiny = make_image(3, 2, [](uint32_t x, uint32_t y) {
    const uint8_t v = ((x + y) & 1) ? 255 : 0;
    return std::array<uint8_t, 4>{v, v, v, 255};
  });
  std::vector<uint8_t> bytes;
  encode_level(tiny, fb::TextureEncoding::Bc1, bytes);
  EXPECT_EQ(bytes.size(), 8u);
  EXPECT_EQ(psnr(tiny, decode_level(bytes, fb::TextureEncoding::Bc1, 3, 2), 3), 99.0);
}

// ---- the stage -------------------------------------------------------------------------------

SourceTexture texture_of(const Image& img, TextureRole role, const std::string& name) {
  SourceTexture t;
  t.role = role;
  t.name = name;
  t.mime = "image/png";
  t.data = png_of(img);
  return t;
}

TEST(TextureCook, FormatPerRoleAndContent) {
  const Image opaque = make_image(16, 8, [](uint32_t x, uint32_t y) {
    return std::array<uint8_t, 4>{uint8_t(x * 16), uint8_t(y * 30), 50, 255};
  });
  const Image cutout = make_image(16, 8, [](uint32_t x, uint32_t) {
    return std::array<uint8_t, 4>{200, 100, 50, uint8_t(x < 8 ? 255 : 0)};
  });
  const Image grey = make_image(16, 8, [](uint32_t x, uint32_t) {
    return std::array<uint8_t, 4>{uint8_t(x * 16), uint8_t(x * 16), uint8_t(x * 16), 255};
  });
  const Image flat_normal = make_image(16, 8, [](uint32_t, uint32_t) {
    return std::array<uint8_t, 4>{128, 128, 255, 255};
  });
  SourceScene scene;
  scene.materials.resize(1);
  scene.materials[0].textures = {
      texture_of(opaque, TextureRole::Diffuse, "a"), texture_of(cutout, TextureRole::Diffuse, "b"),
      texture_of(grey, TextureRole::Specular, "c"), texture_of(opaque, TextureRole::Specular, "d"),
      texture_of(flat_normal, TextureRole::Normal, "e")};
  std::vector<TextureRecord> records;
  ASSERT_TRUE(cook_textures(scene, TextureOutput::Compressed, "test", records).ok());
  ASSERT_EQ(records.size(), 5u);
  const struct {
    fb::TextureEncoding e;
    bool srgb;
  } expected[] = {{fb::TextureEncoding::Bc1, true},
                  {fb::TextureEncoding::Bc3, true},
                  {fb::TextureEncoding::Bc4, false},
                  {fb::TextureEncoding::Bc1, false},
                  {fb::TextureEncoding::Bc5, false}};
  for (size_t i = 0; i < 5; ++i) {
    const SourceTexture& t = scene.materials[0].textures[i];
    EXPECT_EQ(static_cast<fb::TextureEncoding>(t.encoding), expected[i].e) << i;
    EXPECT_EQ(t.srgb, expected[i].srgb) << i;
    EXPECT_EQ(t.width, 16u);
    EXPECT_EQ(t.height, 8u);
    EXPECT_EQ(t.mip_count, 5u);
    EXPECT_EQ(t.data.size(), texture_chain_bytes(expected[i].e, 16, 8, 5)) << i;
    EXPECT_TRUE(t.mime.empty());
    EXPECT_EQ(records[i].cooked_bytes, t.data.size());
    EXPECT_EQ(records[i].gpu_rgba8_bytes, texture_chain_bytes(fb::TextureEncoding::Rgba8, 16, 8, 5));
    EXPECT_GT(records[i].psnr_db, 25.0f) << i;  // 2-D colour ramps inside each block: BC1's hardest case
  }
  EXPECT_LT(records[4].normal_max_deg, 1.0f);  // a flat normal map survives BC5 exactly (to quantisation)

  // rgba8: uncompressed chains, colour still sRGB; source: the bytes as read.
  SourceScene raw;
  raw.materials.resize(1);
  raw.materials[0].textures = {texture_of(opaque, TextureRole::Diffuse, "a")};
  records.clear();
  ASSERT_TRUE(cook_textures(raw, TextureOutput::Rgba8, "test", records).ok());
  EXPECT_EQ(static_cast<fb::TextureEncoding>(raw.materials[0].textures[0].encoding), fb::TextureEncoding::Rgba8);
  EXPECT_TRUE(raw.materials[0].textures[0].srgb);
  EXPECT_EQ(std::vector<uint8_t>(raw.materials[0].textures[0].data.begin(),
                                 raw.materials[0].textures[0].data.begin() + 16 * 8 * 4),
            decode_rgba(png_of(opaque))->rgba);  // level 0 is the source's texels, bottom row first
  SourceScene source;
  source.materials.resize(1);
  source.materials[0].textures = {texture_of(opaque, TextureRole::Diffuse, "a")};
  const std::vector<uint8_t> png = source.materials[0].textures[0].data;
  records.clear();
  ASSERT_TRUE(cook_textures(source, TextureOutput::Source, "test", records).ok());
  EXPECT_EQ(source.materials[0].textures[0].data, png);
  EXPECT_EQ(source.materials[0].textures[0].encoding, 0);
  EXPECT_EQ(records[0].encoding, "source");
}

// A PBR source's maps (format v11) by role: occlusion keeps R in BC4; metallic-roughness moves
// glTF's G (roughness) and B (metallic) into BC5's R and G; emissive is colour (BC1 sRGB, BC3 with
// alpha). Gradients per channel, so a channel taken from the wrong source channel cannot match.
TEST(TextureCook, PbrMapsCookByRoleWithTheirChannels) {
  const Image orm = make_image(16, 16, [](uint32_t x, uint32_t y) {
    return std::array<uint8_t, 4>{uint8_t(x * 16), uint8_t(y * 16), uint8_t(255 - x * 16), 255};
  });
  const Image glow = make_image(16, 8, [](uint32_t x, uint32_t) {
    return std::array<uint8_t, 4>{uint8_t(x * 16), 40, 0, 255};
  });
  SourceScene scene;
  scene.materials.resize(1);
  scene.materials[0].textures = {texture_of(orm, TextureRole::Occlusion, "orm"),
                                 texture_of(orm, TextureRole::MetallicRoughness, "orm"),
                                 texture_of(glow, TextureRole::Emissive, "glow")};
  std::vector<TextureRecord> records;
  ASSERT_TRUE(cook_textures(scene, TextureOutput::Compressed, "test", records).ok());
  ASSERT_EQ(records.size(), 3u) << "one image in two roles is cooked once per role";
  const SourceTexture &occlusion = scene.materials[0].textures[0], &mr = scene.materials[0].textures[1],
                      &emissive = scene.materials[0].textures[2];
  EXPECT_EQ(static_cast<fb::TextureEncoding>(occlusion.encoding), fb::TextureEncoding::Bc4);
  EXPECT_FALSE(occlusion.srgb);
  EXPECT_EQ(static_cast<fb::TextureEncoding>(mr.encoding), fb::TextureEncoding::Bc5);
  EXPECT_FALSE(mr.srgb);
  EXPECT_EQ(static_cast<fb::TextureEncoding>(emissive.encoding), fb::TextureEncoding::Bc1);
  EXPECT_TRUE(emissive.srgb);
  EXPECT_EQ(records[0].role, "occlusion");
  EXPECT_EQ(records[1].role, "metallic-roughness");
  EXPECT_EQ(records[2].role, "emissive");
  const Image occlusion0 = decode_level(occlusion.data, fb::TextureEncoding::Bc4, 16, 16);
  const Image mr0 = decode_level(mr.data, fb::TextureEncoding::Bc5, 16, 16);
  const Image source = *decode_rgba(png_of(orm));  // rows bottom to top, as the cooked levels
  int worst_occlusion = 0, worst_roughness = 0, worst_metallic = 0;
  for (size_t i = 0; i < source.rgba.size(); i += 4) {
    worst_occlusion = std::max(worst_occlusion, std::abs(occlusion0.rgba[i] - source.rgba[i]));
    worst_roughness = std::max(worst_roughness, std::abs(mr0.rgba[i] - source.rgba[i + 1]));
    worst_metallic = std::max(worst_metallic, std::abs(mr0.rgba[i + 1] - source.rgba[i + 2]));
  }
  EXPECT_LE(worst_occlusion, 4) << "occlusion is the source's R";
  EXPECT_LE(worst_roughness, 4) << "the cooked R is the source's G (roughness)";
  EXPECT_LE(worst_metallic, 4) << "the cooked G is the source's B (metallic)";
  EXPECT_GT(records[1].psnr_db, 40.0f);
}

TEST(TextureCook, OneCookedTexturePerImageAndRole) {
  const Image img = make_image(8, 8, [](uint32_t x, uint32_t y) {
    return std::array<uint8_t, 4>{uint8_t(x * 30), uint8_t(y * 30), 9, 255};
  });
  SourceScene scene;
  scene.materials.resize(3);
  scene.materials[0].textures = {texture_of(img, TextureRole::Diffuse, "skin.png")};
  scene.materials[1].textures = {texture_of(img, TextureRole::Diffuse, "skin.png"),
                                 texture_of(img, TextureRole::Specular, "skin.png")};
  scene.materials[2].textures = {texture_of(img, TextureRole::Diffuse, "copy.png")};
  std::vector<TextureRecord> records;
  ASSERT_TRUE(cook_textures(scene, TextureOutput::Compressed, "test", records).ok());
  EXPECT_EQ(records.size(), 2u);  // the diffuse image once, the same image as a specular map once
  EXPECT_EQ(scene.materials[0].textures[0].same_as, -1);
  EXPECT_EQ(scene.materials[1].textures[0].same_as, 0);
  EXPECT_TRUE(scene.materials[1].textures[0].data.empty());
  EXPECT_EQ(scene.materials[1].textures[1].same_as, -1);
  EXPECT_EQ(scene.materials[2].textures[0].same_as, 0);  // same bytes under another name
}

TEST(TextureCook, OtherImageFormatsBecomePng) {
  const Image img = make_image(6, 5, [](uint32_t x, uint32_t y) {
    return std::array<uint8_t, 4>{uint8_t(x * 40), uint8_t(y * 50), 77, 255};
  });
  std::vector<uint8_t> bmp, tga;
  const auto append = [](void* ctx, void* data, int size) {
    auto* o = static_cast<std::vector<uint8_t>*>(ctx);
    o->insert(o->end(), static_cast<uint8_t*>(data), static_cast<uint8_t*>(data) + size);
  };
  stbi_write_bmp_to_func(append, &bmp, 6, 5, 4, img.rgba.data());
  stbi_write_tga_to_func(append, &tga, 6, 5, 4, img.rgba.data());
  std::string pnm = "P6\n6 5\n255\n";
  for (size_t i = 0; i < img.rgba.size(); i += 4) pnm.append(reinterpret_cast<const char*>(&img.rgba[i]), 3);
  const std::vector<uint8_t> ppm(pnm.begin(), pnm.end());
  for (const auto& [bytes, kind, named_tga] :
       {std::tuple{bmp, "BMP", false}, {tga, "TGA", true}, {ppm, "PNM", false}}) {
    ASSERT_STREQ(other_image_format(bytes, named_tga), kind);
    const auto png = other_to_png(bytes, named_tga);
    ASSERT_TRUE(png.ok()) << kind << ": " << png.error().message;
    ASSERT_TRUE(check_image(*png).ok()) << kind;
    const auto a = decode_rgba(*png), b = decode_rgba(png_of(img));
    ASSERT_TRUE(a.ok() && b.ok());
    EXPECT_EQ(a->rgba, b->rgba) << kind << ": the same pixels";
  }
  // A TGA has no signature: without the name it is not taken, and text named .tga is refused.
  EXPECT_EQ(other_image_format(tga, false), nullptr);
  const std::string text = "hello, this is not an image at all";
  const std::vector<uint8_t> text_bytes(text.begin(), text.end());
  EXPECT_FALSE(other_to_png(text_bytes, true).ok());
  EXPECT_FALSE(other_to_png(text_bytes, false).ok());
  // A BMP header claiming a huge image is refused before any pixel is allocated.
  std::vector<uint8_t> bomb = bmp;
  const int32_t huge = 100000;
  std::memcpy(&bomb[18], &huge, 4);
  std::memcpy(&bomb[22], &huge, 4);
  const auto refused = other_to_png(bomb, false);
  ASSERT_FALSE(refused.ok());
}

// ---- real assets through the cooker and the loader ---------------------------------------------

TEST(TextureCook, SamplesCookToGpuReadyChains) {
  const std::filesystem::path out = test::make_temp_dir("texture-cook");
  std::vector<std::filesystem::path> sources = {test::source_dir() / "assets/CesiumMan/CesiumMan.glb",
                                                test::source_dir() / "assets/Fox/Fox.glb"};
  if (std::filesystem::exists(test::shared_assets() / "AnimeBoy/scene.gltf"))
    sources.push_back(test::shared_assets() / "AnimeBoy/scene.gltf");
  for (const auto& source : sources) {
    const std::filesystem::path cooked = out / (source.stem().string() + ".ossa");
    CookOptions options;
    const CookRecord r = cook_file(source, cooked, options);
    ASSERT_TRUE(r.ok) << r.error;
    ASSERT_FALSE(r.texture_records.empty()) << source;
    auto asset = Asset::open(cooked.string());
    ASSERT_TRUE(asset.ok()) << asset.error().message;
    size_t checked = 0;
    for (size_t m = 0; m < asset->material_count(); ++m) {
      const auto* textures = asset->material(m).textures();
      if (textures == nullptr) continue;
      for (const fb::Texture* t : *textures) {
        const TextureView view{t};
        ASSERT_TRUE(view.gpu_ready()) << source;
        EXPECT_EQ(view.mip_count(), texture_full_mip_count(view.width(), view.height()));
        const TextureLevel last = view.level(view.mip_count() - 1);
        EXPECT_EQ(last.width, 1u);
        EXPECT_EQ(last.height, 1u);
        if (t->role() == fb::TextureRole::Diffuse) {
          EXPECT_TRUE(view.srgb());
        }
        ++checked;
      }
    }
    EXPECT_GT(checked, 0u);
    // Every record: 1/4 of the GPU memory a decoded RGBA8 chain takes at most (BC3; BC1 is 1/8),
    // plus the whole blocks the 2 x 2 and 1 x 1 levels round up to, and close to the source.
    for (const TextureRecord& t : r.texture_records) {
      EXPECT_LE(static_cast<double>(t.cooked_bytes) / static_cast<double>(t.gpu_rgba8_bytes), 0.2501) << t.name;
      EXPECT_GT(t.psnr_db, 35.0f) << t.name;
    }
  }
}

TEST(TextureCook, CesiumManLevelZeroMatchesTheSourceImage) {
  // The cooked level 0, decoded as a GPU would, against the source's PNG decoded by stb_image.
  const std::filesystem::path out = test::make_temp_dir("texture-cesium");
  CookOptions options;
  const CookRecord r = cook_file(test::source_dir() / "assets/CesiumMan/CesiumMan.glb", out / "c.ossa", options);
  ASSERT_TRUE(r.ok) << r.error;
  ASSERT_EQ(r.texture_records.size(), 1u);
  EXPECT_EQ(r.texture_records[0].encoding, "BC1");
  EXPECT_EQ(r.texture_records[0].width, 1024u);
  auto asset = Asset::open((out / "c.ossa").string());
  ASSERT_TRUE(asset.ok());
  const TextureView view{asset->material(0).textures()->Get(0)};
  const TextureLevel level0 = view.level(0);
  const Image gpu = decode_level(level0.bytes, view.encoding(), level0.width, level0.height);
  options.textures = TextureOutput::Source;
  const CookRecord s = cook_file(test::source_dir() / "assets/CesiumMan/CesiumMan.glb", out / "s.ossa", options);
  ASSERT_TRUE(s.ok) << s.error;
  auto source_asset = Asset::open((out / "s.ossa").string());
  ASSERT_TRUE(source_asset.ok());
  const fb::Texture* png = source_asset->material(0).textures()->Get(0);
  EXPECT_FALSE(TextureView{png}.gpu_ready());
  const auto decoded = decode_rgba({png->data()->data(), png->data()->size()});
  ASSERT_TRUE(decoded.ok());
  EXPECT_GT(psnr(*decoded, gpu, 3), 38.0);
  EXPECT_NEAR(psnr(*decoded, gpu, 3), r.texture_records[0].psnr_db, 0.05);  // the report says what was measured
}

}  // namespace
