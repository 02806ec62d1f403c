// cooked_rig.h — a rig as `ossa-cook --skeleton REF.ossa` sees it, for benches that cook clip-only
// sources (Pab/walk.fbx) in-process: REF_SOURCE is cooked into a scratch directory with default
// options and its skeleton read back from the file (load_reference_skeleton), so the clips are
// measured against the same rig, with the same floats, as a cook against the cooked rig.
#pragma once
#include <filesystem>

#include "cooker/model/source_scene.h"
#include <ossa/format/result.h>

namespace ossa::bench {

/// Cooks `source` and returns the cooked file's skeleton; errors name the source. The scratch
/// directory is removed before returning. Cost: one cook of `source`.
Result<cook::SourceSkeleton> cooked_rig(const std::filesystem::path& source);

}  // namespace ossa::bench
