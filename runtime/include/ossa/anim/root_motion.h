// root_motion.h — moving a character by the motion its clip was authored with.
//
// The cooker can extract the root's ground-plane translation and yaw into Clip.root_motion (and
// remove them from the root joint), so the clip plays in place and the host moves the character
// by the delta between the previous and the current time. Deltas are loop-correct: a wrap adds
// whole cycles (the clip's end-to-start displacement), and reverse playback gives the negative.
#pragma once
#include <glm/glm.hpp>

#include <ossa/loader/asset.h>

namespace ossa {

/// The character's motion from one time to another, expressed in its own frame at the first
/// time (its position and heading then). A host keeping world position P and yaw Psi does
///   P += rotate(Psi, delta.translation); Psi += delta.yaw
/// with rotate = right-handed rotation about the clip's up axis (glm::angleAxis(Psi, up)).
struct RootMotionDelta {
  glm::vec3 translation{0.0f};  // ground plane (0 along up), in the character's frame at `from`
  float yaw = 0.0f;             // radians about the clip's up axis
};

/// True when the clip carries root motion.
bool has_root_motion(const ClipView& clip);

/// Motion from playing the clip from time `from` to time `to`, where the times are unwrapped
/// playback times (they may lie outside [0, duration] when looping: loops = floor(t / duration)).
/// Without root motion: zero. O(1) (interpolates two samples each end).
RootMotionDelta root_motion_delta(const ClipView& clip, double from, double to);

}  // namespace ossa
