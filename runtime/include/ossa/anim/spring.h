// spring.h — spring bones: hair, tails, cloth strips and ears that trail the animated pose.
//
// A chain of joints (each the parent of the next) whose tails are Verlet particles: every step a
// tail keeps (1 - drag) of its velocity, is pulled towards where the animation puts it
// (stiffness), falls (gravity), is held at its bone's length from its head, and is pushed out of
// sphere and capsule colliders on other joints; each joint then turns the shortest way from its
// animated direction to its tail. This is the model VRM standardised (VRMC_springBone) and Godot
// 4.4 adopted; ossa's differences are for determinism and frame-rate independence:
// - a fixed internal step (SpringSettings::step): update(dt) runs however many whole steps dt
//   covers and banks the rest, and the chain's animated base (the parent of its first joint) is
//   interpolated across the steps of one update, so 30, 60 and 144 Hz frames drive the same
//   simulation (measured in the tests: tails within 1 cm after 2 s);
// - the collider push comes last in a step, so no tail ends a step inside a collider;
// - a base that moves more than SpringSettings::teleport_distance in one update resets the chain
//   to the animated pose instead of whipping it across the world.
//
// State is per character instance and allocated by make_spring_chain, never in update. The job
// reads and writes a local pose and model matrices the caller owns, as the rest of the runtime:
// update changes the chain joints' local rotations and their model matrices; joints below the
// chain that are not in it need the caller's local_to_model afterwards (or run the chain last).
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include <ossa/anim/pose.h>
#include <ossa/format/result.h>

namespace ossa {

struct SpringSettings {
  float stiffness = 4.0f;                 // pull towards the animated tail, per second (0: none)
  float drag = 0.4f;                      // velocity lost per step, in [0, 1]
  glm::vec3 gravity{0.0f, -9.81f, 0.0f};  // model-space acceleration, units / s^2
  float radius = 0.0f;                    // each tail's collision radius
  float step = 1.0f / 120.0f;             // fixed internal step, seconds
  float teleport_distance = 0.0f;         // > 0: a base moving further in one update resets the chain
  float tail_length = 0.1f;               // the last joint's bone length (it has no child in the chain)
};

/// A sphere (tail == offset) or capsule (offset .. tail) of `radius`, placed in `joint`'s local
/// space, which tails are kept out of.
struct SpringCollider {
  uint16_t joint = 0;
  glm::vec3 offset{0.0f};
  glm::vec3 tail{0.0f};
  float radius = 0.0f;
};

/// One chain's state: the tails' positions now and one step ago, the base's placement at the
/// last update, and the time banked towards the next step. Opaque; made by make_spring_chain.
struct SpringChain {
  std::vector<uint16_t> joints;              // parents first, joints[i] the parent of joints[i + 1]
  std::vector<glm::vec3> current, previous;  // model-space tails, one per joint
  std::vector<glm::quat> scratch_rotation;   // per-joint working storage for update
  SpringSettings settings;
  glm::mat4 base_before{1.0f};  // the base's model matrix at the end of the last update
  float banked = 0.0f;          // seconds not yet simulated (< settings.step)
  bool started = false;         // false until the first update (which resets)
};

/// A chain over `joints` (each joint the parent of the next in `parents`; at least one). Errors
/// name the first joint that breaks the chain, an index out of range, or a setting out of range
/// (step <= 0, drag outside [0, 1], non-finite values). Allocates the state. O(joints).
Result<SpringChain> make_spring_chain(std::span<const int16_t> parents, std::span<const uint16_t> joints,
                                      const SpringSettings& settings);

/// Puts every tail where the animation has it, at rest: the next update starts from the pose in
/// `model` (call after a teleport or a cut; update does it itself for teleport_distance).
void reset_spring_chain(SpringChain& chain, std::span<const int16_t> parents, ConstPoseSpan local,
                        std::span<const glm::mat4> model);

/// Advances the chain by dt seconds (fixed steps, see above) from the animated `local` pose and
/// its `model` matrices, then writes the chain joints' new local rotations into `local` and
/// their model matrices into `model`. Colliders are placed by `model` as given. Allocation-free.
/// O(steps * joints * colliders).
void update_spring_chain(SpringChain& chain, float dt, std::span<const int16_t> parents, PoseSpan local,
                         std::span<glm::mat4> model, std::span<const SpringCollider> colliders);

}  // namespace ossa
