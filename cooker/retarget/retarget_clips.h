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

#include "cooker/model/cook_record.h"
#include "cooker/model/source_scene.h"
#include "tools/retarget/map_file.h"
#include <ossa/format/result.h>

namespace ossa::cook {

/// The retarget's inputs besides the scene.
struct RetargetTarget {
  const SourceSkeleton* skeleton = nullptr;     // the target rig (from TARGET.ossa)
  std::string name;                             // TARGET.ossa's file name, for messages
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
