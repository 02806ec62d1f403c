// morph_build.cpp — quantize and sparsify morph targets (morph_build.h).
#include "cooker/mesh/morph_build.h"

#include <algorithm>
#include <cmath>

namespace ossa::cook {
namespace {

constexpr float kSteps = 32767.0f;

/// Angle between two directions, 0 when either is (near) zero.
float angle_between(const glm::vec3& a, const glm::vec3& b) {
  const float la = glm::length(a), lb = glm::length(b);
  if (!(la > 1e-12f) || !(lb > 1e-12f)) return 0.0f;
  const float c = std::clamp(glm::dot(a, b) / (la * lb), -1.0f, 1.0f);
  // acos loses precision near 1: use atan2 of |a x b| and a . b instead.
  return std::atan2(glm::length(glm::cross(a, b)) / (la * lb), c);
}

glm::vec3 step_for(const std::vector<glm::vec3>& deltas, const std::vector<uint8_t>& listed) {
  glm::vec3 largest(0.0f);
  for (size_t v = 0; v < deltas.size(); ++v)
    if (listed[v]) largest = glm::max(largest, glm::abs(deltas[v]));
  return largest / kSteps;
}

std::array<int16_t, 3> quantize(const glm::vec3& d, const glm::vec3& step) {
  std::array<int16_t, 3> q{};
  for (int a = 0; a < 3; ++a) {
    const float x = step[a] > 0.0f ? std::round(d[a] / step[a]) : 0.0f;
    q[static_cast<size_t>(a)] = static_cast<int16_t>(std::clamp(x, -kSteps, kSteps));
  }
  return q;
}

glm::vec3 dequantize(const std::array<int16_t, 3>& q, const glm::vec3& step) {
  return glm::vec3(q[0], q[1], q[2]) * step;
}

template <class T>
void compact(std::vector<T>& v, const std::vector<unsigned>& remap, size_t unique) {
  if (v.empty()) return;
  std::vector<T> out(unique);
  for (size_t i = 0; i < v.size(); ++i)
    if (remap[i] != ~0u) out[remap[i]] = v[i];
  v = std::move(out);
}

}  // namespace

DenseMorph quantize_morph(const MorphStreams& target, const std::vector<glm::vec3>& base_normals,
                          const std::vector<glm::vec3>& base_tangents, const MorphBounds& bounds) {
  const size_t n = target.positions.size();
  const bool normals = !target.normals.empty() && base_normals.size() == n;
  const bool tangents = !target.tangents.empty() && base_tangents.size() == n;
  DenseMorph out;
  out.name = target.name;
  out.default_weight = target.default_weight;
  out.listed.assign(n, 0);
  for (size_t v = 0; v < n; ++v) {
    bool moves = glm::length(target.positions[v]) > bounds.position;
    if (normals) moves = moves || angle_between(base_normals[v], base_normals[v] + target.normals[v]) > bounds.angle;
    if (tangents)
      moves = moves || angle_between(base_tangents[v], base_tangents[v] + target.tangents[v]) > bounds.angle;
    out.listed[v] = moves ? 1 : 0;
  }
  out.position_step = step_for(target.positions, out.listed);
  if (normals) out.normal_step = step_for(target.normals, out.listed);
  if (tangents) out.tangent_step = step_for(target.tangents, out.listed);
  out.positions.assign(n, {0, 0, 0});
  if (normals) out.normals.assign(n, {0, 0, 0});
  if (tangents) out.tangents.assign(n, {0, 0, 0});
  for (size_t v = 0; v < n; ++v) {
    if (out.listed[v]) {
      out.positions[v] = quantize(target.positions[v], out.position_step);
      if (normals) out.normals[v] = quantize(target.normals[v], out.normal_step);
      if (tangents) out.tangents[v] = quantize(target.tangents[v], out.tangent_step);
    }
    const glm::vec3 p = out.listed[v] ? dequantize(out.positions[v], out.position_step) : glm::vec3(0.0f);
    out.position_error = std::max(out.position_error, glm::length(target.positions[v] - p));
    if (normals) {
      const glm::vec3 d = out.listed[v] ? dequantize(out.normals[v], out.normal_step) : glm::vec3(0.0f);
      out.normal_error =
          std::max(out.normal_error, angle_between(base_normals[v] + target.normals[v], base_normals[v] + d));
    }
  }
  return out;
}

void remap_morph(DenseMorph& target, const std::vector<unsigned>& remap, size_t unique) {
  compact(target.positions, remap, unique);
  compact(target.normals, remap, unique);
  compact(target.tangents, remap, unique);
  compact(target.listed, remap, unique);
}

CookedMorphTarget sparsify(const DenseMorph& target) {
  CookedMorphTarget out;
  out.name = target.name;
  out.default_weight = target.default_weight;
  out.position_step = target.position_step;
  out.normal_step = target.normal_step;
  out.tangent_step = target.tangent_step;
  out.position_error = target.position_error;
  out.normal_error = target.normal_error;
  out.position_bound = target.position_bound;
  const size_t n = target.positions.size();
  const size_t streams = 1 + (target.normals.empty() ? 0 : 1) + (target.tangents.empty() ? 0 : 1);
  out.source_bytes = static_cast<uint32_t>(std::min<size_t>(n * 12 * streams, UINT32_MAX));
  for (size_t v = 0; v < n; ++v) {
    if (!target.listed[v]) continue;
    out.vertices.push_back(static_cast<uint32_t>(v));
    out.position_deltas.insert(out.position_deltas.end(), target.positions[v].begin(), target.positions[v].end());
    if (!target.normals.empty())
      out.normal_deltas.insert(out.normal_deltas.end(), target.normals[v].begin(), target.normals[v].end());
    if (!target.tangents.empty())
      out.tangent_deltas.insert(out.tangent_deltas.end(), target.tangents[v].begin(), target.tangents[v].end());
  }
  return out;
}

}  // namespace ossa::cook
