// hash.cpp — FNV-1a 64 and the skeleton hash built on it (see hash.h).
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
  uint64_t h = kFnvOffset;
  const size_t n = names.size() < parents.size() ? names.size() : parents.size();
  for (size_t i = 0; i < n; ++i) {
    h = hash_bytes(names[i].data(), names[i].size(), h);
    const unsigned char zero = 0;
    h = hash_bytes(&zero, 1, h);
    const auto p = static_cast<uint16_t>(parents[i]);
    const unsigned char le[2] = {static_cast<unsigned char>(p & 0xff), static_cast<unsigned char>(p >> 8)};
    h = hash_bytes(le, 2, h);
  }
  return h;
}

}  // namespace ossa
