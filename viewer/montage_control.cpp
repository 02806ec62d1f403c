// montage_control.cpp — see montage_control.h.
#include "viewer/montage_control.h"

#include <charconv>
#include <cmath>
#include <cstdio>

namespace ossa::view {
namespace {

std::string list(const GraphDriver& d, int montage) {
  std::string out;
  const GraphDefinition& def = *d.definition;
  const size_t n = montage < 0 ? def.montage_count() : def.section_count(static_cast<size_t>(montage));
  for (size_t i = 0; i < n; ++i)
    out += (out.empty() ? "'" : ", '") +
           std::string(montage < 0 ? def.montage_name(i) : def.section_name(static_cast<size_t>(montage), i)) + "'";
  return out.empty() ? "none" : out;
}

/// "TEXT@T" -> (TEXT, T); T 0 when absent; false when T is not a finite number >= 0.
bool split_time(std::string_view text, std::string_view* what, double* time) {
  const size_t at = text.rfind('@');
  *what = text.substr(0, at);
  *time = 0.0;
  if (at == std::string_view::npos) return true;
  const std::string_view t = text.substr(at + 1);
  const auto r = std::from_chars(t.data(), t.data() + t.size(), *time);
  return r.ec == std::errc() && r.ptr == t.data() + t.size() && std::isfinite(*time) && *time >= 0.0;
}

const char* event_word(MontageEventType t) {
  switch (t) {
    case MontageEventType::Started: return "started";
    case MontageEventType::BlendingOut: return "blending out";
    case MontageEventType::Ended: return "ended";
    case MontageEventType::Notify: return "event";
    case MontageEventType::NotifyBegin: return "begin";
    case MontageEventType::NotifyEnd: return "end";
    case MontageEventType::BranchingPoint: return "branching point";
  }
  return "?";
}

}  // namespace

Status add_montage_commands(GraphDriver& driver, const std::vector<std::string>& plays,
                            const std::vector<std::string>& nexts, const std::vector<std::string>& jumps) {
  const GraphDefinition& def = *driver.definition;
  const std::string where = "graph '" + driver.name + "'";
  int montage = -1;
  for (const std::string& text : plays) {
    std::string_view name;
    MontageCommand c;
    if (!split_time(text, &name, &c.time))
      return Error{where + ": --montage '" + text + "': expected NAME or NAME@SECONDS"};
    c.montage = montage = def.find_montage(name);
    if (montage < 0)
      return Error{where + ": --montage '" + text + "': no montage named '" + std::string(name) +
                   "' (montages: " + list(driver, -1) + ")"};
    driver.montage_commands.push_back(c);
  }
  const auto section = [&](std::string_view name, const std::string& option, const std::string& text,
                           int* out) -> Status {
    if (montage < 0) return Error{where + ": " + option + " '" + text + "' needs a --montage to act on"};
    *out = def.find_section(static_cast<size_t>(montage), name);
    if (*out < 0)
      return Error{where + ": " + option + " '" + text + "': montage '" +
                   std::string(def.montage_name(static_cast<size_t>(montage))) + "' has no section '" +
                   std::string(name) + "' (sections: " + list(driver, montage) + ")"};
    return {};
  };
  for (const std::string& text : nexts) {
    std::string_view link;
    MontageCommand c;
    c.kind = MontageCommand::Kind::Next;
    const size_t eq = text.find('=');
    if (eq == std::string::npos || !split_time(text, &link, &c.time) || link.size() <= eq)
      return Error{where + ": --montage-next '" + text + "': expected SECTION=NEXT@SECONDS (NEXT empty: the end)"};
    c.montage = montage;
    if (Status s = section(link.substr(0, eq), "--montage-next", text, &c.section); !s) return s;
    if (link.size() > eq + 1)
      if (Status s = section(link.substr(eq + 1), "--montage-next", text, &c.next); !s) return s;
    driver.montage_commands.push_back(c);
  }
  for (const std::string& text : jumps) {
    std::string_view name;
    MontageCommand c;
    c.kind = MontageCommand::Kind::Jump;
    if (!split_time(text, &name, &c.time))
      return Error{where + ": --montage-jump '" + text + "': expected SECTION@SECONDS"};
    c.montage = montage;
    if (Status s = section(name, "--montage-jump", text, &c.section); !s) return s;
    driver.montage_commands.push_back(c);
  }
  return {};
}

void play_montage_everywhere(GraphDriver& driver, int m) {
  for (GraphInstance& g : driver.instances) g.play_montage(m);
  driver.shown_montage = m;
}

void run_montage_commands(GraphDriver& driver) {
  for (MontageCommand& c : driver.montage_commands) {
    if (c.done || c.time > driver.time + 1e-6) continue;
    c.done = true;
    switch (c.kind) {
      case MontageCommand::Kind::Play: play_montage_everywhere(driver, c.montage); break;
      case MontageCommand::Kind::Next:
        for (GraphInstance& g : driver.instances) g.set_next_section(c.montage, c.section, c.next);
        break;
      case MontageCommand::Kind::Jump:
        for (GraphInstance& g : driver.instances) g.jump_to_section(c.montage, c.section);
        break;
    }
  }
}

void log_montage_events(GraphDriver& driver) {
  const GraphDefinition& def = *driver.definition;
  for (const MontageEvent& e : driver.instances.front().montage_events()) {
    char line[200];
    const std::string_view m = def.montage_name(e.montage);
    std::snprintf(line, sizeof line, "%8.2f s  %.*s: %s%s%.*s @ %.2f s%s", driver.time, static_cast<int>(m.size()),
                  m.data(), event_word(e.type), e.name.empty() ? "" : " ", static_cast<int>(e.name.size()),
                  e.name.data(), e.position, e.interrupted ? " (interrupted)" : "");
    driver.recent_events.emplace_front(line);
    if (driver.recent_events.size() > kGraphEventLog) driver.recent_events.pop_back();
  }
}

bool toggle_montage(GraphDriver& driver) {
  const GraphDefinition& def = *driver.definition;
  if (def.montage_count() == 0 || driver.instances.empty()) return false;
  const int m = driver.shown_montage >= 0 ? driver.shown_montage : 0;
  const MontageStatus st = driver.instances.front().montage_status(m);
  if (!st.playing || st.blending_out) {
    play_montage_everywhere(driver, m);
    return true;
  }
  const size_t sections = def.section_count(static_cast<size_t>(m));
  for (size_t k = 0; k < sections; ++k) {
    if (def.section_next(static_cast<size_t>(m), k) != static_cast<int>(k)) continue;
    const int after = k + 1 < sections ? static_cast<int>(k + 1) : -1;
    for (GraphInstance& g : driver.instances) g.set_next_section(m, static_cast<int>(k), after);
  }
  return true;
}

std::string montage_state_text(const GraphDriver& driver, int m) {
  const MontageStatus st = driver.instances.front().montage_status(m);
  if (!st.playing) return "stopped";
  const GraphDefinition& def = *driver.definition;
  char text[160];
  const std::string_view section =
      def.section_name(static_cast<size_t>(m), static_cast<size_t>(std::max(st.section, 0)));
  std::snprintf(text, sizeof text, "%s  %.*s  %.2f / %.2f s  weight %.2f", st.blending_out ? "blending out" : "playing",
                static_cast<int>(section.size()), section.data(), st.position,
                def.montage_length(static_cast<size_t>(m)), st.weight);
  return text;
}

}  // namespace ossa::view
