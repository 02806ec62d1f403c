// morph_build.h — a merged mesh's morph targets: dense float deltas -> quantized, sparse targets.
//
// mesh_build.cpp carries every target as dense per-vertex streams through welding, merging and
// reordering (so a target can never lose its vertices), and hands them here once the vertex order
// is final. Here each target is quantized against the cook's bounds and made sparse:
//   - a vertex is listed when its position delta exceeds the position bound, or its normal (or
//     tangent) turns by more than the angle bound; every other vertex's delta is dropped, and its
//     whole delta counts as error;
//   - listed deltas are int16 steps of a per-target, per-axis step (max |delta| / 32767), so the
//     quantization error is at most half a step per axis.
// The achieved errors (over all vertices, listed or not) are returned for the file and the report.
// Dense quantized deltas stay available until sparsify(), because mesh_build's last weld (vertices
// whose quantized bytes are equal) must compare them too: two vertices merge only when every
// target moves them alike.
#pragma once
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include <glm/glm.hpp>

namespace ossa::cook {

/// One target's dense float deltas over a merged mesh's vertices.
struct MorphStreams {
  std::string name;
  float default_weight = 0.0f;
  std::vector<glm::vec3> positions;  // one per vertex
  std::vector<glm::vec3> normals;    // empty or one per vertex
  std::vector<glm::vec3> tangents;   // empty or one per vertex
};

struct MorphBounds {
  float position = 2e-5f;   // largest position error, mesh units
  float angle = 0.001745f;  // largest normal / tangent turn error, radians (0.1 degree)
};

/// A target quantized but still dense (one entry per vertex; unlisted entries hold zeros).
struct DenseMorph {
  std::string name;
  float default_weight = 0.0f;
  glm::vec3 position_step{0.0f}, normal_step{0.0f}, tangent_step{0.0f};
  std::vector<std::array<int16_t, 3>> positions, normals, tangents;  // normals / tangents may be empty
  std::vector<uint8_t> listed;                                       // 1 when the vertex is stored
  float position_error = 0.0f;                                       // mesh units
  float normal_error = 0.0f;                                         // radians
  float position_bound = 0.0f;  // mesh units: what position_error is held to (mesh_group.cpp)
};

/// The target as stored: listed vertices ascending, three int16 per listed vertex per stream.
struct CookedMorphTarget {
  std::string name;
  float default_weight = 0.0f;
  std::vector<uint32_t> vertices;
  std::vector<int16_t> position_deltas, normal_deltas, tangent_deltas;
  glm::vec3 position_step{0.0f}, normal_step{0.0f}, tangent_step{0.0f};
  float position_error = 0.0f, normal_error = 0.0f;
  float position_bound = 0.0f;  // mesh units
  uint32_t source_bytes = 0;    // the dense float deltas it came from (12 bytes per vertex per stream)
};

/// Quantizes one target against `bounds`. base_normals / base_tangents are the vertices' own
/// directions (for the angle tests; tangents may be empty). O(vertices).
DenseMorph quantize_morph(const MorphStreams& target, const std::vector<glm::vec3>& base_normals,
                          const std::vector<glm::vec3>& base_tangents, const MorphBounds& bounds);

/// Reorders / merges a dense target's vertices as meshoptimizer's remap says (remap[v] = new
/// index, ~0u dropped; `unique` new vertices). O(vertices).
void remap_morph(DenseMorph& target, const std::vector<unsigned>& remap, size_t unique);

/// The stored form: only listed vertices. O(vertices).
CookedMorphTarget sparsify(const DenseMorph& target);

}  // namespace ossa::cook
