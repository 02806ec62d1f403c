// window.h — a GLFW window with an OpenGL 3.3 core context, visible or hidden.
//
// The headless mode uses a hidden window only to own a context (it renders into its own
// framebuffer object, so the image size is not limited by the X screen); the interactive mode a
// visible one with multisampling. GLFW's own errors are captured and returned as the message of
// the failure, so "no display", "no GL 3.3" and the like reach the user in words.
#pragma once
#include <string>

#include <ossa/format/result.h>
#include "viewer/gl.h"

namespace ossa::view {

struct WindowOptions {
  int width = 1280;
  int height = 720;
  bool visible = true;
  int samples = 4;  // default framebuffer multisampling (visible windows)
  std::string title = "ossa-view";
};

/// Owns a GLFW window (and GLFW itself: one window per process). Move-only.
class Window {
 public:
  Window() = default;
  explicit Window(GLFWwindow* handle) : handle_(handle) {}
  Window(Window&& other) noexcept : handle_(other.handle_) { other.handle_ = nullptr; }
  Window& operator=(Window&& other) noexcept;
  Window(const Window&) = delete;
  Window& operator=(const Window&) = delete;
  ~Window();
  GLFWwindow* get() const { return handle_; }

 private:
  GLFWwindow* handle_ = nullptr;
};

/// glfwInit + a 3.3 core, forward-compatible context made current. Errors say what GLFW said
/// ("X11: The DISPLAY environment variable is missing", "GLX: Failed to create context: ...").
Result<Window> create_window(const WindowOptions& options);

/// "OpenGL 4.5 (Core Profile) Mesa 22.3.6, llvmpipe (LLVM 15.0.6, 256 bits)" for the current
/// context.
std::string gl_description();

}  // namespace ossa::view
