// vector_isa.cpp — ossa/anim/vector_isa.h: the process-wide choice of the per-joint loops' copy
// (internal/vector_clones.h). AVX2 alone is what those copies need (they use no FMA), and only
// builds that have the copy may select it; the CPU query is internal/cpu.h's.
#include <ossa/anim/vector_isa.h>

#include <atomic>

#include "internal/cpu.h"
#include "internal/vector_clones.h"

namespace ossa {
namespace {

bool avx2_copy_runs() { return OSSA_HAVE_VECTOR_CLONES && detail::cpu_has_avx2(); }

std::atomic<bool>& avx2_selected() {
  static std::atomic<bool> selected{avx2_copy_runs()};
  return selected;
}

}  // namespace

VectorIsa best_vector_isa() {
  static const VectorIsa best = avx2_copy_runs() ? VectorIsa::Avx2 : VectorIsa::Baseline;
  return best;
}

VectorIsa vector_isa() {
  return avx2_selected().load(std::memory_order_relaxed) ? VectorIsa::Avx2 : VectorIsa::Baseline;
}

bool set_vector_isa(VectorIsa isa) {
  if (isa == VectorIsa::Avx2 && best_vector_isa() != VectorIsa::Avx2) return false;
  avx2_selected().store(isa == VectorIsa::Avx2, std::memory_order_relaxed);
  return true;
}

namespace detail {
bool vector_avx2_selected() { return avx2_selected().load(std::memory_order_relaxed); }
}  // namespace detail

}  // namespace ossa
