// graph_montage.cpp — see graph_montage.h. Like graph_compile.cpp: every problem is reported with
// the position of the value at fault, a part that failed is marked and skipped by the checks that
// depend on it, and nothing here throws.
#include "cooker/graph/graph_montage.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <type_traits>

#include "cooker/clip/clip_events.h"

namespace ossa::cook {
namespace {

using json::Member;
using json::Pos;
using json::Type;
using json::Value;

constexpr double kMaxSeconds = 1e6, kMinRate = 1e-3, kMaxRate = 1000.0;
constexpr size_t kMaxTracks = 64, kMaxSections = 256, kMaxWindows = 64;  // internal/validate_montage.h
constexpr float kDefaultBlend = 0.25f;

std::string number_text(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%g", v);
  return buf;
}

std::string quoted(const std::vector<std::string>& names) {
  std::string out;
  for (const std::string& n : names) out += (out.empty() ? "'" : ", '") + n + "'";
  return out;
}

/// Calls f(child) for each node index node `n` refers to (state machines: their states' nodes).
template <class F>
void for_children(const GraphDef& g, const NodeDef& n, F&& f) {
  std::visit(
      [&](const auto& d) {
        using T = std::decay_t<decltype(d)>;
        if constexpr (std::is_same_v<T, BlendAlphaDef>) {
          f(d.a), f(d.b);
        } else if constexpr (std::is_same_v<T, SelectDef>) {
          for (uint16_t c : d.children) f(c);
        } else if constexpr (std::is_same_v<T, LayeredDef>) {
          f(d.base);
          for (const LayerDef& l : d.layers) f(l.node);
        } else if constexpr (std::is_same_v<T, AdditiveDef>) {
          f(d.base), f(d.additive);
        } else if constexpr (std::is_same_v<T, StateMachineRefDef>) {
          if (d.machine < g.machines.size())
            for (const StateDef& s : g.machines[d.machine].states) f(s.node);
        } else if constexpr (requires { d.input; }) {
          f(d.input);
        }
      },
      n.kind);
}

void mark_subtree(const GraphDef& g, uint16_t n, std::vector<uint8_t>& marked) {
  if (n >= g.nodes.size() || marked[n]) return;
  marked[n] = 1;
  for_children(g, g.nodes[n], [&](uint16_t c) { mark_subtree(g, c, marked); });
}

}  // namespace

int MontageCompiler::slot_node(const Value& v, const std::string& name) {
  const std::string what = "a slot node";
  check.expect_keys(v, {"slot", "input", "group", "mask", "mode", "mesh_space_rotation", "name"}, what);
  SlotDef s;
  const Value& slot_name = *v.find("slot");
  bool ok = check.expect_name(slot_name, "\"slot\" (the slot's name, which montage tracks play on)", &s.slot);
  s.group = "default";
  if (const Value* g = v.find("group")) ok &= check.expect_name(*g, "a slot's \"group\"", &s.group);
  int input = -1;
  if (const Value* in = v.find("input")) input = node(*in, "");
  else check.error(v.pos, what + " needs \"input\": the node whose pose it passes through while no montage plays");
  ok &= input >= 0;
  if (const Value* mask = v.find("mask")) {
    if (!check.expect(*mask, Type::Array, "\"mask\" ([{\"joint\": ...}, ...])")) {
      ok = false;
    } else {
      if (mask->items.empty()) ok = check.error(mask->pos, "\"mask\" is empty: leave it out to play on every joint");
      for (const Value& e : mask->items) {
        if (!check.expect(e, Type::Object, "a mask entry ({\"joint\": ..., \"depth\": ...})")) {
          ok = false;
          continue;
        }
        check.expect_keys(e, {"joint", "depth"}, "a mask entry");
        MaskEntryDef entry;
        const Value* jv = e.find("joint");
        const int j = jv ? joint(*jv, "a slot's mask") : -1;
        if (!jv) check.error(e.pos, "a mask entry needs \"joint\"");
        ok &= j >= 0;
        entry.joint = static_cast<uint16_t>(std::max(j, 0));
        if (const Value* d = e.find("depth")) {
          long long depth = -1;
          ok &= check.expect_integer(*d, "a mask's \"depth\" (-1: all descendants)", -1, 32767, &depth);
          entry.depth = static_cast<int16_t>(depth);
        }
        s.mask.push_back(entry);
      }
    }
  }
  if (const Value* mode = v.find("mode")) {
    if (!check.expect(*mode, Type::String, "a slot's \"mode\"")) ok = false;
    else if (mode->string == "additive") s.additive = true;
    else if (mode->string != "override")
      ok = check.error(mode->pos, "unknown slot mode '" + mode->string + "'; modes: override, additive");
  }
  if (const Value* m = v.find("mesh_space_rotation")) {
    if (check.expect(*m, Type::Bool, "\"mesh_space_rotation\"")) s.mesh_space_rotation = m->boolean;
    else ok = false;
  }
  if (!ok) return -1;
  s.input = static_cast<uint16_t>(input);
  graph.nodes.push_back({name, s});
  const auto index = static_cast<uint16_t>(graph.nodes.size() - 1);
  if (collecting) slots.push_back({s.slot, s.group, slot_name.pos, index});
  return index;
}

void MontageCompiler::check_slot_placement() {
  std::vector<uint8_t> gated(graph.nodes.size(), 0);
  for (const NodeDef& n : graph.nodes) {
    if (const auto* l = std::get_if<LayeredDef>(&n.kind)) {
      for (const LayerDef& layer : l->layers)
        if (layer.weight_parameter >= 0 || layer.weight == 0.0f) mark_subtree(graph, layer.node, gated);
    } else if (const auto* a = std::get_if<AdditiveDef>(&n.kind)) {
      if (a->weight_parameter >= 0 || a->weight == 0.0f) mark_subtree(graph, a->additive, gated);
    }
  }
  for (const SlotSeen& s : slots)
    if (s.node < gated.size() && gated[s.node])
      check.error(s.pos, "slot '" + s.slot +
                             "' is inside a layer (or an additive's added input) whose weight can be 0, where its "
                             "montages would play nothing; put the slot above the layered or additive node");
}

void MontageCompiler::montages(const Value* list) {
  if (!list || !check.expect(*list, Type::Object, "\"montages\" ({\"<montage>\": {...}, ...})")) return;
  if (list->members.size() > kMaxGraphMontages)
    check.error(list->pos, "more than " + std::to_string(kMaxGraphMontages) + " montages");
  std::vector<std::string> slot_names;
  for (const SlotSeen& s : slots)
    if (std::find(slot_names.begin(), slot_names.end(), s.slot) == slot_names.end()) slot_names.push_back(s.slot);
  // One slot name, one group: a montage of the group finds every node of that name.
  for (size_t i = 0; i < slots.size(); ++i)
    for (size_t k = 0; k < i; ++k)
      if (slots[k].slot == slots[i].slot && slots[k].group != slots[i].group) {
        check.error(slots[i].pos, "slot '" + slots[i].slot + "' is in group '" + slots[i].group +
                                      "' here and in group '" + slots[k].group + "' elsewhere; a slot has one group");
        break;
      }

  for (const Member& entry : list->members) {
    MontageDef m;
    m.name = entry.key;
    const std::string label = "montage '" + entry.key + "'";
    if (entry.key.empty()) check.error(entry.key_pos, "a montage name must not be empty");
    const Value& v = entry.value;
    if (!check.expect(v, Type::Object, label)) continue;
    check.expect_keys(
        v,
        {"group", "tracks", "sections", "blend_in", "blend_out", "blend_out_trigger", "rate", "root_motion", "events"},
        label);
    bool ok = !entry.key.empty();
    m.group = "default";
    if (const Value* g = v.find("group")) ok &= check.expect_name(*g, label + " \"group\"", &m.group);

    const auto read_number = [&](const Value& x, const std::string& what, double lo, double hi, float* out) {
      double d = 0.0;
      if (!check.expect_number(x, what, &d)) return false;
      if (d < lo || d > hi)
        return check.error(
            x.pos, what + " must be within [" + number_text(lo) + ", " + number_text(hi) + "], not " + number_text(d));
      *out = static_cast<float>(d);
      return true;
    };

    // Tracks: slot name -> segments laid end to end.
    double length = 0.0;
    bool tracks_ok = false;
    if (const Value* tracks = v.find("tracks")) {
      tracks_ok = check.expect(*tracks, Type::Object, label + " \"tracks\" ({\"<slot>\": [segments], ...})");
      if (tracks_ok && (tracks->members.empty() || tracks->members.size() > kMaxTracks))
        tracks_ok = check.error(tracks->pos, label + " needs 1 to " + std::to_string(kMaxTracks) + " tracks");
      const std::vector<Member> no_tracks;
      for (const Member& t : tracks_ok ? tracks->members : no_tracks) {
        MontageTrackDef track;
        track.slot = t.key;
        const auto seen = std::find_if(slots.begin(), slots.end(), [&](const SlotSeen& s) { return s.slot == t.key; });
        if (seen == slots.end()) {
          const std::string hint = json::closest_name(t.key, slot_names);
          tracks_ok = check.error(
              t.key_pos, "unknown slot '" + t.key + "' in " + label +
                             (hint.empty() ? "" : " (did you mean '" + hint + "'?)") +
                             (slot_names.empty() ? "; the graph has no slot nodes" : "; slots: " + quoted(slot_names)));
        } else if (ok && seen->group != m.group) {
          tracks_ok =
              check.error(t.key_pos, label + " (group '" + m.group + "') has a track for slot '" + t.key +
                                         "' of group '" + seen->group + "'; a montage plays slots of its group");
        }
        if (!check.expect(t.value, Type::Array, "a track (an array of segments)")) {
          tracks_ok = false;
          continue;
        }
        if (t.value.items.empty()) tracks_ok = check.error(t.value.pos, "track '" + t.key + "' has no segments");
        double track_length = 0.0;
        for (const Value& sv : t.value.items) {
          if (!check.expect(sv, Type::Object, "a segment ({\"clip\": ..., \"start\": ..., \"end\": ...})")) {
            tracks_ok = false;
            continue;
          }
          check.expect_keys(sv, {"clip", "start", "end", "rate"}, "a segment");
          MontageSegmentDef seg;
          const Value* cv = sv.find("clip");
          if (!cv) {
            tracks_ok = check.error(sv.pos, "a segment needs \"clip\"");
            continue;
          }
          const int c = clip(*cv, "a montage segment");
          if (c < 0) {
            tracks_ok = false;
            continue;
          }
          seg.clip = static_cast<uint16_t>(c);
          const double duration = clip_duration[seg.clip];
          seg.end = static_cast<float>(duration);
          bool seg_ok = true;
          if (const Value* x = sv.find("start"))
            seg_ok &= read_number(*x, "a segment's \"start\" (clip seconds)", 0.0, duration, &seg.start);
          if (const Value* x = sv.find("end"))
            seg_ok &= read_number(*x, "a segment's \"end\" (clip seconds)", 0.0, duration, &seg.end);
          if (const Value* x = sv.find("rate"))
            seg_ok &= read_number(*x, "a segment's \"rate\"", kMinRate, kMaxRate, &seg.rate);
          if (seg_ok && !(seg.end > seg.start))
            seg_ok = check.error(sv.find("end") ? sv.find("end")->pos : sv.pos,
                                 "a segment's \"end\" (" + number_text(seg.end) + " s) must be after its \"start\" (" +
                                     number_text(seg.start) + " s)");
          tracks_ok &= seg_ok;
          if (seg_ok) track_length += (static_cast<double>(seg.end) - seg.start) / seg.rate;
          track.segments.push_back(seg);
        }
        length = std::max(length, track_length);
        m.tracks.push_back(std::move(track));
      }
      if (tracks_ok && length > kMaxSeconds)
        tracks_ok = check.error(tracks->pos, label + " is " + number_text(length) + " s long, more than 1e6 s");
    } else {
      check.error(v.pos, label + " needs \"tracks\": {\"<slot>\": [{\"clip\": ...}, ...]}");
    }
    ok &= tracks_ok;

    // Sections: name -> {"time", "next"}, written in time order.
    const Value* sections = v.find("sections");
    std::vector<const Value*> next_of;  // each section's "next" (null when absent)
    if (sections && check.expect(*sections, Type::Object, label + " \"sections\" ({\"<name>\": {\"time\": ...}})")) {
      if (sections->members.empty() || sections->members.size() > kMaxSections)
        ok = check.error(sections->pos, label + " needs 1 to " + std::to_string(kMaxSections) + " sections");
      for (const Member& s : sections->members) {
        MontageSectionDef sec;
        sec.name = s.key;
        next_of.push_back(nullptr);
        if (s.key.empty()) ok = check.error(s.key_pos, "a section name must not be empty");
        if (!check.expect(s.value, Type::Object, "section '" + s.key + "' ({\"time\": ..., \"next\": ...})")) {
          ok = false;
          m.sections.push_back(sec);
          continue;
        }
        check.expect_keys(s.value, {"time", "next"}, "a section");
        next_of.back() = s.value.find("next");
        const Value* tv = s.value.find("time");
        if (!tv) {
          ok = check.error(s.value.pos, "section '" + s.key + "' needs \"time\" (where it starts on the timeline)");
        } else if (read_number(*tv, "section '" + s.key + "' \"time\"", 0.0, kMaxSeconds, &sec.start)) {
          if (m.sections.empty() && sec.start != 0.0f)
            ok = check.error(tv->pos, "the first section ('" + s.key + "') must start at time 0");
          else if (!m.sections.empty() && !(sec.start > m.sections.back().start))
            ok = check.error(tv->pos, "section '" + s.key + "' starts at " + number_text(sec.start) +
                                          " s, not after section '" + m.sections.back().name +
                                          "'; write sections in the order of their times");
          else if (tracks_ok && !(sec.start < length))
            ok = check.error(tv->pos, "section '" + s.key + "' starts at " + number_text(sec.start) +
                                          " s, not before the montage's end (" + number_text(length) + " s)");
        } else {
          ok = false;
        }
        m.sections.push_back(sec);
      }
      std::vector<std::string> names;
      for (const MontageSectionDef& s : m.sections) names.push_back(s.name);
      for (size_t k = 0; k < m.sections.size(); ++k) {
        const Value* nv = next_of[k];
        if (!nv) {  // absent: the section after it in time (the last: the end)
          m.sections[k].next = k + 1 < m.sections.size() ? static_cast<int16_t>(k + 1) : int16_t{-1};
        } else if (nv->is(Type::Null)) {
          m.sections[k].next = -1;
        } else if (check.expect(*nv, Type::String, "\"next\" (a section name, or null: the montage ends)")) {
          const auto at = std::find(names.begin(), names.end(), nv->string);
          if (at == names.end()) {
            const std::string hint = json::closest_name(nv->string, names);
            ok = check.error(nv->pos, "\"next\" '" + nv->string + "' is not a section of " + label +
                                          (hint.empty() ? "" : " (did you mean '" + hint + "'?)") +
                                          "; sections: " + quoted(names));
          } else {
            m.sections[k].next = static_cast<int16_t>(at - names.begin());
          }
        } else {
          ok = false;
        }
      }
    } else {
      if (!sections) check.error(v.pos, label + " needs \"sections\": {\"<name>\": {\"time\": 0}, ...}");
      ok = false;
    }

    // Blending.
    m.blend_in = m.blend_out = kDefaultBlend;
    const auto read_blend = [&](const char* key, float* time, MontageCurveDef* curve) {
      const Value* b = v.find(key);
      if (!b) return true;
      const std::string what = label + " \"" + key + "\"";
      if (b->is(Type::Number)) return read_number(*b, what + " (seconds)", 0.0, kMaxSeconds, time);
      if (!check.expect(*b, Type::Object, what + " (seconds, or {\"time\": ..., \"curve\": ...})")) return false;
      check.expect_keys(*b, {"time", "curve"}, what);
      bool fine = true;
      if (const Value* t = b->find("time"))
        fine &= read_number(*t, what + " \"time\" (seconds)", 0.0, kMaxSeconds, time);
      if (const Value* c = b->find("curve")) {
        static const std::vector<std::string_view> kCurves = {"linear", "cubic", "inertialize"};
        if (!check.expect(*c, Type::String, what + " \"curve\"")) return false;
        const auto at = std::find(kCurves.begin(), kCurves.end(), c->string);
        if (at == kCurves.end()) {
          const std::string hint = json::closest_name(c->string, kCurves);
          return check.error(c->pos, "unknown blend curve '" + c->string + "'" +
                                         (hint.empty() ? "" : " (did you mean '" + hint + "'?)") +
                                         "; curves: linear, cubic, inertialize");
        }
        *curve = static_cast<MontageCurveDef>(at - kCurves.begin());
      }
      return fine;
    };
    ok &= read_blend("blend_in", &m.blend_in, &m.blend_in_curve);
    ok &= read_blend("blend_out", &m.blend_out, &m.blend_out_curve);
    if (const Value* t = v.find("blend_out_trigger"))
      ok &= read_number(*t, label + " \"blend_out_trigger\" (seconds before the end)", 0.0, kMaxSeconds,
                        &m.blend_out_trigger);
    if (const Value* r = v.find("rate")) ok &= read_number(*r, label + " \"rate\"", kMinRate, kMaxRate, &m.rate);
    if (const Value* rm = v.find("root_motion")) {
      if (check.expect(*rm, Type::Bool, label + " \"root_motion\"")) m.root_motion = rm->boolean;
      else ok = false;
    }

    // Events: instant, windows ("duration"), branching points ("branch": true).
    if (const Value* events = v.find("events"); events && check.expect(*events, Type::Array, label + " \"events\"")) {
      size_t windows = 0;
      for (const Value& e : events->items) {
        if (!check.expect(e, Type::Object, "a montage event ({\"name\": ..., \"time\": ...})")) {
          ok = false;
          continue;
        }
        check.expect_keys(e, {"name", "time", "duration", "branch"}, "a montage event");
        MontageNotifyDef n;
        const Value* nv = e.find("name");
        if (!nv) ok = check.error(e.pos, "a montage event needs \"name\"");
        else ok &= check.expect_name(*nv, "a montage event's \"name\"", &n.name);
        const Value* tv = e.find("time");
        const double end = tracks_ok ? length : kMaxSeconds;
        if (!tv) ok = check.error(e.pos, "a montage event needs \"time\" (timeline seconds)");
        else ok &= read_number(*tv, "a montage event's \"time\" (timeline seconds)", 0.0, end, &n.time);
        if (const Value* d = e.find("duration")) {
          if (read_number(*d, "a montage event's \"duration\" (seconds)", 0.0, kMaxSeconds, &n.duration)) {
            if (!(n.duration > 0.0f))
              ok = check.error(d->pos, "a montage event's \"duration\" must be above 0 (leave it out for an instant)");
            else n.kind = MontageNotifyKindDef::Window;
            if (++windows > kMaxWindows)
              ok = check.error(d->pos,
                               label + " has more than " + std::to_string(kMaxWindows) + " events with a duration");
          } else {
            ok = false;
          }
        }
        if (const Value* b = e.find("branch")) {
          if (!check.expect(*b, Type::Bool, "\"branch\"")) {
            ok = false;
          } else if (b->boolean && n.kind == MontageNotifyKindDef::Window) {
            ok = check.error(b->pos, "a branching point is an instant: it cannot also have a \"duration\"");
          } else if (b->boolean) {
            n.kind = MontageNotifyKindDef::BranchingPoint;
          }
        }
        m.notifies.push_back(std::move(n));
      }
      std::stable_sort(m.notifies.begin(), m.notifies.end(),
                       [](const MontageNotifyDef& a, const MontageNotifyDef& b) { return a.time < b.time; });
    } else if (events) {
      ok = false;
    }
    if (ok) graph.montages.push_back(std::move(m));
  }
}

}  // namespace ossa::cook
