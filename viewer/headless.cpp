// headless.cpp — see headless.h.
#include "viewer/headless.h"

#include <chrono>
#include <cmath>
#include <cstdio>
#include <string>

#include "tools/cli/cli.h"
#include "viewer/app.h"
#include "viewer/gl_util.h"
#include "viewer/offscreen.h"
#include "viewer/setup.h"
#include "viewer/snapshot.h"
#include "viewer/window.h"

namespace ossa::view {
namespace {

constexpr float kFrameStep = 1.0f / 60.0f;
constexpr float kClothPreroll = 2.0f;  // seconds of the clip played before the first frame when there is cloth

/// The whole run, with errors as values; run_headless turns them into the exit status. A window
/// that cannot be made (no display, no GL 3.3) sets `cannot_run`: nothing could be tried then.
Status render_headless(const ViewerOptions& o, bool& cannot_run) {
  const auto start = std::chrono::steady_clock::now();
  const std::string& name = o.files.front();
  // Open the files first: a bad file is reported as such even where no display exists.
  Result<Scene> scene = load_scene(o.files);
  if (!scene) return scene.error();

  WindowOptions wo;
  wo.width = 64;
  wo.height = 64;
  wo.visible = false;
  Result<Window> window = create_window(wo);
  if (!window) {
    cannot_run = true;
    return Error{name + ": " + window.error().message};
  }
  if (Status s = check_gl("creating the context"); !s) return Error{name + ": " + s.message()};

  Result<Renderer> renderer = create_renderer();
  if (!renderer) return Error{name + ": " + renderer.error().message};
  App app;
  app.renderer = std::move(*renderer);
  const float aspect = static_cast<float>(o.width) / static_cast<float>(o.height);
  if (Status s = setup_app(app, std::move(*scene), o, aspect); !s) return s;

  Playback& p = app.animator.playback;
  p.playing = true;  // --paused means nothing here: frames step 1/60 s towards --time
  const bool graph = app.animator.use_graph && app.animator.graph;
  if (graph) {
    // A graph cannot seek: play --time seconds of it in 1/60 s steps, then the frames follow on.
    PoseTimings ignored;
    for (float t = 0.0f; t + 0.5f * kFrameStep < o.time; t += kFrameStep) {
      advance(app.scene, app.animator, kFrameStep);
      produce_local_poses(app.scene, app.animator, ignored);
      if (!app.cloth.empty()) {
        compute_model_poses(app.scene, app.animator, ignored);
        if (Status s = step_cloth(app, kFrameStep); !s) return s;
      }
    }
  } else {
    // N frames 1/60 s apart, the last at --time: start (N - 1) steps earlier.
    const float rate = o.speed != 0.0f ? o.speed : 1.0f;
    p.time = advance_time(p.time, -kFrameStep * static_cast<float>(o.frames - 1), rate,
                          clip_duration(app.scene, app.animator), p.loop);
    if (!app.cloth.empty() && app.cloth.enabled) {
      // Cloth has a history: the clip plays kClothPreroll seconds (in 1/60 s frames) before the
      // first frame, so the image shows the cloth as it is in motion, not at rest.
      const int steps = static_cast<int>(std::lround(kClothPreroll / kFrameStep));
      p.time = advance_time(p.time, -kFrameStep * static_cast<float>(steps), rate,
                            clip_duration(app.scene, app.animator), p.loop);
      PoseTimings ignored;
      for (int k = 0; k < steps; ++k) {
        advance(app.scene, app.animator, kFrameStep);
        produce_local_poses(app.scene, app.animator, ignored);
        compute_model_poses(app.scene, app.animator, ignored);
        if (Status s = step_cloth(app, kFrameStep); !s) return s;
      }
    }
  }
  if (app.retarget) {  // the source clip likewise ends at --time
    RetargetView& v = *app.retarget;
    const float rate = o.speed != 0.0f ? o.speed : 1.0f;
    set_time(v.source, v.animator, o.time - rate * kFrameStep * static_cast<float>(o.frames - 1));
  }

  Result<Offscreen> target = create_offscreen(o.width, o.height, o.msaa);
  if (!target) return Error{name + ": " + target.error().message};
  if (Status s = check_gl("setting up"); !s) return Error{name + ": " + s.message()};

  FrameTimings total;
  for (int f = 0; f < o.frames; ++f) {
    bind_offscreen(*target);
    float dt = f == 0 ? 0.0f : kFrameStep;
    if (!graph && f == o.frames - 1) {
      set_time(app.scene, app.animator, o.time);  // exactly --time, no drift
      if (app.retarget) set_time(app.retarget->source, app.retarget->animator, o.time);
      dt = 0.0f;
    }
    if (Status s = step_and_render(app, dt, o.width, o.height, total); !s) return s;
    if (Status s = check_gl("drawing frame " + std::to_string(f)); !s) return Error{name + ": " + s.message()};
    if (f == 0 && o.first_frame_time) {
      glFinish();
      const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - start).count();
      // The texture line first: the bench stops reading at first-frame-ms.
      std::printf("texture-bytes %llu\n", static_cast<unsigned long long>(texture_bytes(app.renderer.materials)));
      std::printf("first-frame-ms %.3f\n", ms);
      std::fflush(stdout);
    }
  }
  if (!o.screenshot.empty()) {
    const std::vector<uint8_t> rgb = read_rgb(*target);
    if (Status s = check_gl("reading the image back"); !s) return Error{name + ": " + s.message()};
    if (Status s = write_png(o.screenshot, o.width, o.height, rgb); !s) return s;
  }
  if (o.stats) {
    const double n = o.frames;
    std::printf("framed (%g %g %g) .. (%g %g %g)\n", app.framing.min.x, app.framing.min.y, app.framing.min.z,
                app.framing.max.x, app.framing.max.y, app.framing.max.z);
    std::printf(
        "frames %d  sample %.3f ms  blend %.3f ms  graph %.3f ms  skin %.3f ms  draw %.3f ms  gpu %.3f ms (per "
        "frame)\n",
        o.frames, total.sample_ms / n, total.blend_ms / n, total.graph_ms / n, total.skin_ms / n, total.draw_ms / n,
        total.gpu_ms / n);
    std::printf("cloth particles from the vertex shader %.0f  meshes skinned on the CPU %.0f (per frame)\n",
                total.shader_cloth_particles / n, total.cpu_skinned_meshes / n);
  }
  destroy_offscreen(*target);
  release_scene(app.renderer);
  release_app_gpu(app);
  return {};
}

}  // namespace

int run_headless(const ViewerOptions& options) {
  bool cannot_run = false;
  const Status s = render_headless(options, cannot_run);
  if (s) return cli::kExitOk;
  std::fprintf(stderr, "ossa-view: %s\n", s.message().c_str());
  return cannot_run ? cli::kExitUsage : cli::kExitFailed;
}

}  // namespace ossa::view
