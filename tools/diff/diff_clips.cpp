// diff_clips.cpp — the clip section of ossa-diff: clips matched by name, played with the runtime's
// sampler on both sides and measured with the cooker's probe-point measure (<ossa/anim/pose_error.h>).
//
// Each pair of clips is sampled (ossa::sample, no looping, so the last time is the last frame) at
// both clips' own frame times and the points 1/4, 2/4 and 3/4 of the way between them
// (kClipErrorSubdivisions), over the shorter duration: where the cooker measures its bound, frames
// and what a player sees between them, so ossa-diff of a lossless cook against a compressed one
// reports the compressed cook's own figure. At every time both poses go to model space through their
// own rigs and every joint paired by name (diff_internal.h's joint mapping, the same one the
// skeleton section uses) is measured; the clip's error is the largest, with the joint and time
// where it occurs. A clip-only file's clips play on the --skeleton rig given for its side.
// Duration, frame rate, events and root motion (presence, then the trajectory) are compared too,
// and every morph weight track both clips hold (paired by name) at the same times. A clip that
// drives only morph weights (no joint channel: a blend-shape animal without a skeleton) needs no
// rig: its weights are all there is to compare.
#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <string>
#include <vector>

#include <ossa/anim/pose.h>
#include <ossa/anim/pose_error.h>
#include <ossa/anim/root_motion.h>
#include <ossa/anim/morph.h>
#include <ossa/anim/sample.h>
#include "common/message.h"
#include "tools/diff/diff_internal.h"

namespace ossa::diff::internal {
namespace {

constexpr const char* kSection = "clips";
constexpr double kTimeEpsilon = 1e-4;  // s: durations and event times closer than this are equal
constexpr double kRateEpsilon = 1e-3;  // Hz

/// The rig a clip plays on: its file's skeleton when it binds to it, else the side's rig file.
std::optional<SkeletonView> rig_for(const ClipView& clip, const Asset& file, const Asset* rig) {
  if (const SkeletonView s = file.skeleton(); !s.empty() && check_clip_binding(clip, s, "").ok()) return s;
  if (rig != nullptr && check_clip_binding(clip, rig->skeleton(), "").ok()) return rig->skeleton();
  return std::nullopt;
}

/// A clip with no joint channel and no root motion: morph weights only, played without a rig.
bool morph_only(const ClipView& clip) {
  return clip.constants().empty() && clip.animated().empty() && clip.root_motion() == nullptr;
}

/// A side whose file has no skeleton cannot play its clips without a rig that binds them (clips of
/// morph weights only aside).
Status check_side(const Asset& file, const Asset* rig, const char* side) {
  if (!file.skeleton().empty()) return {};
  for (size_t i = 0; i < file.clip_count(); ++i) {
    const ClipView clip = file.clip(i);
    if (morph_only(clip) || rig_for(clip, file, rig)) continue;
    if (rig == nullptr)
      return Error{file.name() + ": a clip-only file (no skeleton): pass --skeleton (or --" + side +
                   "-skeleton) with the cooked rig its clips were made for"};
    return Error{rig->name() + ": clip " + quote_name(clip.name()) + " of " + file.name() +
                 " was not cooked for this skeleton (" +
                 check_clip_binding(clip, rig->skeleton(), clip.name()).message() + ")"};
  }
  return {};
}

ClipSide side_of(const ClipView& clip, double mm_per_unit) {
  ClipSide s;
  s.duration_s = clip.duration();
  s.rate_hz = clip.sample_rate();
  s.frame_count = clip.frame_count();
  s.root_motion = has_root_motion(clip);
  if (const auto* events = clip.fb->events())
    for (const fb::ClipEvent* e : *events)
      s.events.push_back({std::string(flatbuffers::GetStringView(e->name())), e->time()});
  if (const fb::ClipCompression* c = clip.compression()) s.cooker_max_error_mm = c->max_error() * mm_per_unit;
  return s;
}

struct SampleTime {
  double t;
  bool old_frame;  // one of the old clip's own frame times
};

std::vector<SampleTime> sample_times(const ClipView& a, const ClipView& b) {
  const double end = std::min<double>(a.duration(), b.duration());
  std::vector<SampleTime> times;
  const auto add_grid = [&](double rate, uint32_t frames, bool old_frames) {
    for (uint32_t f = 0; f < frames; ++f) {
      for (uint32_t k = 0; k < kClipErrorSubdivisions; ++k) {
        if (k > 0 && f + 1 >= frames) break;
        const double t = (f + static_cast<double>(k) / kClipErrorSubdivisions) / rate;
        if (t > end + 1e-9) break;
        times.push_back({std::min(t, end), old_frames && k == 0});
      }
    }
  };
  add_grid(a.sample_rate(), a.frame_count(), true);
  add_grid(b.sample_rate(), b.frame_count(), false);
  times.push_back({end, false});
  std::sort(times.begin(), times.end(), [](const SampleTime& x, const SampleTime& y) { return x.t < y.t; });
  std::vector<SampleTime> unique;
  for (const SampleTime& s : times) {
    if (!unique.empty() && s.t - unique.back().t < 1e-7) {
      unique.back().old_frame = unique.back().old_frame || s.old_frame;
    } else {
      unique.push_back(s);
    }
  }
  return unique;
}

/// One side of a clip pair: its sampler state and the pose buffers, allocated once.
struct Player {
  ClipView clip;
  SkeletonView rig;
  SamplingCache cache;
  Pose pose;
  std::vector<ModelAffine> model;

