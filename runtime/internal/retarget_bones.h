// retarget_bones.h — the humanoid profile's bone count, as the loader checks a graph's retarget
// nodes against it (validate_graph.cpp: each node stores one joint per profile bone and rig).
// Internal to the runtime. A constant of its own because the loader is the first room and cannot
// read <ossa/retarget/humanoid.h>; humanoid_profile.cpp asserts that the two agree.
#pragma once
#include <cstddef>

namespace ossa::detail {

inline constexpr size_t kRetargetBoneCount = 52;  // kHumanoidBoneCount

}  // namespace ossa::detail
