// retarget.h — a pose of one humanoid rig played on another: the ossa::retarget job.
//
// The transfer goes through the humanoid profile (humanoid.h) and each rig's retarget pose, a
// T-pose made from its bind pose: arms, forearms and hands turned to point straight out along the
// body's left / right axis, thighs and shins straight down, feet turned to face forward (their
// pitch kept: a foot's sole is flat in its own rest pose). An A-pose rig and a T-pose rig then
// stand the same way, and a bone's motion is its model-space rotation away from that pose:
//     delta_i = source_model_rotation_i * inverse(source_retarget_model_rotation_i)
//     target_model_rotation_j = R * delta_i * inverse(R) * target_retarget_model_rotation_j
// with R the turn between the rigs' body frames (a Z-up rig and a Y-up rig, facing -Z or +Z).
// That is VRM's per-bone formula written in model space; taking local rotations back from model
// ones, parents first, is what lets either rig have joints the other lacks between its bones (a
// twist bone, a collar, a second neck joint): they keep their rest and the next bone compensates,
// so a bone the target lacks is folded into its children.
//
// Chains of other bone counts (spine, neck, fingers) are interpolated by normalized length, as
// Unreal's IK Retargeter's "Interpolated" mode: a target joint at 40 % of its chain takes the
// rotation found at 40 % of the source's chain (slerp between the two source joints around it).
// The hips' position is carried over scaled by the ratio of the hips' heights above the floor,
// so a walk keeps its stride for the target's legs and root motion travels with it. Joints outside
// the profile keep their rest (or a pose the caller gives, e.g. the target's own tail clip); one of
// the same name on both rigs follows the source's local motion, which is what makes a rig
// retargeted onto itself reproduce the source exactly.
//
// Feet: given contacts (find them over a clip with find_foot_contacts), each planted target ankle
// is held where the scaled source holds its own, at the target's own stance (FootContact): the pelvis first moves by
// what the planted feet need (their mean, so a single planted foot costs the legs nothing and the limbs keep the
// source's directions), then a two-bone IK pass (ik.h) takes the rest (the two feet of a double support disagreeing),
// keeping each foot's own orientation.
//
// Shape: make_retarget_map (setup: allocates, validates, builds both retarget poses and every
// per-joint decision into a plain struct) and retarget (per frame: spans in, pose out, no
// allocation, no virtual call, O(source joints + target joints)).
#pragma once
#include <array>
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include <ossa/anim/pose.h>
#include <ossa/format/result.h>
#include <ossa/retarget/humanoid.h>

namespace ossa {

/// How a rig's retarget pose is made from its bind pose.
enum class RestPose : uint8_t {
  Straighten,  // limbs turned onto the profile's axes (the default: A-pose and T-pose rigs meet)
  Bind,        // the bind pose as it is (a rig already in the exact pose it should be matched in)
};

/// A joint's retarget-pose local rotation set by hand (a map file's "rest_rotations"), applied
/// after straightening.
struct RestRotation {
  int16_t joint = -1;
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};
};

/// One rig as a retarget sees it. Spans must stay valid during make_retarget_map only.
struct RetargetRig {
  std::string_view name;                    // for messages
  std::span<const int16_t> parents;         // parents[i] < i, -1 for roots
  std::span<const Transform> bind;          // local bind pose, one per joint
  std::span<const std::string_view> names;  // joint names (extra joints are matched by name); may be empty
  HumanoidMap humanoid;                     // map_humanoid(...) or a map file's
  RestPose rest = RestPose::Straighten;
  std::span<const RestRotation> rest_rotations;
};

