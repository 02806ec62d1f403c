// options.cpp — see options.h. CLI11 does the parsing through tools/cli (the conventions
// every ossa tool shares); its exceptions stay inside that library.
#include "viewer/options.h"

#include <charconv>
#include <cmath>

#include "tools/cli/cli.h"

namespace ossa::view {
namespace {
constexpr float kMaxSeconds = 3600.0f;
constexpr float kMaxMorphWeight = 1000.0f;  // runtime/internal/validator.h kMaxMorphWeight
}  // namespace

std::optional<std::pair<int, int>> parse_size(const std::string& text) {
  const size_t x = text.find('x');
  if (x == std::string::npos) return std::nullopt;
  int w = 0, h = 0;
  const char* b = text.data();
  const auto rw = std::from_chars(b, b + x, w);
  const auto rh = std::from_chars(b + x + 1, b + text.size(), h);
  if (rw.ec != std::errc() || rw.ptr != b + x || rh.ec != std::errc() || rh.ptr != b + text.size()) return std::nullopt;
  if (w < 1 || h < 1 || w > 16384 || h > 16384) return std::nullopt;
  return std::make_pair(w, h);
}

std::optional<std::pair<float, float>> parse_turn(const std::string& text) {
  const size_t at = text.find('@');
  const auto number = [](std::string_view t) -> std::optional<float> {
    float v = 0.0f;
    const auto r = std::from_chars(t.data(), t.data() + t.size(), v);
    if (t.empty() || r.ec != std::errc() || r.ptr != t.data() + t.size() || !std::isfinite(v)) return std::nullopt;
    return v;
  };
  const auto rate = number(std::string_view(text).substr(0, at));
  const auto after =
      at == std::string::npos ? std::optional<float>(0.0f) : number(std::string_view(text).substr(at + 1));
  if (!rate || !after || std::fabs(*rate) > 3600.0f || *after < 0.0f || *after > kMaxSeconds) return std::nullopt;
  return std::make_pair(*rate, *after);
}

std::optional<std::pair<std::string, float>> parse_morph(const std::string& text) {
  const size_t eq = text.rfind('=');
  if (eq == std::string::npos || eq == 0 || eq + 1 == text.size()) return std::nullopt;
  float w = 0.0f;
  const char* b = text.data() + eq + 1;
  const char* e = text.data() + text.size();
  const auto r = std::from_chars(b, e, w);
  if (r.ec != std::errc() || r.ptr != e || !std::isfinite(w) || std::fabs(w) > kMaxMorphWeight) return std::nullopt;
  return std::make_pair(text.substr(0, eq), w);
}

ParsedOptions parse_options(int argc, const char* const* argv) {
  cli::Command command("ossa-view",
                       "ossa-view: look at cooked .ossa characters and play their clips; the window also cooks sources "
                       "dropped on it (GLFW + OpenGL 3.3)",
                       "when the files could not be shown (a file refused, a name not found, a GL error)");
  CLI::App& app = command.app();
  ViewerOptions o;
  std::string size;
  bool no_grid = false;
  app.add_option("files", o.files,
                 "a character .ossa, then any clip files cooked for its skeleton (the window may start without)");
  app.add_option("--clip", o.clip, "start with this clip (its name)");
  app.add_option("--time", o.time, "clip time in seconds (headless: of the captured frame)");
  app.add_option("--speed", o.speed, "playback rate");
  app.add_flag("--paused", o.paused, "start paused");
  app.add_flag("--bind-pose", o.bind_pose, "show the bind pose instead of the clip");
  app.add_flag("--cpu-skinning", o.cpu_skinning, "skin on the CPU with the runtime's skin_cpu (reference path)");
  std::string cloth = "on";
  app.add_option("--cloth", cloth, "simulate the character's cloth (on), or draw it as skinned (off)")
      ->check(CLI::IsMember({"on", "off"}));
  app.add_flag("--show-cloth", o.show_cloth, "draw the cloth's particles, edges and colliders");
  app.add_option("--wind", o.wind, "wind for the cloth, X,Y,Z metres per second (world space)")
      ->delimiter(',')
      ->expected(3);
  app.add_option("--move", o.move, "move the character forwards at this many metres per second (an in-place clip runs)")
      ->check(CLI::Range(-100.0f, 100.0f));
  app.add_option("--turn", o.turn,
                 "turn the character DEG_PER_S degrees per second about +Y, from AFTER seconds of play "
                 "on (DEG_PER_S[@AFTER]); the cloth feels the turn");
  app.add_option("--crowd", o.crowd, "draw N instances with offset times, instanced")->check(CLI::Range(1u, 4096u));
  app.add_flag("--wireframe", o.wireframe, "wireframe overlay");
  app.add_flag("--skeleton", o.skeleton, "skeleton overlay");
  app.add_flag("--no-grid", no_grid, "no ground grid");
  app.add_option("--yaw", o.yaw_degrees, "camera yaw in degrees from the character's front (0: facing it)");
  app.add_option("--front", o.front, "which way the character faces: auto (from its feet, bounds.h) or +z, -z, +x, -x")
      ->check(CLI::IsMember({"auto", "+z", "-z", "+x", "-x"}));
  app.add_option("--pitch", o.pitch_degrees, "camera elevation in degrees")->check(CLI::Range(-89.0f, 89.0f));
  app.add_option("--size", size, "window / image size, WxH (default 1280x720)");
  app.add_option("--msaa", o.msaa, "multisampling (1: off)")->check(CLI::Range(1, 16));
  app.add_option("--frames", o.frames, "headless: render N frames, 1/60 s apart, ending at --time")
      ->check(CLI::Range(1, 100000));
  app.add_option("--screenshot", o.screenshot, "headless: write the last frame to this PNG");
  app.add_flag("--first-frame-time", o.first_frame_time, "print first-frame-ms once the first frame is finished");
  app.add_flag("--stats", o.stats, "headless: print the average frame-time split and how cloth was drawn");
  app.add_option("--graph", o.graph, "drive the character with the animation graph of this name");
  app.add_option("--set,--param", o.set,
                 "graph parameter start value, NAME=VALUE (a trigger: NAME; a vector: NAME=X,Y,Z); repeatable")
      ->needs("--graph")
      ->allow_extra_args(false);  // one value per --set: the files may follow
  app.add_flag("--show-procedural", o.show_procedural,
               "draw the procedural overlays (targets, ground under the feet, springs) in headless images too")
      ->needs("--graph");
  app.add_option("--montage", o.montage,
                 "play the graph's montage NAME when the graph's time reaches T (default 0); repeatable")
      ->type_name("NAME[@T]")
      ->needs("--graph")
      ->allow_extra_args(false);
  app.add_option("--montage-next", o.montage_next,
                 "at graph time T, link the last --montage's SECTION to NEXT (NEXT empty: the end); repeatable")
      ->type_name("SECTION=NEXT[@T]")
      ->needs("--montage")
      ->allow_extra_args(false);
  app.add_option("--montage-jump", o.montage_jump, "at graph time T, jump the last --montage to SECTION; repeatable")
      ->type_name("SECTION[@T]")
      ->needs("--montage")
      ->allow_extra_args(false);
  app.add_option("--retarget-from", o.retarget_from,
                 "play a clip of this humanoid character on the opened one, drawn beside it (repeatable: the source "
                 "character, then clip files cooked for it)")
      ->allow_extra_args(false);
  app.add_option("--retarget-map", o.retarget_map, "a humanoid map file for --retarget-from (docs/RETARGET.md)")
      ->needs("--retarget-from");
  app.add_option("--retarget-clip", o.retarget_clip, "the source clip --retarget-from plays (default: its first)")
      ->needs("--retarget-from");
  app.add_flag("--show-mapping", o.show_mapping, "draw the retarget's joint mapping in headless images too")
      ->needs("--retarget-from");
  std::vector<std::string> morphs;
  app.add_option("--morph", morphs,
                 "hold the morph targets named NAME at WEIGHT (clips no longer drive them); repeatable")
      ->type_name("NAME=WEIGHT")
      ->allow_extra_args(false);  // one value per --morph: the files may follow
  app.add_option("--window-frames", o.window_frames,
                 "window mode: exit after N frames (--screenshot captures the window)")
      ->check(CLI::Range(1, 1000000));
  std::string panel;
  app.add_option("--panel", panel, "window: start with the panel open or collapsed (Tab toggles it)")
      ->check(CLI::IsMember({"open", "collapsed"}));
  app.add_option("--ui-scale", o.ui_scale, "window: panel text and widget size (default: the monitor's content scale)")
      ->check(CLI::Range(0.5f, 4.0f));
  app.add_option("--browse", o.browse, "window: start the panel's file browser in this folder");
  app.add_option(
         "--cook-and-open", o.cook_and_open,
         "window: cook this source (FBX, glTF, GLB, DAE, BVH, OBJ) with ossa-cook in the background, then open it; "
         "repeatable")
      ->allow_extra_args(false);
  if (const auto exit_now = command.parse(argc, argv)) return {std::nullopt, *exit_now};
  o.panel_collapsed = panel == "collapsed";
  o.quiet = command.quiet();
  o.verbose = command.verbose();
  if (!size.empty()) {
    const auto wh = parse_size(size);
    if (!wh)
      return {std::nullopt, command.usage_error("--size: expected WxH with both in 1..16384, got '" + size + "'")};
    o.width = wh->first;
    o.height = wh->second;
  }
  o.grid = !no_grid;
  if (!o.turn.empty() && !parse_turn(o.turn))
    return {std::nullopt, command.usage_error("--turn: expected DEG_PER_S[@AFTER] (degrees per second within +-3600, "
                                              "seconds >= 0), got '" +
                                              o.turn + "'")};
  o.cloth = cloth == "on";
  for (const std::string& m : morphs) {
    const auto parsed = parse_morph(m);
    if (!parsed)
      return {std::nullopt,
              command.usage_error("--morph: expected NAME=WEIGHT with a finite weight within +-1000, got '" + m + "'")};
    o.morphs.push_back(*parsed);
  }
  // A graph cannot seek: headless --time T plays T seconds in 1/60 s steps, so T is bounded (an
  // hour is 216,000 steps); a clip's time wraps, but must still be a number.
  if (!std::isfinite(o.time) || std::fabs(o.time) > kMaxSeconds)
    return {std::nullopt,
            command.usage_error("--time: expected a finite number of seconds within +-" +
                                std::to_string(static_cast<int>(kMaxSeconds)) + ", got " + std::to_string(o.time))};
  if (!o.screenshot.empty() && o.frames == 0 && o.window_frames == 0) o.frames = 1;
  if (o.files.empty() && o.headless())
    return {std::nullopt,
            command.usage_error("files is required: a character .ossa to render (only the window may start "
                                "without one)")};
  if (o.headless() && (!o.cook_and_open.empty() || !o.browse.empty()))
    return {std::nullopt,
            command.usage_error("--cook-and-open and --browse are for the window (use --window-frames N)")};
  return {o, 0};
}

}  // namespace ossa::view
