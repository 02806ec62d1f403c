// texture.h — a cooked texture as the GPU takes it: encoding, size, and each mip level's bytes.
//
// The cooker stores textures as complete mip chains in the encodings GPUs sample directly
// (block-compressed BC1 / BC3 / BC4 / BC5, or RGBA8), packed level 0 first with no padding
// (format/ossa.fbs, TextureEncoding). Nothing about a level is stored: its size and byte range
// follow from the encoding and level 0's size, so there is nothing for a file to get inconsistent
// beyond one total, which the loader checks (validate.h: a chain's bytes must equal
// texture_chain_bytes exactly). An engine walks the levels and hands each span to its upload call
// (glCompressedTexImage2D, a Vulkan buffer-to-image copy) with no decode and no mip generation.
// A texture cooked with `--texture-format source` (encoding Source) holds the PNG / JPEG bytes
// instead, and has no levels here: the engine decodes it as it would any image file.
//
// Everything here is arithmetic on a loader-verified file: O(1) per call except texture_level,
// O(level). No allocation.
#pragma once
#include <cstdint>
#include <span>

#include <ossa/format/ossa_generated.h>

namespace ossa {

/// The largest side the loader accepts for a cooked texture (the cooker's own limit too).
inline constexpr uint32_t kMaxTextureSide = 16384;

/// Bytes per 4 x 4 block of a block-compressed encoding; 0 for Source and Rgba8.
uint32_t texture_block_bytes(fb::TextureEncoding encoding);

/// Bytes of one level `width` x `height` in `encoding` (0 for Source). Block encodings round each
/// side up to a multiple of 4 texels.
uint64_t texture_level_bytes(fb::TextureEncoding encoding, uint32_t width, uint32_t height);

/// Levels of a full chain from `width` x `height` down to 1 x 1: 1 + floor(log2(max side)).
uint32_t texture_full_mip_count(uint32_t width, uint32_t height);

/// Bytes of the first `mip_count` levels of a chain whose level 0 is `width` x `height`.
uint64_t texture_chain_bytes(fb::TextureEncoding encoding, uint32_t width, uint32_t height, uint32_t mip_count);

/// One mip level: its size in texels and its bytes inside the file.
struct TextureLevel {
  uint32_t width = 0, height = 0;
  std::span<const uint8_t> bytes;
};

/// A loader-verified texture, read through its table.
struct TextureView {
  const fb::Texture* fb = nullptr;

  fb::TextureRole role() const { return fb->role(); }
  fb::TextureEncoding encoding() const { return fb->encoding(); }
  /// True for the encodings a GPU samples as they are (everything but Source).
  bool gpu_ready() const { return fb->encoding() != fb::TextureEncoding::Source; }
  /// Colour stored in sRGB: upload it through an sRGB format so sampling returns linear values.
  bool srgb() const { return fb->srgb(); }
  uint32_t width() const { return fb->width(); }
  uint32_t height() const { return fb->height(); }
  uint32_t mip_count() const { return gpu_ready() ? fb->mip_count() : 0; }
  /// Every byte the texture embeds (the whole chain, or the source image); empty when it is only
  /// referenced by path.
  std::span<const uint8_t> data() const;
  /// Level `level` < mip_count(); an empty level past the end. O(level).
  TextureLevel level(uint32_t level) const;
};

}  // namespace ossa
