// version.h — the numbers every side of ossa agrees on.
//
// kFormatVersion is written into File.version by the cooker and checked by every loader; it moves
// whenever format/ossa.fbs changes what a reader sees (goldens are regenerated in the same commit).
// kCookerVersion is recorded in each file's provenance so caches can tell cooker builds apart.
#pragma once
#include <cstdint>

namespace ossa {
inline constexpr uint32_t kFormatVersion = 3;  // 2: compressed clips; 3: animation graphs, clip events
inline constexpr const char* kCookerVersion = "ossa-cook 0.3.0";
inline constexpr const char* kFileIdentifier = "OSSA";
}  // namespace ossa
