// first_frame_ossa.cpp — the cooked side of ossa-bench-first-frame's "every character" row: one
// process, one context, each .ossa file opened with the viewer's own code and one frame drawn.
//
// A single file is timed with the real ossa-view executable (--first-frame-time). Several files
// need one process that shows them one after another, which ossa-view does not do from its
// command line (a second character replaces the first only when dropped on the window), so this
// child does what its headless mode does per file — load_scene, setup_app (upload, textures),
// step_and_render into an offscreen target, glFinish — in one context, as the Assimp child does
// for the sources (first_frame_assimp.h).
#include <chrono>
#include <cstdio>
#include <string>
#include <vector>

#include "bench/first_frame_assimp.h"
#include "viewer/app.h"
#include "viewer/gl_util.h"
#include "viewer/materials.h"
#include "viewer/offscreen.h"
#include "viewer/options.h"
#include "viewer/setup.h"
#include "viewer/window.h"

namespace ossa::bench {
namespace {

Status run(std::span<const std::string> files, int width, int height, int samples,
           std::chrono::steady_clock::time_point start) {
  Result<view::Window> window = child_window();
  if (!window) return window.error();
  Result<view::Renderer> renderer = view::create_renderer();
  if (!renderer) return renderer.error();
  view::App app;
  app.renderer = std::move(*renderer);
  Result<view::Offscreen> target = view::create_offscreen(width, height, samples);
  if (!target) return target.error();
  const float aspect = static_cast<float>(width) / static_cast<float>(height);
  uint64_t texture_bytes = 0;
  for (const std::string& file : files) {
    view::ViewerOptions o;
    o.files = {file};
    o.width = width;
    o.height = height;
    o.grid = false;
    o.quiet = true;
    const std::vector<std::string> one{file};
    Result<view::Scene> scene = view::load_scene(one);
    if (!scene) return scene.error();
    if (Status s = view::setup_app(app, std::move(*scene), o, aspect); !s) return s;
    view::bind_offscreen(*target);
    view::FrameTimings timings;
    if (Status s = view::step_and_render(app, 0.0f, width, height, timings); !s) return s;
    glFinish();
    if (Status s = view::check_gl(file); !s) return s;
    texture_bytes += view::texture_bytes(app.renderer.materials);
  }
  print_first_frame(texture_bytes, start);
  return {};
}

}  // namespace

int run_ossa_first_frame(std::span<const std::string> files, int width, int height, int samples) {
  const auto start = std::chrono::steady_clock::now();
  return exit_status(run(files, width, height, samples, start));
}

}  // namespace ossa::bench
