// cloth_options.h — the "cloth" cook settings (docs/CLOTH.md) as the model holds them: what
// cooker/model/cloth_settings.h reads from `<stem>.cook.json` and CookOptions carries to the mesh
// stage (cooker/mesh/cloth_build.h). Kept in the model so that the options do not include a stage.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace ossa::cook {

/// A mesh region named in the settings.
struct ClothRegion {
  std::string mesh;                     // a source mesh's name, or
  std::string material;                 // a material's name
  std::vector<std::string> pin_joints;  // its vertices moved mostly by these stay skinned
  float pin_within_m = 0.01f;           // ... and those within this of a vertex outside the region
  float ramp_m = 0.1f;                  // weight rises from 0 to 1 over this distance from a pinned one
};

/// A collider named in the settings: a sphere at `offset` on `joint`, or a capsule from it to
/// `to`'s origin (a child joint) or to `tail`.
struct ClothColliderSetting {
  std::string joint, to;
  glm::vec3 offset_m{0.0f}, tail_m{0.0f};
  bool has_tail = false;
  float radius_m = 0.05f;
};

/// The "cloth" settings (cloth_settings.h reads them). Lengths in metres, times in seconds.
struct ClothOptions {
  bool paint = true;  // vertex colour set 1 marks cloth
  std::vector<ClothRegion> regions;
  float max_distance_m = 0.0f;  // > 0: green x this; 0: no limit
  float backstop_m = 0.0f;      // > 0: blue x this; 0: none
  float thickness_m = 0.01f;
  float stretch_compliance = 0.0f;
  float bend_compliance = 1e-4f;
  float tether_scale = 1.0f;
  float damping = 1.0f;
  float drag = 0.5f;
  float gravity_ms2 = 9.81f;  // along the model's down axis, -Y (outputs are Y-up)
  float linear_inertia = 1.0f, angular_inertia = 1.0f;
  float teleport_distance_m = 2.0f;
  float max_speed_ms = 30.0f;
  bool auto_colliders = true;  // fit colliders when none are named
  std::vector<ClothColliderSetting> colliders;
  uint32_t max_colliders = 6;
  uint8_t up_axis = 1;         // 0 x, 1 y, 2 z: always 1, outputs are Y-up (import_axes.cpp)
  bool from_settings = false;  // a settings file gave these (canonical() then records them)
  /// Canonical text for the cook's options string ("" when there is nothing to say).
  std::string canonical() const;
};

}  // namespace ossa::cook
