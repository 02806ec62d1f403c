// gl_util.cpp — see gl_util.h.
#include "viewer/gl_util.h"

#include <cstdio>
#include <vector>

namespace ossa::view {
namespace {

const char* gl_error_name(GLenum e) {
  switch (e) {
    case GL_INVALID_ENUM: return "GL_INVALID_ENUM";
    case GL_INVALID_VALUE: return "GL_INVALID_VALUE";
    case GL_INVALID_OPERATION: return "GL_INVALID_OPERATION";
    case GL_INVALID_FRAMEBUFFER_OPERATION: return "GL_INVALID_FRAMEBUFFER_OPERATION";
    case GL_OUT_OF_MEMORY: return "GL_OUT_OF_MEMORY";
    default: return "unknown GL error";
  }
}

/// The source with `defines` after its first line (the #version directive, after any leading
/// comment lines).
std::string with_defines(const char* source, std::string_view defines) {
  std::string s(source);
  if (defines.empty()) return s;
  const size_t version = s.find("#version");
  if (version == std::string::npos) return s;
  const size_t eol = s.find('\n', version);
  const size_t at = eol == std::string::npos ? s.size() : eol + 1;
  s.insert(at, std::string(defines) + "\n");
  return s;
}

Result<GLuint> compile(std::string_view name, GLenum stage, const std::string& source) {
  const GLuint shader = glCreateShader(stage);
  const char* text = source.c_str();
  glShaderSource(shader, 1, &text, nullptr);
  glCompileShader(shader);
  GLint ok = GL_FALSE;
  glGetShaderiv(shader, GL_COMPILE_STATUS, &ok);
  if (ok == GL_TRUE) return shader;
  GLint length = 0;
  glGetShaderiv(shader, GL_INFO_LOG_LENGTH, &length);
  std::vector<char> log(static_cast<size_t>(length > 0 ? length : 1), '\0');
  glGetShaderInfoLog(shader, static_cast<GLsizei>(log.size()), nullptr, log.data());
  glDeleteShader(shader);
  return Error{std::string(name) + (stage == GL_VERTEX_SHADER ? " (vertex)" : " (fragment)") +
               ": shader does not compile: " + log.data()};
}

}  // namespace

Status check_gl(std::string_view where) {
  std::string errors;
  for (int i = 0; i < 16; ++i) {  // a lost context can report errors forever
    const GLenum e = glGetError();
    if (e == GL_NO_ERROR) break;
    char code[16];
    std::snprintf(code, sizeof code, "0x%x", e);
    if (!errors.empty()) errors += ", ";
    errors += std::string(gl_error_name(e)) + " (" + code + ")";
  }
  if (errors.empty()) return {};
  return Error{"GL error " + errors + " after " + std::string(where)};
}

Result<GLuint> build_program(std::string_view name, const char* vertex_source, const char* fragment_source,
                             std::string_view defines) {
  Result<GLuint> vs = compile(name, GL_VERTEX_SHADER, with_defines(vertex_source, defines));
  if (!vs) return vs.error();
  Result<GLuint> fs = compile(name, GL_FRAGMENT_SHADER, with_defines(fragment_source, defines));
  if (!fs) {
    glDeleteShader(*vs);
    return fs.error();
  }
  const GLuint program = glCreateProgram();
  glAttachShader(program, *vs);
  glAttachShader(program, *fs);
  glLinkProgram(program);
  glDeleteShader(*vs);
  glDeleteShader(*fs);
  GLint ok = GL_FALSE;
  glGetProgramiv(program, GL_LINK_STATUS, &ok);
  if (ok == GL_TRUE) return program;
  GLint length = 0;
  glGetProgramiv(program, GL_INFO_LOG_LENGTH, &length);
  std::vector<char> log(static_cast<size_t>(length > 0 ? length : 1), '\0');
  glGetProgramInfoLog(program, static_cast<GLsizei>(log.size()), nullptr, log.data());
  glDeleteProgram(program);
  return Error{std::string(name) + ": program does not link: " + log.data()};
}

void make_texture_buffer(GLenum format, const void* data, size_t bytes, GLenum usage, GLuint& buffer, GLuint& texture) {
  glGenBuffers(1, &buffer);
  glBindBuffer(GL_TEXTURE_BUFFER, buffer);
  glBufferData(GL_TEXTURE_BUFFER, static_cast<GLsizeiptr>(bytes), data, usage);
  glGenTextures(1, &texture);
  glBindTexture(GL_TEXTURE_BUFFER, texture);
  glTexBuffer(GL_TEXTURE_BUFFER, format, buffer);
  glBindTexture(GL_TEXTURE_BUFFER, 0);
  glBindBuffer(GL_TEXTURE_BUFFER, 0);
}

}  // namespace ossa::view
