// ik.cpp — two-bone and aim IK (see ik.h for the solves and why they are shaped so).
//
// The arithmetic is double precision: the corrections are composed from three rotations and two
// conjugations, and the end must land within 1e-4 of the chain's length of the target even for
// chains metres long in centimetre units. The cost is a few dozen double operations either way.
#include <ossa/anim/ik.h>

#include <algorithm>
#include <cmath>

namespace ossa {
namespace {

using dvec3 = glm::dvec3;
using dquat = glm::dquat;
using dmat3 = glm::dmat3;

constexpr double kPi = 3.14159265358979323846;

bool finite(const glm::mat4& m) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r])) return false;
  return true;
}

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

dvec3 translation(const glm::mat4& m) { return dvec3(m[3]); }

// The matrix's linear part with each column normalized: its rotation (or rotation times a
// mirror), orthonormal when the matrix has no shear. False when a column is (nearly) zero.
bool orientation(const glm::mat4& m, dmat3* out) {
  dmat3 r{glm::mat3(m)};
  for (int c = 0; c < 3; ++c) {
    const double len = glm::length(r[c]);
    if (!(len > 1e-12)) return false;
    r[c] /= len;
  }
  *out = r;
  return true;
}

// Some unit vector perpendicular to unit v.
dvec3 perpendicular(const dvec3& v) {
  const dvec3 other = std::fabs(v.x) < 0.9 ? dvec3(1, 0, 0) : dvec3(0, 1, 0);
  return glm::normalize(glm::cross(v, other));
}

// The shortest rotation taking unit a onto unit b (a half turn about a perpendicular when they
// are opposite).
dquat from_to(const dvec3& a, const dvec3& b) {
  const double c = glm::dot(a, b);
  if (c < -1.0 + 1e-12) return glm::angleAxis(kPi, perpendicular(a));
  const dvec3 x = glm::cross(a, b);
  return glm::normalize(dquat(1.0 + c, x.x, x.y, x.z));
}

// A model-space rotation q expressed in the local frame of a joint whose orientation is `frame`:
// frame^-1 * q * frame (frame orthonormal, so its inverse is its transpose).
glm::quat to_local(const dmat3& frame, const dquat& q) {
  const dmat3 local = glm::transpose(frame) * glm::mat3_cast(q) * frame;
  dquat r = glm::quat_cast(local);
  r = glm::normalize(r);
  if (r.w < 0.0) r = -r;
  return glm::quat(r);
}

// slerp(identity, q, weight) on the short arc, q unit with w >= 0.
glm::quat weighted(const glm::quat& q, float weight) {
  if (weight >= 1.0f) return q;
  if (!(weight > 0.0f)) return glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
  return glm::normalize(glm::slerp(glm::quat(1.0f, 0.0f, 0.0f, 0.0f), q, weight));
}

}  // namespace

