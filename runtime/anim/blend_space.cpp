// blend_space.cpp — blend-space weights (ossa/anim/blend_space.h).
//
// 1D is a search for the two neighbours of the parameter. 2D is split in two: make_blend_space_2d
// triangulates the samples once (allocating; load/authoring time), and blend_space_2d_weights
// evaluates per frame (no allocation) by one pass over the triangles.
//
// Triangulation: the samples are lexicographically sorted and inserted one at a time, each new
// point (always outside the current hull, being the largest so far) joined to the hull edges it
// sees; Lawson edge flips then make the result Delaunay. This gives what Bowyer-Watson gives but
// needs no enclosing "super triangle": that triangle's far-away vertices are what makes
// Bowyer-Watson drop hull triangles next to nearly collinear hull points and lose precision, and
// blend spaces are full of collinear hull points (grids of speed x direction). Written here rather
// than taken from a library because Debian's geometry libraries (CGAL) are far too heavy for the
// handful of points a blend space has. Points are triangulated in per-axis normalized coordinates
// (BlendSpace2D::axis_scale) so an axis in degrees does not dwarf one in m/s.
//
// Evaluation: for each triangle, barycentric weights of the parameter; when all are >= 0 the
// parameter is inside and those are the weights. Otherwise the nearest point of the triangle's
// edges is a candidate; the nearest candidate over all triangles is the nearest point of the hull
// (the triangles' union is the convex hull), and its weights are the linear ones along that edge.
// Projection onto a convex set is continuous, so the weights are continuous outside and along the
// hull. Barycentrics are normalized by their own sum, which makes them exactly 1 / 0 when the
// parameter equals a sample (the other two sub-areas are exactly zero there).
//
// Cost: 1D O(samples); 2D evaluation O(triangles) with no allocation; triangulation
// O(n log n + flips * triangles^2) — the flips find neighbours by scanning, which is nothing for
// the tens of samples a blend space has.
#include <ossa/anim/blend_space.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <numeric>
#include <string>

