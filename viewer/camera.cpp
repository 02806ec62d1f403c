// camera.cpp — see camera.h.
#include "viewer/camera.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

namespace ossa::view {
namespace {

constexpr float kMaxPitch = 1.5533430f;  // 89 degrees

/// Depth range around what was framed (the grid reaches 10 radii out); a near plane well away
/// from zero keeps depth precision.
void fit_planes(OrbitCamera& c) {
  c.near_plane = std::max(c.distance - 4.0f * c.radius, c.distance * 0.01f);
  c.far_plane = c.distance + 50.0f * c.radius;
}

}  // namespace

OrbitCamera frame_box(const Box& box, float yaw, float pitch, float aspect) {
  OrbitCamera c;
  c.yaw = yaw;
  c.pitch = std::clamp(pitch, -kMaxPitch, kMaxPitch);
  if (box.empty()) {
    c.distance = 3.0f;
    fit_planes(c);
    return c;
  }
  c.target = box.centre();
  c.radius = std::max(glm::length(box.size()) * 0.5f, 1e-4f);
  // The nearest distance at which every corner of the box projects inside the view: a corner at
  // (x right, y up, z towards the eye) from the target is inside when |x| <= (d - z) tan(fov_x / 2)
  // and |y| <= (d - z) tan(fov_y / 2). Tighter than the bounding sphere for long or flat boxes.
  c.distance = 1.0f;
  const glm::mat4 v = view_matrix(c);
  const glm::vec3 right(v[0][0], v[1][0], v[2][0]), up(v[0][1], v[1][1], v[2][1]), back(v[0][2], v[1][2], v[2][2]);
  const float tan_y = std::tan(c.fov_y * 0.5f), tan_x = tan_y * aspect;
  float d = 0.0f;
  for (int corner = 0; corner < 8; ++corner) {
    const glm::vec3 p((corner & 1) ? box.max.x : box.min.x, (corner & 2) ? box.max.y : box.min.y,
                      (corner & 4) ? box.max.z : box.min.z);
    const glm::vec3 q = p - c.target;
    const float z = glm::dot(q, back);
    d = std::max({d, z + std::fabs(glm::dot(q, right)) / tan_x, z + std::fabs(glm::dot(q, up)) / tan_y});
  }
  c.distance = std::max(1.08f * d, 0.1f * c.radius);  // a small margin around the silhouette
  fit_planes(c);
  return c;
}

glm::vec3 eye_position(const OrbitCamera& c) {
  const glm::vec3 dir(std::cos(c.pitch) * std::sin(c.yaw), std::sin(c.pitch), std::cos(c.pitch) * std::cos(c.yaw));
  return c.target + c.distance * dir;
}

glm::mat4 view_matrix(const OrbitCamera& c) { return glm::lookAt(eye_position(c), c.target, glm::vec3(0, 1, 0)); }

glm::mat4 projection_matrix(const OrbitCamera& c, float aspect) {
  return glm::perspective(c.fov_y, aspect, c.near_plane, c.far_plane);
}

void orbit(OrbitCamera& c, float dx, float dy) {
  c.yaw += dx;
  c.pitch = std::clamp(c.pitch + dy, -kMaxPitch, kMaxPitch);
}

void zoom(OrbitCamera& c, float steps) {
  c.distance = std::clamp(c.distance * std::pow(0.9f, steps), c.radius * 0.05f, c.radius * 200.0f);
  fit_planes(c);
}

void pan(OrbitCamera& c, float dx, float dy) {
  const glm::mat4 v = view_matrix(c);
  const glm::vec3 right(v[0][0], v[1][0], v[2][0]), up(v[0][1], v[1][1], v[2][1]);
  c.target += (-dx * right + dy * up) * c.distance;
}

}  // namespace ossa::view
