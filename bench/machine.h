// machine.h — the line every bench prints first: which CPU ran it and which code paths it took.
//
// A figure is never quoted without its machine: the same kernel measured 125 ns on one VM of a
// kind and 250 ns on another, and which clone of a vectorized loop ran decides most of that. The
// runtime's per-joint loops are GCC target_clones (runtime/internal/vector_clones.h), whose ifunc
// resolver takes the AVX2 clone exactly when __builtin_cpu_supports("avx2"), so the clone is
// named here from the same test; skinning dispatches at run time and says which ISA it uses
// (ossa/skinning/skinning.h). Reads /proc/cpuinfo where there is one. O(1) but for that read.
#pragma once
#include <string>

namespace ossa::bench {

/// "cpu: AMD EPYC (family 25, model 17, 2 logical cpus); vector clones: avx2; skinning: avx512"
/// — one line, no newline. Fields that cannot be known read "unknown".
std::string machine_line();

}  // namespace ossa::bench
