// rotation.h — the small rotation helpers the pose jobs that work on model matrices share (spring
// chains, the graph's procedural nodes). Not a public header.
//
// Header-only and inline: they sit in per-joint loops of a few joints each, where a call across
// translation units would cost more than the arithmetic.
#pragma once
#include <cmath>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace ossa::detail {

/// The rotation of a model matrix with its scale divided out (columns normalized; no shear
/// assumed). A zero column is taken as the identity's.
inline glm::quat orientation(const glm::mat4& m) {
  glm::mat3 r(m);
  for (int c = 0; c < 3; ++c) {
    const float len = glm::length(r[c]);
    r[c] = len > 1e-12f ? r[c] / len : glm::vec3(c == 0, c == 1, c == 2);
  }
  return glm::normalize(glm::quat_cast(r));
}

/// The shortest rotation taking unit vector a onto unit vector b (a half turn about an axis
/// perpendicular to a when they are opposite).
inline glm::quat from_to(const glm::vec3& a, const glm::vec3& b) {
  const float c = glm::dot(a, b);
  if (c < -1.0f + 1e-6f) {
    const glm::vec3 other = std::fabs(a.x) < 0.9f ? glm::vec3(1, 0, 0) : glm::vec3(0, 1, 0);
    return glm::angleAxis(3.14159265f, glm::normalize(glm::cross(a, other)));
  }
  const glm::vec3 x = glm::cross(a, b);
  return glm::normalize(glm::quat(1.0f + c, x.x, x.y, x.z));
}

}  // namespace ossa::detail
