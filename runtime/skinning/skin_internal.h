// skin_internal.h — what skinning's source files share: a mesh's facts resolved once per call, the
// output streams, the unorm8 weight table, the portable decoder's batch, the fast paths' vertex
// layout and batch, and the entry points each file offers the others. Internal to runtime/skinning.
//
// Why it is shaped so: skinning.cpp (skin_cpu and the ISA switch) picks a kernel family, and each
// family has its own file: skin_palette.cpp (skinning matrices), skin_portable.cpp (any layout,
// linear blend), skin_dual_quaternion.cpp, and the x86 fast paths for the cooker's quantized layout,
// skin_x86.cpp (per-class loops and their drivers) with skin_x86_batch.cpp (classification,
// direction decoding, renormalization of a batch). Files call each other once per call or per
// batch, never per vertex; what a per-vertex loop uses (finish_direction, kWeight, load_u32) is
// inline here, so every kernel inlines it as it did when it was one file.
#pragma once

#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <span>

#include <glm/glm.hpp>

#include <ossa/skinning/skinning.h>

#include "internal/cpu.h"

#if OSSA_CPU_X86
// GCC 12's AVX-512 headers trip -Wmaybe-uninitialized on their own _mm512_undefined_* helpers
// (GCC bug 105593, fixed in 13); the diagnostic points into the header, so silence it there.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <immintrin.h>
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif
#define OSSA_SKIN_X86 1
#else
#define OSSA_SKIN_X86 0
#endif

