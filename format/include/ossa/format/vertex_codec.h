// vertex_codec.h — the encodings of the quantized vertex layout, one definition for both sides.
//
// The cooker encodes with these; the runtime's CPU skinning and the tests decode with the same
// functions, and the shaders implement the same decode in GLSL. Keeping encode and decode together
// is what keeps "what the cooker wrote" and "what the runtime reads" from drifting apart.
//
// Octahedral normals: a unit vector folded onto the octahedron and unfolded to a square, stored as
// two snorm16 (error ~0.003 degrees). Half floats: IEEE 754 binary16 with round-to-nearest-even.
#pragma once
#include <cmath>
#include <cstdint>

namespace ossa {

struct Float2 {
  float x, y;
};
struct Float3 {
  float x, y, z;
};

/// Snorm16 as OpenGL normalizes it: max(v / 32767, -1).
inline float snorm16_to_float(int16_t v) {
  const float f = static_cast<float>(v) / 32767.0f;
  return f < -1.0f ? -1.0f : f;
}
inline int16_t float_to_snorm16(float f) {
  f = f < -1.0f ? -1.0f : (f > 1.0f ? 1.0f : f);
  return static_cast<int16_t>(std::lround(f * 32767.0f));
}
inline float unorm16_to_float(uint16_t v) { return static_cast<float>(v) / 65535.0f; }
inline uint16_t float_to_unorm16(float f) {
  f = f < 0.0f ? 0.0f : (f > 1.0f ? 1.0f : f);
  return static_cast<uint16_t>(std::lround(f * 65535.0f));
}
/// Unorm8 as OpenGL normalizes it (v / 255): vertex colours. NaN encodes as 0.
inline float unorm8_to_float(uint8_t v) { return static_cast<float>(v) / 255.0f; }
inline uint8_t float_to_unorm8(float f) {
  f = f > 0.0f ? (f > 1.0f ? 1.0f : f) : 0.0f;
  return static_cast<uint8_t>(std::lround(f * 255.0f));
}

/// Unit vector -> octahedral square in [-1, 1]^2. n need not be exactly unit; zero maps to +z.
inline Float2 octahedral_encode(Float3 n) {
  const float l1 = std::fabs(n.x) + std::fabs(n.y) + std::fabs(n.z);
  if (l1 == 0.0f) return {0.0f, 0.0f};
  float x = n.x / l1, y = n.y / l1;
  if (n.z < 0.0f) {
    const float ox = (1.0f - std::fabs(y)) * (x >= 0.0f ? 1.0f : -1.0f);
    const float oy = (1.0f - std::fabs(x)) * (y >= 0.0f ? 1.0f : -1.0f);
    x = ox;
    y = oy;
  }
  return {x, y};
}

/// Octahedral square -> unit vector (normalized).
inline Float3 octahedral_decode(Float2 e) {
  Float3 n{e.x, e.y, 1.0f - std::fabs(e.x) - std::fabs(e.y)};
  const float t = n.z < 0.0f ? -n.z : 0.0f;
  n.x += n.x >= 0.0f ? -t : t;
  n.y += n.y >= 0.0f ? -t : t;
  const float len = std::sqrt(n.x * n.x + n.y * n.y + n.z * n.z);
  return {n.x / len, n.y / len, n.z / len};
}

/// float -> IEEE binary16 bits, round to nearest even; overflow to infinity, NaN kept.
uint16_t float_to_half(float f);
/// IEEE binary16 bits -> float (exact).
float half_to_float(uint16_t h);

/// The influence class of a vertex's four unorm8 weights read as one little-endian word (influence
/// 0's weight in the low byte): 0 for a single weight of 255 (the palette matrix as it is), else 1
/// + the index of the last non-zero weight (all zero: 1). The cooker orders a skinned mesh's
/// vertices by it and skin_cpu runs one loop per class, so both must agree on it exactly.
constexpr int influence_class(uint32_t weights) {
  if (weights == 255u) return 0;
  return 1 + (weights >= (1u << 8)) + (weights >= (1u << 16)) + (weights >= (1u << 24));
}

}  // namespace ossa
