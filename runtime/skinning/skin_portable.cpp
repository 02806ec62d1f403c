// skin_portable.cpp — skin_cpu's portable linear blend path: any valid vertex layout, decoded a
// batch at a time as OpenGL fetches attributes, skinned in plain float code.
//
// Why it is shaped so: it serves float cooks, static meshes, unusual layouts, dual quaternions
// (decode_batch) and CPUs without AVX2, so it decodes as OpenGL does (unorm16 / 65535, snorm16
// max(v / 32767, -1), octahedral directions via ossa/format/vertex_codec.h, unorm8 weights / 255,
// integer joint slots, missing components (0, 0, 0, 1)). Each attribute of a batch of
// kPortableBatch vertices is decoded in one loop specialized for its format (the cooker's two
// layouts have their own loops; anything else goes through fetch_vertex_attribute,
// ossa/skinning/vertex_fetch.h), into plain float arrays; skinning then runs over those arrays
// with no format switch per vertex.
#include <algorithm>
#include <cstdint>
#include <cstring>

#include <ossa/format/vertex_codec.h>
#include <ossa/format/vertex_format.h>
#include <ossa/skinning/vertex_fetch.h>

#include "skinning/skin_internal.h"

namespace ossa::skin_detail {
namespace {

glm::vec3 octahedral(float x, float y) {
  const Float3 n = octahedral_decode({x, y});
  return {n.x, n.y, n.z};
}

void decode_positions(const MeshFacts& m, Decoded& d) {
  const uint8_t* p = m.base + static_cast<size_t>(d.first) * m.stride + m.position->offset();
  switch (m.position->format()) {
    case VertexFormat::Unorm16x4:
      for (uint32_t i = 0; i < d.n; ++i, p += m.stride) {
        uint16_t q[3];
        std::memcpy(q, p, 6);
        d.position[i] = glm::vec3(unorm16_to_float(q[0]), unorm16_to_float(q[1]), unorm16_to_float(q[2]));
      }
      break;
    case VertexFormat::Float32x3:
      for (uint32_t i = 0; i < d.n; ++i, p += m.stride) std::memcpy(&d.position[i][0], p, 12);
      break;
    default:
      for (uint32_t i = 0; i < d.n; ++i, p += m.stride)
        d.position[i] = glm::vec3(fetch_vertex_attribute(p, m.position->format()));
      break;
  }
}

/// A direction attribute: two components can only be the octahedral encoding, more are xyz.
void decode_normals(const MeshFacts& m, Decoded& d) {
  const uint8_t* p = m.base + static_cast<size_t>(d.first) * m.stride + m.normal->offset();
  const VertexFormat f = m.normal->format();
  if (f == VertexFormat::Snorm16x2) {
    for (uint32_t i = 0; i < d.n; ++i, p += m.stride) {
      int16_t e[2];
      std::memcpy(e, p, 4);
      d.normal[i] = octahedral(snorm16_to_float(e[0]), snorm16_to_float(e[1]));
    }
  } else if (f == VertexFormat::Float32x3) {
    for (uint32_t i = 0; i < d.n; ++i, p += m.stride) std::memcpy(&d.normal[i][0], p, 12);
  } else {
    const bool two = vertex_format_info(f).components == 2;
    for (uint32_t i = 0; i < d.n; ++i, p += m.stride) {
      const glm::vec4 v = fetch_vertex_attribute(p, f);
      d.normal[i] = two ? octahedral(v.x, v.y) : glm::vec3(v);
    }
  }
}

/// Tangent xyz and bitangent sign (+-1): Snorm16x4 is octahedral xy + sign z (the cooker's), two
/// components octahedral with sign +1, otherwise xyz + sign of w.
void decode_tangents(const MeshFacts& m, Decoded& d) {
  const uint8_t* p = m.base + static_cast<size_t>(d.first) * m.stride + m.tangent->offset();
  const VertexFormat f = m.tangent->format();
  const bool octa = f == VertexFormat::Snorm16x4 || vertex_format_info(f).components == 2;
  for (uint32_t i = 0; i < d.n; ++i, p += m.stride) {
    const glm::vec4 v = fetch_vertex_attribute(p, f);
    if (octa) d.tangent[i] = glm::vec4(octahedral(v.x, v.y), f == VertexFormat::Snorm16x4 && v.z < 0.0f ? -1.0f : 1.0f);
    else d.tangent[i] = glm::vec4(glm::vec3(v), v.w < 0.0f ? -1.0f : 1.0f);
  }
}

/// Joint slots and weights; a static mesh (no Joints) is slot 0 with weight 1.
void decode_influences(const MeshFacts& m, Decoded& d) {
  if (m.joints == nullptr) {
    for (uint32_t i = 0; i < d.n; ++i) {
      d.slot[i][0] = d.slot[i][1] = d.slot[i][2] = d.slot[i][3] = 0;
      d.weight[i] = glm::vec4(1.0f, 0.0f, 0.0f, 0.0f);
    }
    return;
  }
  const uint8_t* j = m.base + static_cast<size_t>(d.first) * m.stride + m.joints->offset();
  const uint8_t* w = m.base + static_cast<size_t>(d.first) * m.stride + m.weights->offset();
  const bool wide = m.joints->format() == VertexFormat::Uint16x4;
  for (uint32_t i = 0; i < d.n; ++i, j += m.stride) {
    if (wide) {
      uint16_t q[4];
      std::memcpy(q, j, 8);
      for (int k = 0; k < 4; ++k) d.slot[i][k] = q[k];
    } else {
      for (int k = 0; k < 4; ++k) d.slot[i][k] = j[k];
    }
  }
  const VertexFormat wf = m.weights->format();
  if (wf == VertexFormat::Unorm8x4) {
    for (uint32_t i = 0; i < d.n; ++i, w += m.stride)
      d.weight[i] = glm::vec4(kWeight[w[0]], kWeight[w[1]], kWeight[w[2]], kWeight[w[3]]);
  } else if (wf == VertexFormat::Float32x4) {
    for (uint32_t i = 0; i < d.n; ++i, w += m.stride) std::memcpy(&d.weight[i][0], w, 16);
  } else {
    for (uint32_t i = 0; i < d.n; ++i, w += m.stride) d.weight[i] = fetch_vertex_attribute(w, wf);
  }
}

}  // namespace

void decode_batch(const MeshFacts& m, Outputs out, bool positions_too, Decoded& d) {
  if (out.positions != nullptr || positions_too) decode_positions(m, d);
  if (out.normals != nullptr) decode_normals(m, d);
  if (out.tangents != nullptr) decode_tangents(m, d);
  decode_influences(m, d);
}

// ---------------------------------------------------------------------------------------------
// Portable linear blend skinning.

void skin_linear_portable(const MeshFacts& m, const glm::mat4* palette, Outputs out) {
  Decoded d;
  for (d.first = 0; d.first < m.count; d.first += kPortableBatch) {
    d.n = std::min(kPortableBatch, m.count - d.first);
    decode_batch(m, out, false, d);
    for (uint32_t i = 0; i < d.n; ++i) {
      const size_t v = d.first + i;
      // Columns 0-3 (xyz only) of the blended matrix. All four influences, zero weights too: a
      // branch per influence mispredicts more than the multiply-adds it would save.
      float a[16] = {};
      for (int k = 0; k < 4; ++k) {
        const float* p = &palette[d.slot[i][k]][0][0];
        const float w = d.weight[i][k];
        for (int e = 0; e < 16; ++e) a[e] += p[e] * w;  // 4-wide vector code at -O2
      }
      const glm::vec3 c0(a[0], a[1], a[2]), c1(a[4], a[5], a[6]), c2(a[8], a[9], a[10]), c3(a[12], a[13], a[14]);
      if (out.positions != nullptr) {
        const glm::vec3& q = d.position[i];
        const glm::vec3 p = c0 * q.x + c1 * q.y + c2 * q.z + c3;
        std::memcpy(out.positions + 3 * v, &p[0], 12);
      }
      if (out.normals != nullptr) {
        const glm::vec3 n = d.normal[i] * m.direction_prescale;
        const glm::vec3 r = finish_direction(c0 * n.x + c1 * n.y + c2 * n.z, out);
        std::memcpy(out.normals + 3 * v, &r[0], 12);
      }
      if (out.tangents != nullptr) {
        const glm::vec3 t = glm::vec3(d.tangent[i]) * m.direction_prescale;
        const glm::vec4 r(finish_direction(c0 * t.x + c1 * t.y + c2 * t.z, out), d.tangent[i].w);
        std::memcpy(out.tangents + 4 * v, &r[0], 16);
      }
    }
  }
}

}  // namespace ossa::skin_detail
