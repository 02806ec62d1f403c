// snapshot.h — reading back what was drawn and writing it as a PNG (stb_image_write).
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <ossa/format/result.h>

namespace ossa::view {

/// glReadPixels of the bound read framebuffer: RGB8, bottom row first (GL's order).
std::vector<uint8_t> read_framebuffer_rgb(int width, int height);

/// Writes bottom-row-first RGB8 pixels as a PNG (top row first, as PNG stores it). Errors name
/// the path.
Status write_png(const std::string& path, int width, int height, std::span<const uint8_t> rgb);

}  // namespace ossa::view
