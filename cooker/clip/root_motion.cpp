// root_motion.cpp — extracting root motion at cook time (cooker/clip/root_motion.h).
//
// The convention, one definition that the runtime (runtime/anim/root_motion.cpp) and the tests rely on.
// Let u be the up axis, and for frame f of the clip's grid (cooker/model/clip_grid.h) let the root
// joint's local (= model-space) transform be T(p_f) R(q_f) S(s_f). Then
//   ground  g_f = p_f - (p_f . u) u          height h_f = (p_f . u) u
//   yaw     psi_f = angle of the twist of q_f about u (swing-twist decomposition), unwrapped
//           across frames so neighbours differ by less than pi; dpsi_f = psi_f - psi_0
//   Y(a)    = the rotation by a about u (right-handed: glm::angleAxis(a, u))
// and extraction stores and rewrites:
//   root motion   yaws[f]         = dpsi_f
//                 translations[f] = g_f - Y(dpsi_f) g_0           (ground plane; frame 0: 0)
//   root track    p'_f = g_0 + h_f                                (height kept, ground of frame 0)
//                 q'_f = Y(-dpsi_f) q_f                           (heading of frame 0, pitch/roll kept)
//                 s'_f = s_f                                      (scale keys untouched)
// so that with W_f = T(translations[f]) Y(yaws[f]), the rigid motion of the character,
//   W_f . T(p'_f) R(q'_f) S(s_f) = T(p_f) R(q_f) S(s_f)     exactly (Y(.) fixes h_f, which is along u):
// playing the in-place clip under the character transform W reproduces the original root. W's
// pivot is the model origin (not the root's ground point g_0), which is what lets the runtime hand
// the host a plain "translate, then turn" delta; translations[f] is simply g_f - g_0 whenever the
// root starts over the origin or does not turn.
//
// Twist about u is taken on the left (q = Y(psi) * rest): heading is a turn in model space.
// The twist's angle from the projection of q's vector part onto u is the same whichever side the
// swing is on, and Y(a) q has twist angle psi + a exactly, so a pure turn of the character shows up
// entirely as yaw even when the root carries a constant tilt (e.g. a Z-up rig folded into Y-up).
//
// Cost: O(frames * log(keys)) for the root track; one allocation per output vector.
#include "cooker/clip/root_motion.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <glm/gtc/quaternion.hpp>

#include "cooker/model/clip_grid.h"

