// foot_contacts.h — when a source clip's feet are planted, found once per clip, for the retarget
// job's contact fix-up (retarget.h).
//
// A foot is planted while its ankle (the profile's foot joint) is low and slow on the source:
// within `max_height` of its rest height and moving slower than `max_speed`, both
// in units of the source's hips height (so one setting serves a rig in centimetres and one in
// metres, a child and a giant), for at least `min_duration`, and ends where the ankle has
// wandered `max_drift` from where it landed (a capture's standing foot creeps; holding it over
// seconds would drag the leg away from the source's). A contact holds the ankle at the
// mean of its positions over the contact; its weight eases in and out over `blend_time` on either
// side so the IK never pops. Clips are read in model space, so a clip that walks in place (its
// planted foot slides back under a still body) has no contacts: that is the source's own slide.
//
// Setup-time (allocates the list); foot_contacts_at is per frame and allocation-free.
#pragma once
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include <ossa/retarget/retarget.h>

namespace ossa {

struct ContactSettings {
  float max_height = 0.05f;    // above the rest ankle height, x source hips height
  float max_speed = 0.1f;      // source hips heights per second
  float max_drift = 0.03f;     // how far the ankle may wander from where it landed, x source hips height
  float min_duration = 0.08f;  // seconds
  float blend_time = 0.12f;    // seconds of easing either side of a contact
};

/// One contact: frames [first, last] of the clip's grid, its FootContact offset, and the shifts
/// easing into and out of it (all source model space vectors).
struct ContactSpan {
  uint8_t foot = 0;  // 0 left, 1 right
  uint32_t first = 0, last = 0;
  glm::vec3 offset{0.0f};
  glm::vec3 entry_shift{0.0f}, exit_shift{0.0f};  // the held ankle minus the ankle without contacts at first / last
};

/// What contact finding reads of one frame.
struct ContactFrame {
  std::array<glm::vec3, 2> source_ankle{};  // left, right foot joints, source model space
  std::array<glm::vec3, 2> target_ankle{};  // the same on the target, retargeted without contacts
};
/// The frame's ankles, from the scratch of a retarget() call made without contacts.
ContactFrame contact_frame(const RetargetMap& map, const RetargetScratch& scratch);

/// Where a clip's floor stands above its rig's rest floor, source units, for RetargetInput::
/// source_floor: 0 when its lowest ankle comes within 5 % of the hips height of the rest pose's
/// ankle level (a clip made on its rig's floor), else that lowest ankle's height over it (a BVH
/// capture's rest pose has its root at the origin, wherever the capture's floor was).
float clip_floor(const RetargetMap& map, std::span<const ContactFrame> frames);

/// Contacts over a clip, one ContactFrame per frame of its grid. Sorted by foot, then frame.
std::vector<ContactSpan> find_foot_contacts(const RetargetMap& map, std::span<const ContactFrame> frames,
                                            float sample_rate, float floor = 0.0f,
                                            const ContactSettings& settings = {});

/// The contact input for the retarget job at a (fractional) frame (FootContact): inside a contact
/// weight 1 and its offset; within blend_time before or after one, the eased weight and its entry
/// or exit shift. Allocation-free.
void foot_contacts_at(std::span<const ContactSpan> contacts, float frame, float sample_rate, float blend_time,
                      std::span<FootContact, 2> out);

}  // namespace ossa
