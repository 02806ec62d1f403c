// clip_events.cpp — event sidecars and event lists (clip_events.h).
#include "cooker/clip/clip_events.h"

#include <algorithm>
#include <cerrno>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <iterator>

#include "cooker/model/clip_grid.h"
#include "cooker/model/input_log.h"

namespace ossa::cook {
namespace fs = std::filesystem;

fs::path event_sidecar_path(const fs::path& source) {
  return source.parent_path() / (source.stem().string() + ".events.json");
}

float event_duration(const SourceClip& clip) { return frame_grid(clip).duration(); }

namespace {

std::string seconds(double t) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g s", t);
  return buf;
}

}  // namespace

void read_event_list(json::Checker& check, const json::Value& list, float duration, const std::string& clip_label,
                     std::vector<SourceEvent>& out) {
  if (!check.expect(list, json::Type::Array, "the events of " + clip_label)) return;
  for (const json::Value& item : list.items) {
    if (!check.expect(item, json::Type::Object, "an event")) continue;
    check.expect_keys(item, {"name", "time"}, "an event");
    const json::Value* name = item.find("name");
    const json::Value* time = item.find("time");
    if (!name) check.error(item.pos, "an event needs a \"name\"");
    if (!time) check.error(item.pos, "an event needs a \"time\" (seconds from the clip's start)");
    SourceEvent e;
    double t = 0.0;
    const bool name_ok = name && check.expect_name(*name, "an event's \"name\"", &e.name);
    const bool time_ok = time && check.expect_number(*time, "an event's \"time\"", &t);
    if (!name_ok || !time_ok) continue;
    if (t < 0.0) {
      check.error(time->pos, "event '" + e.name + "' of " + clip_label + ": time " + seconds(t) + " is negative");
      continue;
    }
    if (t > static_cast<double>(duration) + kEventTimeSlack) {
      check.error(time->pos, "event '" + e.name + "' of " + clip_label + ": time " + seconds(t) +
                                 " is after the clip's end (" + seconds(duration) + ")");
      continue;
    }
    e.time = std::min(static_cast<float>(t), duration);
    out.push_back(std::move(e));
  }
}

void sort_events(std::vector<SourceEvent>& events) {
  std::stable_sort(events.begin(), events.end(),
                   [](const SourceEvent& a, const SourceEvent& b) { return a.time < b.time; });
  std::vector<SourceEvent> unique;
  unique.reserve(events.size());
  for (SourceEvent& e : events) {
    bool seen = false;
    for (auto it = unique.rbegin(); it != unique.rend() && it->time == e.time; ++it) seen = seen || it->name == e.name;
    if (!seen) unique.push_back(std::move(e));
  }
  events = std::move(unique);
}

Status apply_event_sidecar(std::string_view text, const std::string& sidecar_name, const std::string& source_name,
                           std::vector<SourceClip>& clips) {
  auto doc = json::parse(text, sidecar_name);
  if (!doc) return doc.error();
  json::Checker check(*doc);
  const json::Value& root = doc->root;
  if (!check.expect(root, json::Type::Object, "an events file")) return Error{check.message()};
  check.expect_keys(root, {"ossa_events", "clips"}, "an events file");
  const json::Value* version = root.find("ossa_events");
  if (!version) {
    check.error(root.pos, "not an events file: \"ossa_events\": 1 is missing");
  } else if (!version->is(json::Type::Number) || version->number != 1.0) {
    check.error(version->pos, "\"ossa_events\" must be 1 (the only version this cooker reads)");
  }
  const json::Value* list = root.find("clips");
  if (!list) check.error(root.pos, "an events file needs \"clips\": {\"<clip name>\": [events], ...}");

  std::vector<std::vector<SourceEvent>> added(clips.size());
  if (list && check.expect(*list, json::Type::Object, "\"clips\"")) {
    for (const json::Member& m : list->members) {
      if (m.key == "*") {
        for (size_t c = 0; c < clips.size(); ++c)
          read_event_list(check, m.value, event_duration(clips[c]), "clip '" + clips[c].name + "'", added[c]);
        continue;
      }
      size_t c = 0;
      while (c < clips.size() && !clip_named(clips[c], m.key)) ++c;
      if (c == clips.size()) {
        std::string names;
        for (const SourceClip& clip : clips) names += (names.empty() ? "'" : ", '") + clip.name + "'";
        check.error(m.key_pos, "no clip named '" + m.key + "' in " + source_name +
                                   (names.empty() ? " (it has no clips)" : " (its clips: " + names + ")"));
        continue;
      }
      read_event_list(check, m.value, event_duration(clips[c]), "clip '" + clips[c].name + "'", added[c]);
    }
  }
  if (!check.ok()) return Error{check.message()};
  for (size_t c = 0; c < clips.size(); ++c) {
    clips[c].events.insert(clips[c].events.end(), added[c].begin(), added[c].end());
    sort_events(clips[c].events);
  }
  return {};
}

Result<SidecarRead> attach_sidecar_events(const fs::path& source, std::vector<SourceClip>& clips) {
  SidecarRead read;
  read.path = event_sidecar_path(source);
  // Looked for on every cook, so that a sidecar created later makes the output out of date.
  if (!probe_input(read.path)) return read;
  auto bytes = read_input(read.path);
  if (!bytes) return bytes.error();
  read.bytes = std::move(*bytes);
  read.present = true;
  const std::string_view text(reinterpret_cast<const char*>(read.bytes.data()), read.bytes.size());
  if (Status st = apply_event_sidecar(text, read.path.string(), source.filename().string(), clips); !st)
    return st.error();
  return read;
}

}  // namespace ossa::cook
