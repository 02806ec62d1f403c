// ik.h — inverse kinematics on a model-space pose: two-bone (an arm, a leg) and aim (look-at).
//
// Shaped as a job, as the rest of the runtime: plain input in (the three joints' model-space
// matrices and the goal), two local-space corrections out, no allocation, no skeleton walk. The
// caller multiplies the corrections into the start and mid joints' local rotations and runs
// local_to_model again (or only below the start joint). Working on model-space matrices lets the
// chain's joints have other joints between them (a twist bone between shoulder and elbow) and
// lets the same job run in a graph post-process, a tool or a game's own pose code.
//
// The solve, in model space: (1) bend the mid joint about the chain's bend axis until the
// start-to-end distance equals the start-to-target distance (law of cosines); (2) swing the
// chain about the start joint so the end points at the target; (3) turn the chain about the
// start-to-target axis so the mid joint lies on the pole vector's side of that axis, plus
// `twist`. Step 3 is what stops pole flips: the plane of the chain is taken from the pole, never
// from the target's side of the current plane, so a target crossing the chain's plane leaves the
// elbow where it was. The bend axis is the current bend's (so an elbow bends the way it already
// bends); a straight chain uses `mid_axis` instead.
//
// Softening: past soften * (upper + lower) the reach approaches full extension exponentially
// instead of snapping straight, so an arm reaching for a point that drifts out of range does not
// pop. soften = 1 disables it.
#pragma once
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

namespace ossa {

struct TwoBoneIkInput {
  /// Model-space matrices of the chain's three joints (e.g. shoulder, elbow, wrist). Their
  /// translations give the chain; their rotations convert corrections to local space. Scale is
  /// allowed (it is divided out), shear is not.
  glm::mat4 start{1.0f}, mid{1.0f}, end{1.0f};
  /// The point the end joint should reach, in the same model space.
  glm::vec3 target{0.0f};
  /// A model-space direction, from the start joint, towards which the mid joint bends (the knee's
  /// forward, the elbow's back). Its component along the start-to-target axis is ignored. Zero:
  /// keep the chain's current plane.
  glm::vec3 pole{0.0f};
  /// The bend axis in the mid joint's local space, used only when the chain is straight (no
  /// current bend to follow). A knee bending about its local z has (0, 0, 1).
  glm::vec3 mid_axis{0.0f, 0.0f, 1.0f};
  float twist = 0.0f;   // radians about the start-to-target axis, after the pole
  float soften = 1.0f;  // in (0, 1]: fraction of the chain's length where softening begins
  float weight = 1.0f;  // in [0, 1]: 0 leaves the pose as it is
};

struct TwoBoneIkOutput {
  /// Local-space corrections: new_local_rotation = old_local_rotation * correction.
  glm::quat start_correction{1.0f, 0.0f, 0.0f, 0.0f};
  glm::quat mid_correction{1.0f, 0.0f, 0.0f, 0.0f};
  /// Whether the end reaches the target (within 1e-4 of the chain's length) at full weight:
  /// false when the target is out of reach, inside the chain's minimum reach, or softened.
  bool reached = false;
};

/// Solves one two-bone chain. Returns false and identity corrections when the input cannot be
/// solved (a zero-length bone, a non-finite matrix or target, a singular rotation); otherwise the
/// corrections are unit quaternions, finite for every finite input (a target at the start joint
/// or a straight chain included). Allocation-free. O(1); ossa-bench-anim BM_TwoBoneIk times it.
bool two_bone_ik(const TwoBoneIkInput& input, TwoBoneIkOutput* output);

struct AimIkInput {
  /// Model-space matrix of the joint that turns (a head, a neck, an eye, a turret).
  glm::mat4 joint{1.0f};
  /// The point it should face, in the same model space.
  glm::vec3 target{0.0f};
  /// The joint's facing and up directions in its local space (unit or not; not parallel).
  glm::vec3 forward{0.0f, 0.0f, 1.0f};
  glm::vec3 up{0.0f, 1.0f, 0.0f};
  /// A model-space direction the joint's up should lean towards after aiming (the character's
  /// up, so a head does not roll). Zero: no roll correction, the shortest turn only.
  glm::vec3 pole{0.0f};
  /// Largest turn in radians away from the current facing (a neck's range); pi or more: none.
  float max_angle = 3.14159265f;
  float weight = 1.0f;  // in [0, 1]
};

struct AimIkOutput {
  /// Local-space correction: new_local_rotation = old_local_rotation * correction.
  glm::quat correction{1.0f, 0.0f, 0.0f, 0.0f};
  /// Whether the joint faces the target at full weight (false when max_angle stopped it).
  bool reached = false;
};

/// Turns one joint to face a target: the shortest turn taking its forward onto the direction to
/// the target (at most max_angle), then a roll about that direction bringing its up towards the
/// pole. A chain (spine > neck > head) is aimed by running this joint by joint from the base,
/// each with its share of the weight, refreshing the model matrices in between; the last joint
/// at full weight finishes the aim. Returns false and identity for input it cannot solve
/// (non-finite values, a zero forward or up, a singular joint matrix); a target at the joint
/// itself gives identity. Allocation-free. O(1).
bool aim_ik(const AimIkInput& input, AimIkOutput* output);

}  // namespace ossa
