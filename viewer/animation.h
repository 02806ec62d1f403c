// animation.h — what moves the character: clip playback for one or many instances, and the one
// per-frame step that produces their local poses.
//
// produce_local_poses is the viewer's single "where does this frame's pose come from" point: it
// writes the bind pose, samples the selected clip (cross-fading for a moment after the clip
// changes), or updates an animation graph (graph_driver.h) and copies its output pose.
// Everything after it (local -> model, palettes, drawing) does not care where the pose came from.
//
// A crowd is N instances of the same character playing the same clip at different phases; each
// has its own sampling caches (ossa/anim/sample.h: one cache per clip and playing instance) and pose
// storage, allocated when a clip is selected, never per frame.
//
// Morph weights follow the same path beside the pose: produce_morph_weights gives every instance
// its channels' weights (scene.h binds channels by name): the targets' defaults, overwritten by
// the selected clip's weight tracks at the instance's own time (cross-faded like the pose), then
// by the channels the user holds (the panel's sliders, --morph). Under a graph the weights are the
// graph's output weights (GraphInstance::morph_weights), then the held channels.
#pragma once
#include <cstddef>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include <ossa/format/result.h>
#include <ossa/anim/pose.h>
#include <ossa/anim/sample.h>
#include "viewer/graph_driver.h"
#include "viewer/scene.h"

namespace ossa::view {

struct Playback {
  int clip = -1;       // index into Scene::clips; -1: none (bind pose)
  float time = 0.0f;   // seconds into the clip, for instance 0
  float speed = 1.0f;  // playback rate (negative plays backwards)
  bool playing = true;
  bool loop = true;
  bool bind_pose = false;  // show the skeleton's bind pose instead of the clip
  // The timeline's loop range (layout.h): with loop on, playback wraps within [loop_start,
  // loop_end] when loop_end > loop_start; otherwise over the whole clip. Reset by select_clip.
  float loop_start = 0.0f;
  float loop_end = 0.0f;
  // Cross-fade from the previously selected clip, which keeps playing until the fade ends.
  int from_clip = -1;
  float from_time = 0.0f;
  float fade = 1.0f;  // 0 -> 1 over fade_seconds; 1: no fade in progress
  float fade_seconds = 0.25f;
};

struct AnimInstance {
  float time_offset = 0.0f;  // phase of this instance relative to Playback::time
  SamplingCache cache, from_cache;
  Pose local, from_local;
  std::vector<glm::mat4> model;                          // model-space joint matrices, one per skeleton joint
  std::vector<float> morph_weights, from_morph_weights;  // one per morph channel (scene.h)
};

/// Channels the user holds at a weight (panel sliders, --morph); the others follow the clip.
struct MorphOverrides {
  std::vector<uint8_t> held;  // one per morph channel
  std::vector<float> value;
};

/// The character's own motion through the world (--move, --turn): what a game does with an
/// in-place clip, moving and turning the character's world transform as the clip plays. `world`
/// (a turn about +Y through the model's origin, then the distance travelled) is applied to every
/// instance's model matrices by compute_model_poses, so the drawing, the overlays and the camera's
/// follow all see it, and the cloth (cloth_view.h) receives it as its model-to-world transform.
struct Drive {
  float speed = 0.0f;      // model units per second along the heading
  float turn_rate = 0.0f;  // radians per second about +Y, once `turn_after` seconds have played
  float turn_after = 0.0f;
  glm::vec3 forward{0.0f, 0.0f, 1.0f};  // the character's front (bounds.h facing_of)
  float clock = 0.0f;                   // seconds played
  float heading = 0.0f;                 // radians turned so far
  glm::vec3 position{0.0f};             // distance travelled, model units
  glm::mat4 world{1.0f};                // translate(position) * rotate(heading about +Y)
  bool active() const { return speed != 0.0f || turn_rate != 0.0f; }
};
/// Moves the drive on by `played` seconds (in 1/240 s steps, so the path does not depend on the
/// frame rate beyond that) and updates its world transform.
void advance_drive(Drive& drive, float played);

struct Animator {
  Playback playback;
  Drive drive;  // --move / --turn: the character's motion through the world
  std::vector<AnimInstance> instances;
  std::unique_ptr<GraphDriver> graph;  // --graph: one graph instance per AnimInstance
  bool use_graph = false;              // the graph drives the poses (else the clip list does)
  float graph_dt = 0.0f;               // time advance() banked for the next graph update
  MorphOverrides morph_overrides;
};

/// Instances with bind-pose storage and phases spread over the clip (instance i starts i * 0.618
/// of a loop later). No clip selected yet.
Animator make_animator(const Scene& scene, size_t instance_count);

/// Selects clip `clip` (-1: none) for every instance and rewinds to time 0; with `crossfade` the
/// previous clip fades out over playback.fade_seconds. Errors when a cache cannot be made.
Status select_clip(const Scene& scene, Animator& animator, int clip, bool crossfade);

/// Duration of the selected clip (0 without one).
float clip_duration(const Scene& scene, const Animator& animator);

/// Moves time by dt * speed when playing (wrapping or clamping as playback.loop says; with loop on
/// and a loop range, wrapping within it) and the
/// cross-fade by dt; banks dt * max(speed, 0) for the graph (graphs only run forwards).
void advance(const Scene& scene, Animator& animator, float dt);

/// `time` wrapped into [lo, hi] (a time inside stays as it is, hi included); `lo` when hi <= lo.
float loop_time(float time, float lo, float hi);

/// Sets the clip time (scrub, --time): wrapped or clamped into the clip.
void set_time(const Scene& scene, Animator& animator, float time);

struct PoseTimings {
  double sample_ms = 0.0;  // sampling clips
  double blend_ms = 0.0;   // blending (cross-fade) and local -> model
  double graph_ms = 0.0;   // graph updates (their sampling and blending are inside)
};

/// This frame's local pose of every instance: the bind pose, the graph's output, the selected
/// clip sampled at each instance's time, or the cross-fade of the previous and the selected clip.
/// Allocation-free (but for the graph's event log).
void produce_local_poses(const Scene& scene, Animator& animator, PoseTimings& timings);

/// This frame's morph weights of every instance (AnimInstance::morph_weights): defaults, the
/// selected clip's tracks at each instance's time (cross-faded as the pose is), held channels.
/// Allocation-free. O(instances * (channels + tracks * log keys)).
void produce_morph_weights(const Scene& scene, Animator& animator);

/// Holds channel `channel` at `weight` (held = true) or lets the clip drive it again.
void hold_morph(Animator& animator, size_t channel, bool held, float weight);

/// Local -> model matrices of every instance (AnimInstance::model). Allocation-free.
void compute_model_poses(const Scene& scene, Animator& animator, PoseTimings& timings);

}  // namespace ossa::view
