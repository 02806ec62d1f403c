// window.cpp — see window.h.
#include "viewer/window.h"

namespace ossa::view {
namespace {

std::string g_last_glfw_error;  // GLFW reports errors through a callback; keep the last one

void on_glfw_error(int code, const char* description) {
  g_last_glfw_error = std::string(description ? description : "") + " (GLFW error " + std::to_string(code) + ")";
}

Error glfw_failure(const std::string& what) {
  return Error{what + (g_last_glfw_error.empty() ? "" : ": " + g_last_glfw_error)};
}

}  // namespace

Window& Window::operator=(Window&& other) noexcept {
  if (this != &other) {
    if (handle_) {
      glfwDestroyWindow(handle_);
      glfwTerminate();
    }
    handle_ = other.handle_;
    other.handle_ = nullptr;
  }
  return *this;
}

Window::~Window() {
  if (handle_) {
    glfwDestroyWindow(handle_);
    glfwTerminate();
  }
}

Result<Window> create_window(const WindowOptions& options) {
  glfwSetErrorCallback(on_glfw_error);
  if (glfwInit() != GLFW_TRUE)
    return glfw_failure("cannot initialize GLFW (is there a display? set DISPLAY or run under xvfb-run)");
  glfwDefaultWindowHints();
  glfwWindowHint(GLFW_CONTEXT_VERSION_MAJOR, 3);
  glfwWindowHint(GLFW_CONTEXT_VERSION_MINOR, 3);
  glfwWindowHint(GLFW_OPENGL_PROFILE, GLFW_OPENGL_CORE_PROFILE);
  glfwWindowHint(GLFW_OPENGL_FORWARD_COMPAT, GLFW_TRUE);
  glfwWindowHint(GLFW_VISIBLE, options.visible ? GLFW_TRUE : GLFW_FALSE);
  glfwWindowHint(GLFW_SAMPLES, options.visible ? options.samples : 0);
  GLFWwindow* w = glfwCreateWindow(options.width, options.height, options.title.c_str(), nullptr, nullptr);
  if (w == nullptr) {
    Error e = glfw_failure("cannot create an OpenGL 3.3 core context");
    glfwTerminate();
    return e;
  }
  glfwMakeContextCurrent(w);
  return Window(w);
}

std::string gl_description() {
  const auto str = [](GLenum name) {
    const GLubyte* s = glGetString(name);
    return s ? std::string(reinterpret_cast<const char*>(s)) : std::string("?");
  };
  return "OpenGL " + str(GL_VERSION) + ", " + str(GL_RENDERER);
}

}  // namespace ossa::view
