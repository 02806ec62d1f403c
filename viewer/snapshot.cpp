// snapshot.cpp — see snapshot.h.
#include "viewer/snapshot.h"

#include <stb_image_write.h>

#include "viewer/gl.h"

namespace ossa::view {

std::vector<uint8_t> read_framebuffer_rgb(int width, int height) {
  std::vector<uint8_t> pixels(static_cast<size_t>(width) * static_cast<size_t>(height) * 3);
  glPixelStorei(GL_PACK_ALIGNMENT, 1);
  glReadPixels(0, 0, width, height, GL_RGB, GL_UNSIGNED_BYTE, pixels.data());
  return pixels;
}

Status write_png(const std::string& path, int width, int height, std::span<const uint8_t> rgb) {
  if (rgb.size() < static_cast<size_t>(width) * static_cast<size_t>(height) * 3)
    return Error{path + ": image data too short"};
  // Start at the last row and step backwards: the PNG's first row is GL's top row.
  const uint8_t* top = rgb.data() + static_cast<size_t>(height - 1) * static_cast<size_t>(width) * 3;
  if (stbi_write_png(path.c_str(), width, height, 3, top, -width * 3) == 0)
    return Error{path + ": cannot write the PNG"};
  return {};
}

}  // namespace ossa::view
