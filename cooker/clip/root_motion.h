// root_motion.h — taking root motion out of a clip at cook time (ossa-cook --root-motion).
//
// The root joint's motion over the ground (translation in the plane normal to the up axis) and its
// yaw (rotation about the up axis) are sampled on the clip's frame grid, stored relative to frame
// 0 in SourceClip::root_motion, and removed from the root's track, which keeps its height and
// its pitch/roll. The runtime (ossa/anim/root_motion.h) then moves the character by deltas.
#pragma once
#include <cstdint>

#include "cooker/model/source_scene.h"
#include <ossa/format/result.h>

namespace ossa::cook {

/// Extracts root motion from `clip` in place (joint 0 of `skeleton` is the root). up_axis: 0 x,
/// 1 y, 2 z. Error names the clip when it cannot (e.g. no root track: then nothing changes).
Status extract_root_motion(SourceClip& clip, const SourceSkeleton& skeleton, uint8_t up_axis);

}  // namespace ossa::cook
