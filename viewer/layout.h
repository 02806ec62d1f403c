// layout.h — where things go in the window: the 3D scene beside the panel, the timeline strip
// under it, and how large the panel's text is drawn; and what the timeline strip shows.
//
// The window is split: the ImGui panel takes a strip on the left (none when collapsed), the
// timeline a strip at the bottom of what remains (none without a clip), and the scene is drawn in
// the rest, so the panel never hides the character. Everything that maps between the scene and
// the screen (glViewport, the projection's aspect ratio, camera framing, orbit / pan / gizmo
// picking) takes its numbers from one SceneLayout, computed once per frame. The timeline lives
// here too because it is part of the layout: its height decides the scene's, both are measured in
// the same window units and scaled by the same UI scale.
//
// Two coordinate systems meet here: GLFW's window coordinates (what the cursor, ImGui and the
// panel width are in; top-left origin) and framebuffer pixels (what glViewport takes; bottom-left
// origin). They differ on HiDPI screens where the framebuffer is larger than the window (macOS,
// Wayland), so the layout holds both.
//
// The timeline shows what a cooked clip holds: a tick at every frame some channel keeps a key for
// (taller where more channels key it), so clip compression is visible at a glance, and a marker
// per clip event (ossa.fbs ClipEvent) that names the event when hovered. The playhead is dragged
// to scrub (set_time); two handles above the track set Playback::loop_start / loop_end, within
// which playback wraps when loop is on (animation.h advance). It is drawn with ImGui draw lists in
// an undecorated window pinned to SceneLayout::timeline. The geometry (regions, time <-> x, which
// handle a press grabs) and the key list are plain functions, checked by
// tests/viewer/viewer_unit_test_window.cpp; the keys are computed once per clip, not per frame.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <ossa/loader/asset.h>
#include "viewer/app.h"

namespace ossa::view {

/// A rectangle in window coordinates (top-left origin, y down).
struct Rect {
  float x = 0.0f, y = 0.0f, width = 0.0f, height = 0.0f;
  bool contains(float px, float py) const { return px >= x && py >= y && px < x + width && py < y + height; }
};

struct SceneLayout {
  Rect scene;     // the 3D view, window coordinates
  Rect timeline;  // the strip under it (height 0 when there is none)
  // The scene in framebuffer pixels, for glViewport (bottom-left origin).
  int fb_x = 0, fb_y = 0, fb_width = 1, fb_height = 1;
  float aspect = 1.0f;  // fb_width / fb_height: the projection's aspect ratio
};

/// The layout of a window `window_w` x `window_h` (window coordinates) whose framebuffer is
/// `fb_w` x `fb_h` pixels, with a panel `panel_width` wide on the left (0: collapsed) and a
/// timeline `timeline_height` high under the scene (0: none). The scene keeps at least one pixel
/// each way however large the panel is.
SceneLayout compute_layout(int window_w, int window_h, int fb_w, int fb_h, float panel_width, float timeline_height);

/// The size factor for the panel's text and widgets in window coordinates: the monitor's content
/// scale (glfwGetWindowContentScale: 2 on a 200 % screen) divided by how many framebuffer pixels a
/// window unit holds (2 on macOS Retina, where window coordinates are already points; 1 on X11 and
/// Windows). Clamped to 0.5..4; a non-positive or non-finite input counts as 1.
float ui_scale_for(float content_scale, float framebuffer_per_window);

// ---- what the timeline shows

struct KeyMark {
  float time = 0.0f;      // seconds
  uint32_t channels = 0;  // animated channels with a key at this frame
};
struct EventMark {
  std::string name;
  float time = 0.0f;
};

/// The clip's key frames as times (frame / sample rate, within the duration), one per frame that
/// any animated channel keys, sorted; a clip without animated channels gives one mark at 0.
std::vector<KeyMark> clip_key_marks(const ClipView& clip);
/// The clip's events (sorted by time, as stored).
std::vector<EventMark> clip_event_marks(const ClipView& clip);

// ---- the timeline strip

/// Where time `t` of a clip `duration` long lies on a track from x0, `width` wide (clamped).
float time_to_x(float t, float duration, float x0, float width);
/// The inverse, clamped to [0, duration].
float x_to_time(float x, float duration, float x0, float width);

enum class TimelineGrab { kNone, kPlayhead, kLoopStart, kLoopEnd };
/// What a press at x grabs when the press is in the handle row (`in_handle_row`): the nearer loop
/// handle within `reach` pixels; otherwise (or when none is near) the playhead, which jumps there.
TimelineGrab timeline_grab(float x, bool in_handle_row, float loop_start_x, float loop_end_x, float reach);

struct TimelineState {
  const void* clip = nullptr;  // the clip whose marks are cached (ClipView::fb)
  std::vector<KeyMark> keys;
  std::vector<EventMark> events;
  TimelineGrab dragging = TimelineGrab::kNone;
  bool was_playing = false;  // playback is paused while the playhead is dragged
};

/// The strip's height in window units for the UI scale, or 0 when nothing is shown (no clip
/// selected; or a graph without montages drives the character, whose montages are shown otherwise:
/// montage_panel.h).
float timeline_height(const App& app, float ui_scale);

/// Draws the timeline into `strip` and applies the user's drags to app's playback (a graph driving
/// the character: its montage timeline, montage_panel.h).
void timeline_panel(App& app, TimelineState& state, const Rect& strip, float ui_scale);

}  // namespace ossa::view
