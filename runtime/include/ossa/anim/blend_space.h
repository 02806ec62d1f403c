// blend_space.h — parameter(s) -> clip weights, the way Unreal's blend spaces (studied in the seed
// thesis) map speed / direction to a blend of locomotion clips.
//
// 1D: samples on a line, weights from the two neighbours of the parameter. 2D: samples in the
// plane, triangulated once (Delaunay), weights barycentric in the containing triangle, and from
// the nearest point of the nearest hull edge outside. Blended clips should play synchronized: each
// at rate clip_duration / synchronized_duration so feet stay in phase.
#pragma once
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include <ossa/format/result.h>

namespace ossa {

/// Weights for a 1D blend space. positions: the samples' parameter values, strictly increasing.
/// out has positions.size() entries, sum 1; at most two non-zero; clamped at the ends.
/// O(samples).
void blend_space_1d_weights(std::span<const float> positions, float parameter, std::span<float> out);

struct BlendSpace2D {
  std::vector<glm::vec2> points;
  std::vector<std::array<uint16_t, 3>> triangles;  // counter-clockwise
  /// 1 / the points' extent per axis. Axes carry different units (m/s, degrees), so the
  /// triangulation and the "nearest" of the outside projection measure in these normalized units.
  glm::vec2 axis_scale{1.0f};
};

/// Triangulates sample points (>= 3, not all collinear, no duplicates). Error otherwise.
Result<BlendSpace2D> make_blend_space_2d(std::span<const glm::vec2> points);

/// Weights for a 2D blend space: out has points.size() entries, sum 1, each sample's weight is 1
/// exactly at its point. Allocation-free. O(triangles).
void blend_space_2d_weights(const BlendSpace2D& space, glm::vec2 parameter, std::span<float> out);

/// Weighted mean duration of the blended clips: the common cycle they are scaled to.
float synchronized_duration(std::span<const float> durations, std::span<const float> weights);

}  // namespace ossa
