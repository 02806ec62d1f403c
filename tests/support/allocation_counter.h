// allocation_counter.h — how many times operator new ran, for tests of "allocation-free" promises.
//
// allocation_counter.cpp replaces the global operator new/delete of the test program it is linked
// into (so link it into a test executable only, never into a library): every form that pairs with
// free() is replaced, so no allocation from a library's (or a sanitizer's) operator new is
// released here or the other way round. The align_val_t forms are left alone: they allocate and
// free as a pair on their own.
#pragma once
#include <cstddef>

namespace ossa::test {

/// Allocations through operator new so far in this process.
size_t allocation_count();

}  // namespace ossa::test
