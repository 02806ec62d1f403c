// machine.cpp — see machine.h.
#include "bench/machine.h"

#include <fstream>
#include <thread>

#include <cstring>

#include <ossa/anim/vector_isa.h>
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
  if (vector_isa() == VectorIsa::Avx2) return "avx2";
  return best_vector_isa() == VectorIsa::Avx2 ? "baseline (forced)" : "baseline";
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

CpuVendor cpu_vendor() {
  const std::string id = cpuinfo("vendor_id");
  if (id == "AuthenticAMD") return CpuVendor::Amd;
  if (id == "GenuineIntel") return CpuVendor::Intel;
  return CpuVendor::Other;
}

bool apply_clone(int& argc, char** argv, std::string* error, bool* unavailable) {
  if (unavailable) *unavailable = false;
  for (int i = 1; i < argc; ++i) {
    std::string name;
    int taken = 0;
    if (std::strcmp(argv[i], "--clone") == 0 && i + 1 < argc) {
      name = argv[i + 1];
      taken = 2;
    } else if (std::strncmp(argv[i], "--clone=", 8) == 0) {
      name = argv[i] + 8;
      taken = 1;
    } else if (std::strcmp(argv[i], "--clone") == 0) {
      *error = "--clone needs a value: baseline, avx2 or avx512";
      return false;
    } else {
      continue;
    }
    bool ok = false;
    if (name == "baseline") ok = set_vector_isa(VectorIsa::Baseline) && set_skinning_isa(SkinningIsa::Portable);
    else if (name == "avx2") ok = set_vector_isa(VectorIsa::Avx2) && set_skinning_isa(SkinningIsa::Avx2);
    else if (name == "avx512") ok = set_vector_isa(VectorIsa::Avx2) && set_skinning_isa(SkinningIsa::Avx512);
    else {
      *error = "--clone " + name + ": unknown (baseline, avx2 or avx512)";
      return false;
    }
    if (!ok) {
      *error = "--clone " + name + ": this CPU or build cannot run it";
      if (unavailable) *unavailable = true;
      return false;
    }
    for (int j = i; j + taken < argc; ++j) argv[j] = argv[j + taken];
    argc -= taken;
    argv[argc] = nullptr;
    --i;
  }
  return true;
}

}  // namespace ossa::bench
