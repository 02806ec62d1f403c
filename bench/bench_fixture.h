// bench_fixture.h — the data every ossa-bench-anim benchmark runs on, cooked once per process.
//
// Pab (67 joints, from assets/Pab): its skeleton, the walk / jog / run clips cooked against it
// with default options (the compression a game would ship), and the arnaud skinned mesh. These are
// the assets the ozz-animation figures were measured on, so results compare directly.
#pragma once
#include <ossa/loader/asset.h>

namespace ossa::bench {

struct BenchData {
  Asset skeleton;  // Pab/skeleton.ossa (rig + its own mesh + clip)
  Asset walk, jog, run;  // clip-only files bound to skeleton
  Asset arnaud;    // skinned mesh on the same rig
};

/// Cooks the assets into a temporary directory on first use; exits with a message on failure.
const BenchData& bench_data();

}  // namespace ossa::bench
