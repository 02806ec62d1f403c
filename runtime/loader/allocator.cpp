// allocator.cpp — the installable Allocator (allocator.h) and its default: aligned operator new /
// delete, nothrow, which exist on every C++17 toolchain (std::aligned_alloc does not: MinGW and
// MSVC lack it).
#include <ossa/loader/allocator.h>

#include <new>

namespace ossa {
namespace {

void* default_allocate(size_t size, size_t alignment, void*) {
  return ::operator new (size, std::align_val_t{alignment}, std::nothrow);
}

void default_deallocate(void* p, size_t, size_t alignment, void*) {
  ::operator delete (p, std::align_val_t{alignment});
}

constexpr Allocator kDefault{default_allocate, default_deallocate, nullptr};
Allocator g_allocator = kDefault;

}  // namespace

void set_allocator(const Allocator& a) {
  g_allocator = (a.allocate != nullptr && a.deallocate != nullptr) ? a : kDefault;
}

const Allocator& allocator() { return g_allocator; }

}  // namespace ossa
