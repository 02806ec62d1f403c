// interactive.cpp — see interactive.h.
//
// GLFW callbacks only record input (into InputState through the window user pointer); files
// dropped on the window are queued and opened between frames, never inside a callback. Our
// callbacks are installed before ImGui's GLFW backend, which chains to them, and they ignore the
// mouse and keyboard while ImGui wants them (a click on the panel is not an orbit). A left press
// on a procedural target marker (within kPickPixels), or anywhere with Ctrl held (the nearest
// marker), drags that target in the camera's view plane instead of orbiting
// (procedural_info.h drag_in_view_plane), setting the parameter on every instance.
//
// The scene is drawn beside the panel (layout.h): one SceneLayout per frame gives glViewport
// (Renderer::viewport_x / _y), the aspect ratio the camera frames for, and the region the cursor
// is measured in for picking, so a marker is grabbed where it is drawn. Dropped files, the
// browser's clicks and --cook-and-open go through PendingWork (cook_job.h): opens one frame
// after "loading..." is shown, sources cooked on a thread while frames keep coming. The UI scale
// follows the monitor's content scale (a change rebuilds the font at the new size between frames)
// unless --ui-scale fixes it.
#include "viewer/interactive.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <filesystem>
#include <system_error>
#include <cstdio>
#include <string>
#include <vector>

#include <imgui.h>
#include <backends/imgui_impl_glfw.h>
#include <backends/imgui_impl_opengl3.h>

#include "tools/cli/cli.h"
#include "viewer/app.h"
#include "viewer/gl_util.h"
#include "viewer/graph_keys.h"
#include "viewer/layout.h"
#include "viewer/procedural_draw.h"
#include "viewer/setup.h"
#include "viewer/snapshot.h"
#include "viewer/ui.h"
#include "viewer/window.h"

