// machine.h — the line every bench prints first: which CPU ran it and which code paths it took.
//
// A figure is never quoted without its machine: the same kernel measured 125 ns on one VM of a
// kind and 250 ns on another, and which clone of a vectorized loop ran decides most of that. The
// runtime's per-joint loops and its skinning kernel both dispatch at run time and say which copy
// they run (ossa/anim/vector_isa.h, ossa/skinning/skinning.h), so the line names what ran, and
// apply_clone lets a bench force a copy (--clone). Reads /proc/cpuinfo where there is one. O(1)
// but for that read.
#pragma once
#include <string>

namespace ossa::bench {

/// "cpu: AMD EPYC (family 25, model 17, 2 logical cpus); vector clones: avx2; skinning: avx512"
/// — one line, no newline. Fields that cannot be known read "unknown".
std::string machine_line();

enum class CpuVendor { Amd, Intel, Other };

/// The CPU's vendor from /proc/cpuinfo's vendor_id (AuthenticAMD, GenuineIntel), else Other.
CpuVendor cpu_vendor();

/// Takes `--clone baseline|avx2|avx512` (or `--clone=...`) out of argv, if present, and forces
/// that copy: baseline = the per-joint loops' baseline copy and portable skinning; avx2 = their
/// AVX2 copies; avx512 = the AVX2 per-joint loops (they have no AVX-512 copy) and AVX-512 skinning.
/// False with *error set for an unknown name or a copy this CPU or build cannot run; *unavailable
/// (when given) then says which: true for a known copy this CPU or build cannot run.
bool apply_clone(int& argc, char** argv, std::string* error, bool* unavailable = nullptr);

}  // namespace ossa::bench
