// skinning.cpp — CPU skinning's entry: skin_cpu checks its streams and picks a kernel (linear
// blend, the GPU's reference, or dual quaternion), and the skinning ISA switch.
//
// Why it is shaped so:
// - A portable path decodes any valid layout as OpenGL fetches it (unorm16 / 65535, snorm16
//   max(v / 32767, -1), octahedral directions via ossa/format/vertex_codec.h, unorm8 weights / 255,
//   integer joint slots, missing components (0, 0, 0, 1)), a batch of 64 vertices at a time with
//   one loop per attribute format, and skins in plain float code. It serves float cooks, static
//   meshes, unusual layouts, dual quaternions, and CPUs without AVX2.
// - The cooker's quantized layout (Position Unorm16x4, Normal Snorm16x2, Tangent Snorm16x4, Joints
//   Uint8x4 / Uint16x4, Weights Unorm8x4) has a hand-vectorized path, picked at run time with
//   internal/cpu.h's queries (the default build runs on any x86-64). Intrinsics rather than
//   target_clones: every vertex has its own matrices, so the work is array-of-structures per
//   vertex (a structure-of-arrays form needs 12 gathers per influence, and gathers measured ~1.4
//   cycles per element on this Zen 4), and what makes it fast is in-register shuffles and rsqrt,
//   which auto-vectorized clones do not produce.
// - Influence counts vary from vertex to vertex with no pattern (Pab's arnaud: 35% one, 41% two,
//   18% three, 6% four; consecutive vertices differ 32% of the time), so a branch per vertex on
//   the count mispredicts often, and always blending four doubles the work. Each class runs a loop
//   specialized for it (skin_x86.cpp), including a class for single influences of weight
//   255 that uses the palette matrix as it is. The cooker orders a skinned mesh's vertices by class
//   (as ozz-animation splits skinning jobs by influence count), so each class is one contiguous
//   range, checked as it is skinned; a file in any other order is classified per batch, branch-free.
//
// The de-quantizing affine D (translate(position_offset) * scale(position_scale)) is folded into
// the palette for positions. Directions must not see D's scale, so they are pre-multiplied by its
// inverse, 1 / position_scale per axis (a per-mesh constant): palette3x3 * (n / s) = M3x3 * n with
// M = model * inverse_bind. A GPU shader has to do the same (one uniform) to agree with skin_cpu.
//
// Dual quaternion skinning (skin_dual_quaternion.cpp) splits each palette matrix back into a rigid
// part and a stretch, and blends the rigid parts as dual quaternions.
//
// Costs: skinning_matrices O(slots). skin_cpu O(vertices * influences), allocation-free (stack
// buffers: ~35 KB on the fast path, 16 KB of it the 64-byte aligned palette copy; ~22 KB for dual
// quaternions), no virtual calls, no per-vertex branches on the fast path. Measured on Pab's
// arnaud (3836 vertices, a loop over skin_cpu, Zen 5 VM at ~3.1 GHz, AVX-512 copies, best of
// 1000): ~1.35 ns per vertex for positions, ~1.95 ns with normals (~0.1 less without
// renormalizing: soa_kernel.h), as cooked (class-ordered). An earlier measurement of the other
// paths: ~2.8 / ~4.9 ns classified per batch; portable ~19 / ~32 ns; dual quaternions ~69 ns.
//
// Files: this one resolves a mesh's facts, keeps the ISA switch and dispatches skin_cpu;
// skin_palette.cpp builds palettes; skin_portable.cpp, skin_dual_quaternion.cpp and skin_x86.cpp
// (with skin_x86_batch.cpp and soa_kernel.h) are the kernels; skin_internal.h is what they share.
#include <ossa/skinning/skinning.h>

#include <atomic>
#include <cassert>
#include <cstdint>
#include <cstring>

#include <ossa/format/vertex_codec.h>
#include <ossa/format/vertex_format.h>

#include "internal/cpu.h"
#include "internal/float_env.h"
#include "skinning/skin_internal.h"

