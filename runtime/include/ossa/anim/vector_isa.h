// vector_isa.h — which compiled copy of the per-joint loops runs: AVX2 or baseline x86-64.
//
// The per-joint kernels (sampling's interpolation, blends, additive layers, local_to_model) are
// compiled twice on Linux x86-64 and pick a copy per call from this process-wide setting, which
// starts at the best the CPU has. Benchmarks force a copy to time it (ossa-bench-anim --clone) and
// tests compare them; a game has no reason to call set_vector_isa. Both copies produce
// bit-identical results (no FMA contraction in either). Skinning has its own switch with an
// AVX-512 level (ossa/skinning/skinning.h, set_skinning_isa).
#pragma once
#include <cstdint>

namespace ossa {

enum class VectorIsa : uint8_t { Baseline, Avx2 };

/// The copy the per-joint loops run now. O(1), thread-safe.
VectorIsa vector_isa();

/// Selects a copy for the whole process. Returns false and changes nothing when the CPU lacks
/// AVX2 or the build has no AVX2 copy (Windows, macOS, MSVC, OSSA_NO_TARGET_CLONES). Thread-safe;
/// calls already running finish on the copy they started with.
bool set_vector_isa(VectorIsa isa);

/// The best copy this CPU and build can run.
VectorIsa best_vector_isa();

}  // namespace ossa
