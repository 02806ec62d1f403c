// texture_encode.cpp — see texture_encode.h.
#include "cooker/texture/texture_encode.h"

#include <algorithm>
#include <cstring>

#include <stb_dxt.h>
#include <ossa/loader/texture.h>

namespace ossa::cook {
namespace {

/// Texel (x, y) clamped into the image, as RGBA.
const uint8_t* texel(const Image& image, uint32_t x, uint32_t y) {
  x = std::min(x, image.width - 1);
  y = std::min(y, image.height - 1);
  return &image.rgba[(static_cast<size_t>(y) * image.width + x) * 4];
}

void rgb565(uint16_t c, int out[3]) {
  const int r = (c >> 11) & 31, g = (c >> 5) & 63, b = c & 31;
  out[0] = (r << 3) | (r >> 2);
  out[1] = (g << 2) | (g >> 4);
  out[2] = (b << 3) | (b >> 2);
}

/// A BC1 colour block into 16 RGBA texels; `four_colour_only` for BC3's colour half.
void decode_colour(const uint8_t* b, bool four_colour_only, uint8_t out[16][4]) {
  const uint16_t c0 = static_cast<uint16_t>(b[0] | b[1] << 8), c1 = static_cast<uint16_t>(b[2] | b[3] << 8);
  int p[4][4];
  rgb565(c0, p[0]);
  rgb565(c1, p[1]);
  p[0][3] = p[1][3] = p[2][3] = p[3][3] = 255;
  const bool four = four_colour_only || c0 > c1;
  for (int c = 0; c < 3; ++c) {
    if (four) {
      p[2][c] = (2 * p[0][c] + p[1][c]) / 3;
      p[3][c] = (p[0][c] + 2 * p[1][c]) / 3;
    } else {
      p[2][c] = (p[0][c] + p[1][c]) / 2;
      p[3][c] = 0;
    }
  }
  if (!four) p[3][3] = 0;
  const uint32_t indices = static_cast<uint32_t>(b[4] | b[5] << 8 | b[6] << 16) | static_cast<uint32_t>(b[7]) << 24;
  for (int i = 0; i < 16; ++i)
    for (int c = 0; c < 4; ++c) out[i][c] = static_cast<uint8_t>(p[(indices >> (2 * i)) & 3][c]);
}

/// A BC4 block (also BC3's alpha and each half of BC5) into 16 values.
void decode_single(const uint8_t* b, uint8_t out[16]) {
  int v[8];
  v[0] = b[0];
  v[1] = b[1];
  if (v[0] > v[1]) {
    for (int i = 1; i < 7; ++i) v[i + 1] = ((7 - i) * v[0] + i * v[1]) / 7;
  } else {
    for (int i = 1; i < 5; ++i) v[i + 1] = ((5 - i) * v[0] + i * v[1]) / 5;
    v[6] = 0;
    v[7] = 255;
  }
  uint64_t indices = 0;
  for (int i = 0; i < 6; ++i) indices |= static_cast<uint64_t>(b[2 + i]) << (8 * i);
  for (int i = 0; i < 16; ++i) out[i] = static_cast<uint8_t>(v[(indices >> (3 * i)) & 7]);
}

}  // namespace

void encode_level(const Image& image, fb::TextureEncoding encoding, std::vector<uint8_t>& out) {
  if (encoding == fb::TextureEncoding::Rgba8) {
    out.insert(out.end(), image.rgba.begin(), image.rgba.end());
    return;
  }
  const size_t block_bytes = texture_block_bytes(encoding);
  for (uint32_t by = 0; by < (image.height + 3) / 4; ++by)
    for (uint32_t bx = 0; bx < (image.width + 3) / 4; ++bx) {
      uint8_t rgba[64], r[16], rg[32];
      for (uint32_t y = 0; y < 4; ++y)
        for (uint32_t x = 0; x < 4; ++x) {
          const uint8_t* t = texel(image, bx * 4 + x, by * 4 + y);
          const uint32_t i = y * 4 + x;
          std::memcpy(&rgba[i * 4], t, 4);
          if (encoding == fb::TextureEncoding::Bc1) rgba[i * 4 + 3] = 255;
          r[i] = t[0];
          rg[i * 2] = t[0];
          rg[i * 2 + 1] = t[1];
        }
      uint8_t block[16];
      switch (encoding) {
        case fb::TextureEncoding::Bc1: stb_compress_dxt_block(block, rgba, 0, STB_DXT_HIGHQUAL); break;
        case fb::TextureEncoding::Bc3: stb_compress_dxt_block(block, rgba, 1, STB_DXT_HIGHQUAL); break;
        case fb::TextureEncoding::Bc4: stb_compress_bc4_block(block, r); break;
        default: stb_compress_bc5_block(block, rg); break;
      }
      out.insert(out.end(), block, block + block_bytes);
    }
}

Image decode_level(std::span<const uint8_t> bytes, fb::TextureEncoding encoding, uint32_t width, uint32_t height) {
  Image img;
  img.width = width;
  img.height = height;
  img.rgba.assign(static_cast<size_t>(width) * height * 4, 0);
  if (encoding == fb::TextureEncoding::Rgba8) {
    std::copy_n(bytes.begin(), std::min(bytes.size(), img.rgba.size()), img.rgba.begin());
    return img;
  }
  const size_t block_bytes = texture_block_bytes(encoding);
  const uint32_t bw = (width + 3) / 4;
  for (uint32_t by = 0; by < (height + 3) / 4; ++by)
    for (uint32_t bx = 0; bx < bw; ++bx) {
      const uint8_t* b = bytes.data() + (static_cast<size_t>(by) * bw + bx) * block_bytes;
      uint8_t t[16][4];
      uint8_t a[16], g[16];
      switch (encoding) {
        case fb::TextureEncoding::Bc1: decode_colour(b, false, t); break;
        case fb::TextureEncoding::Bc3:
          decode_single(b, a);
          decode_colour(b + 8, true, t);
          for (int i = 0; i < 16; ++i) t[i][3] = a[i];
          break;
        case fb::TextureEncoding::Bc4:
          decode_single(b, a);
          for (int i = 0; i < 16; ++i) t[i][0] = a[i], t[i][1] = 0, t[i][2] = 0, t[i][3] = 255;
          break;
        default:
          decode_single(b, a);
          decode_single(b + 8, g);
          for (int i = 0; i < 16; ++i) t[i][0] = a[i], t[i][1] = g[i], t[i][2] = 0, t[i][3] = 255;
          break;
      }
      for (uint32_t y = 0; y < 4; ++y)
        for (uint32_t x = 0; x < 4; ++x) {
          const uint32_t px = bx * 4 + x, py = by * 4 + y;
          if (px < width && py < height)
            std::memcpy(&img.rgba[(static_cast<size_t>(py) * width + px) * 4], t[y * 4 + x], 4);
        }
    }
  return img;
}

}  // namespace ossa::cook
