// gltf_evaluate.cpp — glTF samplers evaluated the way the glTF 2.0 specification defines them
// (STEP, LINEAR, CUBICSPLINE), whether a curve is a straight line in disguise, and the names Assimp
// gives glTF nodes; see gltf_samplers.h.
#include "cooker/import/gltf_samplers.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace ossa::cook::gltf {

std::string assimp_node_name(const Animations& file, int index) {
  if (index >= 0 && static_cast<size_t>(index) < file.nodes.size() &&
      !file.nodes[static_cast<size_t>(index)].name.empty()) {
    return file.nodes[static_cast<size_t>(index)].name;
  }
  return "nodes[" + std::to_string(index) + "]";
}

void evaluate(const Sampler& s, double time, double snap, double* out) {
  const size_t w = static_cast<size_t>(s.width);
  const size_t n = s.times.size();
  const size_t per_key = s.interpolation == Interpolation::CubicSpline ? 3 : 1;
  // The value element of key k (the middle of the triple for CUBICSPLINE).
  auto value = [&](size_t k, size_t c) -> double { return s.values[(k * per_key + (per_key == 3 ? 1 : 0)) * w + c]; };
  // Keys reached: times[k] <= time + snap.
  const size_t reached =
      static_cast<size_t>(std::upper_bound(s.times.begin(), s.times.end(), time + snap,
                                           [](double t, float key) { return t < static_cast<double>(key); }) -
                          s.times.begin());
  if (reached == 0 || reached == n || s.interpolation == Interpolation::Step) {
    const size_t k = reached == 0 ? 0 : reached - 1;
    for (size_t c = 0; c < w; ++c) out[c] = value(k, c);
  } else {
    const size_t k = reached - 1;
    const double t0 = s.times[k], t1 = s.times[k + 1];
    const double delta = t1 - t0;
    const double u = std::clamp((time - t0) / delta, 0.0, 1.0);
    if (s.interpolation == Interpolation::CubicSpline) {
      // glTF 2.0, Appendix C: p(u) = (2u³-3u²+1)v_k + (u³-2u²+u)Δ·b_k + (-2u³+3u²)v_k+1 +
      // (u³-u²)Δ·a_k+1, b_k the out-tangent of key k, a_k+1 the in-tangent of key k+1.
      const double u2 = u * u, u3 = u2 * u;
      const double h00 = 2 * u3 - 3 * u2 + 1, h10 = u3 - 2 * u2 + u, h01 = -2 * u3 + 3 * u2, h11 = u3 - u2;
      for (size_t c = 0; c < w; ++c) {
        const double b = s.values[(k * 3 + 2) * w + c];
        const double a = s.values[((k + 1) * 3 + 0) * w + c];
        out[c] = h00 * value(k, c) + h10 * delta * b + h01 * value(k + 1, c) + h11 * delta * a;
      }
    } else if (w == 4 && !s.weights) {
      // LINEAR rotation: slerp on the shorter arc.
      double dot = 0.0;
      for (size_t c = 0; c < 4; ++c) dot += value(k, c) * value(k + 1, c);
      const double sign = dot < 0.0 ? -1.0 : 1.0;
      dot = std::abs(dot);
      double wa = 1.0 - u, wb = u;
      if (dot < 1.0 - 1e-9) {
        const double angle = std::acos(std::min(dot, 1.0));
        wa = std::sin((1.0 - u) * angle) / std::sin(angle);
        wb = std::sin(u * angle) / std::sin(angle);
      }
      for (size_t c = 0; c < 4; ++c) out[c] = wa * value(k, c) + sign * wb * value(k + 1, c);
    } else {
      for (size_t c = 0; c < w; ++c) out[c] = (1.0 - u) * value(k, c) + u * value(k + 1, c);
    }
  }
  if (w == 4 && !s.weights) {
    const double len = std::sqrt(out[0] * out[0] + out[1] * out[1] + out[2] * out[2] + out[3] * out[3]);
    if (len > 1e-12 && std::isfinite(len)) {
      for (size_t c = 0; c < 4; ++c) out[c] /= len;
    }
  }
}

bool is_linear_equivalent(const Sampler& s, double tolerance) {
  if (s.interpolation == Interpolation::Linear) return true;
  const size_t w = static_cast<size_t>(s.width);
  const size_t n = s.times.size();
  const size_t per_key = s.interpolation == Interpolation::CubicSpline ? 3 : 1;
  auto element = [&](size_t k, size_t part, size_t c) {
    return static_cast<double>(s.values[(k * per_key + part) * w + c]);
  };
  const size_t mid = per_key == 3 ? 1 : 0;
  auto near = [&](double a, double b) {
    return std::abs(a - b) <= tolerance * std::max({1.0, std::abs(a), std::abs(b)});
  };
  // Rotations: the straight line between two different quaternions is an nlerp, not the slerp
  // Assimp's keys give, so only a constant rotation counts (q and -q being the same rotation).
  if (w == 4) {
    for (size_t k = 1; k < n; ++k) {
      bool same = true, opposite = true;
      for (size_t c = 0; c < 4; ++c) {
        same = same && near(element(k, mid, c), element(k - 1, mid, c));
        opposite = opposite && near(element(k, mid, c), -element(k - 1, mid, c));
      }
      if (!same && !opposite) return false;
    }
    if (per_key == 3) {
      for (size_t k = 0; k < n; ++k) {
        for (size_t c = 0; c < 4; ++c) {
          if (!near(element(k, 0, c), 0.0) || !near(element(k, 2, c), 0.0)) return false;
        }
      }
    }
    return true;
  }
  for (size_t k = 0; k + 1 < n; ++k) {
    const double delta = static_cast<double>(s.times[k + 1]) - static_cast<double>(s.times[k]);
    for (size_t c = 0; c < w; ++c) {
      const double chord = element(k + 1, mid, c) - element(k, mid, c);
      if (per_key == 1) {
        if (!near(chord, 0.0)) return false;
      } else {
        // Out-tangent of k and in-tangent of k+1, scaled to the segment, equal to the chord.
        if (!near(element(k, 2, c) * delta, chord) || !near(element(k + 1, 0, c) * delta, chord)) {
          return false;
        }
      }
    }
  }
  return true;
}

}  // namespace ossa::cook::gltf
