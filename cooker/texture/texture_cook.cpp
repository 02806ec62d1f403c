// texture_cook.cpp — see texture_cook.h.
#include "cooker/texture/texture_cook.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <tuple>

#include <ossa/format/hash.h>
#include <ossa/loader/texture.h>
#include "cooker/texture/texture_encode.h"
#include "cooker/texture/texture_mips.h"

namespace ossa::cook {
namespace {

const char* role_name(TextureRole role) {
  switch (role) {
    case TextureRole::Normal: return "normal";
    case TextureRole::Specular: return "specular";
    case TextureRole::Occlusion: return "occlusion";
    case TextureRole::MetallicRoughness: return "metallic-roughness";
    case TextureRole::Emissive: return "emissive";
    default: return "diffuse";
  }
}

const char* encoding_name(fb::TextureEncoding e) {
  switch (e) {
    case fb::TextureEncoding::Rgba8: return "RGBA8";
    case fb::TextureEncoding::Bc1: return "BC1";
    case fb::TextureEncoding::Bc3: return "BC3";
    case fb::TextureEncoding::Bc4: return "BC4";
    case fb::TextureEncoding::Bc5: return "BC5";
    default: return "source";
  }
}

/// PSNR over `channels` (a bit mask of RGBA) of two same-sized images; 99 when identical.
float psnr(const Image& a, const Image& b, unsigned channels) {
  double sum = 0.0;
  uint64_t n = 0;
  for (size_t i = 0; i < a.rgba.size(); i += 4)
    for (unsigned c = 0; c < 4; ++c)
      if (channels & (1u << c)) {
        const double d = static_cast<double>(a.rgba[i + c]) - b.rgba[i + c];
        sum += d * d;
        ++n;
      }
  if (n == 0 || sum == 0.0) return 99.0f;
  return static_cast<float>(std::min(99.0, 10.0 * std::log10(255.0 * 255.0 / (sum / static_cast<double>(n)))));
}

/// Mean and largest angle (degrees) between the source's normals and those rebuilt from what
/// the GPU returns for `encoded` (x, y, and z = sqrt(1 - x^2 - y^2), as the viewer's shader does).
void normal_error(const Image& source, const Image& encoded, float& mean_deg, float& max_deg) {
  double sum = 0.0, worst = 0.0;
  const size_t n = source.rgba.size() / 4;
  for (size_t i = 0; i < source.rgba.size(); i += 4) {
    double s[3], e[3];
    for (int c = 0; c < 3; ++c) s[c] = source.rgba[i + c] / 127.5 - 1.0;
    e[0] = encoded.rgba[i] / 127.5 - 1.0;
    e[1] = encoded.rgba[i + 1] / 127.5 - 1.0;
    e[2] = std::sqrt(std::max(0.0, 1.0 - e[0] * e[0] - e[1] * e[1]));
    const double ls = std::sqrt(s[0] * s[0] + s[1] * s[1] + s[2] * s[2]);
    const double le = std::sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2]);
    if (ls < 1e-6 || le < 1e-6) continue;
    const double cosine = std::clamp((s[0] * e[0] + s[1] * e[1] + s[2] * e[2]) / (ls * le), -1.0, 1.0);
    const double deg = std::acos(cosine) * 57.29577951308232;
    sum += deg;
    worst = std::max(worst, deg);
  }
  mean_deg = n > 0 ? static_cast<float>(sum / static_cast<double>(n)) : 0.0f;
  max_deg = static_cast<float>(worst);
}

/// The encoding, sRGB flag and filter for an image in `role`.
struct Choice {
  fb::TextureEncoding encoding;
  bool srgb;
  TexelKind kind;
  unsigned channels;  // stored channels, for PSNR
};

Choice choose(const Image& image, TextureRole role, TextureOutput output) {
  const bool raw = output == TextureOutput::Rgba8;
  switch (role) {
    case TextureRole::Normal:
      return {raw ? fb::TextureEncoding::Rgba8 : fb::TextureEncoding::Bc5, false, TexelKind::Normal, 0x3};
    case TextureRole::Occlusion:  // glTF's occlusion is the R channel
      return {raw ? fb::TextureEncoding::Rgba8 : fb::TextureEncoding::Bc4, false, TexelKind::Data, 0x1};
    case TextureRole::MetallicRoughness:  // after metallic_roughness_channels(): R roughness, G metallic
      return {raw ? fb::TextureEncoding::Rgba8 : fb::TextureEncoding::Bc5, false, TexelKind::Data, 0x3};
    case TextureRole::Specular:
      if (raw) return {fb::TextureEncoding::Rgba8, false, TexelKind::Data, 0xF};
      return greyscale(image) ? Choice{fb::TextureEncoding::Bc4, false, TexelKind::Data, 0x1}
                              : Choice{fb::TextureEncoding::Bc1, false, TexelKind::Data, 0x7};
    default:
      if (raw) return {fb::TextureEncoding::Rgba8, true, TexelKind::Colour, 0xF};
      return opaque(image) ? Choice{fb::TextureEncoding::Bc1, true, TexelKind::Colour, 0x7}
                           : Choice{fb::TextureEncoding::Bc3, true, TexelKind::Colour, 0xF};
  }
}

