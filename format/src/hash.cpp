// hash.cpp — FNV-1a 64 and the word-wise skeleton hash (see hash.h for why they differ).
#include <ossa/format/hash.h>

#include <bit>
#include <cstring>

namespace ossa {
namespace {

constexpr uint64_t kMulA = 0x9e3779b97f4a7c15ull;  // 2^64 / golden ratio, odd
constexpr uint64_t kMulB = 0xc2b2ae3d27d4eb4full;  // xxHash's PRIME64_2, odd

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
inline uint64_t step(uint64_t h, uint64_t word) {
  h = (h ^ word) * kMulA;
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

}  // namespace

uint64_t hash_bytes(const void* data, size_t size, uint64_t state) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < size; ++i) {
    state ^= p[i];
    state *= 0x100000001b3ull;
  }
  return state;
}

uint64_t skeleton_hash_joint(size_t joint, std::string_view name, int16_t parent) {
  const auto* p = reinterpret_cast<const unsigned char*>(name.data());
  const size_t n = name.size();
  uint64_t h = (static_cast<uint64_t>(joint) + 1) * kMulB;
  size_t i = 0;
  for (; i + 8 <= n; i += 8) h = step(h, le64(p + i));
  // The tail, given its length r, maps to one word injectively: 4-7 bytes as two overlapping
  // 32-bit reads, 1-3 bytes as the first, middle and last byte.
  const size_t r = n - i;
  if (r >= 4) h = step(h, le32(p + i) | (le32(p + i + r - 4) << 32));
  else if (r > 0) h = step(h, p[i] | (uint64_t{p[i + r / 2]} << 8) | (uint64_t{p[i + r - 1]} << 16));
  // Length and parent close the joint, so names of different lengths never share a word stream.
  h = step(h, (static_cast<uint64_t>(n) << 16) | static_cast<uint16_t>(parent));
  return fmix64(h);
}

uint64_t skeleton_hash_finish(uint64_t joint_sum, size_t joint_count) {
  return fmix64(joint_sum ^ (static_cast<uint64_t>(joint_count) * kMulA));
}

uint64_t skeleton_hash(std::span<const std::string_view> names, std::span<const int16_t> parents) {
  const size_t n = names.size() < parents.size() ? names.size() : parents.size();
  uint64_t sum = 0;
  for (size_t i = 0; i < n; ++i) sum += skeleton_hash_joint(i, names[i], parents[i]);
  return skeleton_hash_finish(sum, n);
}

}  // namespace ossa
