// texture_mips.cpp — see texture_mips.h.
#include "cooker/texture/texture_mips.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace ossa::cook {
namespace {

float srgb_to_linear(float c) { return c <= 0.04045f ? c / 12.92f : std::pow((c + 0.055f) / 1.055f, 2.4f); }
float linear_to_srgb(float c) { return c <= 0.0031308f ? c * 12.92f : 1.055f * std::pow(c, 1.0f / 2.4f) - 0.055f; }

const std::array<float, 256>& srgb_table() {
  static const std::array<float, 256> table = [] {
    std::array<float, 256> t{};
    for (int i = 0; i < 256; ++i) t[static_cast<size_t>(i)] = srgb_to_linear(static_cast<float>(i) / 255.0f);
    return t;
  }();
  return table;
}

uint8_t to_byte(float unit) { return static_cast<uint8_t>(std::lround(std::clamp(unit, 0.0f, 1.0f) * 255.0f)); }

/// One axis of the area filter: destination texel i covers source [i * s / d, (i + 1) * s / d).
struct Tap {
  uint32_t first = 0;
  std::vector<float> weights;  // over source first, first + 1, ...; they sum to 1
};

std::vector<Tap> taps(uint32_t source, uint32_t dest) {
  std::vector<Tap> out(dest);
  const double scale = static_cast<double>(source) / dest;
  for (uint32_t i = 0; i < dest; ++i) {
    const double lo = i * scale, hi = (i + 1) * scale;
    Tap& t = out[i];
    t.first = static_cast<uint32_t>(lo);
    for (uint32_t s = t.first; s < source && s < hi; ++s) {
      const double w = std::min<double>(hi, s + 1) - std::max<double>(lo, s);
      if (w > 1e-9) t.weights.push_back(static_cast<float>(w / scale));
    }
  }
  return out;
}

/// Texels as floats in the space they are averaged in: linear RGB times alpha and alpha (colour),
/// a vector (normal), or the bytes / 255 (data).
std::vector<float> to_filter_space(const Image& image, TexelKind kind) {
  const std::array<float, 256>& lin = srgb_table();
  std::vector<float> f(image.rgba.size());
  for (size_t i = 0; i < image.rgba.size(); i += 4) {
    const uint8_t* p = &image.rgba[i];
    if (kind == TexelKind::Colour) {
      const float a = p[3] / 255.0f;
      for (int c = 0; c < 3; ++c) f[i + c] = lin[p[c]] * a;
      f[i + 3] = a;
    } else if (kind == TexelKind::Normal) {
      for (int c = 0; c < 3; ++c) f[i + c] = p[c] / 127.5f - 1.0f;
      f[i + 3] = p[3] / 255.0f;
    } else {
      for (int c = 0; c < 4; ++c) f[i + c] = p[c] / 255.0f;
    }
  }
  return f;
}

Image from_filter_space(const std::vector<float>& f, uint32_t width, uint32_t height, TexelKind kind,
                        const std::vector<float>& plain_rgb) {
  Image out;
  out.width = width;
  out.height = height;
  out.rgba.resize(f.size());
  for (size_t i = 0; i < f.size(); i += 4) {
    uint8_t* p = &out.rgba[i];
    if (kind == TexelKind::Colour) {
      const float a = f[i + 3];
      for (int c = 0; c < 3; ++c) {
        // Fully transparent area: nothing to weight by, keep the plain (unweighted) average.
        const float linear = a > 1e-6f ? f[i + c] / a : plain_rgb[i + c];
        p[c] = to_byte(linear_to_srgb(linear));
      }
      p[3] = to_byte(a);
    } else if (kind == TexelKind::Normal) {
      float x = f[i], y = f[i + 1], z = f[i + 2];
      const float len = std::sqrt(x * x + y * y + z * z);
      if (len > 1e-6f) {
        x /= len, y /= len, z /= len;
      } else {
        x = 0.0f, y = 0.0f, z = 1.0f;  // opposite normals cancelled out: face the surface's own normal
      }
      p[0] = to_byte(x * 0.5f + 0.5f);
      p[1] = to_byte(y * 0.5f + 0.5f);
      p[2] = to_byte(z * 0.5f + 0.5f);
      p[3] = to_byte(f[i + 3]);
    } else {
      for (int c = 0; c < 4; ++c) p[c] = to_byte(f[i + c]);
    }
  }
  return out;
}

/// Separable area resample of 4-channel floats from sw x sh to dw x dh.
std::vector<float> resample(const std::vector<float>& src, uint32_t sw, uint32_t sh, uint32_t dw, uint32_t dh) {
  const std::vector<Tap> tx = taps(sw, dw), ty = taps(sh, dh);
  std::vector<float> rows(static_cast<size_t>(dw) * sh * 4, 0.0f);
  for (uint32_t y = 0; y < sh; ++y)
    for (uint32_t x = 0; x < dw; ++x) {
      float* d = &rows[(static_cast<size_t>(y) * dw + x) * 4];
      for (size_t k = 0; k < tx[x].weights.size(); ++k) {
        const float* s = &src[(static_cast<size_t>(y) * sw + tx[x].first + k) * 4];
        for (int c = 0; c < 4; ++c) d[c] += tx[x].weights[k] * s[c];
      }
    }
  std::vector<float> out(static_cast<size_t>(dw) * dh * 4, 0.0f);
  for (uint32_t y = 0; y < dh; ++y)
    for (size_t k = 0; k < ty[y].weights.size(); ++k) {
      const float w = ty[y].weights[k];
      const float* s = &rows[static_cast<size_t>(ty[y].first + k) * dw * 4];
      float* d = &out[static_cast<size_t>(y) * dw * 4];
      for (size_t i = 0; i < static_cast<size_t>(dw) * 4; ++i) d[i] += w * s[i];
    }
  return out;
}

}  // namespace

std::vector<Image> build_mips(const Image& level0, TexelKind kind) {
  std::vector<Image> out;
  uint32_t w = level0.width, h = level0.height;
  std::vector<float> f = to_filter_space(level0, kind);
  // Colour also carries its plain linear average, for areas whose alpha is 0 everywhere.
  std::vector<float> plain;
  if (kind == TexelKind::Colour) {
    const std::array<float, 256>& lin = srgb_table();
    plain.resize(level0.rgba.size());
    for (size_t i = 0; i < plain.size(); ++i) plain[i] = (i % 4 == 3) ? 1.0f : lin[level0.rgba[i]];
  }
  while (w > 1 || h > 1) {
    const uint32_t nw = std::max(1u, w / 2), nh = std::max(1u, h / 2);
    f = resample(f, w, h, nw, nh);
    if (!plain.empty()) plain = resample(plain, w, h, nw, nh);
    w = nw;
    h = nh;
    out.push_back(from_filter_space(f, w, h, kind, plain));
  }
  return out;
}

bool opaque(const Image& image) {
  for (size_t i = 3; i < image.rgba.size(); i += 4)
    if (image.rgba[i] != 255) return false;
  return true;
}

bool greyscale(const Image& image) {
  for (size_t i = 0; i < image.rgba.size(); i += 4)
    if (image.rgba[i] != image.rgba[i + 1] || image.rgba[i] != image.rgba[i + 2]) return false;
  return true;
}

}  // namespace ossa::cook
