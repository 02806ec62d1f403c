// vector_clones.h — how the runtime's per-joint loops get AVX2 code without requiring AVX2.
//
// A function marked OSSA_VECTOR_CLONES is compiled twice, for AVX2 and for baseline x86-64, and
// the loader picks the clone the CPU can run (GCC/clang target_clones, an ifunc). Helpers called
// from such a function are OSSA_INLINE so they are compiled into each clone for its ISA; an
// out-of-line helper would run its baseline code from the AVX2 clone. OSSA_NO_TARGET_CLONES
// builds only the baseline code, to test or time it on an AVX2 machine. Internal to runtime/.
//
// target_clones needs an ifunc, which only ELF targets have: on Windows (PE, MinGW-w64), macOS
// (Mach-O) and with MSVC the functions are compiled once, for the baseline. Linux builds get the
// same two clones as always.
#pragma once

#if defined(__x86_64__) && defined(__ELF__) && (defined(__GNUC__) || defined(__clang__)) && \
    defined(__has_attribute) && !defined(OSSA_NO_TARGET_CLONES)
#if __has_attribute(target_clones)
#define OSSA_VECTOR_CLONES __attribute__((target_clones("avx2", "default")))
#endif
#endif
#ifndef OSSA_VECTOR_CLONES
#define OSSA_VECTOR_CLONES
#endif
#if defined(__GNUC__) || defined(__clang__)
#define OSSA_INLINE [[gnu::always_inline]] inline
#elif defined(_MSC_VER)
#define OSSA_INLINE __forceinline
#else
#define OSSA_INLINE inline
#endif
