// float_env.h — per-call flush-to-zero for the runtime's float kernels. Internal to runtime/.
//
// Why. Rigs exported from matrices carry rest values like 7.7e-34 (decomposition noise: Pab, many
// Blender rigs), and a file cooked elsewhere may carry anything. Interpolating, blending or
// multiplying such a value squares it below FLT_MIN, and every subnormal result or operand costs
// the CPU a microcode assist: on Pab's walk that made sampling 1.8x slower on a Zen 5 EPYC and
// 2-2.5x on an Intel Xeon. The cooker flushes such values (cooker/import/tiny_values.h), but the
// runtime must not depend on who cooked a file, and no bound on its inputs keeps every product of
// an nlerp or a matrix chain normal. So each float kernel runs with MXCSR's flush-to-zero and
// denormals-are-zero bits set, and restores the caller's MXCSR on return: a library must not
// change the floating-point environment of the thread that calls it (PhysX's scoped SIMD guard
// works the same way). Only results that would have been subnormal change: they become 0.
//
// Cost: one MXCSR read per call, and two writes when the caller has not set both bits itself
// (~3-4 ns per call on Zen 5; a host that sets FTZ/DAZ for its game thread pays the read alone).
// The animation graph holds one guard across a whole update, so its inner calls find the bits set.
// Other CPUs: AArch64 cores handle subnormals at full speed, so elsewhere this does nothing.
#pragma once

#if defined(__SSE__) || defined(_M_X64) || (defined(_M_IX86_FP) && _M_IX86_FP >= 1)
#include <xmmintrin.h>
#define OSSA_HAVE_MXCSR 1
#else
#define OSSA_HAVE_MXCSR 0
#endif

namespace ossa::detail {

class FlushDenormals {
 public:
#if OSSA_HAVE_MXCSR
  static constexpr unsigned kBits = 0x8040;  // FTZ (bit 15) | DAZ (bit 6)
  FlushDenormals() : saved_(_mm_getcsr()) {
    if ((saved_ & kBits) != kBits) _mm_setcsr(saved_ | kBits);
  }
  ~FlushDenormals() {
    if ((saved_ & kBits) != kBits) _mm_setcsr(saved_);
  }

 private:
  unsigned saved_;
#else
  FlushDenormals() {}
  ~FlushDenormals() {}
#endif

 public:
  FlushDenormals(const FlushDenormals&) = delete;
  FlushDenormals& operator=(const FlushDenormals&) = delete;
};

}  // namespace ossa::detail
