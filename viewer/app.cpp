// app.cpp — see app.h.
#include "viewer/app.h"

#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include "viewer/procedural_draw.h"
#include "viewer/retarget_view.h"
#include <utility>

namespace ossa::view {
namespace {

/// Crowd placement: a square-ish grid on the ground, spaced by the character's footprint.
std::vector<glm::vec3> crowd_offsets(size_t n, const Box& one) {
  std::vector<glm::vec3> out;
  const auto columns = static_cast<size_t>(std::ceil(std::sqrt(static_cast<double>(n))));
  const glm::vec3 size = one.empty() ? glm::vec3(1.0f) : one.size();
  const float spacing_x = 1.25f * std::max(size.x, 0.6f * size.y);
  const float spacing_z = 1.25f * std::max(size.z, 0.6f * size.y);
  const size_t rows = (n + columns - 1) / columns;
  for (size_t i = 0; i < n; ++i) {
    const float x = (static_cast<float>(i % columns) - 0.5f * static_cast<float>(columns - 1)) * spacing_x;
    const float z = (static_cast<float>(i / columns) - 0.5f * static_cast<float>(rows - 1)) * spacing_z;
    out.emplace_back(n == 1 ? 0.0f : x, 0.0f, n == 1 ? 0.0f : -z);
  }
  return out;
}

/// The character's front: --front's axis, or found from its feet in the bind pose.
Facing facing_from(const std::string& front, const Asset& asset, std::span<const glm::mat4> model) {
  if (front == "auto" || front.size() != 2) return facing_of(asset, model);
  Facing f;
  const float sign = front[0] == '-' ? -1.0f : 1.0f;
  f.forward = front[1] == 'x' ? glm::vec3(sign, 0.0f, 0.0f) : glm::vec3(0.0f, 0.0f, sign);
  f.yaw = std::atan2(f.forward.x, f.forward.z);
  return f;
}

/// Poses sampled over the clip for framing: enough that a limb's sweep between two samples is
/// small next to the character, few enough to cost tens of milliseconds on the largest sample
/// (one CPU skin each, bounds.h) when the camera is framed, never per frame.
constexpr int kFramingSamples = 48;

/// The character over its whole clip, each sample's box moved by the root's horizontal travel
/// since the bind pose taken back (so a walk that leaves the origin is framed in place; following
/// the root moves the camera with it). Empty when no clip plays (bind pose, a graph: graphs
/// cannot seek). Playback is left as it was; the poses are not (the caller poses again).
Box clip_motion_bounds(App& app) {
  Animator& a = app.animator;
  Playback& p = a.playback;
  const float duration = clip_duration(app.scene, a);
  if ((a.graph && a.use_graph) || p.clip < 0 || p.bind_pose || !(duration > 0.0f) || a.instances.empty()) return {};
  const Playback saved = p;
  p.fade = 1.0f;  // the selected clip alone, not a cross-fade in progress
  PoseTimings ignored;
  Box box;
  for (int k = 0; k < kFramingSamples; ++k) {
    p.time = duration * static_cast<float>(k) / static_cast<float>(kFramingSamples - 1);
    produce_local_poses(app.scene, a, ignored);
    compute_model_poses(app.scene, a, ignored);
    const auto& model = a.instances.front().model;
    const Box b = posed_bounds(app.scene.character(), model);
    if (b.empty()) continue;
    glm::vec3 travel = model.empty() ? glm::vec3(0.0f) : glm::vec3(model[0][3]) - app.root_bind;
    travel.y = 0.0f;
    box.add(b.min - travel);
    box.add(b.max - travel);
  }
  p = saved;
  return box;
}

}  // namespace

void frame_camera(App& app, float aspect) {
  glm::vec3 moved(0.0f);
  if (app.crowd == 1 && !app.animator.instances.empty()) {
    // One character: frame it as it is drawn now (the shown clip time, or the bind pose).
    Animator& a = app.animator;
    PoseTimings ignored;
    // The whole clip's motion (issue 28: a wing or an arm that reaches out late left the image).
    const Box motion = app.retarget ? Box{} : clip_motion_bounds(app);
    produce_local_poses(app.scene, a, ignored);
    if (app.retarget) retarget_poses(*app.retarget, a, app.bind_box, 0.0f);
    compute_model_poses(app.scene, a, ignored);
    const auto& model = a.instances.front().model;
    Box shown = posed_bounds(app.scene.character(), model);
    if (!motion.empty()) {
      glm::vec3 travel = model.empty() ? glm::vec3(0.0f) : glm::vec3(model[0][3]) - app.root_bind;
      travel.y = 0.0f;
      shown.add(motion.min + travel);
      shown.add(motion.max + travel);
    }
    // The source as first shown (the same box at any clip time, so --time moves only the figures).
    if (app.retarget && app.retarget->framing.empty()) app.retarget->framing = source_bounds(*app.retarget);
    if (app.retarget && app.retarget->show_source) shown.add(app.retarget->framing);
    if (!shown.empty()) app.framing = shown;
    if (!model.empty()) {
      moved = glm::vec3(model[0][3]) - app.root_bind;
      moved.y = 0.0f;
    }
    // The floor stays under the bind pose too (a frame mid-jump keeps the ground where it is).
    Box ground = app.framing;
    ground.add(app.bind_box);
    set_grid(app.renderer, ground, ground.empty() ? 0.0f : ground.min.y,
             ground.empty() ? 1.0f : 0.5f * glm::length(ground.size()));
  }
  app.camera = frame_box(app.framing, app.facing.yaw + app.angles.yaw, app.angles.pitch, aspect);
  // The framing already holds the root where it is now: following starts from here.
  app.follow_applied = moved;
}

Status open_scene(App& app, std::span<const std::string> paths, size_t crowd, float aspect) {
  Result<Scene> scene = load_scene(paths);
  if (!scene) return scene.error();
  return open_loaded_scene(app, std::move(*scene), crowd, aspect);
}

Status open_loaded_scene(App& app, Scene scene, size_t crowd, float aspect) {
  std::vector<std::string> warnings;
  if (Status s = upload_scene(app.renderer, scene, warnings); !s) {
    // Put the previous scene back on the GPU (its files are still open).
    if (!app.scene.assets.empty()) {
      std::vector<std::string> ignored;
      (void)upload_scene(app.renderer, app.scene, ignored);
    }
    return s;
  }
  app.scene = std::move(scene);
  app.messages = std::move(warnings);
  // A retarget source is mapped onto the new character, or dropped when it cannot be.
  if (app.retarget) {
    const std::vector<std::string> files = app.retarget->files;
    const std::string map = app.retarget->map_file;
    release_retarget_view(*app.retarget);
    app.retarget.reset();
    if (auto view = make_retarget_view(app.scene, files, map, {}); view) app.retarget = std::move(*view);
    else app.messages.push_back(view.error().message);
  }
  app.animator = Animator{};
  // Keep playing the graph by name if the new files have it; otherwise back to clips.
  bool has_graph = false;
  for (const Asset& a : app.scene.assets)
    has_graph = has_graph || (!app.graph_name.empty() && find_graph(a, app.graph_name));
  if (!has_graph) app.graph_name.clear();
  return set_crowd(app, crowd, aspect);
}

Status use_graph(App& app, const std::string& name) {
  Result<GraphDriver> g = make_graph_driver(app.scene, name, app.animator.instances.size());
  if (!g) return g.error();
  for (size_t i = 0; i < g->instances.size() && i < app.offsets.size(); ++i)
    g->instances[i].set_transform(glm::translate(glm::mat4(1.0f), app.offsets[i]));
  app.animator.graph = std::make_unique<GraphDriver>(std::move(*g));
  app.active_handle = -1;
  app.animator.use_graph = true;
  app.animator.graph_dt = 0.0f;
  app.graph_name = name;
  return {};
}

Status set_crowd(App& app, size_t crowd, float aspect) {
  const Playback previous = app.animator.playback;
  MorphOverrides held = std::move(app.animator.morph_overrides);  // the held weights survive too
  const bool had_clip = !app.animator.instances.empty();
  // A graph's parameter values survive a crowd change (triggers are one-shot and do not).
  std::vector<std::pair<int, float>> graph_values;
  std::vector<std::pair<int, glm::vec3>> graph_vectors;
  const bool used_graph = app.animator.use_graph;
  if (app.animator.graph && !app.animator.graph->instances.empty()) {
    const GraphDriver& g = *app.animator.graph;
    for (size_t p = 0; p < g.definition->parameter_count(); ++p) {
      if (g.definition->parameter_type(p) == fb::ParameterType::Trigger) continue;
      if (g.definition->parameter_type(p) == fb::ParameterType::Vector) {
        graph_vectors.emplace_back(static_cast<int>(p), g.instances.front().vector(static_cast<int>(p)));
        continue;
      }
      graph_values.emplace_back(static_cast<int>(p), g.instances.front().value(static_cast<int>(p)));
    }
  }
  app.crowd = crowd == 0 ? 1 : crowd;
  Drive drive = app.animator.drive;  // --move / --turn carry over; the journey starts again
  drive.clock = drive.heading = 0.0f;
  drive.position = glm::vec3(0.0f);
  drive.world = glm::mat4(1.0f);
  app.animator = make_animator(app.scene, app.crowd);
  {
    Result<ViewerCloth> cloth = make_viewer_cloth(app.scene, app.crowd);
    if (!cloth) return cloth.error();
    cloth->enabled = app.cloth.enabled;
    cloth->wind = app.cloth.wind;
    cloth->stiffness = app.cloth.stiffness;
    app.cloth = std::move(*cloth);
  }
  if (held.held.size() == app.scene.morph_channels.size()) app.animator.morph_overrides = std::move(held);

  // Bind pose bounds of one character, then of the whole crowd.
  Animator& a = app.animator;
  PoseTimings ignored;
  produce_local_poses(app.scene, a, ignored);  // no clip yet: bind pose
  compute_model_poses(app.scene, a, ignored);
  const Box one = posed_bounds(app.scene.character(), a.instances.front().model);
  app.bind_box = one;
  app.facing = facing_from(app.front, app.scene.character(), a.instances.front().model);
  drive.forward = app.facing.forward;
  a.drive = drive;
  app.offsets = crowd_offsets(app.crowd, one);
  app.framing = Box{};
  for (const glm::vec3& o : app.offsets) {
    if (!one.empty()) {
      app.framing.add(one.min + o);
      app.framing.add(one.max + o);
    }
  }
  app.root_bind = a.instances.front().model.empty() ? glm::vec3(0.0f) : glm::vec3(a.instances.front().model[0][3]);
  app.follow = app.crowd == 1;
  const float radius = one.empty() ? 1.0f : 0.5f * glm::length(one.size());
  set_grid(app.renderer, app.framing, app.framing.empty() ? 0.0f : app.framing.min.y, radius);

  const int clip = had_clip ? previous.clip : (app.scene.clips.empty() ? -1 : 0);
  if (Status s = play_clip(app, clip, false); !s) return s;
  if (had_clip) {
    Playback& p = a.playback;
    p.time = previous.time;
    p.speed = previous.speed;
    p.playing = previous.playing;
    p.loop = previous.loop;
    p.bind_pose = previous.bind_pose;
    p.loop_start = previous.loop_start;
    p.loop_end = previous.loop_end;
  }
  if (!app.graph_name.empty()) {
    if (Status s = use_graph(app, app.graph_name); !s) return s;
    for (const auto& [index, value] : graph_values) set_graph_value(*app.animator.graph, index, value);
    for (const auto& [index, value] : graph_vectors) (void)set_graph_vector(*app.animator.graph, index, value);
    app.animator.use_graph = used_graph || graph_values.empty();
  }
  // Mocap has no body and its bind is often a zero pose at the origin (BVH OFFSETs) while the
  // capture stands elsewhere; a prop may reach past the skeleton: frame what is shown.
  frame_camera(app, aspect);
  return {};
}

Status open_or_add(App& app, std::span<const std::string> paths, float aspect) {
  for (const std::string& p : paths) {
    Result<bool> has_mesh = file_has_mesh(p);
    if (!has_mesh) return has_mesh.error();
    if (*has_mesh) return open_scene(app, paths, app.crowd, aspect);
  }
  if (app.scene.assets.empty())
    return Error{paths.empty() ? "nothing to open" : paths.front() + ": has no mesh to show"};
  const size_t before = app.scene.clips.size();
  for (const std::string& p : paths) {
    if (Status s = add_clip_file(app.scene, p); !s) return s;
  }
  // Play the first clip added.
  return play_clip(app, static_cast<int>(before), true);
}

Status set_retarget(App& app, std::span<const std::string> files, const std::string& map_file, const std::string& clip,
                    float aspect) {
  std::unique_ptr<RetargetView> view;
  if (!files.empty()) {
    if (app.scene.assets.empty()) return Error{"--retarget-from: no character opened to retarget onto"};
    auto made = make_retarget_view(app.scene, files, map_file, clip);
    if (!made) return made.error();
    view = std::move(*made);
  }
  if (app.retarget) release_retarget_view(*app.retarget);
  app.retarget = std::move(view);
  frame_camera(app, aspect);
  return {};
}

void release_app_gpu(App& app) {
  if (app.retarget) release_retarget_view(*app.retarget);
  app.retarget.reset();
  destroy_renderer(app.renderer);
}

Status play_clip(App& app, int clip, bool crossfade) { return select_clip(app.scene, app.animator, clip, crossfade); }

Status step_cloth(App& app, float dt) {
  if (app.cloth.empty()) return {};
  // The cloth moves with the time played: none while paused, none for a graph banking no time.
  const Playback& p = app.animator.playback;
  const float played = app.animator.use_graph ? dt : (p.playing ? dt * std::fabs(p.speed) : 0.0f);
  return step_viewer_cloth(app.cloth, app.scene, app.animator, app.renderer.bind, app.offsets, played);
}

Status step_and_render(App& app, float dt, int width, int height, FrameTimings& timings) {
  advance(app.scene, app.animator, dt);
  PoseTimings pose;
  produce_local_poses(app.scene, app.animator, pose);
  if (app.retarget) {
    const Playback& p = app.animator.playback;
    retarget_poses(*app.retarget, app.animator, app.bind_box, p.playing && !p.bind_pose ? dt * p.speed : 0.0f);
  }
  compute_model_poses(app.scene, app.animator, pose);
  produce_morph_weights(app.scene, app.animator);
  timings.sample_ms += pose.sample_ms;
  timings.blend_ms += pose.blend_ms;
  timings.graph_ms += pose.graph_ms;

  // Follow instance 0's root over the ground, so a clip that travels stays in view.
  const auto& model = app.animator.instances.front().model;
  if (app.follow && !model.empty()) {
    glm::vec3 moved = glm::vec3(model[0][3]) - app.root_bind;
    moved.y = 0.0f;
    app.camera.target += moved - app.follow_applied;
    app.follow_applied = moved;
  }
  if (Status s = step_cloth(app, dt); !s) return s;
  if (app.toggles.procedural) {
    const float size = app.bind_box.empty() ? 1.0f : 0.5f * glm::length(app.bind_box.size());
    build_procedural_overlay(app.animator, app.offsets, size, app.active_handle, app.renderer.overlay);
  } else {
    app.renderer.overlay.clear();
  }
  if (app.show_cloth) build_cloth_overlay(app.cloth, app.animator, app.offsets, app.renderer.overlay);
  ViewToggles toggles = app.toggles;
  if (app.retarget && app.retarget->show_source) {
    // The source first, then the character over the same frame (its grid and overlays last).
    RetargetView& v = *app.retarget;
    if (app.toggles.mapping && !app.offsets.empty())
      build_mapping_lines(v, app.animator, app.offsets.front(), app.renderer.overlay);
    v.renderer.viewport_x = app.renderer.viewport_x;
    v.renderer.viewport_y = app.renderer.viewport_y;
    v.renderer.overlay.clear();
    ViewToggles source = app.toggles;
    source.grid = false;
    const glm::vec3 here(0.0f);
    if (Status s = render_frame(v.renderer, v.source, v.animator, std::span<const glm::vec3>(&here, 1), app.camera,
                                source, width, height, timings);
        !s)
      return s;
    toggles.keep_frame = true;
  }
  return render_frame(app.renderer, app.scene, app.animator, app.offsets, app.camera, toggles, width, height, timings,
                      &app.cloth);
}

}  // namespace ossa::view