namespace ossa::skin_detail {

using fb::VertexFormat;
using fb::VertexSemantic;

inline uint32_t load_u32(const uint8_t* p) {
  uint32_t v;
  std::memcpy(&v, p, 4);
  return v;
}
inline uint64_t load_u64(const uint8_t* p) {
  uint64_t v;
  std::memcpy(&v, p, 8);
  return v;
}

// ---------------------------------------------------------------------------------------------
// What a mesh holds, resolved once per call.

struct MeshFacts {
  const uint8_t* base = nullptr;
  uint32_t count = 0;
  uint32_t stride = 0;
  const fb::VertexAttribute* position = nullptr;
  const fb::VertexAttribute* normal = nullptr;
  const fb::VertexAttribute* tangent = nullptr;
  const fb::VertexAttribute* joints = nullptr;  // both or neither (validate.cpp)
  const fb::VertexAttribute* weights = nullptr;
  size_t slot_count = 0;                // mesh.joints().size()
  bool dequantize = false;              // D applies: a normalized position format
  glm::vec3 offset{0.0f}, scale{1.0f};  // D
  glm::vec3 direction_prescale{1.0f};   // 1 / scale (0 on a zero axis)
};

/// Resolves the facts of mesh (skinning.cpp).
MeshFacts mesh_facts(const MeshView& mesh);

// ---------------------------------------------------------------------------------------------
/// unorm8 weight -> float, exactly b / 255.0f as OpenGL normalizes it. (A constexpr variable has
/// internal linkage: each file that reads it has its own aligned copy, addressed as before.)
constexpr std::array<float, 256> make_weight_table() {
  std::array<float, 256> t{};
  for (int i = 0; i < 256; ++i) t[static_cast<size_t>(i)] = static_cast<float>(i) / 255.0f;
  return t;
}
alignas(64) constexpr std::array<float, 256> kWeight = make_weight_table();

namespace {
/// v / |v|, or zero for a zero vector (what the fast paths' guarded rsqrt gives too). Never
/// inlined: inlined into an AVX2 function (normalize_xyz_w's tail) its dot product would contract
/// into FMAs and round differently from the portable paths' calls.
[[gnu::noinline]] glm::vec3 normalize_or_zero(glm::vec3 v) {
  const float len2 = glm::dot(v, v);
  return len2 > 0.0f ? v * (1.0f / std::sqrt(len2)) : glm::vec3(0.0f);
}
}  // namespace

/// Where skin_cpu writes; null streams are not written.
struct Outputs {
  float* positions = nullptr;
  float* normals = nullptr;
  float* tangents = nullptr;
  bool renormalize = true;  // SkinnedStreams::renormalize
};

/// A transformed direction as the caller asked for it: unit length, or as transformed.
inline glm::vec3 finish_direction(glm::vec3 v, const Outputs& out) {
  return out.renormalize ? normalize_or_zero(v) : v;
}

// ---------------------------------------------------------------------------------------------
// Portable path (skin_portable.cpp): attributes decoded a batch at a time as OpenGL fetches them.

constexpr uint32_t kPortableBatch = 64;

struct Decoded {
  uint32_t first = 0, n = 0;
  glm::vec3 position[kPortableBatch];  // as stored (normalized for quantized layouts: D is in the palette)
  glm::vec3 normal[kPortableBatch];    // unit
  glm::vec4 tangent[kPortableBatch];   // unit xyz, sign
  uint32_t slot[kPortableBatch][4];
  glm::vec4 weight[kPortableBatch];
};

/// Decodes the batch [d.first, d.first + d.n): positions when out asks for them or positions_too,
/// the directions out asks for, and the influences.
void decode_batch(const MeshFacts& m, Outputs out, bool positions_too, Decoded& d);

/// Linear blend skinning of any layout, in plain float code.
void skin_linear_portable(const MeshFacts& m, const glm::mat4* palette, Outputs out);

/// Dual quaternion skinning (skin_dual_quaternion.cpp): portable, an option, not the hot path.
void skin_dual_quaternion(const MeshFacts& m, std::span<const glm::mat4> palette, Outputs out);

#if OSSA_SKIN_X86

// ---------------------------------------------------------------------------------------------
// x86 fast paths for the cooker's quantized layout (skin_x86.cpp, skin_x86_batch.cpp).

// internal/cpu.h: target attributes on GCC / Clang, nothing on MSVC (which needs none).
#define OSSA_TARGET_AVX2 OSSA_TARGET("avx2,fma,bmi,bmi2,popcnt")
#define OSSA_TARGET_AVX512 OSSA_TARGET("avx2,fma,bmi,bmi2,popcnt,avx512f,avx512vl,avx512bw,avx512dq")
#if defined(_MSC_VER) && !defined(__clang__)
#define OSSA_POPCOUNT(x) static_cast<int>(__popcnt(x))
#else
#define OSSA_POPCOUNT(x) __builtin_popcount(x)
#endif

/// directly followed by the weights (the cooker's layout: one 8-byte load fetches both).
enum class Slots { Narrow, Wide, Packed };

struct FastMesh {
  const uint8_t* base;
  uint32_t count, stride;
  uint32_t off_position, off_normal, off_tangent, off_joints, off_weights;
  Slots slots;
  float prescale[3];  // direction_prescale
};

/// 256 vertices per batch: lists, classes and decoded directions stay in L1 (~13 KB), and the
/// five list loops' exit mispredictions are paid once per batch.
constexpr uint32_t kBatch = 256;

/// Classes: 0 = one influence of weight exactly 255 (the palette matrix itself: no blending);
/// c = 1..4: the last non-zero weight is influence c - 1, so influences 0..c-1 are blended (zero
/// weights below it blend as 0, harmlessly). All-zero weights are class 1: a zero matrix, as
/// OpenGL would blend them.
constexpr int kClasses = 5;

struct Batch {
  uint32_t first = 0, n = 0;
  uint32_t count[kClasses] = {};
  alignas(32) uint32_t lists[kClasses][kBatch + 16];
  alignas(32) float normal[kBatch][4];   // x, y, z, 0
  alignas(32) float tangent[kBatch][4];  // x, y, z, bitangent sign
};

/// Lists b's vertices by influence class: 8 at a time (AVX2) or 16 (AVX-512).
OSSA_TARGET_AVX2 void classify_avx2(const FastMesh& m, Batch& b);
OSSA_TARGET_AVX512 void classify_avx512(const FastMesh& m, Batch& b);

/// Normals (and tangents) of the batch into b.normal / b.tangent, times the prescale.
template <bool kTangents>
OSSA_TARGET_AVX2 void decode_directions(const FastMesh& m, Batch& b);

/// Normalizes n packed xyz vectors in place.
OSSA_TARGET_AVX2 void normalize_xyz(float* p, uint32_t n);
/// Normalizes the xyz of n packed xyzw vectors in place (w kept).
OSSA_TARGET_AVX2 void normalize_xyz_w(float* p, uint32_t n);

/// Skins m with the fast paths if its layout is the cooker's quantized one (8- or 16-bit slots)
/// and returns true; returns false, writing nothing, for any other layout.
bool skin_quantized(const MeshFacts& m, const float* palette, Outputs out, bool avx512);

#endif  // OSSA_SKIN_X86

}  // namespace ossa::skin_detail
