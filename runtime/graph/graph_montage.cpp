// graph_montage.cpp — montages at runtime (graph.h): binding them to the definition, the host's
// calls (play, stop, sections, rate, queries) and advancing every playing montage once per update,
// before the graph is evaluated. The slot node that shows them is graph_slot.cpp.
//
// A montage play lives in one of kMaxMontagePlays fixed entries of the instance; its section links
// are a fixed row of State::montage_links, its sampling caches are the instance's, one per distinct
// clip of each montage. Nothing is allocated after the instance is made.
//
// Notifies are markers on the timeline (graph_internal.h Marker), sorted once. Advancing plays the
// timeline distance dt * rate through the sections: each span [from, to) played fires the markers
// inside it in order, with the montage standing exactly at each marker's time when it is raised, so
// a listener's jump takes effect from there; reaching a section's end follows its link (a jump),
// and the final end includes markers exactly at it. A marker is therefore fired once per time
// playback passes it, whatever the frame rate: across loops, jumps, rate changes and long frames.
// Windows are open while playback is inside them: they open when their begin is passed or a jump
// lands inside, and close when their end is passed, a jump leaves them or the montage ends.
#include <algorithm>
#include <cmath>
#include <limits>

#include "graph/graph_internal.h"
#include <ossa/anim/pose_ops.h>

