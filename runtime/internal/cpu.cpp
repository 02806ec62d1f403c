// cpu.cpp — cpu.h: CPU feature queries through __builtin_cpu_supports (GCC, Clang, MinGW-w64) or
// CPUID + XGETBV (MSVC). Answers are computed once (function-local statics: thread-safe). The
// skinning kernels' choice (skinning/) and the per-joint loops' copy (anim/vector_isa.cpp) read them.
#include "internal/cpu.h"

#if OSSA_CPU_X86 && defined(_MSC_VER) && !defined(__clang__)
#include <immintrin.h>
#include <intrin.h>
#elif OSSA_CPU_X86
#include <cpuid.h>
#endif

namespace ossa::detail {
namespace {

struct Features {
  bool avx2 = false;  // AVX2 with the OS's YMM state: all the per-joint loops' copy needs
  bool avx2_fma = false;
  bool avx512 = false;
  bool avx512_split = false;  // 512-bit operations run as two 256-bit halves
};

#if OSSA_CPU_X86
/// AMD family 19h (Zen 3 and Zen 4; only Zen 4 has AVX-512) from CPUID leaves 0 and 1: its
/// 512-bit operations take two passes through 256-bit units. Later AMD families (Zen 5) and
/// Intel's AVX-512 parts run them at full width.
bool amd_family_19h(unsigned vendor_ebx, unsigned vendor_ecx, unsigned vendor_edx, unsigned leaf1_eax) {
  // "AuthenticAMD" as CPUID 0 returns it in EBX, EDX, ECX.
  if (vendor_ebx != 0x68747541u || vendor_edx != 0x69746e65u || vendor_ecx != 0x444d4163u) return false;
  const unsigned base = (leaf1_eax >> 8) & 0xfu, extended = (leaf1_eax >> 20) & 0xffu;
  return base == 0xfu && base + extended == 0x19u;
}
#endif

Features detect() {
  Features f;
#if OSSA_CPU_X86 && (defined(__GNUC__) || defined(__clang__))
  __builtin_cpu_init();
  f.avx2 = __builtin_cpu_supports("avx2");
  f.avx2_fma = f.avx2 && __builtin_cpu_supports("fma") && __builtin_cpu_supports("bmi") &&
               __builtin_cpu_supports("bmi2") && __builtin_cpu_supports("popcnt");
  f.avx512 = f.avx2_fma && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
             __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq");
  unsigned max_leaf = 0, ebx = 0, ecx = 0, edx = 0, eax1 = 0, b1 = 0, c1 = 0, d1 = 0;
  if (f.avx512 && __get_cpuid(0, &max_leaf, &ebx, &ecx, &edx) && __get_cpuid(1, &eax1, &b1, &c1, &d1))
    f.avx512_split = amd_family_19h(ebx, ecx, edx, eax1);
#elif OSSA_CPU_X86 && defined(_MSC_VER)
  int r[4];
  __cpuid(r, 0);
  const int max_leaf = r[0];
  if (max_leaf < 7) return f;
  __cpuid(r, 1);
  const unsigned leaf1_eax = static_cast<unsigned>(r[0]);
  const bool osxsave = (r[2] & (1 << 27)) != 0, fma = (r[2] & (1 << 12)) != 0, popcnt = (r[2] & (1 << 23)) != 0,
             avx = (r[2] & (1 << 28)) != 0;
  if (!osxsave || !avx) return f;
  const unsigned long long xcr0 = _xgetbv(0);
  const bool ymm_state = (xcr0 & 0x6) == 0x6;    // XMM + YMM
  const bool zmm_state = (xcr0 & 0xe6) == 0xe6;  // + opmask, ZMM_Hi256, Hi16_ZMM
  __cpuidex(r, 7, 0);
  const bool avx2 = (r[1] & (1 << 5)) != 0, bmi1 = (r[1] & (1 << 3)) != 0, bmi2 = (r[1] & (1 << 8)) != 0;
  const bool avx512f = (r[1] & (1 << 16)) != 0, avx512dq = (r[1] & (1 << 17)) != 0, avx512bw = (r[1] & (1 << 30)) != 0,
             avx512vl = (r[1] & (1u << 31)) != 0;
  f.avx2 = ymm_state && avx2;
  f.avx2_fma = f.avx2 && fma && bmi1 && bmi2 && popcnt;
  f.avx512 = f.avx2_fma && zmm_state && avx512f && avx512vl && avx512bw && avx512dq;
  int v[4];
  __cpuid(v, 0);
  f.avx512_split = f.avx512 && amd_family_19h(static_cast<unsigned>(v[1]), static_cast<unsigned>(v[2]),
                                              static_cast<unsigned>(v[3]), leaf1_eax);
#endif
  return f;
}

const Features& features() {
  static const Features f = detect();
  return f;
}

}  // namespace

bool cpu_has_avx2() { return features().avx2; }
bool cpu_has_avx2_fma() { return features().avx2_fma; }
bool cpu_has_avx512() { return features().avx512; }
bool cpu_avx512_split() { return features().avx512_split; }

}  // namespace ossa::detail
