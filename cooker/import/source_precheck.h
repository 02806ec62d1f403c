// source_precheck.h — what the cooker does to a source's bytes before Assimp sees them.
//
// Assimp 5.2 (Debian 12) crashes on some spec-valid or merely deep files, and a crash inside the
// importer can only be contained (the worker process, cooker/cli/worker.h), not explained. Where
// the cause is cheap to see in the bytes, it is handled here first, in ossa's own code:
//   - hierarchies deeper than kMaxHierarchyDepth are refused with a message: Assimp's importers
//     and post-processing recurse once per level and overflow the stack (a 20,000-node glTF
//     chain or Collada `<node>` chain, a 100,000-level FBX). Measured by an iterative scan of the
//     glTF node tree, the Collada `<node>` tree (nesting, and `<instance_node>` references, which
//     Assimp expands in place), the BVH and ASCII FBX brace nesting and the binary FBX records;
//   - a glTF skin without `inverseBindMatrices` (optional in the spec: identity matrices) gets
//     an explicit accessor of identity matrices, because Assimp dereferences the missing one;
//     a skin without joints, or with indices that name no node or accessor, is refused (found by
//     tests/fuzz/source_fuzz.py: Assimp dereferences those too).
// Files of other formats, and files this scan cannot read, pass unchanged: Assimp then reports
// its own error.
#pragma once
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <ossa/format/result.h>

namespace ossa::cook {

/// Deepest node hierarchy a source may have (levels below the root). Far above any real rig
/// (a human is ~10 levels deep, a long tail chain ~100) and far below what overflows a stack.
inline constexpr uint32_t kMaxHierarchyDepth = 1000;

/// Checks (and for glTF, patches) the main input's bytes; `extension` is lower case with the dot.
/// Returns the bytes Assimp should read: unchanged (nullopt) or patched. The error names no file
/// (the caller does). O(file size).
Result<std::optional<std::vector<uint8_t>>> precheck_source(std::span<const uint8_t> bytes,
                                                            const std::string& extension);

}  // namespace ossa::cook
