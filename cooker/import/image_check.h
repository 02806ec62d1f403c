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

/// A TGA texture (no signature of its own: allowed only where the file name says .tga, and then
/// its header must pass stb_image's TGA test and it must decode) converted to the PNG the format
/// embeds, so a game's loader still sees only PNG and JPEG. The pixels are kept exactly (PNG is
/// lossless; stb_image_write's encoder is deterministic, so the cook stays byte-reproducible).
/// Bounded like check_image before any pixel is allocated. O(pixels).
Result<std::vector<uint8_t>> tga_to_png(std::span<const uint8_t> bytes);

/// Checks `bytes` as above. The error says what is wrong ("not a PNG or JPEG image (starts with
/// ...)", "claims 20000 x 20000 pixels", "does not decode: <reason>"), without a file name: the
/// caller names the file and what referenced it. O(pixels) for the decode.
Result<ImageInfo> check_image(std::span<const uint8_t> bytes);

}  // namespace ossa::cook
