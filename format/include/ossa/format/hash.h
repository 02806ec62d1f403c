// hash.h — 64-bit content hashes shared by cooker and runtime.
//
// FNV-1a 64 for content (texture bytes, diff fingerprints): tiny, dependency-free, stable across
// platforms and releases, which is what a hash stored in files needs.
//
// The skeleton hash (format v8) is its own word-wise function because every load recomputes it to
// prove the stored one honest: byte-serial FNV-1a costs a 64-bit multiply per name byte in one
// dependency chain (~1.2 us for Pab's 67 joints, 8% of opening its skeleton file). Each joint is
// hashed alone, eight name bytes per multiply, seeded by its index, and the joints are summed, so
// the chains are independent and the CPU overlaps them. Neither hash is cryptographic and neither
// needs to be: they identify inputs for caching and rigs for binding clips; they do not defend
// against forgery.
#pragma once
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace ossa {

inline constexpr uint64_t kFnvOffset = 0xcbf29ce484222325ull;

/// Folds bytes into a running FNV-1a 64 state; start from kFnvOffset. O(n).
uint64_t hash_bytes(const void* data, size_t size, uint64_t state = kFnvOffset);

/// One joint's term of the skeleton hash: its name (8 bytes per step, the 1-7 byte tail read as
/// one word, then the name's length and the parent as a final word) seeded by its index `joint`.
/// O(name length). Exposed so a loader can hash while it walks the joints.
uint64_t skeleton_hash_joint(size_t joint, std::string_view name, int16_t parent);

/// Finishes a skeleton hash from the wrapping sum of every joint's skeleton_hash_joint. O(1).
uint64_t skeleton_hash_finish(uint64_t joint_sum, size_t joint_count);

/// Hash of a rig (format v8): every joint's name and parent index, in the file's joint order
/// ("ab","c" != "a","bc"; the same names in another order differ). names and parents have the
/// same length (the shorter one bounds it). O(total name length).
uint64_t skeleton_hash(std::span<const std::string_view> names, std::span<const int16_t> parents);

}  // namespace ossa