/// A rig's retarget pose and body frame, as make_retarget_map builds them (exposed for tools: the
/// viewer draws it, ossa-inspect prints the frame).
struct RetargetPose {
  std::vector<Transform> local;             // the retarget (T-) pose, local, one per joint
  std::vector<glm::mat4> model;             // its model matrices
  glm::quat frame{1.0f, 0.0f, 0.0f, 0.0f};  // rig model space -> profile space (+x left, +y up, +z forward)
  glm::vec3 up{0.0f, 1.0f, 0.0f};           // the rig's up, model space
  glm::vec3 pelvis{0.0f};                   // midway between the upper legs' joints (where the legs hang)
  glm::vec3 origin{0.0f};                   // the point under the pelvis at the height of the ankles
  float hips_height = 0.0f;                 // the pelvis above the ankles (the legs' reach), rig units
  float ankle_height = 0.0f;                // the ankles (foot joints, mean of both) above the floor
};

/// Builds one rig's retarget pose (check_humanoid must pass first). Errors name the rig.
Result<RetargetPose> make_retarget_pose(const RetargetRig& rig);

/// How one target joint is driven (RetargetMap::steps).
enum class RetargetStep : uint8_t {
  Keep,      // the target's base pose (bind, or RetargetInput::target_base)
  Copy,      // a same-named source joint's local motion relative to its rest
  Rotate,    // one source joint's model-space delta
  Blend,     // slerp of two source joints' deltas (chains of other bone counts)
  Hips,      // Rotate, and placed so the pelvis lands on the source's pelvis mapped by map_point
             // (with whatever the source's hips move against its own legs, scaled)
  Anchored,  // Rotate, placed at its rest offset from its shin (an IK rig's foot), plus whatever
             // the source's foot moves away from its own shin's offset, scaled
};

/// Everything a retarget needs, decided once. Plain data; share it between characters and threads.
struct RetargetMap {
  struct Step {
    int16_t joint = -1;
    RetargetStep kind = RetargetStep::Keep;
    int16_t source_a = -1, source_b = -1;  // Rotate/Blend/Hips/Anchored: source joints; Copy: source_a
    float weight = 0.0f;                   // Blend: slerp(delta_a, delta_b, weight)
    glm::quat rest{1.0f, 0.0f, 0.0f,
                   0.0f};  // inverse(R) * target retarget-pose model rotation; Copy: target rest local
    glm::quat source_rest_local_inverse{1.0f, 0.0f, 0.0f, 0.0f};  // Copy
    /// Rotate/Hips/Anchored: the source joint has this joint's name under a parent of the same name
    /// (the same rig, or one of its family): its own translation and scale away from its bind
    /// ride along too, so a rig retargeted onto itself is reproduced exactly. Across rigs only
    /// rotations are carried (a clip's translation keys may disagree with its skin's bind).
    bool same_joint = false;
    int16_t anchor = -1;     // Anchored: the target joint it hangs from
    glm::vec3 offset{0.0f};  // Anchored: its position in the anchor's frame; Hips: its
                             // position from the pelvis, in its retarget-pose frame
  };
  struct Leg {
    int16_t upper = -1, lower = -1, foot = -1;  // target joints
    int16_t source_lower = -1, source_foot = -1;
    glm::vec3 source_offset{0.0f};  // the source foot's retarget-pose position in its shin's frame
  };

  uint32_t source_joint_count = 0, target_joint_count = 0;
  std::vector<int16_t> source_parents, target_parents;
  HumanoidMap source_humanoid, target_humanoid;
  RetargetPose source_pose, target_pose;
  std::vector<Transform> source_bind, target_bind;
  std::vector<glm::quat> source_rest_inverse;  // per source joint: inverse retarget-pose model rotation
  std::vector<glm::quat> target_rest_inverse;  // per target joint: the same
  glm::quat rotation{1.0f, 0.0f, 0.0f, 0.0f};  // R: source model directions -> target model directions
  float scale = 1.0f;                          // target hips height / source hips height (over the ankles)
  std::vector<Step> steps;                     // every target joint once, parents (and anchors) first
  std::array<Leg, 2> legs;                     // left, right
  glm::vec3 source_hips_offset{0.0f};          // source hips minus pelvis in its retarget pose
  glm::quat target_hips_rest_inverse{1.0f, 0.0f, 0.0f,
                                     0.0f};    // the target hips' retarget-pose model rotation, inverted
  glm::vec3 target_forward{0.0f, 0.0f, 1.0f};  // the target's forward, model space (a straight knee bends along it)

