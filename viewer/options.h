// options.h — the ossa-view command line.
//
//   ossa-view FILE.ossa [MORE.ossa ...] [--clip NAME] [--time T] [--speed S] [--paused]
//             [--bind-pose] [--cpu-skinning] [--crowd N] [--wireframe] [--skeleton] [--no-grid]
//             [--yaw DEG] [--pitch DEG] [--front auto|+z|-z|+x|-x] [--size WxH] [--msaa N]
//             [--frames N] [--screenshot OUT.png] [--first-frame-time] [--stats]
//             [--window-frames N] [--graph NAME [--set|--param PARAM=VALUE ...] [--show-procedural]
//              [--montage NAME[@T] [--montage-next SECTION=NEXT[@T]] [--montage-jump SECTION[@T]]]]
//             [--morph NAME=WEIGHT ...] [--move M_PER_S] [--turn DEG_PER_S[@AFTER]]
//             [--retarget-from SOURCE.ossa ... [--retarget-map MAP.json] [--retarget-clip NAME] [--show-mapping]]
//             [--panel open|collapsed] [--ui-scale S] [--browse DIR] [--cook-and-open SOURCE ...]
//             [-q | -v] [--version] [--help]
//   ossa-view [--browse DIR] [--cook-and-open SOURCE ...] [...]     (the window, no file yet)
//
// --move and --turn move the character through the world as a game moves one playing an in-place
// clip (animation.h Drive): forwards at M_PER_S metres per second, turning DEG_PER_S degrees per
// second about +Y once AFTER seconds have played; the cloth receives the turn in its world transform.
// --yaw turns the camera from the character's front: auto-detected from its feet (bounds.h
// facing_of; +Z when they do not tell), or named with --front.
// With --frames or --screenshot the viewer runs headless (hidden window, offscreen framebuffer):
// it renders N frames 1/60 s apart ending at --time, writes the last one as a PNG, and exits.
// --window-frames N runs the window mode (panel included) for N frames and exits, writing the
// window's last frame to --screenshot if given: how the interactive path is tested.
// --graph NAME drives the character with an animation graph found in any of the files; --set
// (or its alias --param) gives its parameters start values (a trigger is fired by naming it: --set
// stop; a vector parameter takes three numbers: --param look_target=150,160,100). --show-procedural
// draws the procedural nodes' overlays in headless images too: IK / aim targets, the ground
// under each placed foot, spring chains and colliders (procedural_draw.h). A graph cannot
// seek, so headless --time T plays T seconds of the graph in 1/60 s steps before the N frames.
// --montage NAME@T plays the graph's montage NAME (format v9) once the graph has played T seconds
// (default 0); --montage-next SECTION=NEXT@T and --montage-jump SECTION@T change its section links
// or jump at their times (montage_control.h), so a headless image can show a montage at any point.
// --retarget-from SOURCE.ossa (repeatable: the source character, then clip files cooked for it)
// plays a clip of another humanoid rig on the character through the live retarget job, the
// source drawn beside it (retarget_view.h); --retarget-map names a humanoid map file for rigs whose
// joint names do not say, --retarget-clip the source clip, and --show-mapping draws the lines
// between mapped joints in headless images too (the window shows them by default; the panel's
// Retarget section toggles them). --time, --speed and --paused apply to the source clip too.
// --morph NAME=WEIGHT holds a morph target channel (every target of that name) at WEIGHT, as the
// panel's slider does: clips no longer drive it; repeatable; a name the character lacks is an
// error listing the names it has.
// The window's panel is a sidebar the scene is laid out beside (layout.h); --panel collapsed starts
// with it hidden (Tab toggles it), --ui-scale S sizes its text and widgets (default: the monitor's
// content scale, ui_scale_for). --browse DIR starts the panel's file browser in DIR (default: the
// first file's folder, else the current directory) with its section open. --cook-and-open SOURCE
// cooks a source file (FBX, glTF, GLB, DAE, BVH, OBJ) with ossa-cook in the background, as a
// dropped source is, and opens the result; repeatable. The window needs no file to start: without
// one it shows the browser (and what --cook-and-open makes once cooked).
// With --window-frames N, the N frames are counted once no cook or open is pending, so a test
// captures the cooked character; a failed cook is the panel's error status, which makes the exit
// status 1 (the message, the cooker's own, on stderr). -v also prints the layout of the captured
// frame ("layout: panel P, scene X Y W H, timeline H") and what was cooked and opened, with times.
// -q prints only errors (no warnings such as a texture left out); -v adds the OpenGL version and
// renderer and what was loaded. Parsing is separate from running so tests and the bench can build
// command lines with the same names.
//
// Exit status (tools/cli/cli.h): 0 success; 1 the files could not be shown (a file refused,
// a clip / graph / parameter not found, a GL error, the screenshot not written); 2 usage error, or
// no OpenGL 3.3 window can be made (no display).
#pragma once
#include <optional>
#include <string>
#include <utility>
#include <vector>

