// import_scene.h — the cooker's only door to Assimp: a source file in, a SourceScene out.
//
// What this stage owns: reading FBX / glTF / GLB / Collada / BVH with fixed import settings,
// finding the skeleton (the joints skins and animations address, closed under ancestry up to one
// root, the way the seed blog picks the root as the top node whose subtree holds no mesh), folding
// Assimp's `$AssimpFbx$` helper nodes into their joints (their animation too) and non-joint nodes
// above the root into the root, flattening joints parents-first, capping influences at 4, and
// resampling clips into per-joint TRS keys in seconds. Everything after it sees no Assimp type.
#pragma once
#include <string>

#include "cooker/model/source_scene.h"
#include <ossa/format/result.h>

namespace ossa::cook {

struct ImportOptions {
  /// Clip-only cooking: bind clips (and skins, if any) to this rig by joint name instead of the
  /// file's own skeleton. Joints the source animates or skins that the reference lacks are an
  /// error naming them. The imported scene's skeleton is then this reference.
  const SourceSkeleton* reference = nullptr;
  /// The source's length unit in metres, overriding what the file says or what is assumed for a
  /// unit-less format (BVH); 0: from the file (--metres-per-unit, the per-asset setting).
  float metres_per_unit = 0.0f;
  /// The source's up axis (0 x, 1 y, 2 z), overriding what the file states or its format's
  /// convention; -1: those (--up-axis, the per-asset setting). Every scene is turned Y-up.
  int up_axis = -1;
};

/// Imports `path`. Errors name the file and what is wrong (Assimp's message when it cannot read
/// it). Deterministic: the same bytes give the same SourceScene. Cost: Assimp's import, then
/// O(nodes + vertices + keys).
Result<SourceScene> import_scene(const std::string& path, const ImportOptions& options = {});

/// The aiProcess_* flags the cooker imports with (also used by ossa-bench-load to time Assimp).
unsigned assimp_import_flags();

}  // namespace ossa::cook