/// glTF's metallic-roughness texels (G roughness, B metallic) as the format stores them in every
/// encoding: R roughness, G metallic, B 0, A 255, so the two channels fit BC5.
void metallic_roughness_channels(Image& image) {
  for (size_t i = 0; i + 3 < image.rgba.size(); i += 4) {
    image.rgba[i] = image.rgba[i + 1];
    image.rgba[i + 1] = image.rgba[i + 2];
    image.rgba[i + 2] = 0;
    image.rgba[i + 3] = 255;
  }
}

Result<TextureRecord> cook_one(SourceTexture& t, TextureOutput output) {
  TextureRecord r;
  r.name = t.name.empty() ? t.path : t.name;
  r.role = role_name(t.role);
  r.source_bytes = t.data.size();
  auto decoded = decode_rgba(t.data);
  if (!decoded) return decoded.error();
  if (t.role == TextureRole::MetallicRoughness && output != TextureOutput::Source)
    metallic_roughness_channels(*decoded);
  const Image& level0 = *decoded;
  r.width = level0.width;
  r.height = level0.height;
  r.mips = texture_full_mip_count(level0.width, level0.height);
  r.gpu_rgba8_bytes = texture_chain_bytes(fb::TextureEncoding::Rgba8, r.width, r.height, r.mips);
  if (output == TextureOutput::Source) {
    r.encoding = "source";
    r.cooked_bytes = t.data.size();
    r.mips = 0;
    r.psnr_db = 99.0f;
    return r;
  }
  const Choice c = choose(level0, t.role, output);
  std::vector<uint8_t> chain;
  chain.reserve(static_cast<size_t>(texture_chain_bytes(c.encoding, r.width, r.height, r.mips)));
  encode_level(level0, c.encoding, chain);
  const Image back = decode_level(chain, c.encoding, r.width, r.height);
  if (t.role == TextureRole::Normal) {
    normal_error(level0, back, r.normal_mean_deg, r.normal_max_deg);
  }
  r.psnr_db = psnr(level0, back, c.channels);
  for (const Image& level : build_mips(level0, c.kind)) encode_level(level, c.encoding, chain);
  t.data = std::move(chain);
  t.mime.clear();
  t.encoding = static_cast<uint8_t>(c.encoding);
  t.srgb = c.srgb;
  t.width = r.width;
  t.height = r.height;
  t.mip_count = static_cast<uint8_t>(r.mips);
  r.encoding = encoding_name(c.encoding);
  r.srgb = c.srgb;
  r.cooked_bytes = t.data.size();
  return r;
}

}  // namespace

Status cook_textures(SourceScene& scene, TextureOutput output, const std::string& label,
                     std::vector<TextureRecord>& records) {
  // First every repeat is found while all bytes are still as read: (role, size, hash) -> the
  // first uses with that key, compared in full. Then only first uses are cooked.
  std::vector<SourceTexture*> all;
  for (SourceMaterial& m : scene.materials)
    for (SourceTexture& t : m.textures) all.push_back(&t);
  std::map<std::tuple<uint8_t, size_t, uint64_t>, std::vector<int32_t>> seen;
  for (size_t i = 0; i < all.size(); ++i) {
    SourceTexture& t = *all[i];
    t.same_as = -1;
    if (t.data.empty()) continue;  // known by path only
    auto& firsts = seen[{static_cast<uint8_t>(t.role), t.data.size(), hash_bytes(t.data.data(), t.data.size())}];
    for (const int32_t first : firsts)
      if (all[static_cast<size_t>(first)]->data == t.data) {
        t.same_as = first;
        break;
      }
    if (t.same_as < 0) firsts.push_back(static_cast<int32_t>(i));
  }
  for (SourceMaterial& m : scene.materials)
    for (SourceTexture& t : m.textures) {
      if (t.same_as >= 0) {
        t.data.clear();  // the writer stores the first use's table for it
        t.data.shrink_to_fit();
        continue;
      }
      if (t.data.empty()) continue;
      auto r = cook_one(t, output);
      if (!r) return Error{label + ": material '" + m.name + "': texture '" + t.name + "' " + r.error().message};
      records.push_back(std::move(*r));
    }
  return {};
}

}  // namespace ossa::cook
