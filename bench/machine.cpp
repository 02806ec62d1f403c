// machine.cpp — see machine.h.
#include "bench/machine.h"

#include <fstream>
#include <thread>

#include <ossa/skinning/skinning.h>

namespace ossa::bench {
namespace {

/// The value of the first "key : value" line of /proc/cpuinfo whose key is `key`, or "unknown".
std::string cpuinfo(const std::string& key) {
  std::ifstream in("/proc/cpuinfo");
  std::string line;
  while (std::getline(in, line)) {
    const size_t colon = line.find(':');
    if (colon == std::string::npos) continue;
    std::string k = line.substr(0, colon);
    while (!k.empty() && (k.back() == ' ' || k.back() == '\t')) k.pop_back();
    if (k == key) return colon + 2 <= line.size() ? line.substr(colon + 2) : "";
  }
  return "unknown";
}

const char* vector_clone() {
#if defined(__x86_64__) && defined(__ELF__) && (defined(__GNUC__) || defined(__clang__)) && !defined(OSSA_NO_TARGET_CLONES)
  return __builtin_cpu_supports("avx2") ? "avx2" : "baseline";
#else
  return "baseline (no target_clones on this platform)";
#endif
}

const char* skinning_name(SkinningIsa isa) {
  switch (isa) {
    case SkinningIsa::Avx2: return "avx2";
    case SkinningIsa::Avx512: return "avx512";
    default: return "portable";
  }
}

}  // namespace

std::string machine_line() {
  return "cpu: " + cpuinfo("model name") + " (family " + cpuinfo("cpu family") + ", model " + cpuinfo("model") + ", " +
         std::to_string(std::thread::hardware_concurrency()) + " logical cpus); vector clones: " + vector_clone() +
         "; skinning: " + skinning_name(skinning_isa());
}

}  // namespace ossa::bench
