// texture.cpp — see ossa/loader/texture.h.
#include <ossa/loader/texture.h>

#include <algorithm>

namespace ossa {

uint32_t texture_block_bytes(fb::TextureEncoding encoding) {
  switch (encoding) {
    case fb::TextureEncoding::Bc1:
    case fb::TextureEncoding::Bc4: return 8;
    case fb::TextureEncoding::Bc3:
    case fb::TextureEncoding::Bc5: return 16;
    default: return 0;
  }
}

uint64_t texture_level_bytes(fb::TextureEncoding encoding, uint32_t width, uint32_t height) {
  if (encoding == fb::TextureEncoding::Rgba8) return uint64_t{width} * height * 4;
  const uint64_t block = texture_block_bytes(encoding);
  return ((uint64_t{width} + 3) / 4) * ((uint64_t{height} + 3) / 4) * block;
}

uint32_t texture_full_mip_count(uint32_t width, uint32_t height) {
  uint32_t side = std::max(width, height), levels = 1;
  while (side > 1) {
    side >>= 1;
    ++levels;
  }
  return levels;
}

uint64_t texture_chain_bytes(fb::TextureEncoding encoding, uint32_t width, uint32_t height, uint32_t mip_count) {
  uint64_t total = 0;
  for (uint32_t k = 0; k < mip_count && k < 32; ++k)
    total += texture_level_bytes(encoding, std::max(1u, width >> k), std::max(1u, height >> k));
  return total;
}

std::span<const uint8_t> TextureView::data() const {
  if (fb == nullptr || fb->data() == nullptr) return {};
  return {fb->data()->data(), fb->data()->size()};
}

TextureLevel TextureView::level(uint32_t level) const {
  if (fb == nullptr || level >= mip_count()) return {};
  const uint64_t offset = texture_chain_bytes(encoding(), width(), height(), level);
  const uint32_t w = std::max(1u, width() >> level), h = std::max(1u, height() >> level);
  const uint64_t size = texture_level_bytes(encoding(), w, h);
  const std::span<const uint8_t> all = data();
  if (offset + size > all.size()) return {};  // cannot happen in a verified file
  return {w, h, all.subspan(static_cast<size_t>(offset), static_cast<size_t>(size))};
}

}  // namespace ossa