  void at(double t, double length_factor) {
    sample(clip, static_cast<float>(t), SampleOptions{false, RotationInterpolation::Nlerp}, cache, pose);
    local_to_model_affine(rig.parents(), pose, model);
    if (length_factor != 1.0)
      for (ModelAffine& m : model) m.origin *= length_factor;
  }
};

std::optional<Player> make_player(const ClipView& clip, const SkeletonView& rig) {
  auto cache = make_sampling_cache(clip, rig);
  if (!cache) return std::nullopt;
  const auto joints = static_cast<uint32_t>(rig.joint_count());
  return Player{clip, rig, std::move(cache).value(), Pose(joints), std::vector<ModelAffine>(joints)};
}

void compare_events(Context& c, const std::string& label, ClipItem& item) {
  const auto& a = item.old_side.events;
  const auto& b = item.new_side.events;
  const auto text = [](const ClipEventFact& e) { return quote_name(e.name) + " at " + num(e.time_s) + " s"; };
  for (size_t i = 0; i < std::max(a.size(), b.size()); ++i) {
    const std::string where = "event " + std::to_string(i);
    if (i >= b.size()) {
      c.add_text(kSection, label, "event removed", text(a[i]), where);
    } else if (i >= a.size()) {
      c.add_text(kSection, label, "event added", text(b[i]), where);
    } else if (a[i].name != b[i].name || std::fabs(a[i].time_s - b[i].time_s) > kTimeEpsilon) {
      c.add_text(kSection, label, "event", text(a[i]) + " -> " + text(b[i]), where);
    } else {
      continue;
    }
    item.events_same = false;
  }
}

/// Largest yaw difference, wrapped to [0, 180] degrees.
double yaw_difference_deg(double a, double b) {
  const double d = std::remainder(a - b, 2.0 * std::numbers::pi);
  return std::fabs(d) * 180.0 / std::numbers::pi;
}

void measure(Context& c, const std::string& label, ClipItem& item, Player& a, Player& b) {
  const bool same_rig = a.rig.hash() == b.rig.hash();
  std::vector<std::pair<size_t, size_t>> pairs;
  if (same_rig) {
    for (size_t j = 0; j < a.rig.joint_count(); ++j) pairs.emplace_back(j, j);
  } else {
    const JointMapping m = map_joints(a.rig, b.rig);
    for (size_t j = 0; j < m.old_to_new.size(); ++j)
      if (m.old_to_new[j] >= 0) pairs.emplace_back(j, static_cast<size_t>(m.old_to_new[j]));
    item.joints_skipped = a.rig.joint_count() + b.rig.joint_count() - 2 * pairs.size();
    if (item.joints_skipped > 0)
      c.report.notes.push_back("clip '" + label + "': the rigs differ; " + std::to_string(pairs.size()) +
                               " joints compared by name, " + std::to_string(item.joints_skipped) +
                               " joints in one rig only skipped");
  }
  item.joints_compared = pairs.size();
  const double probe = c.probe_old_units(), factor = c.new_to_old(), mm = c.old_mm();
  const bool root_motion = item.old_side.root_motion && item.new_side.root_motion;
  double rm_mm = 0.0, rm_deg = 0.0;
  const std::vector<SampleTime> times = sample_times(a.clip, b.clip);
  for (const SampleTime& st : times) {
    a.at(st.t, 1.0);
    b.at(st.t, factor);
    for (const auto& [i, k] : pairs) {
      const double err = probe_error(a.model[i], b.model[k], probe) * mm;
      if (item.worst_joint.empty() || err > item.max_error_mm) {
        item.max_error_mm = err;
        item.worst_joint = std::string(a.rig.joint_name(i));
        item.worst_time_s = st.t;
      }
      if (st.old_frame) item.max_error_at_frames_mm = std::max(item.max_error_at_frames_mm, err);
    }
    if (root_motion) {
      const RootMotionDelta x = root_motion_delta(a.clip, 0.0, st.t), y = root_motion_delta(b.clip, 0.0, st.t);
      rm_mm = std::max(rm_mm, glm::length(glm::dvec3(x.translation) * mm - glm::dvec3(y.translation) * (factor * mm)));
      rm_deg = std::max(rm_deg, yaw_difference_deg(x.yaw, y.yaw));
    }
  }
  item.times = times.size();
  item.sampled = true;
  if (item.max_error_mm > c.tolerance_mm)
    c.add_figure(kSection, label, "joint error", item.max_error_mm, "mm", c.tolerance_mm,
                 "joint " + quote_name(item.worst_joint) + " at " + num(item.worst_time_s) + " s");
  if (!root_motion) return;
  item.root_motion_mm = rm_mm;
  item.root_motion_deg = rm_deg;
  if (rm_mm > c.tolerance_mm) c.add_figure(kSection, label, "root motion translation", rm_mm, "mm", c.tolerance_mm);
  // A yaw difference is judged by how far it moves a point at the probe distance.
  const double limit_deg =
      2.0 * std::asin(std::min(1.0, c.tolerance_mm / (2.0 * kProbeMetres * 1000.0))) * 180.0 / std::numbers::pi;
  if (rm_deg > limit_deg) c.add_figure(kSection, label, "root motion yaw", rm_deg, "deg", limit_deg);
}

/// Weight tracks: added and removed ones named, the paired ones sampled at `times`.
void compare_morph_weights(Context& c, const std::string& label, ClipItem& item, const ClipView& a, const ClipView& b,
                           const std::vector<SampleTime>& times) {
  std::vector<std::string> old_names, new_names;
  for (size_t i = 0; i < a.morph_track_count(); ++i)
    old_names.emplace_back(flatbuffers::GetStringView(a.morph_track(i).name()));
  for (size_t k = 0; k < b.morph_track_count(); ++k)
    new_names.emplace_back(flatbuffers::GetStringView(b.morph_track(k).name()));
  const NameMatch m = match_by_name(old_names, new_names);
  for (size_t i : m.only_old) c.add_text(kSection, label, "morph track removed", quote_name(old_names[i]));
  for (size_t k : m.only_new) c.add_text(kSection, label, "morph track added", quote_name(new_names[k]));
  std::string worst;
  double worst_time = 0.0;
  for (const auto& [i, k] : m.pairs) {
    for (const SampleTime& st : times) {
      const auto t = static_cast<float>(st.t);
      const double d = std::fabs(static_cast<double>(sample_morph_track(a, a.morph_track(i), t)) -
                                 static_cast<double>(sample_morph_track(b, b.morph_track(k), t)));
      if (worst.empty() || d > item.max_morph_weight_error) {
        item.max_morph_weight_error = d;
        worst = old_names[i];
        worst_time = st.t;
      }
    }
  }
  item.morph_tracks_compared = m.pairs.size();
  if (item.max_morph_weight_error > kMorphWeightTolerance)
    c.add_figure(kSection, label, "morph weight", item.max_morph_weight_error, "", kMorphWeightTolerance,
                 "track " + quote_name(worst) + " at " + num(worst_time) + " s");
}

ClipItem compare_clip(Context& c, const std::string& label, const ClipView& a, const ClipView& b) {
  ClipItem item;
  item.name = label;
  item.old_side = side_of(a, c.old_mm());
  item.new_side = side_of(b, c.new_mm());
  const ClipSide &x = item.old_side, &y = item.new_side;
  if (std::fabs(x.duration_s - y.duration_s) > kTimeEpsilon)
    c.add_figure(kSection, label, "duration", std::fabs(x.duration_s - y.duration_s), "s", kTimeEpsilon,
                 num(x.duration_s) + " s -> " + num(y.duration_s) + " s");
  if (std::fabs(x.rate_hz - y.rate_hz) > kRateEpsilon)
    c.add_figure(kSection, label, "frame rate", std::fabs(x.rate_hz - y.rate_hz), "Hz", kRateEpsilon,
                 num(x.rate_hz) + " Hz -> " + num(y.rate_hz) + " Hz");
  if (x.root_motion != y.root_motion) c.add_text(kSection, label, "root motion", x.root_motion ? "removed" : "added");
  compare_events(c, label, item);
  compare_morph_weights(c, label, item, a, b, sample_times(a, b));
  if (morph_only(a) && morph_only(b)) {
    item.times = sample_times(a, b).size();
    item.sampled = true;
    return item;
  }

  const auto rig_a = rig_for(a, c.old_asset, c.old_rig), rig_b = rig_for(b, c.new_asset, c.new_rig);
  std::optional<Player> pa, pb;
  if (rig_a && rig_b) {
    pa = make_player(a, *rig_a);
    pb = make_player(b, *rig_b);
  }
  if (!pa || !pb) {
    item.note = "no skeleton its clip binds to on the " + std::string(!rig_a ? "old" : "new") + " side: not sampled";
    c.add_text(kSection, label, "not comparable", item.note);
    return item;
  }
  measure(c, label, item, *pa, *pb);
  return item;
}

}  // namespace

Status compare_clips(Context& c) {
  if (Status s = check_side(c.old_asset, c.old_rig, "old"); !s) return s;
  if (Status s = check_side(c.new_asset, c.new_rig, "new"); !s) return s;
  ClipSection& out = c.report.clips;
  out.old_count = c.old_asset.clip_count();
  out.new_count = c.new_asset.clip_count();
  std::vector<std::string> old_names, new_names;
  for (size_t i = 0; i < out.old_count; ++i) old_names.emplace_back(c.old_asset.clip(i).name());
  for (size_t k = 0; k < out.new_count; ++k) new_names.emplace_back(c.new_asset.clip(k).name());
  const NameMatch m = match_by_name(old_names, new_names);
  report_added_removed(c, kSection, m, old_names, new_names, out.added, out.removed);
  for (const auto& [i, k] : m.pairs) {
    ClipItem item = compare_clip(c, item_label(old_names, i), c.old_asset.clip(i), c.new_asset.clip(k));
    out.max_error_mm = std::max(out.max_error_mm, item.max_error_mm);
    out.items.push_back(std::move(item));
  }
  return {};
}

}  // namespace ossa::diff::internal
