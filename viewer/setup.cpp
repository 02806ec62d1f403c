// setup.cpp — see setup.h.
#include "viewer/setup.h"

#include "viewer/montage_control.h"

#include <cmath>
#include <cstdio>
#include <utility>

#include <glm/gtc/constants.hpp>

#include "viewer/window.h"

namespace ossa::view {

void apply_view_options(App& app, const ViewerOptions& o) {
  app.angles.yaw = glm::radians(o.yaw_degrees);
  app.angles.pitch = glm::radians(o.pitch_degrees);
  app.front = o.front;
  app.toggles.cpu_skinning = o.cpu_skinning;
  app.toggles.wireframe = o.wireframe;
  app.toggles.skeleton = o.skeleton;
  app.toggles.grid = o.grid;
  app.toggles.procedural = o.show_procedural || !o.headless();  // on in the window, asked for in images
  app.cloth.enabled = o.cloth;
  app.show_cloth = o.show_cloth;
  if (o.wind.size() == 3) app.cloth.wind = glm::vec3(o.wind[0], o.wind[1], o.wind[2]);
  app.toggles.mapping = o.show_mapping || !o.headless();
}

Status setup_app(App& app, Scene scene, const ViewerOptions& o, float aspect) {
  const std::string name = o.files.front();
  apply_view_options(app, o);
  if (Status s = open_loaded_scene(app, std::move(scene), o.crowd, aspect); !s) return s;
  if (!o.quiet)
    for (const std::string& w : app.messages) std::fprintf(stderr, "ossa-view: warning: %s\n", w.c_str());
  if (o.verbose) {
    const SceneCounts c = count(app.scene);
    std::fprintf(stderr, "ossa-view: %s\n", gl_description().c_str());
    std::fprintf(
        stderr, "ossa-view: %s: %zu joints, %zu meshes, %zu vertices, %zu triangles; %zu clips from %zu files\n",
        name.c_str(), c.joints, c.meshes, c.vertices, c.triangles, app.scene.clips.size(), app.scene.assets.size());
    const char* why = app.facing.from_feet ? "from the feet"
                      : o.front == "auto"  ? "the feet do not tell: glTF's +z"
                                           : "--front";
    std::fprintf(stderr, "ossa-view: front: %s (%s, lopsided by %.3f of the height); camera yaw %.0f deg\n",
                 axis_name(app.facing.forward), why, app.facing.evidence,
                 std::remainder(glm::degrees(app.facing.yaw + app.angles.yaw), 360.0f));
  }

  if (!o.clip.empty()) {
    const int c = find_clip(app.scene, o.clip);
    if (c < 0) {
      std::string names;
      for (const SceneClip& sc : app.scene.clips) names += (names.empty() ? "'" : ", '") + sc.label + "'";
      return Error{name + ": no clip named '" + o.clip + "' (clips: " + (names.empty() ? "none" : names) + ")"};
    }
    if (Status s = play_clip(app, c, false); !s) return s;
  }
  if (!o.graph.empty()) {
    if (Status s = use_graph(app, o.graph); !s) return s;
    for (const std::string& assignment : o.set) {
      const size_t eq = assignment.find('=');
      const std::string parameter = assignment.substr(0, eq);
      const std::string value = eq == std::string::npos ? "1" : assignment.substr(eq + 1);
      if (Status s = set_graph_parameter(*app.animator.graph, parameter, value); !s)
        return Error{name + ": " + s.message()};
    }
    if (Status s = add_montage_commands(*app.animator.graph, o.montage, o.montage_next, o.montage_jump); !s)
      return Error{name + ": " + s.message()};
  }
  for (const auto& [morph, weight] : o.morphs) {
    const int c = find_morph_channel(app.scene, morph);
    if (c < 0) {
      std::string names;
      for (std::string_view n : app.scene.morph_channels) names += (names.empty() ? "'" : ", '") + std::string(n) + "'";
      return Error{name + ": no morph target named '" + morph +
                   "' (morph targets: " + (names.empty() ? "none" : names) + ")"};
    }
    hold_morph(app.animator, static_cast<size_t>(c), true, weight);
  }
  if (!o.retarget_from.empty()) {
    if (Status s = set_retarget(app, o.retarget_from, o.retarget_map, o.retarget_clip, aspect); !s) return s;
    set_time(app.retarget->source, app.retarget->animator, o.time);
  }
  if (o.move != 0.0f || !o.turn.empty()) {  // --move / --turn: the character's motion through the world
    Drive& d = app.animator.drive;
    const float metres = app.scene.character().file().metres_per_unit();
    d.speed = o.move / (metres > 0.0f ? metres : 1.0f);
    d.forward = app.facing.forward;
    if (const auto turn = parse_turn(o.turn)) {
      d.turn_rate = glm::radians(turn->first);
      d.turn_after = turn->second;
    }
  }
  Playback& p = app.animator.playback;
  p.bind_pose = o.bind_pose;
  p.speed = o.speed;
  p.playing = !o.paused;
  set_time(app.scene, app.animator, o.time);
  frame_camera(app, aspect);  // the clip, the time and the pose are chosen: frame what is shown
  return {};
}

}  // namespace ossa::view
