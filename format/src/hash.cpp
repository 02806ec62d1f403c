// hash.cpp — FNV-1a 64 and the word-wise skeleton hash (see hash.h for why they differ).
#include <ossa/format/hash.h>

namespace ossa {
uint64_t hash_bytes(const void* data, size_t size, uint64_t state) {
  const auto* p = static_cast<const unsigned char*>(data);
  for (size_t i = 0; i < size; ++i) {
    state ^= p[i];
    state *= 0x100000001b3ull;
  }
  return state;
}

uint64_t skeleton_hash(std::span<const std::string_view> names, std::span<const int16_t> parents) {
  const size_t n = names.size() < parents.size() ? names.size() : parents.size();
  uint64_t sum = 0;
  for (size_t i = 0; i < n; ++i) sum += skeleton_hash_joint(i, names[i], parents[i]);
  return skeleton_hash_finish(sum, n);
}

}  // namespace ossa
