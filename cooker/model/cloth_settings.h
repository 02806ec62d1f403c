// cloth_settings.h — the "cloth" member of a cook settings file (docs/CLOTH.md) read into
// ClothOptions, every mistake reported at its position with the checker's "did you mean".
//
//   "cloth": {
//     "paint": true,                                   // vertex colour set 1 marks cloth
//     "regions": [{"mesh": "Cape", "pin_joints": ["Spine2"], "pin_within": 0.01, "ramp": 0.1}],
//     "max_distance": 0, "backstop": 0, "thickness": 0.01,             // metres
//     "stretch_compliance": 0, "bend_compliance": 1e-4, "tether_scale": 1,
//     "damping": 1, "drag": 0.5, "gravity": 9.81, "linear_inertia": 1, "angular_inertia": 1,
//     "teleport_distance": 2, "max_speed": 30,
//     "colliders": "auto" | "none" | [{"joint": "LeftUpLeg", "to": "LeftLeg", "radius": 0.07},
//                                     {"joint": "Head", "offset": [0, 0.1, 0], "radius": 0.12}],
//     "max_colliders": 6
//   }
#pragma once
#include "cooker/json/json_check.h"
#include "cooker/model/cloth_options.h"

namespace ossa::cook {

/// Reads `value` (the "cloth" object) over `out`. Errors go to `check`; returns check.ok()-style
/// success of this member.
bool read_cloth_settings(json::Checker& check, const json::Value& value, ClothOptions& out);

}  // namespace ossa::cook