namespace ossa {
using namespace graph_detail;
using State = GraphInstance::State;

namespace graph_detail {
namespace {

constexpr uint32_t kMaxSectionSteps = 1024;  // section ends followed in one update (a tiny looping section
                                             // under a huge dt plays at most this many passes)
constexpr double kNever = std::numeric_limits<double>::infinity();

std::string_view sv(const flatbuffers::String* s) { return flatbuffers::GetStringView(s); }

double section_end(const MontageInfo& mi, int k) {
  return static_cast<size_t>(k) + 1 < mi.section_start.size() ? mi.section_start[static_cast<size_t>(k) + 1]
                                                              : mi.length;
}

/// Timeline distance from the play's position to the montage's end along its links; infinite when
/// the links loop.
double distance_to_end(const MontageInfo& mi, const MontagePlay& p) {
  if (p.at_end) return 0.0;
  int k = p.next[p.section];
  if (k == p.section) return kNever;  // the common loop, without walking it
  double d = section_end(mi, p.section) - p.position;
  const size_t sections = mi.section_start.size();
  for (size_t steps = 0; k >= 0; ++steps) {
    if (steps >= sections) return kNever;
    d += section_end(mi, k) - mi.section_start[static_cast<size_t>(k)];
    k = p.next[k];
  }
  return d;
}

std::string_view notify_name(const MontageInfo& mi, uint16_t notify) {
  return sv(mi.fb->notifies()->Get(notify)->name());
}

void raise(State& s, MontageEventType type, const MontagePlay& p, std::string_view name, double position,
           bool interrupted = false) {
  const MontageEvent e{type, static_cast<uint16_t>(p.montage), name, static_cast<float>(position), interrupted};
  if (s.montage_events.size() < s.event_capacity) s.montage_events.push_back(e);
  else ++s.dropped;
  if (s.listener && s.self) s.listener(*s.self, e, s.listener_user);
}

float curve_value(fb::MontageCurve curve, float u) {
  switch (curve) {
    case fb::MontageCurve::Cubic: return u * u * (3.0f - 2.0f * u);
    case fb::MontageCurve::Inertialize: return 1.0f;
    default: return u;
  }
}

void begin_blend(MontagePlay& p, float to, float time, fb::MontageCurve curve, double elapsed, bool fresh) {
  p.blend_from = p.weight;
  p.blend_to = to;
  p.blend_time = time;
  p.curve = curve;
  p.blend_elapsed = elapsed;
  p.blend_fresh = fresh;
}

void start_blend_out(State& s, MontagePlay& p, float time, fb::MontageCurve curve, bool interrupted, double elapsed,
                     bool fresh) {
  if (p.blending_out) return;
  p.blending_out = true;
  p.interrupted = interrupted;
  begin_blend(p, 0.0f, time, curve, elapsed, fresh);
  raise(s, MontageEventType::BlendingOut, p, {}, p.position, interrupted);
}

void step_weight(State& s, MontagePlay& p, float dt) {
  if (!p.blend_fresh) p.blend_elapsed += dt;
  p.blend_fresh = false;
  const float u = p.blend_time > 0.0f ? static_cast<float>(std::min(1.0, p.blend_elapsed / p.blend_time)) : 1.0f;
  const float w = p.blend_from + (p.blend_to - p.blend_from) * curve_value(p.curve, u);
  if (p.curve == fb::MontageCurve::Inertialize && w != p.weight && p.blend_time > 0.0f) {
    p.switch_update = s.update_counter;  // the slots showing it capture an offset this update
    p.switch_time = p.blend_time;
  }
  p.weight = w;
}

/// Moves the play to the start of `section`: windows it leaves close, windows it lands inside open.
void jump(State& s, MontagePlay& p, const MontageInfo& mi, int section) {
  const double from = p.position, to = mi.section_start[static_cast<size_t>(section)];
  const uint64_t serial = p.serial;
  for (size_t w = 0; w < mi.windows.size() && p.serial == serial; ++w) {
    const fb::MontageNotify& n = *mi.fb->notifies()->Get(mi.windows[w]);
    const bool open = (p.open >> w) & 1u, holds = n.time() <= to && to < double(n.time()) + n.duration();
    if (open && !holds) {
      p.open &= ~(uint64_t{1} << w);
      raise(s, MontageEventType::NotifyEnd, p, sv(n.name()), from);
    }
  }
  if (p.serial != serial) return;
  p.section = static_cast<uint16_t>(section);
  p.position = to;
  p.at_end = false;
  ++p.revision;
  for (size_t w = 0; w < mi.windows.size() && p.serial == serial; ++w) {
    const fb::MontageNotify& n = *mi.fb->notifies()->Get(mi.windows[w]);
    // A window beginning exactly here opens when playback passes its begin marker.
    if (!((p.open >> w) & 1u) && n.time() < to && to < double(n.time()) + n.duration()) {
      p.open |= uint64_t{1} << w;
      raise(s, MontageEventType::NotifyBegin, p, sv(n.name()), to);
    }
  }
}

/// Root motion of the montage's first track over timeline span [a, b), composed onto the update's.
void add_root_motion(State& s, const MontageInfo& mi, double a, double b) {
  if (!(b > a) || !mi.fb->root_motion()) return;
  const TrackInfo& t = s.def->tracks[mi.first_track];
  for (uint32_t k = 0; k < t.segment_count; ++k) {
    const SegmentInfo& seg = s.def->segments[t.first_segment + k];
    const double lo = std::max(a, seg.begin), hi = std::min(b, seg.end);
    if (!(hi > lo)) continue;
    const ClipView& clip = s.def->clips[seg.clip];
    if (!has_root_motion(clip)) continue;
    const double from = seg.clip_start + (lo - seg.begin) * seg.rate, to = seg.clip_start + (hi - seg.begin) * seg.rate;
    const RootMotionDelta d = root_motion_delta(clip, from, to);
    const uint8_t axis = clip.fb->root_motion()->up_axis();
    glm::vec3 up(0.0f);
    up[axis < 3 ? axis : 1] = 1.0f;
    s.root_motion_up = up;
    s.root_motion.translation += glm::angleAxis(s.root_motion.yaw, up) * d.translation;
    s.root_motion.yaw += d.yaw;
  }
}

/// Plays dt of the play's timeline: markers, section links, the end; then its automatic blend out.
void advance_play(State& s, MontagePlay& p, float dt) {
  const MontageInfo& mi = s.def->montages[static_cast<size_t>(p.montage)];
  const uint64_t serial = p.serial;
  const auto alive = [&] { return p.montage >= 0 && p.serial == serial; };
  const double rate = p.rate;
  const double before = rate > 0.0 ? distance_to_end(mi, p) / rate : (p.at_end ? 0.0 : kNever);
  const bool moves_character = mi.fb->root_motion() && !p.interrupted;
  const Marker* markers = s.def->markers.data() + mi.first_marker;
  const Marker* markers_end = markers + mi.marker_count;
  double remaining = static_cast<double>(dt) * rate;
  for (uint32_t steps = 0; remaining > 0.0 && !p.at_end && steps < kMaxSectionSteps;) {
    const int sec = p.section;
    const double end = section_end(mi, sec);
    const double stop = std::min(p.position + remaining, end);
    const bool final_end = p.next[sec] < 0 && stop >= end;
    const uint32_t revision = p.revision;
    bool jumped = false;
    const Marker* m =
        std::lower_bound(markers, markers_end, p.position, [](const Marker& k, double t) { return k.time < t; });
    for (; m != markers_end && (m->time < stop || (final_end && m->time == stop)); ++m) {
      if (moves_character) add_root_motion(s, mi, p.position, m->time);
      remaining -= m->time - p.position;
      p.position = m->time;
      const uint64_t bit = uint64_t{1} << m->window;
      switch (m->type) {
        case MarkerType::Instant: raise(s, MontageEventType::Notify, p, notify_name(mi, m->notify), m->time); break;
        case MarkerType::Branch:
          raise(s, MontageEventType::BranchingPoint, p, notify_name(mi, m->notify), m->time);
          break;
        case MarkerType::Begin:
          if (!(p.open & bit)) {
            p.open |= bit;
            raise(s, MontageEventType::NotifyBegin, p, notify_name(mi, m->notify), m->time);
          }
          break;
        case MarkerType::End:
          if (p.open & bit) {
            p.open &= ~bit;
            raise(s, MontageEventType::NotifyEnd, p, notify_name(mi, m->notify), m->time);
          }
          break;
      }
      if (!alive()) return;
      if (p.revision != revision) {  // a listener jumped: play the rest from there
        jumped = true;
        break;
      }
    }
    ++steps;
    if (jumped) continue;
    if (moves_character) add_root_motion(s, mi, p.position, stop);
    remaining -= stop - p.position;
    p.position = stop;
    if (p.position < end) break;
    const int next = p.next[sec];
    if (next < 0) {
      p.at_end = true;
      break;
    }
    jump(s, p, mi, next);
    if (!alive()) return;
  }

  // The automatic blend out: when the playing time left reaches the trigger (or at the end), in
  // seconds of playing time on both sides, so a rate changes nothing about where it ends.
  if (p.blending_out) return;
  const fb::Montage& fm = *mi.fb;
  const double trigger = fm.blend_out_trigger() >= 0.0f ? fm.blend_out_trigger() : fm.blend_out();
  const double after = p.at_end ? -std::max(remaining, 0.0) / std::max(rate, 1e-9)
                                : (rate > 0.0 ? distance_to_end(mi, p) / rate : kNever);
  if (!(after <= trigger)) return;
  // Begun where the trigger was crossed within this update (not earlier than the update's start).
  const double elapsed = before > trigger ? std::clamp(trigger - after, 0.0, double(dt)) : 0.0;
  start_blend_out(s, p, fm.blend_out(), fm.blend_out_curve(), false, elapsed, true);
}

/// Ends a play: its open windows close, Ended is raised, the entry is freed.
void end_play(State& s, MontagePlay& p) {
  const MontageInfo& mi = s.def->montages[static_cast<size_t>(p.montage)];
  const uint64_t serial = p.serial;
  for (size_t w = 0; w < mi.windows.size() && p.serial == serial; ++w) {
    if (!((p.open >> w) & 1u)) continue;
    p.open &= ~(uint64_t{1} << w);
    raise(s, MontageEventType::NotifyEnd, p, notify_name(mi, mi.windows[w]), p.position);
  }
  if (p.serial != serial) return;
  p.ended = true;
  raise(s, MontageEventType::Ended, p, {}, p.position, p.interrupted);
  if (p.serial == serial) p.montage = -1;
}

MontagePlay* find_play(State& s, int montage, bool prefer_active) {
  MontagePlay* best = nullptr;
  for (MontagePlay& p : s.plays) {
    if (p.montage != montage || p.montage < 0 || p.ended) continue;
    const auto rank = [&](const MontagePlay& q) { return (prefer_active && !q.blending_out ? 1 : 0); };
    if (!best || rank(p) > rank(*best) || (rank(p) == rank(*best) && p.serial > best->serial)) best = &p;
  }
  return best;
}

}  // namespace

uint16_t intern_name(std::vector<std::string_view>& names, std::string_view name) {
  const auto it = std::find(names.begin(), names.end(), name);
  if (it != names.end()) return static_cast<uint16_t>(it - names.begin());
  names.push_back(name);
  return static_cast<uint16_t>(names.size() - 1);
}

const TrackInfo* track_for(const GraphDefinition::Impl& d, const MontageInfo& m, uint16_t slot) {
  for (uint32_t t = 0; t < m.track_count; ++t)
    if (d.tracks[m.first_track + t].slot == slot) return &d.tracks[m.first_track + t];
  return nullptr;
}

void sample_track(State& s, const TrackInfo& track, double position, PoseSpan out, uint16_t* clip, float* time) {
  const SegmentInfo* seg = &s.def->segments[track.first_segment];
  for (uint32_t k = 1; k < track.segment_count && position >= seg->end; ++k) ++seg;
  const double local = std::clamp(position, seg->begin, seg->end) - seg->begin;
  const float t = std::clamp(static_cast<float>(seg->clip_start + local * seg->rate), seg->clip_start, seg->clip_end);
  SampleOptions options;
  options.loop = false;
  sample(s.def->clips[seg->clip], t, options, s.montage_caches[seg->cache], out);
  *clip = seg->clip;
  *time = t;
}

Status bind_montages(GraphDefinition::Impl& d, const std::string& where) {
  bind_slots(d);
  if (const auto* montages = d.graph->montages()) {
    for (flatbuffers::uoffset_t i = 0; i < montages->size(); ++i) {
      const fb::Montage& m = *montages->Get(i);
      const std::string at = where + ": montage '" + std::string(sv(m.name())) + "'";
      MontageInfo mi;
      mi.fb = &m;
      mi.group = intern_name(d.groups, sv(m.group()));
      mi.first_track = static_cast<uint32_t>(d.tracks.size());
      mi.track_count = m.tracks()->size();
      for (const fb::MontageTrack* track : *m.tracks()) {
        TrackInfo ti;
        ti.slot = intern_name(d.slot_names, sv(track->slot()));
        const size_t first_cache = d.montage_cache_clips.size();
        std::vector<uint8_t> shown = slot_shown_joints(d, ti.slot);
        ti.first_segment = static_cast<uint32_t>(d.segments.size());
        ti.segment_count = track->segments()->size();
        for (const fb::MontageSegment* seg : *track->segments()) {
          const ClipView& clip = d.clips[seg->clip()];
          if (seg->end() > clip.duration() + 1e-4f)
            return Error{at + ": a segment of clip '" + std::string(clip.name()) + "' ends at " +
                         std::to_string(seg->end()) + " s, after the clip's end (" + std::to_string(clip.duration()) +
                         " s)"};
          SegmentInfo si;
          si.clip = seg->clip();
          si.clip_start = seg->start();
          si.clip_end = std::min(seg->end(), clip.duration());
          si.rate = seg->rate();
          const auto cached = std::find(d.montage_cache_clips.begin() + static_cast<std::ptrdiff_t>(first_cache),
                                        d.montage_cache_clips.end(), seg->clip());
          si.cache = static_cast<uint32_t>(cached - d.montage_cache_clips.begin());
          if (cached == d.montage_cache_clips.end()) {
            d.montage_cache_clips.push_back(seg->clip());
            d.montage_cache_joints.push_back(shown);
          }
          si.begin = ti.length;
          ti.length +=
              (static_cast<double>(seg->end()) - static_cast<double>(seg->start())) / static_cast<double>(seg->rate());
          si.end = ti.length;
          d.segments.push_back(si);
        }
        mi.length = std::max(mi.length, ti.length);
        // The track's first frame: what an additive slot measures the track's change against.
        const SegmentInfo& first = d.segments[ti.first_segment];
        auto cache = make_sampling_cache(d.clips[first.clip], d.skeleton, &d.prototypes[first.clip]);
        if (!cache) return Error{at + ": " + cache.error().message};
        Pose reference(d.joints);
        SampleOptions options;
        options.loop = false;
        sample(d.clips[first.clip], first.clip_start, options, *cache, reference);
        d.track_reference.push_back(std::move(reference));
        d.tracks.push_back(ti);
      }
      for (const fb::MontageSection* sec : *m.sections()) mi.section_start.push_back(sec->start());
      d.max_sections = std::max<uint32_t>(d.max_sections, m.sections()->size());
      mi.first_marker = static_cast<uint32_t>(d.markers.size());
      if (const auto* notifies = m.notifies()) {
        for (flatbuffers::uoffset_t k = 0; k < notifies->size(); ++k) {
          const fb::MontageNotify& n = *notifies->Get(k);
          const auto notify = static_cast<uint16_t>(k);
          switch (n.kind()) {
            case fb::MontageNotifyKind::Window: {
              const auto bit = static_cast<uint8_t>(mi.windows.size());
              mi.windows.push_back(notify);
              d.markers.push_back({n.time(), notify, MarkerType::Begin, bit});
              d.markers.push_back({static_cast<double>(n.time()) + n.duration(), notify, MarkerType::End, bit});
              break;
            }
            case fb::MontageNotifyKind::BranchingPoint:
              d.markers.push_back({n.time(), notify, MarkerType::Branch, 0});
              break;
            default: d.markers.push_back({n.time(), notify, MarkerType::Instant, 0}); break;
          }
        }
      }
      mi.marker_count = static_cast<uint32_t>(d.markers.size()) - mi.first_marker;
      std::stable_sort(d.markers.begin() + mi.first_marker, d.markers.end(), [](const Marker& a, const Marker& b) {
        return a.time < b.time || (a.time == b.time && a.type < b.type);
      });
      mi.inertial =
          m.blend_in_curve() == fb::MontageCurve::Inertialize || m.blend_out_curve() == fb::MontageCurve::Inertialize;
      d.montages.push_back(std::move(mi));
    }
  }
  // The filtered prototypes, once every filter has its final address.
  for (size_t k = 0; k < d.montage_cache_clips.size(); ++k) {
    const uint16_t clip = d.montage_cache_clips[k];
    auto prototype = make_sampling_cache(d.clips[clip], d.skeleton, nullptr, d.montage_cache_joints[k]);
    if (!prototype) return Error{where + ": " + prototype.error().message};
    d.montage_prototypes.push_back(std::move(*prototype));
  }
  for (SlotInfo& slot : d.slots)
    for (const MontageInfo& mi : d.montages)
      if (mi.group == slot.group && mi.inertial && slot.inertia < 0)
        slot.inertia = static_cast<int32_t>(d.inertial_slots++);
  d.identity = Pose(d.joints);
  return {};
}

void advance_montages(State& s, float dt) {
  // The events of the update before last go; those host calls raised since the last one stay.
  if (s.montage_events_old > 0) {
    s.montage_events.erase(s.montage_events.begin(),
                           s.montage_events.begin() +
                               static_cast<std::ptrdiff_t>(std::min(s.montage_events_old, s.montage_events.size())));
    s.montage_events_old = 0;
  }
  s.root_motion = RootMotionDelta{};
  if (!s.montages_active) return;  // nothing plays: a graph with montages costs this much per update
  for (MontagePlay& p : s.plays) {
    p.weight_before = p.weight;
    p.slot_weight = 0.0f;
  }
  for (size_t i = 0; i < s.plays.size(); ++i)
    if (s.plays[i].montage >= 0 && !s.plays[i].ended) advance_play(s, s.plays[i], dt);
  for (MontagePlay& p : s.plays)
    if (p.montage >= 0) step_weight(s, p, dt);
}

void finish_montages(State& s) {
  if (s.montages_active) {
    bool any = false;
    for (MontagePlay& p : s.plays) {
      if (p.montage >= 0 && p.blending_out && !(p.weight > 0.0f)) end_play(s, p);
      any |= p.montage >= 0;
    }
    s.montages_active = any;
  }
  s.montage_events_old = s.montage_events.size();
}

void clear_montages(State& s) {
  for (MontagePlay& p : s.plays) p.montage = -1;
  s.montages_active = false;
  for (MachineState& m : s.slot_inertia) {
    m.inertial = false;
    m.last_update = m.before_last_update = 0;
  }
  s.montage_events.clear();
  s.montage_events_old = 0;
  s.root_motion = RootMotionDelta{};
}

}  // namespace graph_detail

// ---- the definition's montage queries -------------------------------------------------------

size_t GraphDefinition::montage_count() const { return impl_->montages.size(); }
std::string_view GraphDefinition::montage_name(size_t m) const {
  return m < montage_count() ? sv(impl_->montages[m].fb->name()) : std::string_view();
}
int GraphDefinition::find_montage(std::string_view name) const {
  for (size_t m = 0; m < montage_count(); ++m)
    if (montage_name(m) == name) return static_cast<int>(m);
  return -1;
}
std::string_view GraphDefinition::montage_group(size_t m) const {
  return m < montage_count() ? impl_->groups[impl_->montages[m].group] : std::string_view();
}
float GraphDefinition::montage_length(size_t m) const {
  return m < montage_count() ? static_cast<float>(impl_->montages[m].length) : 0.0f;
}
size_t GraphDefinition::section_count(size_t m) const {
  return m < montage_count() ? impl_->montages[m].section_start.size() : 0;
}
std::string_view GraphDefinition::section_name(size_t m, size_t k) const {
  return k < section_count(m)
             ? sv(impl_->montages[m].fb->sections()->Get(static_cast<flatbuffers::uoffset_t>(k))->name())
             : std::string_view();
}
float GraphDefinition::section_start(size_t m, size_t k) const {
  return k < section_count(m) ? static_cast<float>(impl_->montages[m].section_start[k]) : 0.0f;
}
int GraphDefinition::section_next(size_t m, size_t k) const {
  return k < section_count(m) ? impl_->montages[m].fb->sections()->Get(static_cast<flatbuffers::uoffset_t>(k))->next()
                              : -1;
}
int GraphDefinition::find_section(size_t m, std::string_view name) const {
  for (size_t k = 0; k < section_count(m); ++k)
    if (section_name(m, k) == name) return static_cast<int>(k);
  return -1;
}

// ---- the host's calls -----------------------------------------------------------------------

bool GraphInstance::play_montage(int montage, float rate, int start_section) {
  State& s = *state_;
  s.self = this;
  const GraphDefinition::Impl& d = *s.def;
  if (montage < 0 || static_cast<size_t>(montage) >= d.montages.size() || !(rate >= 0.0f && rate <= 1000.0f))
    return false;
  const MontageInfo& mi = d.montages[static_cast<size_t>(montage)];
  const int section = start_section < 0 ? 0 : start_section;
  if (static_cast<size_t>(section) >= mi.section_start.size()) return false;
  const fb::Montage& fm = *mi.fb;
  // One montage per group: the one playing blends out over this one's blend in.
  for (MontagePlay& p : s.plays)
    if (p.montage >= 0 && !p.blending_out && d.montages[static_cast<size_t>(p.montage)].group == mi.group)
      start_blend_out(s, p, fm.blend_in(), fm.blend_in_curve(), true, 0.0f, false);
  MontagePlay* slot = nullptr;
  for (MontagePlay& p : s.plays)
    if (p.montage < 0) slot = slot ? slot : &p;
  if (!slot) {  // all taken: the faintest (oldest among equals) makes room
    for (MontagePlay& p : s.plays)
      if (!slot || p.weight < slot->weight || (p.weight == slot->weight && p.serial < slot->serial)) slot = &p;
    slot->interrupted = true;
    end_play(s, *slot);
    if (slot->montage >= 0) return false;  // a listener played another into it
  }
  int16_t* links = slot->next;
  *slot = MontagePlay{};
  slot->next = links;
  slot->montage = montage;
  slot->serial = ++s.play_serial;
  s.montages_active = true;
  slot->section = static_cast<uint16_t>(section);
  slot->position = mi.section_start[static_cast<size_t>(section)];
  slot->rate = rate * fm.rate();
  for (size_t k = 0; k < mi.section_start.size(); ++k)
    links[k] = fm.sections()->Get(static_cast<flatbuffers::uoffset_t>(k))->next();
  begin_blend(*slot, 1.0f, fm.blend_in(), fm.blend_in_curve(), 0.0f, false);
  const uint64_t serial = slot->serial;
  raise(s, MontageEventType::Started, *slot, {}, slot->position);
  if (slot->serial == serial) jump(s, *slot, mi, section);  // opens the windows the start lands inside
  return true;
}

bool GraphInstance::play_montage(std::string_view montage, float rate, std::string_view start_section) {
  const int m = definition().find_montage(montage);
  if (m < 0) return false;
  int section = -1;
  if (!start_section.empty() && (section = definition().find_section(static_cast<size_t>(m), start_section)) < 0)
    return false;
  return play_montage(m, rate, section);
}

bool GraphInstance::stop_montage(int montage, float blend_out) {
  State& s = *state_;
  s.self = this;
  if (std::isnan(blend_out) || blend_out > 1e6f) return false;
  bool any = false;
  for (MontagePlay& p : s.plays) {
    if (p.montage < 0 || p.blending_out || (montage >= 0 && p.montage != montage)) continue;
    const fb::Montage& fm = *s.def->montages[static_cast<size_t>(p.montage)].fb;
    start_blend_out(s, p, blend_out >= 0.0f ? blend_out : fm.blend_out(), fm.blend_out_curve(), true, 0.0f, false);
    any = true;
  }
  return any;
}

bool GraphInstance::stop_montage(std::string_view montage, float blend_out) {
  const int m = definition().find_montage(montage);
  return m >= 0 && stop_montage(m, blend_out);
}

bool GraphInstance::set_next_section(int montage, int section, int next) {
  State& s = *state_;
  MontagePlay* p = find_play(s, montage, true);
  if (!p) return false;
  const size_t sections = s.def->montages[static_cast<size_t>(montage)].section_start.size();
  if (section < 0 || static_cast<size_t>(section) >= sections || next < -1 || next >= static_cast<int>(sections))
    return false;
  p->next[section] = static_cast<int16_t>(next);
  return true;
}

bool GraphInstance::set_next_section(std::string_view montage, std::string_view section, std::string_view next) {
  const int m = definition().find_montage(montage);
  if (m < 0) return false;
  const int from = definition().find_section(static_cast<size_t>(m), section);
  const int to = next.empty() ? -1 : definition().find_section(static_cast<size_t>(m), next);
  return from >= 0 && (next.empty() || to >= 0) && set_next_section(m, from, to);
}

bool GraphInstance::jump_to_section(int montage, int section) {
  State& s = *state_;
  s.self = this;
  MontagePlay* p = find_play(s, montage, true);
  if (!p || section < 0) return false;
  const MontageInfo& mi = s.def->montages[static_cast<size_t>(montage)];
  if (static_cast<size_t>(section) >= mi.section_start.size()) return false;
  jump(s, *p, mi, section);
  return true;
}

bool GraphInstance::jump_to_section(std::string_view montage, std::string_view section) {
  const int m = definition().find_montage(montage);
  return m >= 0 && jump_to_section(m, definition().find_section(static_cast<size_t>(m), section));
}

bool GraphInstance::set_montage_rate(int montage, float rate) {
  State& s = *state_;
  MontagePlay* p = find_play(s, montage, true);
  if (!p || !(rate >= 0.0f && rate <= 1000.0f)) return false;
  p->rate = rate * s.def->montages[static_cast<size_t>(montage)].fb->rate();
  return true;
}

MontageStatus GraphInstance::montage_status(int montage) const {
  MontageStatus out;
  MontagePlay* p = find_play(*state_, montage, true);
  if (!p) return out;
  out.playing = true;
  out.blending_out = p->blending_out;
  out.position = static_cast<float>(p->position);
  out.section = p->section;
  out.weight = p->weight;
  out.rate = p->rate;
  out.slot_weight = p->slot_weight;
  return out;
}

std::span<const MontageEvent> GraphInstance::montage_events() const { return state_->montage_events; }

void GraphInstance::set_montage_listener(MontageListener listener, void* user) {
  state_->listener = listener;
  state_->listener_user = user;
}

RootMotionDelta GraphInstance::root_motion() const { return state_->root_motion; }

}  // namespace ossa
