// cpu.cpp — cpu.h: CPU feature queries through __builtin_cpu_supports (GCC, Clang, MinGW-w64) or
// CPUID + XGETBV (MSVC). Answers are computed once (function-local statics: thread-safe). The
// skinning kernels' choice (skinning/) and the per-joint loops' copy (anim/vector_isa.cpp) read them.
#include "internal/cpu.h"

#if OSSA_CPU_X86 && defined(_MSC_VER) && !defined(__clang__)
#include <immintrin.h>
#include <intrin.h>
#endif

namespace ossa::detail {
namespace {

struct Features {
  bool avx2 = false;  // AVX2 with the OS's YMM state: all the per-joint loops' copy needs
  bool avx2_fma = false;
  bool avx512 = false;
};

Features detect() {
  Features f;
#if OSSA_CPU_X86 && (defined(__GNUC__) || defined(__clang__))
  __builtin_cpu_init();
  f.avx2 = __builtin_cpu_supports("avx2");
  f.avx2_fma = f.avx2 && __builtin_cpu_supports("fma") && __builtin_cpu_supports("bmi") &&
               __builtin_cpu_supports("bmi2") && __builtin_cpu_supports("popcnt");
  f.avx512 = f.avx2_fma && __builtin_cpu_supports("avx512f") && __builtin_cpu_supports("avx512vl") &&
             __builtin_cpu_supports("avx512bw") && __builtin_cpu_supports("avx512dq");
#elif OSSA_CPU_X86 && defined(_MSC_VER)
  int r[4];
  __cpuid(r, 0);
  const int max_leaf = r[0];
  if (max_leaf < 7) return f;
  __cpuid(r, 1);
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

}  // namespace ossa::detail
