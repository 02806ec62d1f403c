// hash.h — 64-bit content hashes shared by cooker and runtime.
//
// FNV-1a 64: tiny, dependency-free, stable across platforms and releases, which is what a hash
// stored in files needs. It is not cryptographic and does not need to be: it identifies inputs for
// caching and rigs for binding clips, it does not defend against forgery.
#pragma once
#include <cstddef>
#include <cstdint>
#include <span>
#include <string_view>

namespace ossa {

inline constexpr uint64_t kFnvOffset = 0xcbf29ce484222325ull;

/// Folds bytes into a running FNV-1a 64 state; start from kFnvOffset. O(n).
uint64_t hash_bytes(const void* data, size_t size, uint64_t state = kFnvOffset);

/// Hash of a rig: every joint name (with its terminating zero, so "ab","c" != "a","bc") followed
/// by its parent index as little-endian int16. Joint order matters: it is the file's joint order.
/// names and parents have the same length. O(total name length).
uint64_t skeleton_hash(std::span<const std::string_view> names, std::span<const int16_t> parents);

}  // namespace ossa