namespace ossa::view {
namespace {

struct InputState {
  App* app = nullptr;
  UiState* ui = nullptr;
  GraphKeys graph_keys;
  SceneLayout layout;  // this frame's (the scene's region and aspect ratio)
  bool orbiting = false, panning = false;
  std::vector<glm::vec3> handles;  // scratch: the target markers' positions when a drag starts
  double last_x = 0.0, last_y = 0.0;
  std::vector<std::string> dropped;
  bool scale_changed = false;  // the window moved to a monitor of another content scale
};

InputState& input_of(GLFWwindow* w) { return *static_cast<InputState*>(glfwGetWindowUserPointer(w)); }

constexpr float kPickPixels = 14.0f;

/// The target marker a left press at the cursor grabs (Ctrl: the nearest anywhere), or -1. The
/// cursor is measured from the scene region's corner, the projection uses its aspect ratio.
int grab_handle(InputState& in, bool ctrl) {
  App& app = *in.app;
  if (!app.toggles.procedural || !app.animator.graph || !app.animator.use_graph) return -1;
  handle_positions(app.animator, app.offsets, in.handles);
  if (in.handles.empty()) return -1;
  const Rect& r = in.layout.scene;
  const glm::vec2 viewport(std::max(r.width, 1.0f), std::max(r.height, 1.0f));
  const glm::mat4 vp = projection_matrix(app.camera, viewport.x / viewport.y) * view_matrix(app.camera);
  const glm::vec2 cursor(static_cast<float>(in.last_x) - r.x, static_cast<float>(in.last_y) - r.y);
  return pick_point(vp, viewport, in.handles, cursor, ctrl ? 1e9f : kPickPixels);
}

/// Moves the grabbed target by a drag of (dx, dy) window units.
void drag_handle(const InputState& in, App& app, double dx, double dy) {
  GraphDriver& g = *app.animator.graph;
  if (app.active_handle < 0 || static_cast<size_t>(app.active_handle) >= g.procedural.targets.size()) return;
  const TargetHandle& h = g.procedural.targets[static_cast<size_t>(app.active_handle)];
  const glm::vec3 offset = app.offsets.empty() ? glm::vec3(0.0f) : app.offsets.front();
  const glm::vec3 p = handle_position(g.instances.front(), h, offset);
  const glm::vec3 moved =
      drag_in_view_plane(p, view_matrix(app.camera), app.camera.fov_y, std::max(in.layout.scene.height, 1.0f),
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
  if (action == GLFW_PRESS && key == GLFW_KEY_TAB) {
    in.ui->panel_open = !in.ui->panel_open;
    return;
  }
  if (app.scene.assets.empty()) {
    if (action == GLFW_PRESS && key == GLFW_KEY_ESCAPE) glfwSetWindowShouldClose(w, GLFW_TRUE);
    return;
  }
  if (app.animator.graph && app.animator.use_graph && graph_key(*app.animator.graph, in.graph_keys, key, action))
    return;
  if (action == GLFW_RELEASE) return;
  Playback& p = app.animator.playback;
  switch (key) {
    case GLFW_KEY_SPACE: p.playing = !p.playing; break;
    case GLFW_KEY_B: p.bind_pose = !p.bind_pose; break;
    case GLFW_KEY_F: app.toggles.wireframe = !app.toggles.wireframe; break;
    case GLFW_KEY_K: app.toggles.skeleton = !app.toggles.skeleton; break;
    case GLFW_KEY_G: app.toggles.grid = !app.toggles.grid; break;
    case GLFW_KEY_R: frame_camera(app, in.layout.aspect); break;
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
  // A press outside the scene region (on the panel's strip or the timeline) is not the scene's.
  if (pressed && !in.layout.scene.contains(static_cast<float>(in.last_x), static_cast<float>(in.last_y))) return;
  if (in.app->scene.assets.empty()) return;
  if (button == GLFW_MOUSE_BUTTON_LEFT) {
    in.app->active_handle = pressed ? grab_handle(in, (mods & GLFW_MOD_CONTROL) != 0) : -1;
    in.orbiting = pressed && in.app->active_handle < 0;
  }
  if (button == GLFW_MOUSE_BUTTON_RIGHT || button == GLFW_MOUSE_BUTTON_MIDDLE) in.panning = pressed;
}

void on_cursor(GLFWwindow* w, double x, double y) {
  InputState& in = input_of(w);
  const double dx = x - in.last_x, dy = y - in.last_y;
  in.last_x = x;
  in.last_y = y;
  const double height = std::max(in.layout.scene.height, 1.0f);
  if (in.app->active_handle >= 0 && in.app->animator.graph) drag_handle(in, *in.app, dx, dy);
  if (in.orbiting) orbit(in.app->camera, static_cast<float>(-dx * 0.01), static_cast<float>(dy * 0.01));
  if (in.panning) pan(in.app->camera, static_cast<float>(dx / height), static_cast<float>(dy / height));
}

void on_scroll(GLFWwindow* w, double /*dx*/, double dy) {
  if (ImGui::GetCurrentContext() && ImGui::GetIO().WantCaptureMouse) return;
  InputState& in = input_of(w);
  if (!in.layout.scene.contains(static_cast<float>(in.last_x), static_cast<float>(in.last_y))) return;
  zoom(in.app->camera, static_cast<float>(dy));
}

void on_drop(GLFWwindow* w, int count, const char** paths) {
  InputState& in = input_of(w);
  for (int i = 0; i < count; ++i) in.dropped.emplace_back(paths[i]);
}

void on_content_scale(GLFWwindow* w, float /*x*/, float /*y*/) { input_of(w).scale_changed = true; }

/// The UI scale now: --ui-scale, else the monitor's content scale over the framebuffer / window
/// ratio (layout.h ui_scale_for).
float current_ui_scale(GLFWwindow* w, const ViewerOptions& o, float fb_per_window) {
  if (o.ui_scale > 0.0f) return o.ui_scale;
  float sx = 1.0f, sy = 1.0f;
  glfwGetWindowContentScale(w, &sx, &sy);
  return ui_scale_for(sx, fb_per_window);
}

/// Rebuilds ImGui's style and font for `scale`: the style's sizes scaled from the dark style's,
/// the default font rasterized at its size in framebuffer pixels (sharp on HiDPI) and drawn at
/// 1 / fb_per_window of it in window units. Between frames only (the font texture is remade).
void apply_ui_scale(float scale, float fb_per_window, bool remake_texture) {
  ImGuiStyle style;
  ImGui::StyleColorsDark(&style);
  style.ScaleAllSizes(scale);
  ImGui::GetStyle() = style;
  ImGuiIO& io = ImGui::GetIO();
  io.Fonts->Clear();
  ImFontConfig font;
  font.SizePixels = std::round(13.0f * scale * fb_per_window);
  io.Fonts->AddFontDefault(&font);
  io.FontGlobalScale = 1.0f / fb_per_window;
  if (remake_texture) {
    ImGui_ImplOpenGL3_DestroyFontsTexture();
    ImGui_ImplOpenGL3_CreateFontsTexture();
  }
}

/// -v's account of the captured frame's panel (panel_fit.h): every region's rectangle, then each
/// widget cut off, then a summary line the tests look for.
void print_panel_audit(const PanelAudit& a) {
  for (const PanelRegion& r : a.regions)
    std::fprintf(stderr, "ossa-view: panel region %s: %.0f %.0f %.0f %.0f in panel %.0f %.0f %.0f %.0f\n",
                 r.name.c_str(), r.rect.x, r.rect.y, r.rect.width, r.rect.height, a.panel.x, a.panel.y, a.panel.width,
                 a.panel.height);
  const std::vector<std::string> problems = a.problems();
  for (const std::string& p : problems) std::fprintf(stderr, "ossa-view: panel cut off: %s\n", p.c_str());
  std::fprintf(stderr, "ossa-view: panel check: %zu regions, %zu cut off\n", a.regions.size(), problems.size());
}

}  // namespace

int run_interactive(const ViewerOptions& o) {
  const auto fail = [](const std::string& m) {
    std::fprintf(stderr, "ossa-view: %s\n", m.c_str());
    return 1;
  };
  const std::string first = o.files.empty() ? std::string("ossa-view") : o.files.front();
  Result<Scene> scene = o.files.empty() ? Result<Scene>(Scene{}) : load_scene(o.files);
  if (!scene) return fail(scene.error().message);
  WindowOptions wo;
  wo.width = o.width;
  wo.height = o.height;
  wo.samples = o.msaa > 1 ? o.msaa : 0;
  wo.title = o.files.empty() ? std::string("ossa-view") : "ossa-view — " + o.files.front();
  Result<Window> window = create_window(wo);
  if (!window) {
    fail(first + ": " + window.error().message);
    return cli::kExitUsage;  // no display: the viewer cannot run at all
  }
  GLFWwindow* w = window->get();
  glfwSwapInterval(1);

  Result<Renderer> renderer = create_renderer();
  if (!renderer) return fail(first + ": " + renderer.error().message);
  App app;
  app.renderer = std::move(*renderer);
  UiState ui;
  ui.panel_open = !o.panel_collapsed;
  InputState input;
  input.app = &app;
  input.ui = &ui;
  int fb_width = 0, fb_height = 0, win_width = 0, win_height = 0;
  const auto measure = [&] {
    glfwGetFramebufferSize(w, &fb_width, &fb_height);
    glfwGetWindowSize(w, &win_width, &win_height);
    return win_width > 0 ? static_cast<float>(fb_width) / static_cast<float>(win_width) : 1.0f;
  };
  float fb_per_window = measure();
  ui.ui_scale = current_ui_scale(w, o, fb_per_window);
  const auto layout_now = [&] {
    return compute_layout(win_width, win_height, fb_width, fb_height, panel_width(ui),
                          timeline_height(app, ui.ui_scale));
  };
  input.layout = layout_now();
  apply_view_options(app, o);
  if (!o.files.empty()) {
    if (Status s = setup_app(app, std::move(*scene), o, input.layout.aspect); !s) return fail(s.message());
    input.layout = layout_now();  // with the timeline, now that a clip may be selected
    frame_camera(app, input.layout.aspect);
  }
  std::error_code no_cwd;
  const std::filesystem::path cwd = std::filesystem::current_path(no_cwd);
  browse(ui.browser, o.browse.empty() ? start_folder(o.files, no_cwd ? std::filesystem::path("/") : cwd)
                                      : std::filesystem::path(o.browse));
  ui.browser.open_section = !o.browse.empty();
  if (o.verbose)
    std::fprintf(stderr, "ossa-view: browsing %s: %zu entries\n", ui.browser.folder.c_str(), ui.browser.entries.size());
  request_paths(ui.work, o.cook_and_open);

  glfwSetWindowUserPointer(w, &input);
  glfwSetKeyCallback(w, on_key);
  glfwSetMouseButtonCallback(w, on_mouse_button);
  glfwSetCursorPosCallback(w, on_cursor);
  glfwSetScrollCallback(w, on_scroll);
  glfwSetDropCallback(w, on_drop);
  glfwSetWindowContentScaleCallback(w, on_content_scale);

  IMGUI_CHECKVERSION();
  ImGui::CreateContext();
  ImGui::GetIO().IniFilename = nullptr;   // no imgui.ini written into the working directory
  ImGui_ImplGlfw_InitForOpenGL(w, true);  // chains to the callbacks above
  ImGui_ImplOpenGL3_Init("#version 330 core");
  apply_ui_scale(ui.ui_scale, fb_per_window, false);  // the backend makes the font texture on its first frame

  auto last = std::chrono::steady_clock::now();
  int status = 0;
  size_t logged = 0;
  for (int counted = 0; !glfwWindowShouldClose(w);) {
    glfwPollEvents();
    fb_per_window = measure();
    if (fb_width <= 0 || fb_height <= 0 || win_width <= 0 || win_height <= 0) {  // minimized
      glfwWaitEvents();
      continue;
    }
    if (const float scale = current_ui_scale(w, o, fb_per_window); input.scale_changed || scale != ui.ui_scale) {
      input.scale_changed = false;
      ui.ui_scale = scale;
      apply_ui_scale(scale, fb_per_window, true);
    }
    input.layout = layout_now();
    if (!input.dropped.empty()) {
      request_paths(ui.work, input.dropped);
      input.dropped.clear();
    }
    step_pending_work(ui.work, app, input.layout.aspect, ui.status);
    for (; o.verbose && logged < ui.work.log.size(); ++logged)
      std::fprintf(stderr, "ossa-view: %s\n", ui.work.log[logged].c_str());
    const auto now = std::chrono::steady_clock::now();
    const double frame_ms = std::chrono::duration<double, std::milli>(now - last).count();
    last = now;

    input.layout = layout_now();
    ImGui_ImplOpenGL3_NewFrame();
    ImGui_ImplGlfw_NewFrame();
    ImGui::NewFrame();
    draw_panels(app, ui, input.layout);
    if (ui.graph_slider_touched) input.graph_keys.driving = false;
    ImGui::Render();

    // The panel toggle or a clip change this frame moves the scene's region: lay out again.
    input.layout = layout_now();
    const SceneLayout& l = input.layout;
    glBindFramebuffer(GL_FRAMEBUFFER, 0);
    glViewport(0, 0, fb_width, fb_height);
    glClearColor(0.08f, 0.08f, 0.09f, 1.0f);
    glClear(GL_COLOR_BUFFER_BIT | GL_DEPTH_BUFFER_BIT);
    FrameTimings timings;
    const float dt = static_cast<float>(std::min(frame_ms, 100.0) / 1000.0);  // no leaps after a stall
    if (!app.scene.assets.empty()) {
      if (app.animator.graph && app.animator.use_graph) drive_graph_keys(*app.animator.graph, input.graph_keys, dt);
      app.renderer.viewport_x = l.fb_x;
      app.renderer.viewport_y = l.fb_y;
      if (Status s = step_and_render(app, dt, l.fb_width, l.fb_height, timings); !s) ui.status = s.message();
      record_frame(ui, timings, frame_ms);
    }
    ImGui_ImplOpenGL3_RenderDrawData(ImGui::GetDrawData());
    if (Status s = check_gl("drawing a frame"); !s) ui.status = s.message();
    // --window-frames N counts frames once nothing is pending, so a capture waits for every cook
    // and open; without it (0) the window stays until it is closed.
    counted += busy(ui.work) ? 0 : 1;
    if (o.window_frames > 0 &&
        counted == o.window_frames) {  // automation: capture the window, panel included, and stop
      if (o.verbose)
        std::fprintf(stderr,
                     "ossa-view: layout: panel %.0f, scene %.0f %.0f %.0f %.0f, timeline %.0f (window %dx%d, "
                     "framebuffer %dx%d)\n",
                     panel_width(ui), l.scene.x, l.scene.y, l.scene.width, l.scene.height, l.timeline.height, win_width,
                     win_height, fb_width, fb_height);
      if (o.verbose && ui.panel_open) print_panel_audit(ui.audit);
      if (!o.screenshot.empty()) {
        glReadBuffer(GL_BACK);
        if (Status s = write_png(o.screenshot, fb_width, fb_height, read_framebuffer_rgb(fb_width, fb_height)); !s) {
          status = fail(s.message());
        }
      }
      if (Status s = check_gl("the window frames"); !s) status = fail(first + ": " + s.message());
      if (!ui.status.empty()) status = fail(ui.status);
      glfwSetWindowShouldClose(w, GLFW_TRUE);
    }
    glfwSwapBuffers(w);
    note_indicator_drawn(ui.work);
  }

  ImGui_ImplOpenGL3_Shutdown();
  ImGui_ImplGlfw_Shutdown();
  ImGui::DestroyContext();
  release_app_gpu(app);
  return status;
}

}  // namespace ossa::view
