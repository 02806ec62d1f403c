// bench_fixture.h — the data every ossa-bench-anim benchmark runs on, cooked once per process.
//
// Pab (67 joints, from assets/Pab): its skeleton, the walk / jog / run clips and the long crossed-arms
// clip cooked against it with default options (the compression a game would ship), and the arnaud
// skinned mesh. These are
// the assets the ozz-animation figures were measured on, so results compare directly.
#pragma once
#include <cstdint>
#include <vector>

#include <ossa/loader/asset.h>

namespace ossa::bench {

struct BenchData {
  Asset skeleton;        // Pab/skeleton.ossa (rig + its own mesh + clip)
  Asset walk, jog, run;  // clip-only files bound to skeleton
  Asset arnaud;          // skinned mesh on the same rig
  Asset crossarms;       // clip-only, the longest of Pab's clips (seeks)
};

/// Cooks the assets into a temporary directory on first use; exits with a message on failure.
const BenchData& bench_data();

/// A copy of `asset`'s file bytes whose first mesh has its influence classes dealt out in turn
/// (one vertex of each class, each class keeping its order): what a file cooked before the class
/// ordering, or by another tool, looks like to skin_cpu. Same vertices, same file otherwise (the
/// index buffer is not renumbered: skinning does not read it). O(file size).
std::vector<uint8_t> dealt_copy(const Asset& asset);

/// A copy of a skeleton file's bytes whose bind pose carries decomposition noise: every rotation and
/// translation component that is exactly 0 holds +-7.7e-34 instead (alternating signs), as Pab's
/// own FBX has in five of them and as a file cooked without the cooker's flush of tiny values
/// keeps them (cooker/import/tiny_values.h). What a rig cooked elsewhere looks like to the
/// runtime: the same pose to 1e-33, and every such value squared below FLT_MIN by interpolation.
/// Sets *noisy to the number of values changed. O(joints).
std::vector<uint8_t> noisy_rest_copy(const Asset& skeleton, size_t* noisy);

}  // namespace ossa::bench
