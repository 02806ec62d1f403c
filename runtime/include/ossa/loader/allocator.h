// allocator.h — where the runtime's own raw memory comes from.
//
// The runtime makes few, large, aligned allocations: an Asset's heap copy of a file (16-byte
// aligned), a Pose's storage (32-byte aligned) and a SamplingCache's key buffers (32-byte
// aligned). An engine with its own heaps, budgets or tracking routes them through set_allocator.
// Containers inside runtime objects (std::vector, std::string) still use the global operator new;
// this hook covers the blocks whose size scales with the data.
//
// It lives in the loader room because the loader is the runtime's bottom layer that every other
// room (anim, skinning, graph) already depends on; format/ is shared with the cooker and allocates
// nothing at run time, so it is not the place for a runtime policy.
//
// A plain struct of function pointers plus a user pointer (no virtual interface): it can be filled
// from C, needs no inheritance, and calling it costs one indirect call per allocation.
#pragma once
#include <cstddef>

namespace ossa {

struct Allocator {
  /// Returns `size` bytes aligned to `alignment` (a power of two, at least 16), or nullptr on
  /// failure. `size` is never 0.
  void* (*allocate)(size_t size, size_t alignment, void* user) = nullptr;
  /// Frees a block from allocate with the same size and alignment. Never called with nullptr.
  void (*deallocate)(void* p, size_t size, size_t alignment, void* user) = nullptr;
  void* user = nullptr;
};

/// Installs the allocator the runtime uses from now on; an Allocator with a null function pointer
/// restores the default (aligned operator new / delete, nothrow). Install it at startup, before
/// any Asset, Pose, SamplingCache or GraphInstance exists: a block is always freed through the
/// allocator current at the time, so switching while blocks are alive hands them to the wrong
/// deallocate. Not synchronized with concurrent allocation. O(1).
void set_allocator(const Allocator& allocator);

/// The allocator in use (the default one unless set_allocator replaced it). O(1).
const Allocator& allocator();

}  // namespace ossa
