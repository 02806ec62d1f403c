// skin_dual_quaternion.cpp — skin_cpu's dual quaternion skinning (SkinningMethod::DualQuaternion):
// portable, an option, not the hot path.
//
// Why it is shaped so: dual quaternion skinning needs rigid transforms. Each palette matrix is
// split back into M = palette * D^-1, and M into translation, rotation R and a 3x3 stretch
// S = R^T * M3x3 (R from a Gram-Schmidt orthonormalization of M's columns, so S is identity for
// rigid M and carries scale and mirroring otherwise). A vertex is D-applied, stretched by the
// weight-blended S (linear, like Kavan et al.'s scale handling), then moved by the blended,
// normalized dual quaternion. Dual quaternions are aligned to the first influence's hemisphere
// (shortest arc). For one influence, or identical rigid matrices, this equals linear blending up
// to rounding. Vertices are decoded by the portable path's decode_batch (skin_portable.cpp).
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>

#include <glm/gtc/quaternion.hpp>

#include "skinning/skin_internal.h"

namespace ossa::skin_detail {
namespace {

struct SlotDq {
  glm::quat real{1.0f, 0.0f, 0.0f, 0.0f};
  glm::quat dual{0.0f, 0.0f, 0.0f, 0.0f};
  glm::mat3 stretch{1.0f};
};

/// palette = M * D  ->  M = T(t) * R * S, as a unit dual quaternion (R, t) and the stretch S.
SlotDq make_slot_dq(const glm::mat4& palette, const MeshFacts& m) {
  glm::vec3 c[3];
  for (int a = 0; a < 3; ++a) c[a] = glm::vec3(palette[a]) * m.direction_prescale[a];
  const glm::vec3 t = glm::vec3(palette[3]) - (c[0] * m.offset.x + c[1] * m.offset.y + c[2] * m.offset.z);
  const glm::mat3 m3(c[0], c[1], c[2]);
  // Gram-Schmidt: a proper rotation whatever M holds (a mirror ends up in S's determinant).
  glm::vec3 r0 = normalize_or_zero(c[0]);
  if (r0 == glm::vec3(0.0f)) r0 = glm::vec3(1.0f, 0.0f, 0.0f);
  glm::vec3 r1 = normalize_or_zero(c[1] - glm::dot(c[1], r0) * r0);
  if (r1 == glm::vec3(0.0f)) {
    const glm::vec3 helper = std::fabs(r0.x) < 0.9f ? glm::vec3(1.0f, 0.0f, 0.0f) : glm::vec3(0.0f, 1.0f, 0.0f);
    r1 = glm::normalize(glm::cross(helper, r0));
  }
  const glm::mat3 r(r0, r1, glm::cross(r0, r1));
  SlotDq d;
  d.real = glm::normalize(glm::quat_cast(r));
  d.stretch = glm::transpose(glm::mat3_cast(d.real)) * m3;
  d.dual = glm::quat(0.0f, t.x, t.y, t.z) * d.real * 0.5f;
  return d;
}

}  // namespace

void skin_dual_quaternion(const MeshFacts& m, std::span<const glm::mat4> palette, Outputs out) {
  // Per-slot conversions on the stack for meshes with up to 256 slots (every 8-bit-slot mesh);
  // larger palettes convert per influence.
  constexpr size_t kCached = 256;
  SlotDq cache[kCached];
  const size_t slots = m.joints != nullptr ? std::min(palette.size(), m.slot_count) : 1;
  const bool cached = slots <= kCached;
  if (cached)
    for (size_t s = 0; s < slots; ++s) cache[s] = make_slot_dq(palette[s], m);

  Decoded d;
  for (d.first = 0; d.first < m.count; d.first += kPortableBatch) {
    d.n = std::min(kPortableBatch, m.count - d.first);
    decode_batch(m, out, false, d);
    for (uint32_t i = 0; i < d.n; ++i) {
      const size_t v = d.first + i;
      glm::quat real(0.0f, 0.0f, 0.0f, 0.0f), dual(0.0f, 0.0f, 0.0f, 0.0f);
      glm::mat3 stretch(0.0f);
      bool have_first = false;
      glm::quat first(1.0f, 0.0f, 0.0f, 0.0f);
      for (int k = 0; k < 4; ++k) {
        const float w = d.weight[i][k];
        if (w == 0.0f) continue;
        const SlotDq s = cached ? cache[d.slot[i][k]] : make_slot_dq(palette[d.slot[i][k]], m);
        if (!have_first) {
          first = s.real;
          have_first = true;
        }
        const float signed_w = glm::dot(s.real, first) < 0.0f ? -w : w;  // shortest arc
        real = real + s.real * signed_w;
        dual = dual + s.dual * signed_w;
        stretch += s.stretch * w;
      }
      const float len = glm::length(real);
      if (len > 1e-20f) {
        real = real * (1.0f / len);
        dual = dual * (1.0f / len);
      } else {
        real = glm::quat(1.0f, 0.0f, 0.0f, 0.0f);
        dual = glm::quat(0.0f, 0.0f, 0.0f, 0.0f);
      }
      const glm::vec3 rv(real.x, real.y, real.z), dv(dual.x, dual.y, dual.z);
      if (out.positions != nullptr) {
        const glm::vec3 p = m.dequantize ? m.offset + m.scale * d.position[i] : d.position[i];
        const glm::vec3 moved = real * (stretch * p) + 2.0f * (real.w * dv - dual.w * rv + glm::cross(rv, dv));
        std::memcpy(out.positions + 3 * v, &moved[0], 12);
      }
      if (out.normals != nullptr) {
        const glm::vec3 n = finish_direction(real * (stretch * d.normal[i]), out);
        std::memcpy(out.normals + 3 * v, &n[0], 12);
      }
      if (out.tangents != nullptr) {
        const glm::vec4 r(finish_direction(real * (stretch * glm::vec3(d.tangent[i])), out), d.tangent[i].w);
        std::memcpy(out.tangents + 4 * v, &r[0], 16);
      }
    }
  }
}

}  // namespace ossa::skin_detail
