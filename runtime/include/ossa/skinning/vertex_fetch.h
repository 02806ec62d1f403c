// vertex_fetch.h — one vertex attribute decoded as OpenGL fetches it, for CPU readers of a
// cooked vertex buffer (skin_cpu's portable path, the viewer's morph-target CPU path).
//
// Any fb::VertexFormat: normalized formats scaled as OpenGL normalizes them (unorm16 / 65535,
// snorm16 max(v / 32767, -1), unorm8 / 255; ossa/format/vertex_codec.h), half floats exact, integer
// formats (joint slots) as their values, missing components (0, 0, 0, 1). It returns the stored
// components only: two-component directions stay octahedral, and what they mean (octahedral,
// tangent sign) is the caller's. Cost: one switch on the format and at most a 16-byte load, no
// allocation; inline, since skin_cpu calls it per vertex. Callers decoding many vertices of one
// known format do better with a loop specialized for it (skin_cpu does, for the cooker's layout).
#pragma once
#include <cstddef>
#include <cstdint>
#include <cstring>

#include <glm/glm.hpp>

#include <ossa/format/ossa_generated.h>
#include <ossa/format/vertex_codec.h>

namespace ossa {

/// The attribute at p (of the given format) as a vertex shader sees it; see the file comment.
inline glm::vec4 fetch_vertex_attribute(const uint8_t* p, fb::VertexFormat format) {
  using F = fb::VertexFormat;
  glm::vec4 r(0.0f, 0.0f, 0.0f, 1.0f);
  switch (format) {
    case F::Float32x2: std::memcpy(&r[0], p, 8); break;
    case F::Float32x3: std::memcpy(&r[0], p, 12); break;
    case F::Float32x4: std::memcpy(&r[0], p, 16); break;
    case F::Unorm16x4: {
      uint16_t q[4];
      std::memcpy(q, p, 8);
      for (int i = 0; i < 4; ++i) r[i] = unorm16_to_float(q[i]);
      break;
    }
    case F::Snorm16x2:
    case F::Snorm16x4: {
      const int n = format == F::Snorm16x2 ? 2 : 4;
      int16_t q[4];
      std::memcpy(q, p, 2 * static_cast<size_t>(n));
      for (int i = 0; i < n; ++i) r[i] = snorm16_to_float(q[i]);
      break;
    }
    case F::Float16x2: {
      uint16_t h[2];
      std::memcpy(h, p, 4);
      r[0] = half_to_float(h[0]);
      r[1] = half_to_float(h[1]);
      break;
    }
    case F::Uint8x4:
      for (int i = 0; i < 4; ++i) r[i] = p[i];
      break;
    case F::Uint16x4: {
      uint16_t q[4];
      std::memcpy(q, p, 8);
      for (int i = 0; i < 4; ++i) r[i] = q[i];
      break;
    }
    case F::Unorm8x4:
      for (int i = 0; i < 4; ++i) r[i] = unorm8_to_float(p[i]);
      break;
  }
  return r;
}

}  // namespace ossa
