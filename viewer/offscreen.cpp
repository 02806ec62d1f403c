// offscreen.cpp — see offscreen.h.
#include "viewer/offscreen.h"

#include <algorithm>
#include <string>

#include "viewer/snapshot.h"

namespace ossa::view {
namespace {

GLuint renderbuffer(int samples, GLenum format, int w, int h) {
  GLuint rb = 0;
  glGenRenderbuffers(1, &rb);
  glBindRenderbuffer(GL_RENDERBUFFER, rb);
  if (samples > 1) glRenderbufferStorageMultisample(GL_RENDERBUFFER, samples, format, w, h);
  else glRenderbufferStorage(GL_RENDERBUFFER, format, w, h);
  return rb;
}

Status complete(const char* what) {
  const GLenum s = glCheckFramebufferStatus(GL_FRAMEBUFFER);
  if (s == GL_FRAMEBUFFER_COMPLETE) return {};
  return Error{std::string(what) + " framebuffer is incomplete (status 0x" + std::to_string(s) + ")"};
}

}  // namespace

Result<Offscreen> create_offscreen(int width, int height, int samples) {
  Offscreen o;
  o.width = width;
  o.height = height;
  GLint max_samples = 1;
  glGetIntegerv(GL_MAX_SAMPLES, &max_samples);
  o.samples = std::clamp(samples, 1, std::max(1, static_cast<int>(max_samples)));
  GLint max_size = 0;
  glGetIntegerv(GL_MAX_RENDERBUFFER_SIZE, &max_size);
  if (width > max_size || height > max_size) {
    return Error{"image size " + std::to_string(width) + "x" + std::to_string(height) + " exceeds this GL's limit of " +
                 std::to_string(max_size)};
  }
  glGenFramebuffers(1, &o.draw_fbo);
  glBindFramebuffer(GL_FRAMEBUFFER, o.draw_fbo);
  o.color = renderbuffer(o.samples, GL_RGBA8, width, height);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, o.color);
  o.depth = renderbuffer(o.samples, GL_DEPTH_COMPONENT24, width, height);
  glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_DEPTH_ATTACHMENT, GL_RENDERBUFFER, o.depth);
  if (Status s = complete("offscreen"); !s) {
    destroy_offscreen(o);
    return s.error();
  }
  if (o.samples > 1) {
    glGenFramebuffers(1, &o.resolve_fbo);
    glBindFramebuffer(GL_FRAMEBUFFER, o.resolve_fbo);
    o.resolve_color = renderbuffer(1, GL_RGBA8, width, height);
    glFramebufferRenderbuffer(GL_FRAMEBUFFER, GL_COLOR_ATTACHMENT0, GL_RENDERBUFFER, o.resolve_color);
    if (Status s = complete("resolve"); !s) {
      destroy_offscreen(o);
      return s.error();
    }
  }
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  return o;
}

void destroy_offscreen(Offscreen& o) {
  const GLuint fbos[] = {o.draw_fbo, o.resolve_fbo};
  for (GLuint f : fbos) {
    if (f) glDeleteFramebuffers(1, &f);
  }
  const GLuint rbs[] = {o.color, o.depth, o.resolve_color};
  for (GLuint r : rbs) {
    if (r) glDeleteRenderbuffers(1, &r);
  }
  o = Offscreen{};
}

void bind_offscreen(const Offscreen& o) { glBindFramebuffer(GL_FRAMEBUFFER, o.draw_fbo); }

std::vector<uint8_t> read_rgb(const Offscreen& o) {
  GLuint source = o.draw_fbo;
  if (o.samples > 1) {
    glBindFramebuffer(GL_READ_FRAMEBUFFER, o.draw_fbo);
    glBindFramebuffer(GL_DRAW_FRAMEBUFFER, o.resolve_fbo);
    glBlitFramebuffer(0, 0, o.width, o.height, 0, 0, o.width, o.height, GL_COLOR_BUFFER_BIT, GL_NEAREST);
    source = o.resolve_fbo;
  }
  glBindFramebuffer(GL_READ_FRAMEBUFFER, source);
  std::vector<uint8_t> pixels = read_framebuffer_rgb(o.width, o.height);
  glBindFramebuffer(GL_FRAMEBUFFER, 0);
  return pixels;
}

}  // namespace ossa::view
