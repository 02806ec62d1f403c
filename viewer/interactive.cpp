// interactive.cpp — see interactive.h.
//
// GLFW callbacks only record input (into InputState through the window user pointer); files
// dropped on the window are queued and opened between frames, never inside a callback. Our
// callbacks are installed before ImGui's GLFW backend, which chains to them, and they ignore the
// mouse and keyboard while ImGui wants them (a click on the panel is not an orbit). A left press
// on a procedural target marker (within kPickPixels), or anywhere with Ctrl held (the nearest
// marker), drags that target in the camera's view plane instead of orbiting
// (procedural_info.h drag_in_view_plane), setting the parameter on every instance.
#include "viewer/interactive.h"

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include <imgui.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>

#include "runtime/tools/cli/cli.h"
#include "viewer/app.h"
#include "viewer/gl_util.h"
#include "viewer/graph_keys.h"
#include "viewer/procedural_draw.h"
#include "viewer/setup.h"
#include "viewer/snapshot.h"
#include "viewer/ui.h"
#include "viewer/window.h"

namespace ossa::view {
namespace {

struct InputState {
  App* app = nullptr;
  GraphKeys graph_keys;
  float aspect = 1.0f;
  bool orbiting = false, panning = false;
  std::vector<glm::vec3> handles;  // scratch: the target markers' positions when a drag starts
  double last_x = 0.0, last_y = 0.0;
  std::vector<std::string> dropped;
};

InputState& input_of(GLFWwindow* w) { return *static_cast<InputState*>(glfwGetWindowUserPointer(w)); }

constexpr float kPickPixels = 14.0f;

/// The target marker a left press at the cursor grabs (Ctrl: the nearest anywhere), or -1.
int grab_handle(GLFWwindow* w, InputState& in, bool ctrl) {
  App& app = *in.app;
  if (!app.toggles.procedural || !app.animator.graph || !app.animator.use_graph) return -1;
  handle_positions(app.animator, app.offsets, in.handles);
  if (in.handles.empty()) return -1;
  int width = 1, height = 1;
  glfwGetWindowSize(w, &width, &height);
  const glm::vec2 viewport(static_cast<float>(std::max(width, 1)), static_cast<float>(std::max(height, 1)));
  const glm::mat4 vp = projection_matrix(app.camera, viewport.x / viewport.y) * view_matrix(app.camera);
  return pick_point(vp, viewport, in.handles, glm::vec2(static_cast<float>(in.last_x), static_cast<float>(in.last_y)),
                    ctrl ? 1e9f : kPickPixels);
}

/// Moves the grabbed target by a drag of (dx, dy) window pixels.
void drag_handle(GLFWwindow* w, App& app, double dx, double dy) {
  GraphDriver& g = *app.animator.graph;
  if (app.active_handle < 0 || static_cast<size_t>(app.active_handle) >= g.procedural.targets.size()) return;
  const TargetHandle& h = g.procedural.targets[static_cast<size_t>(app.active_handle)];
  const glm::vec3 offset = app.offsets.empty() ? glm::vec3(0.0f) : app.offsets.front();
  int width = 1, height = 1;
  glfwGetWindowSize(w, &width, &height);
  const glm::vec3 p = handle_position(g.instances.front(), h, offset);
  const glm::vec3 moved = drag_in_view_plane(p, view_matrix(app.camera), app.camera.fov_y, static_cast<float>(height),
                                             static_cast<float>(dx), static_cast<float>(dy));
  (void)set_graph_vector(g, h.parameter, handle_value(h, moved, offset));
}

void step_clip(App& app, int direction) {
  const int n = static_cast<int>(app.scene.clips.size());
  if (n == 0) return;
  const int next = ((app.animator.playback.clip < 0 ? 0 : app.animator.playback.clip + direction) % n + n) % n;
  (void)play_clip(app, next, true);
}

void on_key(GLFWwindow* w, int key, int /*scancode*/, int action, int /*mods*/) {
  // Releases always reach the graph keys (a key let go over the panel must not stay held).
  if (action != GLFW_RELEASE && ImGui::GetCurrentContext() && ImGui::GetIO().WantCaptureKeyboard) return;
  InputState& in = input_of(w);
  App& app = *in.app;
  if (app.animator.graph && app.animator.use_graph && graph_key(*app.animator.graph, in.graph_keys, key, action)) return;
  if (action == GLFW_RELEASE) return;
  Playback& p = app.animator.playback;
  switch (key) {
    case GLFW_KEY_SPACE: p.playing = !p.playing; break;
    case GLFW_KEY_B: p.bind_pose = !p.bind_pose; break;
    case GLFW_KEY_F: app.toggles.wireframe = !app.toggles.wireframe; break;
    case GLFW_KEY_K: app.toggles.skeleton = !app.toggles.skeleton; break;
    case GLFW_KEY_G: app.toggles.grid = !app.toggles.grid; break;
    case GLFW_KEY_R: frame_camera(app, in.aspect); break;
    case GLFW_KEY_UP: step_clip(app, -1); break;
    case GLFW_KEY_DOWN: step_clip(app, 1); break;
    case GLFW_KEY_ESCAPE: glfwSetWindowShouldClose(w, GLFW_TRUE); break;
    default: break;
  }
}

void on_mouse_button(GLFWwindow* w, int button, int action, int mods) {
  InputState& in = input_of(w);
  const bool pressed = action == GLFW_PRESS;
  if (pressed && ImGui::GetCurrentContext() && ImGui::GetIO().WantCaptureMouse) return;
  glfwGetCursorPos(w, &in.last_x, &in.last_y);
  if (button == GLFW_MOUSE_BUTTON_LEFT) {
    in.app->active_handle = pressed ? grab_handle(w, in, (mods & GLFW_MOD_CONTROL) != 0) : -1;
    in.orbiting = pressed && in.app->active_handle < 0;
  }
  if (button == GLFW_MOUSE_BUTTON_RIGHT || button == GLFW_MOUSE_BUTTON_MIDDLE) in.panning = pressed;
}

void on_cursor(GLFWwindow* w, double x, double y) {
  InputState& in = input_of(w);
  const double dx = x - in.last_x, dy = y - in.last_y;
  in.last_x = x;
  in.last_y = y;
  int width = 1, height = 1;
  glfwGetWindowSize(w, &width, &height);
  if (in.app->active_handle >= 0 && in.app->animator.graph) drag_handle(w, *in.app, dx, dy);
  if (in.orbiting) orbit(in.app->camera, static_cast<float>(-dx * 0.01), static_cast<float>(dy * 0.01));
  if (in.panning) pan(in.app->camera, static_cast<float>(dx / height), static_cast<float>(dy / height));
}

void on_scroll(GLFWwindow* w, double /*dx*/, double dy) {
  if (ImGui::GetCurrentContext() && ImGui::GetIO().WantCaptureMouse) return;
  zoom(input_of(w).app->camera, static_cast<float>(dy));
}

void on_drop(GLFWwindow* w, int count, const char** paths) {
  InputState& in = input_of(w);
  for (int i = 0; i < count; ++i) in.dropped.emplace_back(paths[i]);
}

}  // namespace

int run_interactive(const ViewerOptions& o) {
  const auto fail = [](const std::string& m) {
    std::fprintf(stderr, "ossa-view: %s\n", m.c_str());
    return 1;
  };
  Result<Scene> scene = load_scene(o.files);
  if (!scene) return fail(scene.error().message);
  WindowOptions wo;
  wo.width = o.width;
  wo.height = o.height;
  wo.samples = o.msaa > 1 ? o.msaa : 0;
  wo.title = "ossa-view — " + o.files.front();
  Result<Window> window = create_window(wo);
  if (!window) {
    fail(o.files.front() + ": " + window.error().message);
    return cli::kExitUsage;  // no display: the viewer cannot run at all
  }
  GLFWwindow* w = window->get();
  glfwSwapInterval(1);

  Result<Renderer> renderer = create_renderer();
  if (!renderer) return fail(o.files.front() + ": " + renderer.error().message);
  App app;
  app.renderer = std::move(*renderer);
  int fb_width = 0, fb_height = 0;
  glfwGetFramebufferSize(w, &fb_width, &fb_height);
  InputState input;
  input.app = &app;
  input.aspect = fb_height > 0 ? static_cast<float>(fb_width) / static_cast<float>(fb_height) : 1.0f;
  if (Status s = setup_app(app, std::move(*scene), o, input.aspect); !s) return fail(s.message());

  glfwSetWindowUserPointer(w, &input);
  glfwSetKeyCallback(w, on_key);
  glfwSetMouseButtonCallback(w, on_mouse_button);
  glfwSetCursorPosCallback(w, on_cursor);
  glfwSetScrollCallback(w, on_scroll);
  glfwSetDropCallback(w, on_drop);

  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;  // no imgui.ini written into the working directory
  ImGui::StyleColorsDark();
  ImGui_ImplGlfw_InitForOpenGL(w, true);  // chains to the callbacks above
  ImGui_ImplOpenGL3_Init("#version 330 core");

  UiState ui;
  auto last = std::chrono::steady_clock::now();
  int status = 0;
  for (int frame = 1; !glfwWindowShouldClose(w); ++frame) {
    glfwPollEvents();
    glfwGetFramebufferSize(w, &fb_width, &fb_height);
    if (fb_width <= 0 || fb_height <= 0) {  // minimized
      glfwWaitEvents();
      continue;
    }
    input.aspect = static_cast<float>(fb_width) / static_cast<float>(fb_height);
    if (!input.dropped.empty()) {
      const std::vector<std::string> paths = std::move(input.dropped);
      input.dropped.clear();
      const Status s = open_or_add(app, paths, input.aspect);
      ui.status = s ? std::string() : s.message();
    }
    const auto now = std::chrono::steady_clock::now();
    const double frame_ms = std::chrono::duration<double, std::milli>(now - last).count();
    last = now;

    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    draw_panels(app, ui, input.aspect);
    if (ui.graph_slider_touched) input.graph_keys.driving = false;
    ImGui::Render();

    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    FrameTimings timings;
    const float dt = static_cast<float>(std::min(frame_ms, 100.0) / 1000.0);  // no leaps after a stall
    if (app.animator.graph && app.animator.use_graph) drive_graph_keys(*app.animator.graph, input.graph_keys, dt);
    if (Status s = step_and_render(app, dt, fb_width, fb_height, timings); !s) ui.status = s.message();
    record_frame(ui, timings, frame_ms);
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    if (Status s = check_gl("drawing a frame"); !s) ui.status = s.message();
    if (frame == o.window_frames) {  // automation: capture the window, panel included, and stop
      if (!o.screenshot.empty()) {
        glReadBuffer(GL_BACK);
        if (Status s = write_png(o.screenshot, fb_width, fb_height, read_framebuffer_rgb(fb_width, fb_height)); !s) {
          status = fail(s.message());
        }
      }
      if (Status s = check_gl("the window frames"); !s) status = fail(o.files.front() + ": " + s.message());
      if (!ui.status.empty()) status = fail(ui.status);
      glfwSetWindowShouldClose(w, GLFW_TRUE);
    }
    glfwSwapBuffers(w);
  }

  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  destroy_renderer(app.renderer);
  return status;
}

}  // namespace ossa::view
