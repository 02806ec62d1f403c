// image_check.cpp — signature, header bounds and a full decode of a texture (see image_check.h).
#include "cooker/import/image_check.h"

#include <cstdio>
#include <cstring>
#include <limits>

// stb_image, private to this file (STB_IMAGE_STATIC): the viewer links its own copy, and a program
// that links both (ossa-bench-first-frame) must not see two definitions. Every format it reads.
#define STB_IMAGE_STATIC
#define STB_IMAGE_IMPLEMENTATION
#define STBI_NO_STDIO
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wunused-function"
#pragma GCC diagnostic ignored "-Wmissing-field-initializers"
#pragma GCC diagnostic ignored "-Wsign-compare"
#pragma GCC diagnostic ignored "-Wshadow"
#pragma GCC diagnostic ignored "-Wconversion"
#pragma GCC diagnostic ignored "-Wdouble-promotion"
#endif
#include <stb_image.h>
#define STB_IMAGE_WRITE_STATIC
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STBI_WRITE_NO_STDIO
#include <stb_image_write.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

namespace ossa::cook {

namespace {

/// The size limit every decode checks from the header first: a "claims W x H pixels" error
/// when a side is not 1..kMaxImageSide or the area is over kMaxImagePixels.
Status within_limits(int64_t w, int64_t h) {
  if (w > 0 && h > 0 && w <= kMaxImageSide && h <= kMaxImageSide && uint64_t(w) * uint64_t(h) <= kMaxImagePixels)
    return {};
  return Error{"claims " + std::to_string(w) + " x " + std::to_string(h) + " pixels, over the limit of " +
               std::to_string(kMaxImageSide) + " per side and " + std::to_string(kMaxImagePixels) + " pixels"};
}

}  // namespace

Result<ImageInfo> check_image(std::span<const uint8_t> bytes) {
  ImageInfo info;
  const auto at = [&](size_t i) { return i < bytes.size() ? bytes[i] : 0; };
  if (bytes.size() >= 8 && at(0) == 0x89 && at(1) == 'P' && at(2) == 'N' && at(3) == 'G' && at(4) == '\r' &&
      at(5) == '\n' && at(6) == 0x1A && at(7) == '\n') {
    info.mime = "image/png";
  } else if (bytes.size() >= 3 && at(0) == 0xFF && at(1) == 0xD8 && at(2) == 0xFF) {
    info.mime = "image/jpeg";
  } else {
    char start[64];
    std::snprintf(start, sizeof start, "%02x %02x %02x %02x", at(0), at(1), at(2), at(3));
    return Error{std::string("is not a PNG or JPEG image (its bytes start ") + start + ")"};
  }
  if (bytes.size() > static_cast<size_t>(std::numeric_limits<int>::max())) return Error{"is too large to decode"};
  const auto* data = reinterpret_cast<const stbi_uc*>(bytes.data());
  const int size = static_cast<int>(bytes.size());
  int w = 0, h = 0, channels = 0;
  // A PNG's size is in its first chunk: read it here, so a bomb is named as one even where
  // stb_image would only say "unknown image type".
  const auto be32 = [&](size_t i) {
    return uint32_t(at(i)) << 24 | uint32_t(at(i + 1)) << 16 | uint32_t(at(i + 2)) << 8 | at(i + 3);
  };
  if (info.mime == "image/png" && bytes.size() >= 24 && at(12) == 'I' && at(13) == 'H' && at(14) == 'D' &&
      at(15) == 'R') {
    if (Status s = within_limits(be32(16), be32(20)); !s) return s.error();
  }
  if (!stbi_info_from_memory(data, size, &w, &h, &channels))
    return Error{"is not a readable " + info.mime.substr(6) + " image: " + stbi_failure_reason()};
  if (Status s = within_limits(w, h); !s) return s.error();
  stbi_uc* pixels = stbi_load_from_memory(data, size, &w, &h, &channels, 0);
  if (pixels == nullptr) return Error{"does not decode as " + info.mime.substr(6) + ": " + stbi_failure_reason()};
  stbi_image_free(pixels);
  info.width = w;
  info.height = h;
  return info;
}

namespace {

void append_bytes(void* context, void* data, int size) {
  auto* out = static_cast<std::vector<uint8_t>*>(context);
  const auto* begin = static_cast<const uint8_t*>(data);
  out->insert(out->end(), begin, begin + size);
}

}  // namespace

const char* other_image_format(std::span<const uint8_t> bytes, bool named_tga) {
  const auto starts = [&](const char* sig, size_t n) {
    return bytes.size() >= n && std::memcmp(bytes.data(), sig, n) == 0;
  };
  if (starts("BM", 2)) return "BMP";
  if (starts("GIF87a", 6) || starts("GIF89a", 6)) return "GIF";
  if (starts("8BPS", 4)) return "PSD";
  if (starts("#?RADIANCE", 10) || starts("#?RGBE", 6)) return "HDR";
  if (starts("\x53\x80\xF6\x34", 4)) return "PIC";
  if (bytes.size() >= 2 && bytes[0] == 'P' && (bytes[1] == '5' || bytes[1] == '6')) return "PNM";
  if (named_tga) return "TGA";
  return nullptr;
}

Result<std::vector<uint8_t>> other_to_png(std::span<const uint8_t> bytes, bool named_tga) {
  const char* kind = other_image_format(bytes, named_tga);
  if (kind == nullptr) {
    char start[64];
    const auto at = [&](size_t i) { return i < bytes.size() ? bytes[i] : 0; };
    std::snprintf(start, sizeof start, "%02x %02x %02x %02x", at(0), at(1), at(2), at(3));
    return Error{std::string("is not an image format the cooker reads (its bytes start ") + start + ")"};
  }
  const std::string name = kind;
  if (bytes.size() > static_cast<size_t>(std::numeric_limits<int>::max())) return Error{"is too large to decode"};
  const auto* data = reinterpret_cast<const stbi_uc*>(bytes.data());
  const int size = static_cast<int>(bytes.size());
  int w = 0, h = 0, channels = 0;
  // stbi_info reads the header only: a text file named .tga fails it here.
  if (!stbi_info_from_memory(data, size, &w, &h, &channels))
    return Error{"is not a " + name + " image (its header is not a " + name + " header)"};
  if (Status s = within_limits(w, h); !s) return s.error();
  stbi_uc* pixels = stbi_load_from_memory(data, size, &w, &h, &channels, 0);
  if (pixels == nullptr) return Error{"does not decode as " + name + ": " + stbi_failure_reason()};
  std::vector<uint8_t> png;
  const int ok = stbi_write_png_to_func(append_bytes, &png, w, h, channels, pixels, w * channels);
  stbi_image_free(pixels);
  if (!ok || png.empty()) return Error{"could not be converted to PNG"};
  return png;
}

Result<DecodedImage> decode_rgba(std::span<const uint8_t> bytes) {
  if (bytes.size() > static_cast<size_t>(std::numeric_limits<int>::max())) return Error{"is too large to decode"};
  const auto* data = reinterpret_cast<const stbi_uc*>(bytes.data());
  const int size = static_cast<int>(bytes.size());
  int w = 0, h = 0, channels = 0;
  if (!stbi_info_from_memory(data, size, &w, &h, &channels))
    return Error{std::string("does not decode: ") + stbi_failure_reason()};
  if (Status s = within_limits(w, h); !s) return s.error();
  stbi_set_flip_vertically_on_load_thread(1);  // this thread's loads only: the format stores rows bottom-up
  stbi_uc* pixels = stbi_load_from_memory(data, size, &w, &h, &channels, 4);
  stbi_set_flip_vertically_on_load_thread(0);
  if (pixels == nullptr) return Error{std::string("does not decode: ") + stbi_failure_reason()};
  DecodedImage out;
  out.width = static_cast<uint32_t>(w);
  out.height = static_cast<uint32_t>(h);
  out.rgba.assign(pixels, pixels + static_cast<size_t>(w) * static_cast<size_t>(h) * 4);
  stbi_image_free(pixels);
  return out;
}

}  // namespace ossa::cook