namespace ossa::cook {
namespace {

constexpr double kPi = 3.14159265358979323846;

/// Index i of the key segment [i - 1, i] holding t and the blend factor there; t outside the
/// keys clamps to the first / last key (i == 1, f == 0 / i == last, f == 1).
size_t segment(const std::vector<float>& times, double t, double* f) {
  const size_t i = static_cast<size_t>(std::upper_bound(times.begin(), times.end(), t) - times.begin());
  if (i == 0) {
    *f = 0.0;
    return 1;
  }
  if (i == times.size()) {
    *f = 1.0;
    return times.size() - 1;
  }
  *f = (t - times[i - 1]) / (static_cast<double>(times[i]) - times[i - 1]);
  return i;
}

glm::dvec3 sample_vec(const std::vector<float>& times, const std::vector<glm::vec3>& values, double t,
                      const glm::vec3& bind) {
  if (times.empty() || values.size() != times.size()) return glm::dvec3(bind);
  if (times.size() == 1) return glm::dvec3(values[0]);
  double f = 0.0;
  const size_t i = segment(times, t, &f);
  return glm::mix(glm::dvec3(values[i - 1]), glm::dvec3(values[i]), f);
}

glm::dquat sample_quat(const std::vector<float>& times, const std::vector<glm::quat>& values, double t,
                       const glm::quat& bind) {
  if (times.empty() || values.size() != times.size()) return glm::normalize(glm::dquat(bind));
  if (times.size() == 1) return glm::normalize(glm::dquat(values[0]));
  double f = 0.0;
  const size_t i = segment(times, t, &f);
  const glm::dquat a(values[i - 1]);
  glm::dquat b(values[i]);
  if (glm::dot(a, b) < 0.0) b = -b;  // shortest arc
  return glm::normalize(glm::slerp(a, b, f));
}

/// Angle of the twist of q about the unit axis `up`, in (-2 pi, 2 pi]; `fallback` when q is a
/// half turn about an axis normal to up (its twist is undefined there).
double twist_angle(const glm::dquat& q, const glm::dvec3& up, double fallback) {
  const double along = q.x * up.x + q.y * up.y + q.z * up.z;
  if (std::abs(along) < 1e-9 && std::abs(q.w) < 1e-9) return fallback;
  return 2.0 * std::atan2(along, q.w);
}

}  // namespace

Status extract_root_motion(SourceClip& clip, const SourceSkeleton& skeleton, uint8_t up_axis) {
  const std::string where = "clip '" + clip.name + "': root motion: ";
  if (up_axis > 2) return Error{where + "up axis must be 0 (x), 1 (y) or 2 (z), not " + std::to_string(up_axis)};
  if (skeleton.joints.empty()) return Error{where + "the file has no skeleton"};
  const SourceJoint& root = skeleton.joints[0];
  auto track_it =
      std::find_if(clip.tracks.begin(), clip.tracks.end(), [](const SourceTrack& t) { return t.joint == 0; });
  if (track_it == clip.tracks.end()) return Error{where + "no track animates the root joint '" + root.name + "'"};
  const FrameGrid grid = frame_grid(clip);
  if (grid.frame_count > kMaxFrames)
    return Error{where + std::to_string(grid.frame_count) + " frames, more than the " + std::to_string(kMaxFrames) +
                 " a clip may have"};
  SourceTrack& track = *track_it;

  glm::dvec3 up(0.0);
  up[up_axis] = 1.0;
  const uint32_t frames = grid.frame_count;
  std::vector<glm::dvec3> p(frames);
  std::vector<glm::dquat> q(frames);
  std::vector<double> yaw(frames);
  double previous = 0.0;
  for (uint32_t f = 0; f < frames; ++f) {
    const double t = static_cast<double>(grid.time(f));
    p[f] = sample_vec(track.translation_times, track.translations, t, root.translation);
    q[f] = sample_quat(track.rotation_times, track.rotations, t, root.rotation);
    double a = twist_angle(q[f], up, previous);
    // Unwrap: the representative of a (mod 2 pi) nearest the previous frame's yaw.
    if (f > 0) a += 2.0 * kPi * std::round((previous - a) / (2.0 * kPi));
    yaw[f] = a;
    previous = a;
  }

  const glm::dvec3 g0 = p[0] - glm::dot(p[0], up) * up;
  SourceRootMotion motion;
  motion.up_axis = up_axis;
  motion.translations.resize(frames);
  motion.yaws.resize(frames);
  SourceTrack rewritten;
  rewritten.joint = track.joint;
  rewritten.translation_times.resize(frames);
  rewritten.translations.resize(frames);
  rewritten.rotation_times.resize(frames);
  rewritten.rotations.resize(frames);
  for (uint32_t f = 0; f < frames; ++f) {
    const double dpsi = yaw[f] - yaw[0];
    const glm::dquat turn = glm::angleAxis(dpsi, up);
    const glm::dvec3 height = glm::dot(p[f], up) * up;
    const glm::dvec3 ground = p[f] - height;
    glm::dvec3 moved = ground - turn * g0;
    moved[up_axis] = 0.0;  // exactly in the ground plane (turn * g0 is, up to round-off)
    motion.translations[f] = glm::vec3(moved);
    motion.yaws[f] = static_cast<float>(dpsi);

    glm::dquat in_place = glm::normalize(glm::conjugate(turn) * q[f]);
    // Keep neighbouring keys on one hemisphere, as SourceTrack promises.
    if (f > 0 && glm::dot(in_place, glm::dquat(rewritten.rotations[f - 1])) < 0.0) in_place = -in_place;
    rewritten.translation_times[f] = grid.time(f);
    rewritten.translations[f] = glm::vec3(g0 + height);
    rewritten.rotation_times[f] = grid.time(f);
    rewritten.rotations[f] = glm::quat(in_place);
  }
  track.translation_times = std::move(rewritten.translation_times);
  track.translations = std::move(rewritten.translations);
  track.rotation_times = std::move(rewritten.rotation_times);
  track.rotations = std::move(rewritten.rotations);
  clip.root_motion = std::move(motion);
  clip.has_root_motion = true;
  return {};
}

}  // namespace ossa::cook
