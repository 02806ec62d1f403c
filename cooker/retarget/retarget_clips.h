// retarget_clips.h — the cook-time retarget (ossa-cook --retarget-to TARGET.ossa [--map FILE]):
// a source's clips, played on its own rig, become clips of another rig.
//
// The transfer is the runtime's ossa::retarget job (ossa/retarget/retarget.h), run at every frame
// of each clip's grid, so a clip cooked for a rig and the same clip retargeted live give the same
// pose. Per clip, three passes: the source's model space alone (the clip's floor), the transfer
// without contacts (where the retarget puts each ankle), then with the contacts found from those
// (ossa/retarget/foot_contacts.h). The result replaces the scene's rig, clips and unit with the
// target's and drops the source's meshes and materials: the output is a clip-only file bound to
// the target rig by its skeleton hash, compressed like any other clip.
//
// The measures a report gives come from the last pass (ossa/retarget/retarget_measure.h):
// direction errors in degrees, each contact's foot slide in millimetres (how far the target's ankle
// strays from where the contact holds it and from its own mean, and the source's own slide for
// comparison), the hips height ratio applied (in metres over metres, so a centimetre rig and a
// metre rig compare).
#pragma once
#include <string>
#include <vector>

#include "cooker/import/source_scene.h"
#include "runtime/tools/retarget/map_file.h"
#include <ossa/format/result.h>

namespace ossa::cook {

/// One contact of a retargeted clip.
struct RetargetContactRecord {
  uint32_t foot = 0;                 // 0 left, 1 right
  float start = 0.0f, end = 0.0f;    // seconds
  float held_mm = 0.0f;              // the target ankle's largest distance from where the contact holds it
  float slide_mm = 0.0f;             // the target ankle's largest distance from its mean (how far it slides)
  float source_slide_mm = 0.0f;      // the source ankle's largest distance from its mean (its own slide)
};

/// What a retarget achieved on one clip (--report "retarget"; docs/RETARGET.md).
struct RetargetRecord {
  std::string clip;
  float hips_ratio = 0.0f;           // target hips height / source's, both in metres over the ankles
  float floor_mm = 0.0f;             // the source clip's floor above its rest pose's (0: none)
  uint32_t frames = 0;
  float limb_max_deg = 0.0f;         // upper arm, forearm, thigh, shin: largest angle to the source's,
                                     // over the limbs the mid-plane guard left alone
  float guard_max_deg = 0.0f;        // the same over the limbs it swung back (what keeping them on their side cost)
  float hand_max_deg = 0.0f;         // hands' outward axis, either hand
  float foot_max_deg = 0.0f;         // feet's forward axis, either foot
  uint32_t crossing_frames = 0;      // frames with a hand or foot across the mid-plane where the source's is not
  uint32_t guarded_frames = 0;       // frames where the mid-plane guard swung a limb back
  std::vector<RetargetContactRecord> contacts;
};

/// The retarget's inputs besides the scene.
struct RetargetTarget {
  const SourceSkeleton* skeleton = nullptr;  // the target rig (from TARGET.ossa)
  std::string name;                          // TARGET.ossa's file name, for messages
  const tools::HumanoidMapFile* map = nullptr;  // --map, or null
  std::string map_name;
};

/// Retargets every clip of `scene` (its own rig the source) onto the target, in place: afterwards
/// the scene holds the target's skeleton and unit, the retargeted clips (events and morph weight
/// tracks kept) and no meshes or materials. Errors start with `label` (the input) and name the rig
/// and what is missing (every humanoid bone it could not find).
Status retarget_scene(SourceScene& scene, const RetargetTarget& target, const std::string& label,
                      std::vector<RetargetRecord>* records);

}  // namespace ossa::cook
