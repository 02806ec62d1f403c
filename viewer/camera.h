// camera.h — an orbit camera: a target, a distance, and two angles.
//
// Plain data plus free functions, so the headless mode, the mouse handlers and the tests all move
// the same camera. Y is up (the cooker keeps Assimp's scene-root space, which is Y-up for glTF and
// for FBX once Assimp applies the file's axis settings). Yaw 0 looks at the model from +Z (glTF's
// "front"), yaw grows counter-clockwise seen from above; pitch is the elevation of the eye.
#pragma once
#include <glm/glm.hpp>

#include "viewer/bounds.h"

namespace ossa::view {

struct OrbitCamera {
  glm::vec3 target{0.0f};
  float distance = 3.0f;
  float yaw = 0.0f;          // radians
  float pitch = 0.0f;        // radians, clamped to (-89, 89) degrees
  float fov_y = 0.6981317f;  // 40 degrees
  float radius = 1.0f;       // extent of what was framed: bounds zoom and the depth range
  float near_plane = 0.01f;
  float far_plane = 100.0f;
};

/// A camera at (yaw, pitch) looking at the centre of `box` from the nearest distance at which all
/// eight corners are in view (8 % margin), for the given aspect ratio (width / height). Near and
/// far planes follow the distance.
OrbitCamera frame_box(const Box& box, float yaw, float pitch, float aspect);

glm::vec3 eye_position(const OrbitCamera& camera);
glm::mat4 view_matrix(const OrbitCamera& camera);
glm::mat4 projection_matrix(const OrbitCamera& camera, float aspect);

/// Mouse drag in radians (dx: yaw, dy: pitch; pitch is clamped).
void orbit(OrbitCamera& camera, float dx, float dy);
/// Scroll: each step moves 10 % closer (positive) or farther; near/far follow.
void zoom(OrbitCamera& camera, float steps);
/// Moves the target in the view plane by a fraction of the distance (right-drag pan).
void pan(OrbitCamera& camera, float dx, float dy);

}  // namespace ossa::view
