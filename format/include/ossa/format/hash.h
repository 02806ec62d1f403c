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
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>
#include <string_view>

namespace ossa {

inline constexpr uint64_t kFnvOffset = 0xcbf29ce484222325ull;

/// Folds bytes into a running FNV-1a 64 state; start from kFnvOffset. O(n).
uint64_t hash_bytes(const void* data, size_t size, uint64_t state = kFnvOffset);

namespace detail {
inline constexpr uint64_t kSkeletonMulA = 0x9e3779b97f4a7c15ull;  // 2^64 / golden ratio, odd
inline constexpr uint64_t kSkeletonMulB = 0xc2b2ae3d27d4eb4full;  // xxHash's PRIME64_2, odd
/// Little-endian loads, so the stored hash is the same on every platform.
inline uint64_t le64(const unsigned char* p) {
  uint64_t v;
  std::memcpy(&v, p, 8);
  if constexpr (std::endian::native == std::endian::big) v = __builtin_bswap64(v);
  return v;
}
inline uint64_t le32(const unsigned char* p) {
  uint32_t v;
  std::memcpy(&v, p, 4);
  if constexpr (std::endian::native == std::endian::big) v = __builtin_bswap32(v);
  return v;
}
/// One step: xor the word in, multiply, fold the high half down so the next multiply sees it.
inline uint64_t skeleton_step(uint64_t h, uint64_t word) {
  h = (h ^ word) * kSkeletonMulA;
  return h ^ (h >> 32);
}
/// MurmurHash3's 64-bit finalizer: every input bit reaches every output bit.
inline uint64_t fmix64(uint64_t h) {
  h ^= h >> 33;
  h *= 0xff51afd7ed558ccdull;
  h ^= h >> 33;
  h *= 0xc4ceb9fe1a85ec53ull;
  return h ^ (h >> 33);
}
}  // namespace detail

/// One joint's term of the skeleton hash: its name (8 bytes per step, the 1-7 byte tail read as
/// one word, then the name's length and the parent as a final word) seeded by its index `joint`.
/// O(name length). Inline and exposed so a loader can hash while it walks the joints, and the
/// compiler can overlap one joint's multiplies with the next joint's loads.
inline uint64_t skeleton_hash_joint(size_t joint, std::string_view name, int16_t parent) {
  const auto* p = reinterpret_cast<const unsigned char*>(name.data());
  const size_t n = name.size();
  uint64_t h = (static_cast<uint64_t>(joint) + 1) * detail::kSkeletonMulB;
  size_t i = 0;
  for (; i + 8 <= n; i += 8) h = detail::skeleton_step(h, detail::le64(p + i));
  // The tail, given its length r, maps to one word injectively: 4-7 bytes as two overlapping
  // 32-bit reads, 1-3 bytes as the first, middle and last byte.
  const size_t r = n - i;
  if (r >= 4) h = detail::skeleton_step(h, detail::le32(p + i) | (detail::le32(p + i + r - 4) << 32));
  else if (r > 0) h = detail::skeleton_step(h, p[i] | (uint64_t{p[i + r / 2]} << 8) | (uint64_t{p[i + r - 1]} << 16));
  // Length and parent close the joint, so names of different lengths never share a word stream.
  h = detail::skeleton_step(h, (static_cast<uint64_t>(n) << 16) | static_cast<uint16_t>(parent));
  return detail::fmix64(h);
}

/// Finishes a skeleton hash from the wrapping sum of every joint's skeleton_hash_joint. O(1).
inline uint64_t skeleton_hash_finish(uint64_t joint_sum, size_t joint_count) {
  return detail::fmix64(joint_sum ^ (static_cast<uint64_t>(joint_count) * detail::kSkeletonMulA));
}

/// Hash of a rig (format v8): every joint's name and parent index, in the file's joint order
/// ("ab","c" != "a","bc"; the same names in another order differ). names and parents have the
/// same length (the shorter one bounds it). O(total name length).
uint64_t skeleton_hash(std::span<const std::string_view> names, std::span<const int16_t> parents);

}  // namespace ossa
