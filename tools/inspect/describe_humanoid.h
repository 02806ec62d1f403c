// describe_humanoid.h — `ossa-inspect FILE --humanoid [--map MAP.json]`: a rig's humanoid mapping
// as a retarget would use it (ossa/retarget/humanoid.h), what it lacks, and its retarget pose.
//
// Text only: it is for a person deciding whether a rig needs a map file (docs/RETARGET.md), so it
// names every profile bone with the joint found for it (or "-"), lists the required bones that are
// missing the way ossa-cook's error does, and says what the retarget pose makes of the bind pose
// (the body's up and left axes, the arms' angle below horizontal: ~0 a T-pose, ~45 an A-pose).
#pragma once
#include <string>

#include <ossa/loader/asset.h>
#include "tools/retarget/map_file.h"

namespace ossa::inspect {

/// The description; `map` (optional) is a parsed map file whose "rig" (or "target", else
/// "source") section applies, `map_name` names it. Errors (a map naming joints the rig lacks) name
/// the file. The rig must have a skeleton.
Result<std::string> describe_humanoid(const Asset& asset, const tools::HumanoidMapFile* map,
                                      const std::string& map_name);

}  // namespace ossa::inspect
