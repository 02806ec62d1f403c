// value_check.cpp — bounds of an imported scene's numbers (see value_check.h).
#include "cooker/import/value_check.h"

#include <cmath>
#include <cstdio>
#include <string>

#include "common/message.h"

namespace ossa::cook {
namespace {

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }
bool bounded(const glm::vec3& v) {
  return finite(v) && std::fabs(v.x) <= kMaxSourceValue && std::fabs(v.y) <= kMaxSourceValue &&
         std::fabs(v.z) <= kMaxSourceValue;
}
bool usable(const glm::quat& q) {
  if (!std::isfinite(q.x) || !std::isfinite(q.y) || !std::isfinite(q.z) || !std::isfinite(q.w)) return false;
  const double n = double(q.x) * q.x + double(q.y) * q.y + double(q.z) * q.z + double(q.w) * q.w;
  return n > 1e-12 && n < 1e12;
}
bool finite(const glm::mat4& m) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!std::isfinite(m[c][r])) return false;
  return true;
}

std::string text(const glm::vec3& v) {
  char buf[96];
  std::snprintf(buf, sizeof buf, "(%g, %g, %g)", double(v.x), double(v.y), double(v.z));
  return buf;
}
std::string text(const glm::quat& q) {
  char buf[112];
  std::snprintf(buf, sizeof buf, "(%g, %g, %g, %g)", double(q.x), double(q.y), double(q.z), double(q.w));
  return buf;
}

// Built with += rather than "'" + std::string&&: GCC 12 at -O2/-O3 reports a false -Wrestrict
// inside the inlined std::string::insert that operator+(const char*, string&&) becomes.
std::string quoted(const std::string& name) {
  std::string out = "'";
  out += detail::printable(name);
  out += '\'';
  return out;
}

const char* kBound = " (the format holds finite values within +-1e7 source units)";

}  // namespace

Status check_scene_values(const SourceScene& scene) {
  const auto& joints = scene.skeleton.joints;
  const auto joint_name = [&](size_t j) { return j < joints.size() ? quoted(joints[j].name) : std::to_string(j); };
  for (size_t j = 0; j < joints.size(); ++j) {
    const SourceJoint& sj = joints[j];
    if (!bounded(sj.translation))
      return Error{"joint " + joint_name(j) + ": bind translation " + text(sj.translation) + " is unusable" + kBound};
    if (!bounded(sj.scale))
      return Error{"joint " + joint_name(j) + ": bind scale " + text(sj.scale) + " is unusable" + kBound};
    if (!usable(sj.rotation))
      return Error{"joint " + joint_name(j) + ": bind rotation " + text(sj.rotation) +
                   " is not a finite, non-zero quaternion"};
    if (!finite(sj.inverse_bind)) return Error{"joint " + joint_name(j) + ": its inverse bind matrix is not finite"};
  }
  for (const SourceMesh& mesh : scene.meshes) {
    const std::string m = "mesh " + quoted(mesh.name);
    for (size_t v = 0; v < mesh.positions.size(); ++v)
      if (!finite(mesh.positions[v]))
        return Error{m + ": vertex " + std::to_string(v) + " position " + text(mesh.positions[v]) + " is not finite"};
    for (size_t v = 0; v < mesh.normals.size(); ++v)
      if (!finite(mesh.normals[v])) return Error{m + ": vertex " + std::to_string(v) + " normal is not finite"};
    for (size_t v = 0; v < mesh.uv0.size(); ++v)
      if (!std::isfinite(mesh.uv0[v].x) || !std::isfinite(mesh.uv0[v].y))
        return Error{m + ": vertex " + std::to_string(v) + " texture coordinate is not finite"};
    for (size_t v = 0; v < mesh.colors.size(); ++v)
      for (int k = 0; k < 4; ++k)
        if (!std::isfinite(mesh.colors[v][k]))
          return Error{m + ": vertex " + std::to_string(v) + " colour is not finite"};
    for (size_t v = 0; v < mesh.weights.size(); ++v)
      for (int k = 0; k < 4; ++k)
        if (!std::isfinite(mesh.weights[v][k]))
          return Error{m + ": vertex " + std::to_string(v) + " weight is not finite"};
    for (const auto& [joint, matrix] : mesh.bind)
      if (!finite(matrix))
        return Error{m + ": the inverse bind matrix of joint " + joint_name(joint) + " is not finite"};
  }
  for (const SourceClip& clip : scene.clips) {
    const std::string c = "clip " + quoted(clip.name);
    if (!std::isfinite(clip.duration) || clip.duration < 0.0f)
      return Error{c + ": its duration is not a finite number >= 0"};
    for (const SourceTrack& t : clip.tracks) {
      const auto key = [&](const char* what, size_t k, float time, const std::string& value, const char* why) {
        char at[64];
        std::snprintf(at, sizeof at, " key %zu (at %g s)", k, double(time));
        return Error{c + ", joint " + joint_name(t.joint) + ": " + what + at + " " + value + " " + why};
      };
      for (size_t k = 0; k < t.translations.size(); ++k)
        if (!bounded(t.translations[k]))
          return key("translation", k, k < t.translation_times.size() ? t.translation_times[k] : 0.0f,
                     text(t.translations[k]), (std::string("is unusable") + kBound).c_str());
      for (size_t k = 0; k < t.scales.size(); ++k)
        if (!bounded(t.scales[k]))
          return key("scale", k, k < t.scale_times.size() ? t.scale_times[k] : 0.0f, text(t.scales[k]),
                     (std::string("is unusable") + kBound).c_str());
      for (size_t k = 0; k < t.rotations.size(); ++k)
        if (!usable(t.rotations[k]))
          return key("rotation", k, k < t.rotation_times.size() ? t.rotation_times[k] : 0.0f, text(t.rotations[k]),
                     "is not a finite, non-zero quaternion");
      for (const std::vector<float>* times : {&t.translation_times, &t.rotation_times, &t.scale_times})
        for (float time : *times)
          if (!std::isfinite(time)) return Error{c + ", joint " + joint_name(t.joint) + ": a key time is not finite"};
    }
    if (clip.has_root_motion) {
      for (size_t k = 0; k < clip.root_motion.translations.size(); ++k)
        if (!bounded(clip.root_motion.translations[k]))
          return Error{c + ": root motion frame " + std::to_string(k) + " is unusable" + kBound};
      for (size_t k = 0; k < clip.root_motion.yaws.size(); ++k)
        if (!std::isfinite(clip.root_motion.yaws[k]))
          return Error{c + ": root motion frame " + std::to_string(k) + " yaw is not finite"};
    }
  }
  return {};
}

}  // namespace ossa::cook