namespace ossa {

// ---------------------------------------------------------------------------------------------
// 1D

void blend_space_1d_weights(std::span<const float> positions, float parameter, std::span<float> out) {
  std::fill(out.begin(), out.end(), 0.0f);
  const size_t n = std::min(positions.size(), out.size());
  if (n == 0) return;
  // `!(x > first)` also catches NaN: a bad parameter still yields weights that sum to 1.
  if (!(parameter > positions[0])) {
    out[0] = 1.0f;
    return;
  }
  if (parameter >= positions[n - 1]) {
    out[n - 1] = 1.0f;
    return;
  }
  // First sample above the parameter; positions[hi - 1] <= parameter < positions[hi].
  const size_t hi = static_cast<size_t>(
      std::upper_bound(positions.begin(), positions.begin() + static_cast<ptrdiff_t>(n), parameter) -
      positions.begin());
  const size_t lo = hi - 1;
  const float t = (parameter - positions[lo]) / (positions[hi] - positions[lo]);
  out[lo] = 1.0f - t;
  out[hi] = t;
}

float synchronized_duration(std::span<const float> durations, std::span<const float> weights) {
  const size_t n = std::min(durations.size(), weights.size());
  double sum = 0.0, weighted = 0.0;
  for (size_t i = 0; i < n; ++i) {
    sum += weights[i];
    weighted += static_cast<double>(weights[i]) * durations[i];
  }
  // Dividing by the weights' own sum keeps the result a mean even when they do not add up to 1.
  return sum > 0.0 ? static_cast<float>(weighted / sum) : 0.0f;
}

// ---------------------------------------------------------------------------------------------
// 2D: triangulation

namespace {

using Vec = glm::dvec2;
using Triangle = std::array<uint16_t, 3>;

double cross(Vec a, Vec b) { return a.x * b.y - a.y * b.x; }
/// > 0 when a, b, c turn counter-clockwise.
double orient(Vec a, Vec b, Vec c) { return cross(b - a, c - a); }
/// > 0 when d is strictly inside the circumcircle of the counter-clockwise triangle a, b, c.
double in_circle(Vec a, Vec b, Vec c, Vec d) {
  const Vec ad = a - d, bd = b - d, cd = c - d;
  return glm::dot(ad, ad) * cross(bd, cd) + glm::dot(bd, bd) * cross(cd, ad) + glm::dot(cd, cd) * cross(ad, bd);
}

// Tolerances in normalized coordinates (every point inside the unit square).
constexpr double kSamePoint = 1e-6;  // closer than this on both axes: a duplicate
constexpr double kCollinear = 1e-9;  // |orient| below this: collinear (twice the triangle area)
constexpr double kFlip = 1e-12;      // in_circle above this: not Delaunay, flip

Error error(const std::string& what) { return Error{"blend space: " + what}; }

/// Lawson flips until every interior edge is locally Delaunay (bounded, so round-off on
/// co-circular points, e.g. a grid, can never loop forever).
void make_delaunay(const std::vector<Vec>& q, std::vector<Triangle>& tris) {
  const size_t max_flips = 16 * tris.size() * tris.size() + 64;
  size_t flips = 0;
  bool changed = true;
  while (changed && flips < max_flips) {
    changed = false;
    for (size_t t = 0; t < tris.size(); ++t) {
      bool flipped = false;  // tris[t] changed: its edges are looked at again in the next pass
      for (int e = 0; e < 3 && !flipped; ++e) {
        const uint16_t a = tris[t][e], b = tris[t][(e + 1) % 3], c = tris[t][(e + 2) % 3];
        // The neighbour across a->b holds the directed edge b->a.
        for (size_t u = 0; u < tris.size(); ++u) {
          if (u == t) continue;
          int f = 0;
          while (f < 3 && !(tris[u][f] == b && tris[u][(f + 1) % 3] == a)) ++f;
          if (f == 3) continue;
          const uint16_t d = tris[u][(f + 2) % 3];
          if (in_circle(q[a], q[b], q[c], q[d]) > kFlip) {
            // Quad a, d, b, c (counter-clockwise; convex since d is inside abc's circle): swap
            // the diagonal a-b for c-d.
            tris[t] = {a, d, c};
            tris[u] = {d, b, c};
            changed = flipped = true;
            ++flips;
          }
          break;
        }
      }
    }
  }
}

}  // namespace

Result<BlendSpace2D> make_blend_space_2d(std::span<const glm::vec2> points) {
  const size_t n = points.size();
  if (n < 3) return error("needs at least 3 samples, has " + std::to_string(n));
  if (n > std::numeric_limits<uint16_t>::max()) return error("too many samples (" + std::to_string(n) + ")");
  glm::vec2 lo = points[0], hi = points[0];
  for (size_t i = 0; i < n; ++i) {
    if (!std::isfinite(points[i].x) || !std::isfinite(points[i].y))
      return error("sample " + std::to_string(i) + " is not finite");
    lo = glm::min(lo, points[i]);
    hi = glm::max(hi, points[i]);
  }
  const glm::dvec2 extent = glm::dvec2(hi) - glm::dvec2(lo);
  if (!(extent.x > 0.0) || !(extent.y > 0.0)) return error("all samples lie on one line");
  std::vector<Vec> q(n);
  for (size_t i = 0; i < n; ++i) q[i] = (glm::dvec2(points[i]) - glm::dvec2(lo)) / extent;
  for (size_t i = 0; i < n; ++i) {
    for (size_t j = i + 1; j < n; ++j) {
      const Vec d = glm::abs(q[i] - q[j]);
      if (d.x <= kSamePoint && d.y <= kSamePoint)
        return error("samples " + std::to_string(i) + " and " + std::to_string(j) + " are at the same point");
    }
  }

  std::vector<uint16_t> order(n);
  std::iota(order.begin(), order.end(), uint16_t{0});
  std::sort(order.begin(), order.end(),
            [&](uint16_t a, uint16_t b) { return q[a].x != q[b].x ? q[a].x < q[b].x : q[a].y < q[b].y; });

  // order[0 .. k) lie on one line (sorted along it); order[k] is the first point off it.
  size_t k = 2;
  while (k < n && std::abs(orient(q[order[0]], q[order[1]], q[order[k]])) <= kCollinear) ++k;
  if (k == n) return error("all samples lie on one line");

  std::vector<Triangle> tris;
  std::vector<uint16_t> hull;  // counter-clockwise, collinear points kept
  const uint16_t apex = order[k];
  const bool left = orient(q[order[0]], q[order[1]], q[apex]) > 0.0;
  for (size_t i = 0; i + 1 < k; ++i) {
    if (left) {
      tris.push_back({order[i], order[i + 1], apex});
    } else {
      tris.push_back({order[i + 1], order[i], apex});
    }
  }
  for (size_t i = 0; i < k; ++i) hull.push_back(order[left ? i : k - 1 - i]);
  hull.push_back(apex);

  std::vector<char> visible;
  for (size_t j = k + 1; j < n; ++j) {
    const uint16_t p = order[j];
    const size_t h = hull.size();
    visible.assign(h, 0);
    size_t most = 0;  // the edge p is most clearly outside of, in case round-off hides them all
    double most_value = std::numeric_limits<double>::infinity();
    bool any = false;
    for (size_t i = 0; i < h; ++i) {
      const double o = orient(q[hull[i]], q[hull[(i + 1) % h]], q[p]);
      visible[i] = o < -kCollinear;
      any = any || visible[i];
      if (o < most_value) {
        most_value = o;
        most = i;
      }
    }
    if (!any) visible[most] = 1;
    // p is the largest point so far, so it is outside the hull and its visible edges are one
    // cyclic run: find its first edge s and last edge e.
    size_t s = 0;
    while (s < h && !(visible[s] && !visible[(s + h - 1) % h])) ++s;
    if (s == h) return error("internal error: triangulation lost its hull");  // every edge visible
    size_t e = s;
    while (visible[(e + 1) % h]) e = (e + 1) % h;
    for (size_t i = s;; i = (i + 1) % h) {
      tris.push_back({hull[i], p, hull[(i + 1) % h]});
      if (i == e) break;
    }
    // Hull vertices strictly inside the run (after s up to e) are now interior; p takes their place.
    std::vector<uint16_t> next;
    next.reserve(h + 1);
    for (size_t i = (e + 1) % h;; i = (i + 1) % h) {
      next.push_back(hull[i]);
      if (i == s) break;
    }
    next.push_back(p);
    hull.swap(next);
  }

  make_delaunay(q, tris);

  BlendSpace2D space;
  space.points.assign(points.begin(), points.end());
  space.triangles = std::move(tris);
  space.axis_scale = glm::vec2(1.0 / extent);
  return space;
}

// ---------------------------------------------------------------------------------------------
// 2D: evaluation

void blend_space_2d_weights(const BlendSpace2D& space, glm::vec2 parameter, std::span<float> out) {
  std::fill(out.begin(), out.end(), 0.0f);
  const size_t n = std::min(space.points.size(), out.size());
  if (n == 0) return;
  // A space not made by make_blend_space_2d, or a non-finite parameter: still weights summing to 1.
  if (space.triangles.empty() || !std::isfinite(parameter.x) || !std::isfinite(parameter.y)) {
    out[0] = 1.0f;
    return;
  }
  const Vec scale(space.axis_scale);
  const Vec param(parameter);
  // Sample positions relative to the parameter, in normalized units: the parameter is the origin.
  auto at = [&](uint16_t i) { return (Vec(space.points[i]) - param) * scale; };

  double best_d2 = std::numeric_limits<double>::infinity();
  uint16_t best_i[2] = {0, 0};
  double best_w[2] = {1.0, 0.0};
  for (const Triangle& tri : space.triangles) {
    if (tri[0] >= n || tri[1] >= n || tri[2] >= n) continue;
    const Vec a = at(tri[0]), b = at(tri[1]), c = at(tri[2]);
    // Twice the signed areas of the sub-triangles opposite each vertex.
    const double wa = cross(b, c), wb = cross(c, a), wc = cross(a, b);
    const double sum = wa + wb + wc;
    if (wa >= 0.0 && wb >= 0.0 && wc >= 0.0 && sum > 0.0) {
      out[tri[0]] = static_cast<float>(wa / sum);
      out[tri[1]] = static_cast<float>(wb / sum);
      out[tri[2]] = static_cast<float>(wc / sum);
      return;
    }
    const Vec v[3] = {a, b, c};
    for (int e = 0; e < 3; ++e) {
      const Vec p0 = v[e], p1 = v[(e + 1) % 3];
      const Vec edge = p1 - p0;
      const double len2 = glm::dot(edge, edge);
      double t = len2 > 0.0 ? -glm::dot(p0, edge) / len2 : 0.0;
      t = std::clamp(t, 0.0, 1.0);
      const Vec closest = p0 + t * edge;
      const double d2 = glm::dot(closest, closest);
      if (d2 < best_d2) {
        best_d2 = d2;
        best_i[0] = tri[e];
        best_i[1] = tri[(e + 1) % 3];
        best_w[0] = 1.0 - t;
        best_w[1] = t;
      }
    }
  }
  out[best_i[0]] += static_cast<float>(best_w[0]);
  out[best_i[1]] += static_cast<float>(best_w[1]);
}

}  // namespace ossa
