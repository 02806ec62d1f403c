// memory.h — the runtime's raw aligned allocations, through the installable Allocator
// (<ossa/loader/allocator.h>). Internal to runtime/.
#pragma once
#include <cstddef>

#include <ossa/loader/allocator.h>

namespace ossa::detail {

/// allocator().allocate, nullptr on failure (and for size 0).
inline void* allocate(size_t size, size_t alignment) {
  if (size == 0) return nullptr;
  const Allocator& a = allocator();
  return a.allocate(size, alignment, a.user);
}

/// allocator().deallocate; ignores nullptr.
inline void deallocate(void* p, size_t size, size_t alignment) {
  if (p == nullptr) return;
  const Allocator& a = allocator();
  a.deallocate(p, size, alignment, a.user);
}

}  // namespace ossa::detail
