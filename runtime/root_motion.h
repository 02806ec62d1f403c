// root_motion.h — moving a character by the motion its clip was authored with.
//
// The cooker can extract the root's ground-plane translation and yaw into Clip.root_motion (and
// remove them from the root joint), so the clip plays in place and the host moves the character
// by the delta between the previous and the current time. Deltas are loop-correct: a wrap adds
// whole cycles (the clip's end-to-start displacement), and reverse playback gives the negative.
#pragma once
#include <glm/glm.hpp>

#include "runtime/asset.h"

namespace ossa {

struct RootMotionDelta {
  glm::vec3 translation{0.0f};  // in the clip's frame at `from`'s start (model space of frame 0)
  float yaw = 0.0f;             // radians about the clip's up axis
};

/// True when the clip carries root motion.
bool has_root_motion(const ClipView& clip);

/// Motion from playing the clip from time `from` to time `to`, where the times are unwrapped
/// playback times (they may lie outside [0, duration] when looping: loops = floor(t / duration)).
/// Without root motion: zero. O(1) (interpolates two samples each end).
RootMotionDelta root_motion_delta(const ClipView& clip, double from, double to);

}  // namespace ossa
