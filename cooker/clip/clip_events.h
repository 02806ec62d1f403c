// clip_events.h — clip events (footsteps, cues) authored as JSON: the sidecar file next to a
// source, and the event lists a graph file gives per clip.
//
// Assimp gives no FBX/glTF timeline markers, so events are authored outside the source: a
// sidecar `<source stem>.events.json` beside `<source>` (docs/GRAPH.md, "Clip events"):
//
//   {"ossa_events": 1, "clips": {"walk": [{"name": "foot_left", "time": 0.93}, ...], "*": [...]}}
//
// keyed by the source's clip names ("*": every clip of the file). Times are seconds from the
// clip's start; each must lie in [0, duration + kEventTimeSlack] and is clamped to the duration,
// the cooked clip's (frame_count - 1) / sample_rate, so what is written satisfies the format's
// [0, duration]. Events end sorted by time (stable: authored order among equal times), with exact
// duplicates (same name and time, e.g. from a sidecar and a graph file) kept once.
#pragma once
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "cooker/json/json_check.h"
#include "cooker/model/source_scene.h"
#include <ossa/format/result.h>

namespace ossa::cook {

/// How far past a clip's end an event time may be written (float rounding in authored data).
inline constexpr double kEventTimeSlack = 1e-4;

/// `<dir>/<stem>.events.json` for `<dir>/<stem>.<ext>`.
std::filesystem::path event_sidecar_path(const std::filesystem::path& source);

/// The duration events are checked against and clamped to: the cooked clip's.
float event_duration(const SourceClip& clip);

/// Reads an event list (`[{"name": ..., "time": ...}, ...]`) for a clip of `duration` seconds,
/// appending to `out`; problems go to `check`, each naming `clip_label` (e.g. "clip 'walk'").
void read_event_list(json::Checker& check, const json::Value& list, float duration, const std::string& clip_label,
                     std::vector<SourceEvent>& out);

/// Sorts by time (stable) and drops exact duplicates. O(n log n).
void sort_events(std::vector<SourceEvent>& events);

/// Applies a sidecar's text to the clips of `source_name` (used in messages): each clip gets its
/// own events and the "*" events, merged with what it has, sorted. Errors (every problem,
/// `sidecar_name:line:col: ...`, one per line) leave `clips` unchanged.
Status apply_event_sidecar(std::string_view text, const std::string& sidecar_name, const std::string& source_name,
                           std::vector<SourceClip>& clips);

struct SidecarRead {
  bool present = false;
  std::filesystem::path path;
  std::vector<uint8_t> bytes;  // what was read, for the provenance hash
};

/// Reads `source`'s sidecar when there is one and applies it to `clips`. No sidecar is not an
/// error (present = false).
Result<SidecarRead> attach_sidecar_events(const std::filesystem::path& source, std::vector<SourceClip>& clips);

}  // namespace ossa::cook
