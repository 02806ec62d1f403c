// validate_montage.cpp — see internal/validate_montage.h. What the montage player
// (graph_montage.cpp, graph_slot.cpp) relies on without a check of its own: clip indices in range,
// every segment and section of positive length (so playback always moves forward and a section
// loop ends), section links in range, notifies sorted and bounded, and numbers it can multiply.
#include "internal/validate_montage.h"

#include <cmath>

#include "common/message.h"

namespace ossa::detail {
namespace {

constexpr double kMaxSeconds = 1e6;
constexpr float kMaxRate = 1000.0f, kMinRate = 1e-3f;

bool seconds_ok(float v) { return std::isfinite(v) && v >= 0.0f && v <= kMaxSeconds; }
bool rate_ok(float v) { return std::isfinite(v) && v >= kMinRate && v <= kMaxRate; }
bool curve_ok(fb::MontageCurve c) { return static_cast<unsigned>(c) <= static_cast<unsigned>(fb::MontageCurve::MAX); }
// Built with += rather than "'" + std::string&&: GCC 12 at -O3 reports a false -Wrestrict inside
// the inlined std::string::insert that operator+(const char*, string&&) becomes (GCC bug 105329).
std::string quoted(const flatbuffers::String* s) {
  std::string out = "'";
  out += printable(flatbuffers::GetStringView(s));
  out += '\'';
  return out;
}

bool spend(uint64_t& budget, uint64_t bytes, bool* over) {
  if (bytes > budget) return !(*over = true);
  budget -= bytes;
  return true;
}

std::string check_montage(const fb::Montage& m, size_t index, size_t clip_count, uint64_t& budget, bool* over) {
  std::string at = format("montage %zu", index);
  if (flatbuffers::GetStringView(m.name()).empty()) return at + ": has an empty name";
  at += ' ';  // not " " + quoted(...): the same false -Wrestrict as in quoted()
  at += quoted(m.name());
  if (flatbuffers::GetStringView(m.group()).empty()) return at + ": has an empty group name";
  if (!rate_ok(m.rate())) return at + format(": rate %g must be within [%g, %g]", m.rate(), kMinRate, kMaxRate);
  if (!seconds_ok(m.blend_in()) || !seconds_ok(m.blend_out()))
    return at + format(": blend in %g s and blend out %g s must be within [0, 1e6]", m.blend_in(), m.blend_out());
  if (!curve_ok(m.blend_in_curve()) || !curve_ok(m.blend_out_curve()))
    return at + format(": unknown blend curve %u / %u", static_cast<unsigned>(m.blend_in_curve()),
                       static_cast<unsigned>(m.blend_out_curve()));
  if (!std::isfinite(m.blend_out_trigger()) || m.blend_out_trigger() > kMaxSeconds)
    return at + format(": blend out trigger %g s must be finite and at most 1e6", m.blend_out_trigger());

  const auto& tracks = *m.tracks();
  if (tracks.size() == 0 || tracks.size() > kMaxMontageTracks)
    return at + format(": %u tracks; a montage needs 1 to %u", tracks.size(), kMaxMontageTracks);
  double length = 0.0;
  for (flatbuffers::uoffset_t t = 0; t < tracks.size(); ++t) {
    const fb::MontageTrack& track = *tracks.Get(t);
    const std::string tat = at + format(" track %u", t);
    if (flatbuffers::GetStringView(track.slot()).empty()) return tat + ": names no slot";
    const auto& segments = *track.segments();
    if (!spend(budget, uint64_t(segments.size()) * 16, over)) return {};
    if (segments.size() == 0 || segments.size() > kMaxMontageSegments)
      return tat + format(": %u segments; a track needs 1 to %u", segments.size(), kMaxMontageSegments);
    for (flatbuffers::uoffset_t k = 0; k < segments.size(); ++k) {
      const fb::MontageSegment& s = *segments.Get(k);
      const std::string sat = tat + format(" segment %u", k);
      if (s.clip() >= clip_count) return sat + format(": clip %u is out of range (%zu clips)", s.clip(), clip_count);
      if (!seconds_ok(s.start()) || !seconds_ok(s.end()) || !(s.end() > s.start()))
        return sat +
               format(": start %g s and end %g s must be within [0, 1e6] with end after start", s.start(), s.end());
      if (!rate_ok(s.rate())) return sat + format(": rate %g must be within [%g, %g]", s.rate(), kMinRate, kMaxRate);
    }
    const double l = montage_track_length(track);
    if (!(l <= kMaxSeconds)) return tat + format(": %g s long, more than 1e6 s", l);
    length = std::max(length, l);
  }

  const auto& sections = *m.sections();
  if (!spend(budget, uint64_t(sections.size()) * 16, over)) return {};
  if (sections.size() == 0 || sections.size() > kMaxMontageSections)
    return at + format(": %u sections; a montage needs 1 to %u", sections.size(), kMaxMontageSections);
  for (flatbuffers::uoffset_t k = 0; k < sections.size(); ++k) {
    const fb::MontageSection& s = *sections.Get(k);
    const std::string sat = at + format(" section %u", k);
    if (flatbuffers::GetStringView(s.name()).empty()) return sat + ": has an empty name";
    if (!std::isfinite(s.start()) || (k == 0 && s.start() != 0.0f))
      return sat + format(": starts at %g s; the first section starts at 0", s.start());
    if (k > 0 && !(s.start() > sections.Get(k - 1)->start()))
      return sat + format(": starts at %g s, not after the section before it", s.start());
    if (!(s.start() < length))
      return sat + format(": starts at %g s, not before the montage's end (%g s)", s.start(), length);
    if (s.next() < -1 || s.next() >= static_cast<int>(sections.size()))
      return sat + format(": next section %d is out of range (%u sections)", s.next(), sections.size());
  }

  if (const auto* notifies = m.notifies()) {
    if (!spend(budget, uint64_t(notifies->size()) * 16, over)) return {};
    if (notifies->size() > kMaxMontageNotifies)
      return at + format(": %u notifies, more than %u", notifies->size(), kMaxMontageNotifies);
    uint32_t windows = 0;
    for (flatbuffers::uoffset_t k = 0; k < notifies->size(); ++k) {
      const fb::MontageNotify& n = *notifies->Get(k);
      const std::string nat = at + format(" notify %u", k);
      if (flatbuffers::GetStringView(n.name()).empty()) return nat + ": has an empty name";
      if (static_cast<unsigned>(n.kind()) > static_cast<unsigned>(fb::MontageNotifyKind::MAX))
        return nat + format(": unknown kind %u", static_cast<unsigned>(n.kind()));
      if (!std::isfinite(n.time()) || n.time() < 0.0f || n.time() > length)
        return nat + format(": time %g s is outside the montage [0, %g s]", n.time(), length);
      if (k > 0 && n.time() < notifies->Get(k - 1)->time()) return nat + ": notifies are not sorted by time";
      const bool window = n.kind() == fb::MontageNotifyKind::Window;
      if (!seconds_ok(n.duration()) || (window && !(n.duration() > 0.0f)))
        return nat + format(": duration %g s must be within [0, 1e6] (above 0 for a window)", n.duration());
      if (window && ++windows > kMaxMontageWindows)
        return at + format(": more than %u window notifies", kMaxMontageWindows);
    }
  }
  return {};
}

}  // namespace

double montage_track_length(const fb::MontageTrack& track) {
  double length = 0.0;
  for (const fb::MontageSegment* s : *track.segments())
    length += (static_cast<double>(s->end()) - static_cast<double>(s->start())) / static_cast<double>(s->rate());
  return length;
}

std::string check_slot_node(const fb::SlotNode& slot, size_t node, uint32_t joint_count, uint64_t& budget,
                            bool* over_budget) {
  const std::string at = format("node %zu (slot)", node);
  if (flatbuffers::GetStringView(slot.slot()).empty()) return at + ": has an empty slot name";
  if (flatbuffers::GetStringView(slot.group()).empty()) return at + ": has an empty group name";
  if (const auto* mask = slot.mask()) {
    if (!spend(budget, uint64_t(mask->size()) * 4, over_budget)) return {};
    for (const fb::MaskEntry* e : *mask) {
      if (e->joint() >= joint_count)
        return at + format(": mask joint %u is out of range (%u joints)", e->joint(), joint_count);
      if (e->depth() < -1) return at + format(": mask depth %d must be -1 (all) or more", e->depth());
    }
  }
  return {};
}

std::string check_montages(const fb::Graph& graph, uint64_t& budget, bool* over_budget) {
  const auto* montages = graph.montages();
  if (!montages) return {};
  if (!spend(budget, uint64_t(montages->size()) * 32, over_budget)) return {};
  const size_t clips = graph.clips()->size();
  for (flatbuffers::uoffset_t i = 0; i < montages->size(); ++i) {
    std::string e = check_montage(*montages->Get(i), i, clips, budget, over_budget);
    if (!e.empty() || *over_budget) return e;
  }
  return {};
}

}  // namespace ossa::detail
