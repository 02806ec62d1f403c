// offscreen.h — a framebuffer object to render into without a visible window.
//
// Headless rendering draws into an FBO of the requested size (multisampled when asked, resolved
// with glBlitFramebuffer), not into the hidden window's default framebuffer: its size is then
// independent of the X screen, and reading it back is well defined.
#pragma once
#include <cstdint>
#include <vector>

#include <ossa/format/result.h>
#include "viewer/gl.h"

namespace ossa::view {

struct Offscreen {
  int width = 0, height = 0, samples = 1;
  GLuint draw_fbo = 0, color = 0, depth = 0;  // where drawing goes (multisampled if samples > 1)
  GLuint resolve_fbo = 0, resolve_color = 0;  // single-sampled copy when samples > 1
};

/// samples is clamped to GL_MAX_SAMPLES. Errors when the framebuffer is incomplete.
Result<Offscreen> create_offscreen(int width, int height, int samples);
void destroy_offscreen(Offscreen& o);
/// Binds the framebuffer to draw into.
void bind_offscreen(const Offscreen& o);
/// Resolves and reads the image: RGB8, bottom row first (GL's order).
std::vector<uint8_t> read_rgb(const Offscreen& o);

}  // namespace ossa::view