  /// A source model-space point carried to the target: origin_t + scale * R (p - origin_s), the
  /// origins under the pelvis at ankle height: the source's pelvis maps onto the target's, and a
  /// planted source ankle onto the target's ankle level whatever each rig's ankle height.
  /// `floor`: how high the source clip's floor stands above its rest pose's (clip_floor).
  glm::vec3 map_point(const glm::vec3& source_point, float floor = 0.0f) const;
};

struct RetargetOptions {
  bool match_extra_joints = true;  // Copy for joints outside the profile with the same name on both rigs
};

/// Builds the map. Errors name the rig and what is wrong: missing humanoid bones (every one),
/// joints not parents first, a bind pose of another length, a degenerate body (head at the hips).
Result<RetargetMap> make_retarget_map(const RetargetRig& source, const RetargetRig& target,
                                      const RetargetOptions& options = {});

/// Per-frame working memory: model matrices and rotations of both rigs (after retarget: the
/// source's pose and the target's final pose, for measuring). One per thread.
struct RetargetScratch {
  std::vector<glm::mat4> source_model, target_model;
  std::vector<glm::quat> source_rotation, target_rotation;
  /// What the last retarget's fix-ups moved (kAdjusted... bits): a limb swung back to its side
  /// of the mid-plane, a leg bent to hold a planted foot.
  uint8_t adjusted = 0;
};
enum RetargetAdjusted : uint8_t {
  kAdjustedLeftArm = 1,
  kAdjustedRightArm = 2,
  kAdjustedLeftLeg = 4,
  kAdjustedRightLeg = 8,  // mid-plane guard
  kHeldLeftFoot = 16,
  kHeldRightFoot = 32,  // contacts
};
RetargetScratch make_retarget_scratch(const RetargetMap& map);

/// One foot's contact for one frame (foot_contacts_at makes them from a clip's ContactSpans).
///   weight 1: planted: the target's ankle is held at map_point(source ankle now + offset): where
///     the scaled source holds its foot, moved by `offset` (the target's own stance: how far its
///     proportions put its ankle from the scaled source's, averaged over the contact), so what
///     the retarget adds to the foot's motion is removed and what the source's foot does is kept;
///   weight in (0, 1): easing in or out of a contact: the ankle is moved from where the retarget
///     puts it by weight * (shift carried over: scale * R * shift), shift being how far the contact
///     holds the ankle from there at the contact's edge (so a swinging foot is not pulled across
///     the ground towards where it will land);
///   weight 0: free.
/// offset and shift are vectors in the source's model space.
struct FootContact {
  float weight = 0.0f;
  glm::vec3 offset{0.0f};
  glm::vec3 shift{0.0f};
};

struct RetargetInput {
  ConstPoseSpan source;                   // the source rig's local pose
  ConstPoseSpan target_base;              // optional: Keep joints' values (empty: the target's bind pose)
  std::span<const FootContact> contacts;  // empty, or {left, right}
  /// How high the source clip's floor stands above its rest pose's, source units (clip_floor):
  /// the clip's floor is put on the target's. 0 for a clip made on its rig's floor.
  float source_floor = 0.0f;
};

/// Retargets one pose into `out` (the target's joint count). Returns false, leaving out untouched,
/// when a span does not match the map (joint counts, contacts neither 0 nor 2, scratch not made for
/// this map). Allocation-free.
bool retarget(const RetargetMap& map, const RetargetInput& input, RetargetScratch& scratch, PoseSpan out);

/// Only the source's model space (scratch.source_model / source_rotation), e.g. to find contacts.
bool pose_source(const RetargetMap& map, ConstPoseSpan source, RetargetScratch& scratch);

/// Where a planted contact (weight 1) holds the target's ankle, once pose_source (or retarget) has
/// posed the source: map_point(source ankle + contact.offset). Target model space.
glm::vec3 held_ankle(const RetargetMap& map, const RetargetScratch& scratch, int foot, const FootContact& contact,
                     float source_floor = 0.0f);

}  // namespace ossa
