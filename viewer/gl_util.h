// gl_util.h — GL errors as values, and shader programs from the embedded sources.
//
// ossa-view must fail loudly when GL does: the headless mode checks glGetError after setup and
// after every frame and exits non-zero naming what failed, so a broken driver, a shader that does
// not compile or a bad attribute setup never produces a silently wrong screenshot.
#pragma once
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

}  // namespace ossa::view