bool two_bone_ik(const TwoBoneIkInput& in, TwoBoneIkOutput* out) {
  *out = TwoBoneIkOutput{};
  if (!finite(in.start) || !finite(in.mid) || !finite(in.end) || !finite(in.target) || !finite(in.pole) ||
      !finite(in.mid_axis) || !std::isfinite(in.twist) || !std::isfinite(in.soften) || !std::isfinite(in.weight))
    return false;
  dmat3 start_frame, mid_frame;
  if (!orientation(in.start, &start_frame) || !orientation(in.mid, &mid_frame)) return false;

  const dvec3 s = translation(in.start), m = translation(in.mid), e = translation(in.end);
  const dvec3 t(in.target);
  const dvec3 u = s - m, v = e - m;  // from the mid joint to the start and to the end
  const double a = glm::length(u), b = glm::length(v);
  const double chain = a + b;
  if (!(a > 1e-9 * std::max(1.0, chain)) || !(b > 1e-9 * std::max(1.0, chain))) return false;

  // The distance the chain must span: the target's, softened past soften * chain, then kept
  // within what the chain can reach.
  const dvec3 to_target = t - s;
  const double target_distance = glm::length(to_target);
  double d = target_distance;
  const double soften = std::clamp(static_cast<double>(in.soften), 1e-3, 1.0);
  if (soften < 1.0) {
    const double start_soft = soften * chain, span = chain - start_soft;
    if (d > start_soft) d = start_soft + span * (1.0 - std::exp(-(d - start_soft) / span));
  }
  d = std::clamp(d, std::fabs(a - b), chain);
  out->reached = std::fabs(d - target_distance) <= 1e-4 * chain;

  // (1) Bend at the mid joint about the current bend axis (mid_axis when straight).
  dvec3 n = glm::cross(u, v);
  if (!(glm::length(n) > 1e-9 * a * b)) {
    n = mid_frame * dvec3(in.mid_axis);
    n -= u * (glm::dot(n, u) / (a * a));  // perpendicular to the upper bone
    if (!(glm::length(n) > 1e-9)) n = perpendicular(u / a);
  }
  n = glm::normalize(n);
  const double current = std::acos(std::clamp(glm::dot(u, v) / (a * b), -1.0, 1.0));
  const double wanted = std::acos(std::clamp((a * a + b * b - d * d) / (2.0 * a * b), -1.0, 1.0));
  const dquat bend = glm::angleAxis(wanted - current, n);
  const dvec3 bent_end = m + bend * v;

  // (2) Swing about the start joint so the end points at the target; (3) turn about that axis
  // so the mid joint lies towards the pole, then twist.
  dquat swing(1.0, 0.0, 0.0, 0.0), turn(1.0, 0.0, 0.0, 0.0);
  const dvec3 reach = bent_end - s;
  if (target_distance > 1e-9 * chain && glm::length(reach) > 1e-9 * chain) {
    const dvec3 k = to_target / target_distance;
    swing = from_to(reach / glm::length(reach), k);
    const dvec3 pole(in.pole);
    const dvec3 p = pole - k * glm::dot(pole, k);
    const dvec3 mid_now = swing * (m - s);
    const dvec3 q = mid_now - k * glm::dot(mid_now, k);
    double angle = static_cast<double>(in.twist);
    if (glm::length(p) > 1e-9 * std::max(1.0, glm::length(pole)) && glm::length(q) > 1e-9 * chain)
      angle += std::atan2(glm::dot(glm::cross(q, p), k), glm::dot(q, p));
    turn = glm::angleAxis(angle, k);
  }
  const dquat start_rotation = turn * swing;

  out->start_correction = weighted(to_local(start_frame, start_rotation), in.weight);
  out->mid_correction = weighted(to_local(mid_frame, bend), in.weight);
  out->reached = out->reached && in.weight >= 1.0f;
  return true;
}

bool aim_ik(const AimIkInput& in, AimIkOutput* out) {
  *out = AimIkOutput{};
  if (!finite(in.joint) || !finite(in.target) || !finite(in.forward) || !finite(in.up) || !finite(in.pole) ||
      !std::isfinite(in.max_angle) || !std::isfinite(in.weight))
    return false;
  dmat3 frame;
  if (!orientation(in.joint, &frame)) return false;
  const double forward_length = glm::length(dvec3(in.forward)), up_length = glm::length(dvec3(in.up));
  if (!(forward_length > 1e-12) || !(up_length > 1e-12)) return false;
  const dvec3 forward = glm::normalize(frame * dvec3(in.forward));
  const dvec3 to_target = dvec3(in.target) - translation(in.joint);
  const double distance = glm::length(to_target);
  if (!(distance > 1e-9 * std::max(1.0, glm::length(translation(in.joint))))) {
    out->reached = true;  // already "facing" a point at its own origin
    return true;
  }
  const dvec3 k = to_target / distance;

  // The shortest turn, limited to max_angle.
  dquat swing = from_to(forward, k);
  const double angle = std::acos(std::clamp(glm::dot(forward, k), -1.0, 1.0));
  const double limit = std::max(0.0, static_cast<double>(in.max_angle));
  out->reached = angle <= limit + 1e-9;
  if (!out->reached) {
    const dvec3 axis =
        glm::length(glm::cross(forward, k)) > 1e-12 ? glm::normalize(glm::cross(forward, k)) : glm::axis(swing);
    swing = glm::angleAxis(limit, axis);
  }
  const dvec3 facing = swing * forward;

  // The roll about the new facing that brings up towards the pole.
  dquat roll(1.0, 0.0, 0.0, 0.0);
  const dvec3 pole(in.pole);
  const dvec3 up = swing * (frame * (dvec3(in.up) / up_length));
  const dvec3 p = pole - facing * glm::dot(pole, facing);
  const dvec3 u = up - facing * glm::dot(up, facing);
  if (glm::length(p) > 1e-9 * std::max(1.0, glm::length(pole)) && glm::length(u) > 1e-9)
    roll = glm::angleAxis(std::atan2(glm::dot(glm::cross(u, p), facing), glm::dot(u, p)), facing);

  out->correction = weighted(to_local(frame, roll * swing), in.weight);
  out->reached = out->reached && in.weight >= 1.0f;
  return true;
}

}  // namespace ossa