namespace ossa {

namespace skin_detail {

MeshFacts mesh_facts(const MeshView& mesh) {
  MeshFacts f;
  f.base = mesh.vertex_bytes().data();
  f.count = mesh.vertex_count();
  f.stride = mesh.vertex_stride();
  f.position = mesh.attribute(VertexSemantic::Position);
  f.normal = mesh.attribute(VertexSemantic::Normal);
  f.tangent = mesh.attribute(VertexSemantic::Tangent);
  f.joints = mesh.attribute(VertexSemantic::Joints);
  f.weights = mesh.attribute(VertexSemantic::Weights);
  if (f.joints == nullptr || f.weights == nullptr) f.joints = f.weights = nullptr;
  f.slot_count = mesh.joints().size();
  f.dequantize = f.position != nullptr && vertex_format_info(f.position->format()).normalized;
  if (f.dequantize) {
    if (const fb::Vec3* o = mesh.fb->position_offset()) f.offset = {o->x(), o->y(), o->z()};
    if (const fb::Vec3* s = mesh.fb->position_scale()) f.scale = {s->x(), s->y(), s->z()};
    for (int a = 0; a < 3; ++a) f.direction_prescale[a] = f.scale[a] != 0.0f ? 1.0f / f.scale[a] : 0.0f;
  }
  return f;
}

}  // namespace skin_detail

using namespace skin_detail;

namespace {

#if OSSA_SKIN_X86
SkinningIsa best_isa() {
  if (detail::cpu_has_avx512()) return SkinningIsa::Avx512;
  return detail::cpu_has_avx2_fma() ? SkinningIsa::Avx2 : SkinningIsa::Portable;
}
#endif  // OSSA_SKIN_X86

/// The selected implementation; the first read detects the CPU (thread-safe static init).
std::atomic<SkinningIsa>& selected_isa() {
  static std::atomic<SkinningIsa> selected{best_isa()};
  return selected;
}

}  // namespace

SkinningIsa skinning_isa() { return selected_isa().load(std::memory_order_relaxed); }

bool set_skinning_isa(SkinningIsa isa) {
  if (static_cast<uint8_t>(isa) > static_cast<uint8_t>(best_isa())) return false;
  selected_isa().store(isa, std::memory_order_relaxed);
  return true;
}

void skin_cpu(const MeshView& mesh, std::span<const glm::mat4> palette, SkinningMethod method, SkinnedStreams out) {
  const MeshFacts m = mesh_facts(mesh);
  if (m.count == 0 || m.position == nullptr) return;
  // Size preconditions: asserted in debug builds; a release build skips a stream that does not
  // fit (or, with too small a palette, everything) rather than read or write out of bounds.
  const size_t n = m.count;
  Outputs o;
  o.renormalize = out.renormalize;
  if (!out.positions.empty()) {
    assert(out.positions.size() >= 3 * n);
    if (out.positions.size() >= 3 * n) o.positions = out.positions.data();
  }
  if (!out.normals.empty()) {
    assert(m.normal != nullptr && out.normals.size() >= 3 * n);
    if (m.normal != nullptr && out.normals.size() >= 3 * n) o.normals = out.normals.data();
  }
  if (!out.tangents.empty()) {
    assert(m.tangent != nullptr && out.tangents.size() >= 4 * n);
    if (m.tangent != nullptr && out.tangents.size() >= 4 * n) o.tangents = out.tangents.data();
  }
  if (o.positions == nullptr && o.normals == nullptr && o.tangents == nullptr) return;
  const detail::FlushDenormals flush;  // internal/float_env.h
  const size_t needed = m.joints != nullptr ? m.slot_count : 1;
  assert(palette.size() >= needed);
  if (palette.size() < needed || needed == 0) return;

  if (method == SkinningMethod::DualQuaternion) {
    skin_dual_quaternion(m, palette, o);
    return;
  }
#if OSSA_SKIN_X86
  const SkinningIsa which = skinning_isa();
  if (which != SkinningIsa::Portable && skin_quantized(m, &palette[0][0][0], o, which == SkinningIsa::Avx512)) return;
#endif
  skin_linear_portable(m, palette.data(), o);
}

InfluenceOrder influence_order(const MeshView& mesh) {
  InfluenceOrder out;
  const fb::VertexAttribute* w = mesh.attribute(fb::VertexSemantic::Weights);
  if (w == nullptr || w->format() != fb::VertexFormat::Unorm8x4) return out;
  out.unorm8_weights = true;
  out.class_ordered = true;
  const uint8_t* at = mesh.vertex_bytes().data() + w->offset();  // validation proved every read
  int last = -1;
  for (uint32_t v = 0; v < mesh.vertex_count(); ++v, at += mesh.vertex_stride()) {
    uint32_t word;
    std::memcpy(&word, at, 4);
    const int c = influence_class(word);
    ++out.vertices_by_class[static_cast<size_t>(c)];
    out.class_runs += c != last ? 1 : 0;
    out.class_ordered = out.class_ordered && c >= last;
    last = c;
  }
  return out;
}

}  // namespace ossa
