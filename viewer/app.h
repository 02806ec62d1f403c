// app.h — the viewer's state and its per-frame step, shared by the window and headless modes.
//
// One App holds the scene (opened files), its GPU form, the animator (clip playback for one
// character or a crowd), the camera and the view toggles. Both front ends do the same thing each
// frame — step_and_render — and differ only in where time and input come from and where the
// pixels go (a window, or an offscreen framebuffer written to a PNG).
#pragma once
#include <cstddef>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include <ossa/format/result.h>
#include "viewer/animation.h"
#include "viewer/bounds.h"
#include "viewer/camera.h"
#include "viewer/cloth_view.h"
#include "viewer/renderer.h"
#include "viewer/retarget_view.h"
#include "viewer/scene.h"

namespace ossa::view {

struct CameraAngles {
  float yaw = 0.5235988f;    // 30 degrees from the character's front: a three-quarter view
  float pitch = 0.1745329f;  // 10 degrees above
};

struct App {
  Scene scene;
  Renderer renderer;
  Animator animator;
  OrbitCamera camera;
  CameraAngles angles;         // from the character's front (facing): yaw 0 looks at its face
  Facing facing;               // which way the character faces (bounds.h), found when it is opened
  std::string front = "auto";  // --front: auto, or the axis it faces ("+z", "-z", "+x", "-x")
  ViewToggles toggles;
  std::vector<glm::vec3> offsets;  // instance placements (crowd grid), one per instance
  Box framing;                     // what the camera frames: one character as shown, a crowd in its bind pose
  Box bind_box;                    // one character in its bind pose (crowd spacing, the floor)
  size_t crowd = 1;
  bool follow = true;                      // keep the camera on instance 0's root as it moves (crowd: off)
  glm::vec3 root_bind{0.0f};               // instance 0's root in the bind pose
  glm::vec3 follow_applied{0.0f};          // how far follow has moved the camera target so far
  std::vector<std::string> messages;       // warnings and errors for the panel / stderr
  std::string graph_name;                  // --graph: re-instantiated when the crowd or the files change
  int active_handle = -1;                  // the target gizmo being dragged (ProceduralInfo::targets), or -1
  ViewerCloth cloth;                       // the character's cloth, per instance (cloth_view.h)
  bool show_cloth = false;                 // the cloth overlay: particles, edges, colliders
  std::unique_ptr<RetargetView> retarget;  // --retarget-from: a clip of another rig drives the character
};

/// Replaces the scene with `paths` (scene.h load_scene), uploads it, builds the crowd and frames
/// the camera for the given aspect ratio. On error the App keeps its previous scene. The renderer
/// must exist (create_renderer).
Status open_scene(App& app, std::span<const std::string> paths, size_t crowd, float aspect);
/// The same for a scene already loaded (the headless mode opens files before it makes a context).
Status open_loaded_scene(App& app, Scene scene, size_t crowd, float aspect);

/// Rebuilds the animator for `crowd` instances (keeping the clip, its time and playback
/// settings), lays them out on a grid, and re-frames the camera and the grid.
Status set_crowd(App& app, size_t crowd, float aspect);

/// Dropped / typed paths: if one has a mesh they replace the scene; otherwise their clips are
/// added to the current character.
Status open_or_add(App& app, std::span<const std::string> paths, float aspect);

/// Points the camera at app.framing from app.angles (turned by app.facing). One character (crowd 1)
/// is first re-framed on its skinned vertices (bounds.h) over the whole clip (48 poses, each moved
/// back by the root's travel, then placed where the root is now), plus the pose shown now (a graph
/// pose: graphs cannot seek).
void frame_camera(App& app, float aspect);

/// Instantiates graph `name` (graph_driver.h) for every instance and lets it drive the poses.
/// Errors name the files (the App keeps its previous pose source then). Each graph instance is
/// told where its character stands (GraphInstance::set_transform: its crowd placement), so
/// world-space targets, foot locks and springs act where it is drawn.
Status use_graph(App& app, const std::string& name);

/// Retarget mode (retarget_view.h): the clip `clip` (empty: the first) of the source `files`
/// drives the character, the source drawn beside it. Replaces any previous source; errors leave
/// the App as it was. Empty `files`: back to the character's own clips.
Status set_retarget(App& app, std::span<const std::string> files, const std::string& map_file, const std::string& clip,
                    float aspect);

/// Frees the GPU objects the App holds (the renderer, a retarget source's); the context must be current.
void release_app_gpu(App& app);

/// Selects a clip by index (-1: none) with an optional cross-fade.
Status play_clip(App& app, int clip, bool crossfade);

/// Steps the cloth (cloth_view.h) by the time dt plays (dt * |speed| for clips, 0 paused), from
/// the animator's current model matrices. Errors name the file.
Status step_cloth(App& app, float dt);

/// Advances playback by dt (when playing), produces this frame's poses, steps the cloth by the
/// time played (cloth_view.h), follows the character, builds the procedural and cloth overlays (toggles.procedural,
/// procedural_draw.h) and draws into the bound framebuffer. Timings accumulate into `timings`.
Status step_and_render(App& app, float dt, int width, int height, FrameTimings& timings);

}  // namespace ossa::view
