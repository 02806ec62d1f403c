// skin_palette.cpp — skinning palettes: skinning_matrices (model * inverse_bind * D per joint slot)
// and prepare_bind_matrices (the constant half, inverse_bind * D, computed once per mesh).
//
// Why it is shaped so: the de-quantizing affine D (translate(position_offset) *
// scale(position_scale)) is folded into the palette for positions, so a shader needs no special
// case (skinning.cpp says how directions undo it). The product runs in SSE (x86-64's baseline) or,
// on the prepared form, in AVX2 with two output columns per register; GLM's generic product runs
// scalar.
#include <algorithm>
#include <cassert>
#include <cstdint>
#include <cstring>
#include <span>

#include "internal/float_env.h"
#include "skinning/skin_internal.h"

namespace ossa {

using namespace skin_detail;

namespace {

/// Slot s's constant palette half: inverse_bind[s] * D, D = translate(offset) * scale(scale) applied
/// on the right (scale columns 0-2, move column 3). A mesh without slots gets D alone.
glm::mat4 bind_matrix(const MeshFacts& m, std::span<const fb::Mat4> inverse_bind, size_t s) {
  glm::mat4 a(1.0f);
  if (!inverse_bind.empty()) std::memcpy(&a[0][0], inverse_bind[s].m()->data(), sizeof a);
  if (m.dequantize) {
    a[3] = a[0] * m.offset.x + a[1] * m.offset.y + a[2] * m.offset.z + a[3];
    for (int c = 0; c < 3; ++c) a[c] = a[c] * m.scale[c];
  }
  return a;
}

/// out = a * b, column-major. Column c of the product is sum_k a.col(k) * b[c][k]: four broadcasts
/// and multiply-adds per column in SSE (x86-64's baseline); GLM's generic product runs scalar.
inline void palette_product(const glm::mat4& a, const glm::mat4& b, glm::mat4& out) {
#if OSSA_SKIN_X86
  const __m128 a0 = _mm_loadu_ps(&a[0][0]), a1 = _mm_loadu_ps(&a[1][0]), a2 = _mm_loadu_ps(&a[2][0]),
               a3 = _mm_loadu_ps(&a[3][0]);
  for (int c = 0; c < 4; ++c) {
    const __m128 lo = _mm_add_ps(_mm_mul_ps(a0, _mm_set1_ps(b[c][0])), _mm_mul_ps(a1, _mm_set1_ps(b[c][1])));
    const __m128 hi = _mm_add_ps(_mm_mul_ps(a2, _mm_set1_ps(b[c][2])), _mm_mul_ps(a3, _mm_set1_ps(b[c][3])));
    _mm_storeu_ps(&out[c][0], _mm_add_ps(lo, hi));
  }
#else
  out = a * b;
#endif
}

const glm::mat4 kIdentity(1.0f);

#if OSSA_SKIN_X86
/// palette[s] = model[joints[s]] * bind[s] for n slots, two output columns per 256-bit register:
/// model's columns duplicated into both lanes (broadcast loads), bind's columns c and c + 1
/// loaded as one register and each element k spread over its lane with an in-lane permute. Four
/// multiply-adds per column pair instead of SSE's broadcast, multiply and add per element:
/// about half the instructions (53 slots: ~120 ns on Zen 5, BM_SkinningMatricesPrepared; BM_Frame,
/// which builds this palette, ran ~7% faster with it, back to back).
OSSA_TARGET_AVX2 void palettes_avx2(const uint16_t* joints, const glm::mat4* bind, const glm::mat4* model,
                                    size_t model_count, glm::mat4* palette, size_t n) {
  for (size_t s = 0; s < n; ++s) {
    const float* a = joints[s] < model_count ? &model[joints[s]][0][0] : &kIdentity[0][0];
    const __m256 a0 = _mm256_broadcast_ps(reinterpret_cast<const __m128*>(a));
    const __m256 a1 = _mm256_broadcast_ps(reinterpret_cast<const __m128*>(a + 4));
    const __m256 a2 = _mm256_broadcast_ps(reinterpret_cast<const __m128*>(a + 8));
    const __m256 a3 = _mm256_broadcast_ps(reinterpret_cast<const __m128*>(a + 12));
    const float* b = &bind[s][0][0];
    float* out = &palette[s][0][0];
    for (int c = 0; c < 4; c += 2) {
      const __m256 bc = _mm256_loadu_ps(b + 4 * c);  // columns c, c + 1
      __m256 r = _mm256_mul_ps(a0, _mm256_permute_ps(bc, 0x00));
      r = _mm256_fmadd_ps(a1, _mm256_permute_ps(bc, 0x55), r);
      r = _mm256_fmadd_ps(a2, _mm256_permute_ps(bc, 0xaa), r);
      r = _mm256_fmadd_ps(a3, _mm256_permute_ps(bc, 0xff), r);
      _mm256_storeu_ps(out + 4 * c, r);
    }
  }
}
#endif

}  // namespace

void skinning_matrices(const MeshView& mesh, std::span<const glm::mat4> model, std::span<glm::mat4> palette) {
  const detail::FlushDenormals flush;  // internal/float_env.h
  const MeshFacts m = mesh_facts(mesh);
  const std::span<const uint16_t> joints = mesh.joints();
  const std::span<const fb::Mat4> inverse_bind = mesh.inverse_bind();
  if (joints.empty()) {
    assert(!palette.empty());
    if (!palette.empty()) palette[0] = bind_matrix(m, inverse_bind, 0);
    return;
  }
  assert(palette.size() >= joints.size());
  const size_t n = std::min(palette.size(), joints.size());
  for (size_t s = 0; s < n; ++s) {
    assert(joints[s] < model.size());
    palette_product(joints[s] < model.size() ? model[joints[s]] : kIdentity, bind_matrix(m, inverse_bind, s),
                    palette[s]);
  }
}

void prepare_bind_matrices(const MeshView& mesh, std::span<glm::mat4> bind) {
  const MeshFacts m = mesh_facts(mesh);
  const std::span<const fb::Mat4> inverse_bind = mesh.inverse_bind();
  const size_t slots = std::max<size_t>(1, inverse_bind.size());
  assert(bind.size() >= slots);
  for (size_t s = 0; s < std::min(bind.size(), slots); ++s) bind[s] = bind_matrix(m, inverse_bind, s);
}

void skinning_matrices(std::span<const uint16_t> joints, std::span<const glm::mat4> bind,
                       std::span<const glm::mat4> model, std::span<glm::mat4> palette) {
  const detail::FlushDenormals flush;  // internal/float_env.h
  if (joints.empty()) {
    if (!palette.empty() && !bind.empty()) palette[0] = bind[0];
    return;
  }
  const size_t n = std::min({joints.size(), bind.size(), palette.size()});
#if OSSA_SKIN_X86
  if (skinning_isa() != SkinningIsa::Portable) {
    palettes_avx2(joints.data(), bind.data(), model.data(), model.size(), palette.data(), n);
    return;
  }
#endif
  for (size_t s = 0; s < n; ++s)
    palette_product(joints[s] < model.size() ? model[joints[s]] : kIdentity, bind[s], palette[s]);
}

}  // namespace ossa
