// cpu.h — run-time CPU feature queries and the target attributes of hand-vectorized code, in one
// place for GCC, Clang and MSVC. Internal to runtime/.
//
// GCC and Clang answer feature queries with __builtin_cpu_supports (libgcc's cpu model, which
// includes the OS's XSAVE check for AVX state; it works under MinGW-w64 and Wine too) and need
// target("...") on a function that uses AVX2 / AVX-512 intrinsics in a baseline build. MSVC has
// neither: it allows intrinsics of any ISA without flags (so the target macros are empty), and the
// queries are CPUID (__cpuid / __cpuidex) plus XGETBV (_xgetbv), which confirms the OS saves the
// YMM / ZMM state. Each query is answered once and cached.
#pragma once

#if defined(__x86_64__) || defined(__i386__) || defined(_M_X64) || defined(_M_IX86)
#define OSSA_CPU_X86 1
#else
#define OSSA_CPU_X86 0
#endif

#if OSSA_CPU_X86 && (defined(__GNUC__) || defined(__clang__))
/// Marks a function compiled for an ISA beyond the build's baseline (GCC / Clang); empty on MSVC.
#define OSSA_TARGET(isa) __attribute__((target(isa)))
#else
#define OSSA_TARGET(isa)
#endif

namespace ossa::detail {

/// AVX2, with OS support for the YMM state: what the per-joint loops' AVX2 copy uses.
bool cpu_has_avx2();
/// AVX2 + FMA + BMI1/2 + POPCNT, with OS support for the YMM state: what the AVX2 kernels use.
bool cpu_has_avx2_fma();
/// cpu_has_avx2_fma() and AVX-512 F/VL/BW/DQ, with OS support for the ZMM state.
bool cpu_has_avx512();
/// cpu_has_avx512() on a CPU that runs a 512-bit operation as two 256-bit halves (AMD Zen 4): a
/// kernel that only widens its arithmetic from 256 to 512 bits gains nothing there, and pays
/// for the extra extracts.
bool cpu_avx512_split();

}  // namespace ossa::detail
