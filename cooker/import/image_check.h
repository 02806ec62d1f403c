// image_check.h — a texture's bytes must be the image they claim to be, before they are embedded.
//
// A texture is identified by its bytes (the PNG or JPEG signature), never by a file name or an
// importer's format hint: a text file named `.png` must not ship as `image/png` to a game that will
// hand it to a decoder. It is then decoded in full (stb_image, the decoder the viewer uses), so
// a truncated or corrupt image fails the cook that names it rather than the game that loads it,
// and its dimensions are bounded first from the header alone, so a "decompression bomb" (a small
// PNG claiming 16384 x 16384) is refused before any pixel memory is allocated.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <ossa/format/result.h>

namespace ossa::cook {

/// Largest side, and largest pixel count, of a texture the cooker embeds.
inline constexpr int kMaxImageSide = 16384;
inline constexpr uint64_t kMaxImagePixels = uint64_t{64} << 20;  // 8192 x 8192

struct ImageInfo {
  std::string mime;  // "image/png" or "image/jpeg"
  int width = 0, height = 0;
};

/// The format of an image that is neither PNG nor JPEG but that the cooker reads (BMP, GIF, PSD,
/// HDR, PIC, PNM by their signatures; TGA, which has none, only where `named_tga`: the file name
/// says .tga), or null.
const char* other_image_format(std::span<const uint8_t> bytes, bool named_tga);

/// Such an image converted to the PNG the format embeds for `--texture-format source`, so a game's
/// loader still sees only PNG and JPEG (HDR is tone-mapped to 8 bits by stb_image; GIF keeps its
/// first frame; PSD its composite). Bounded like check_image before any pixel is allocated; the
/// header must pass stb_image's test for that format and the image must decode. Deterministic
/// (stb_image_write), so the cook stays byte-reproducible. O(pixels).
Result<std::vector<uint8_t>> other_to_png(std::span<const uint8_t> bytes, bool named_tga);

/// An image decoded to RGBA8, rows bottom to top (as the format stores texture levels).
struct DecodedImage {
  uint32_t width = 0, height = 0;
  std::vector<uint8_t> rgba;
};
/// Decodes any image check_image or other_to_png accepted. O(pixels).
Result<DecodedImage> decode_rgba(std::span<const uint8_t> bytes);

/// Checks `bytes` as above. The error says what is wrong ("not a PNG or JPEG image (starts with
/// ...)", "claims 20000 x 20000 pixels", "does not decode: <reason>"), without a file name: the
/// caller names the file and what referenced it. O(pixels) for the decode.
Result<ImageInfo> check_image(std::span<const uint8_t> bytes);

}  // namespace ossa::cook