namespace ossa::view {

struct ViewerOptions {
  std::vector<std::string> files;
  std::string clip;   // empty: the first clip
  float time = 0.0f;  // clip time (s) of the captured frame / where playback starts
  float speed = 1.0f;
  bool paused = false;
  bool bind_pose = false;
  bool cpu_skinning = false;
  bool cloth = true;        // --cloth off: cloth meshes drawn as skinned (to compare)
  bool show_cloth = false;  // --show-cloth: the cloth overlay (particles, edges, colliders)
  std::vector<float> wind;  // --wind X,Y,Z: metres per second, world space
  float move = 0.0f;        // --move: metres per second forwards (animation.h Drive)
  std::string turn;         // --turn DEG_PER_S[@AFTER]: turning, from AFTER seconds of play on
  unsigned crowd = 1;
  bool wireframe = false;
  bool skeleton = false;
  bool grid = true;
  float yaw_degrees = 30.0f;   // from the character's front (--front)
  std::string front = "auto";  // --front: auto (bounds.h facing_of) or +z, -z, +x, -x
  float pitch_degrees = 10.0f;
  int width = 1280;
  int height = 720;
  int msaa = 4;
  int frames = 0;                 // headless: frames to render (default 1 with --screenshot)
  std::string screenshot;         // headless: PNG to write
  bool first_frame_time = false;  // print "first-frame-ms X" (since main) once the first frame is finished
  bool stats = false;             // headless: print the frame-time split
  int window_frames = 0;          // window mode: exit after this many frames (0: when closed)
  std::string graph;              // drive the character with this graph
  std::vector<std::string> set;   // graph parameter start values, "name=value" (or "trigger"; a vector "name=x,y,z")
  bool show_procedural = false;   // headless: draw the procedural overlays (the window shows them by default)
  std::vector<std::string> retarget_from;  // --retarget-from: the source character and its clip files
  std::string retarget_map;                // --retarget-map: a humanoid map file (tools/retarget/map_file.h)
  std::string retarget_clip;               // --retarget-clip: the source clip (empty: its first)
  bool show_mapping = false;               // headless: draw the retarget mapping (the window shows it by default)
  std::vector<std::string> montage;        // --montage NAME[@T]: montages played at graph times
  std::vector<std::string> montage_next;   // --montage-next SECTION=NEXT[@T]
  std::vector<std::string> montage_jump;   // --montage-jump SECTION[@T]
  std::vector<std::pair<std::string, float>> morphs;  // --morph: channels held at a weight
  bool panel_collapsed = false;                       // --panel collapsed: the window starts with the panel hidden
  float ui_scale = 0.0f;                   // --ui-scale: panel size factor (0: from the monitor's content scale)
  std::string browse;                      // --browse: the file browser's first folder (empty: the default)
  std::vector<std::string> cook_and_open;  // --cook-and-open: sources cooked in the background, then opened
  bool quiet = false;                      // -q: errors only
  bool verbose = false;                    // -v: GL information and what was loaded

  bool headless() const { return window_frames == 0 && (frames > 0 || !screenshot.empty()); }
};

/// The parsed options, or the exit status to end with right away (help or version printed: 0; a
/// usage error printed: 2).
struct ParsedOptions {
  std::optional<ViewerOptions> options;
  int exit_code = 0;
};
ParsedOptions parse_options(int argc, const char* const* argv);

/// "smile=0.5" -> ("smile", 0.5); nullopt without a name, an '=' or a finite weight within
/// +-1000 (the loader's bound on stored weights).
std::optional<std::pair<std::string, float>> parse_morph(const std::string& text);

/// "640x480" -> (640, 480); nullopt unless both are in 1..16384.
std::optional<std::pair<int, int>> parse_size(const std::string& text);

/// "90@1.5" -> (90, 1.5), "-45" -> (-45, 0); nullopt unless finite, |rate| <= 3600, after >= 0.
std::optional<std::pair<float, float>> parse_turn(const std::string& text);

}  // namespace ossa::view
