// root_motion.cpp — root-motion deltas between two playback times (ossa/anim/root_motion.h).
//
// Clip.root_motion holds, per frame f, W_f = (translations[f], yaws[f]): the rigid motion
// "translate by translations[f], after turning by yaws[f] about up" that carries the in-place
// clip's model space to where the original clip had it (cooker/clip/root_motion.cpp states the
// convention). Between frames W is interpolated linearly (translation lerp, yaw lerp of the
// unwrapped angles). Over loops, W(k * duration + tau) = E^k . W(tau) with E = W(duration), the
// end-to-start motion of one cycle: each cycle starts where the previous one ended, turned by the
// yaw accumulated so far.
//
// The delta from `from` to `to` is W(from)^-1 . W(to): the motion expressed in the character's own
// frame at `from` (its position and heading at `from`). A host keeping a world position P and yaw
// Psi applies it as
//     P   += Y(Psi) * delta.translation      (Y(a) = rotation by a about the clip's up axis)
//     Psi += delta.yaw
// and because deltas are defined as W(from)^-1 W(to), consecutive deltas compose to the delta over
// their union exactly (no drift however the time is cut into frames), and delta(to, from) is the
// inverse of delta(from, to). Only the number of whole loops *between* from and to enters (E is
// raised to k_to - k_from), in closed form, so a long-running clock neither loops nor loses
// precision.
//
// Cost: O(1): two frame lookups, a few sines and cosines. No allocation.
#include <ossa/anim/root_motion.h>

#include <algorithm>
#include <cmath>

namespace ossa {
namespace {

/// A ground-plane rigid motion: turn by yaw about up, then translate (components along up are 0).
struct Motion {
  glm::dvec3 translation{0.0};
  double yaw = 0.0;
};

/// v turned by angle a about axis `up` (0 x, 1 y, 2 z), right-handed (as glm::angleAxis).
glm::dvec3 turn(const glm::dvec3& v, double a, int up) {
  const int i = (up + 1) % 3, j = (up + 2) % 3;  // axes i, j, up form a right-handed frame
  const double c = std::cos(a), s = std::sin(a);
  glm::dvec3 r = v;
  r[i] = c * v[i] - s * v[j];
  r[j] = s * v[i] + c * v[j];
  return r;
}

/// a then b: (a . b)(x) = a(b(x)).
Motion compose(const Motion& a, const Motion& b, int up) {
  return {a.translation + turn(b.translation, a.yaw, up), a.yaw + b.yaw};
}

Motion inverse(const Motion& m, int up) { return {-turn(m.translation, -m.yaw, up), -m.yaw}; }

/// e composed with itself n times (n may be negative). The translation is
/// sum_{i<n} Y(i theta) t = Y((n - 1) theta / 2) t * sin(n theta / 2) / sin(theta / 2): the
/// geometric series of rotations, in closed form so whole loops cost O(1).
Motion power(const Motion& e, double n, int up) {
  if (n == 0.0) return {};
  if (n < 0.0) return inverse(power(e, -n, up), up);
  const double half = 0.5 * e.yaw;
  const double s = std::sin(half);
  // sin(n x) / sin(x) -> n as x -> 0; double keeps the ratio accurate down to tiny x.
  const double ratio = std::abs(s) > 1e-12 ? std::sin(n * half) / s : n;
  return {turn(e.translation, (n - 1.0) * half, up) * ratio, n * e.yaw};
}

struct Track {
  const flatbuffers::Vector<const fb::Vec3*>* translations = nullptr;
  const flatbuffers::Vector<float>* yaws = nullptr;
  uint32_t frames = 0;  // usable frames (both vectors have at least this many)
  double duration = 0.0;
  int up = 1;
};

glm::dvec3 vec(const fb::Vec3* v) { return {v->x(), v->y(), v->z()}; }

/// W(tau) for tau in [0, duration].
Motion at(const Track& track, double tau) {
  const double x = std::clamp(tau / track.duration, 0.0, 1.0) * (track.frames - 1);
  const uint32_t i = std::min(static_cast<uint32_t>(x), track.frames - 2);
  const double f = x - i;
  Motion m;
  m.translation = glm::mix(vec(track.translations->Get(i)), vec(track.translations->Get(i + 1)), f);
  m.translation[track.up] = 0.0;
  m.yaw = (1.0 - f) * track.yaws->Get(i) + f * track.yaws->Get(i + 1);
  return m;
}

/// The usable root-motion track of a clip: frames >= 2 and a positive duration; else frames == 0.
Track track_of(const ClipView& clip) {
  Track track;
  if (clip.fb == nullptr) return track;
  const fb::RootMotion* rm = clip.fb->root_motion();
  if (rm == nullptr || rm->translations() == nullptr || rm->yaws() == nullptr) return track;
  const double duration = clip.fb->duration();
  // Mismatched lengths are a validation error; the shorter one still bounds every read here.
  const uint32_t frames = std::min(rm->translations()->size(), rm->yaws()->size());
  if (frames < 2 || !(duration > 0.0) || !std::isfinite(duration)) return track;
  track.translations = rm->translations();
  track.yaws = rm->yaws();
  track.frames = frames;
  track.duration = duration;
  track.up = rm->up_axis() % 3;
  return track;
}

}  // namespace

bool has_root_motion(const ClipView& clip) { return clip.fb != nullptr && clip.fb->root_motion() != nullptr; }

RootMotionDelta root_motion_delta(const ClipView& clip, double from, double to) {
  const Track track = track_of(clip);
  if (track.frames == 0 || !std::isfinite(from) || !std::isfinite(to)) return {};
  const double loops_from = std::floor(from / track.duration);
  const double loops_to = std::floor(to / track.duration);
  const Motion start = at(track, from - loops_from * track.duration);
  const Motion end = at(track, to - loops_to * track.duration);
  const Motion cycle = at(track, track.duration);
  // W(from)^-1 W(to) = W(tau_from)^-1 . E^(k_to - k_from) . W(tau_to).
  const Motion m = compose(compose(inverse(start, track.up), power(cycle, loops_to - loops_from, track.up), track.up),
                           end, track.up);
  RootMotionDelta delta;
  delta.translation = glm::vec3(m.translation);
  delta.yaw = static_cast<float>(m.yaw);
  return delta;
}

}  // namespace ossa
