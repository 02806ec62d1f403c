// rig_internal.h — what the two halves of the rig share: import_rig.cpp (the file's own skeleton)
// and import_rig_reference.cpp (a source mapped onto a reference rig, --skeleton). Nothing outside
// those two files includes it.
#pragma once
#include <cstddef>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "cooker/import/import_internal.h"

namespace ossa::cook::detail {

inline constexpr size_t kMaxJoints = 32767;  // Skeleton.parents is [short]

/// The nodes a skeleton grows from.
struct Seeds {
  std::vector<bool> bone;      // per node
  std::vector<bool> animated;  // per node (a helper's keys are marked on its owner)
};

/// "a, b, c" with at most `limit` names, then "and N more": warnings stay readable on big rigs.
std::string name_list(const std::vector<std::string>& names, size_t limit = 12);

/// The seeds inside the rig's top-level subtrees `tops`; warns naming those outside (dropped).
std::vector<int> rig_seeds(const Context& ctx, const NodeGraph& graph, const Seeds& seeds,
                           const std::vector<bool>& tops);

/// Raw nodes from just below `stop` (or from the scene root when stop is -1) down to n.
std::vector<int> chain_to(const NodeGraph& graph, int n, int stop);

/// The product of the chain's node locals, outermost first.
glm::dmat4 chain_local(const NodeGraph& graph, const std::vector<int>& chain);

/// The rig of a clip-only source: `ref`'s joints, matched to the file's nodes by name
/// (import_rig_reference.cpp).
Result<Rig> reference_rig(const Context& ctx, const NodeGraph& graph, const Seeds& seeds, const SourceSkeleton& ref);

}  // namespace ossa::cook::detail
