// vector_clones.h — how the runtime's per-joint loops get AVX2 code without requiring AVX2, and
// how a program picks which copy runs.
//
// A kernel is written once, as an always-inline body (`name_body`), and OSSA_VECTOR_DISPATCH
// compiles it twice — for AVX2 (target("avx2"): 256-bit vectors, no FMA, so both copies give
// bit-identical results) and for baseline x86-64 — and defines the public function, which calls
// the copy selected at run time (ossa/anim/vector_isa.h: the best the CPU has unless a program
// asked for the baseline). Helpers called from a body are OSSA_INLINE so they are compiled into
// each copy for its ISA; an out-of-line helper would run its baseline code from the AVX2 copy.
//
// Why not GCC's target_clones, which this replaced: its ifunc resolver picks a clone once, at
// load time, from the CPU alone, so a benchmark could not time the baseline clone on an AVX2
// machine, nor say for certain which clone it timed. One relaxed atomic load and a well-predicted
// branch per call cost nothing next to a per-joint loop (~100 ns and up).
//
// Only ELF x86-64 builds with GCC or Clang get the AVX2 copy, as with target_clones before: on
// Windows (MinGW-w64's GCC does not align the stack for spilled 256-bit values, GCC bug 54412),
// macOS and MSVC, and with OSSA_NO_TARGET_CLONES, the body is compiled once, for the baseline.
// Internal to runtime/.
#pragma once

#if defined(__x86_64__) && defined(__ELF__) && (defined(__GNUC__) || defined(__clang__)) && \
    !defined(OSSA_NO_TARGET_CLONES)
#define OSSA_HAVE_VECTOR_CLONES 1
#else
#define OSSA_HAVE_VECTOR_CLONES 0
#endif

#if defined(__GNUC__) || defined(__clang__)
#define OSSA_INLINE [[gnu::always_inline]] inline
#elif defined(_MSC_VER)
#define OSSA_INLINE __forceinline
#else
#define OSSA_INLINE inline
#endif

namespace ossa::detail {

/// Whether the AVX2 copies run (ossa/anim/vector_isa.h sets it; runtime/internal/cpu.cpp).
bool vector_avx2_selected();

}  // namespace ossa::detail

#if OSSA_HAVE_VECTOR_CLONES
/// Defines `void name params` over `name##_body args`, compiled for AVX2 and the baseline.
#define OSSA_VECTOR_DISPATCH(name, params, args)                                                 \
  __attribute__((target("avx2"), noinline)) static void name##_avx2 params { name##_body args; } \
  __attribute__((noinline)) static void name##_baseline params { name##_body args; }             \
  void name params {                                                                             \
    if (::ossa::detail::vector_avx2_selected()) name##_avx2 args;                                \
    else name##_baseline args;                                                                   \
  }
#else
#define OSSA_VECTOR_DISPATCH(name, params, args) \
  void name params { name##_body args; }
#endif
