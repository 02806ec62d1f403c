// gl_util.h — GL errors as values, and shader programs from the embedded sources.
//
// ossa-view must fail loudly when GL does: the headless mode checks glGetError after setup and
// after every frame and exits non-zero naming what failed, so a broken driver, a shader that does
// not compile or a bad attribute setup never produces a silently wrong screenshot.
#pragma once
#include <cstddef>
#include <string>
#include <string_view>

#include <ossa/format/result.h>
#include "viewer/gl.h"

namespace ossa::view {

/// Drains glGetError. Error "GL error GL_INVALID_OPERATION (0x502) after <where>" listing every
/// pending error; success when there is none.
Status check_gl(std::string_view where);

/// Compiles and links a program. `defines` is inserted right after each source's #version line.
/// Errors carry the driver's log and the shader's name.
Result<GLuint> build_program(std::string_view name, const char* vertex_source, const char* fragment_source,
                             std::string_view defines = {});

/// A texture buffer of `format` over a new buffer of `bytes` bytes from `data` (null: uninitialized),
/// with `usage` (GL_STATIC_DRAW for data made once, GL_STREAM_DRAW for data replaced each frame).
/// Leaves GL_TEXTURE_BUFFER unbound on both targets.
void make_texture_buffer(GLenum format, const void* data, size_t bytes, GLenum usage, GLuint& buffer, GLuint& texture);

}  // namespace ossa::view
