// blend_space_test.cpp — blend-space weights (ossa/anim/blend_space.h): 1D and 2D weights sum to 1,
// are exact at the samples, interpolate linearly / barycentrically, clamp or project outside, the
// 2D triangulation is Delaunay and rejects degenerate input, evaluation does not allocate, and
// clips scaled to the synchronized duration stay in phase.
//
// Allocation-freedom is measured, not assumed: this binary replaces the global operator new with
// one that counts, and the evaluation loops run between two reads of the counter.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <cstdlib>
#include <new>
#include <string>
#include <vector>

#include <ossa/anim/blend_space.h>
#include "allocation_counter.h"

namespace ossa {
namespace {

float sum(const std::vector<float>& w) {
  float s = 0.0f;
  for (float x : w) s += x;
  return s;
}

// ---------------------------------------------------------------------------------------------
// 1D

TEST(BlendSpace1D, WeightsSumToOneAndAtMostTwoAreNonZero) {
  const std::vector<float> positions = {0.0f, 1.5f, 3.0f, 6.0f};
  std::vector<float> w(positions.size());
  for (float x = -2.0f; x <= 8.0f; x += 0.01f) {
    blend_space_1d_weights(positions, x, w);
    EXPECT_NEAR(sum(w), 1.0f, 1e-6f) << x;
    int non_zero = 0;
    for (float v : w) {
      EXPECT_GE(v, 0.0f);
      non_zero += v != 0.0f;
    }
    EXPECT_LE(non_zero, 2) << x;
  }
}

TEST(BlendSpace1D, ExactAtEachSample) {
  const std::vector<float> positions = {-1.0f, 0.3f, 2.7f, 3.1f, 9.0f};
  std::vector<float> w(positions.size());
  for (size_t i = 0; i < positions.size(); ++i) {
    blend_space_1d_weights(positions, positions[i], w);
    for (size_t j = 0; j < w.size(); ++j) EXPECT_EQ(w[j], i == j ? 1.0f : 0.0f) << i << " " << j;
  }
}

TEST(BlendSpace1D, ClampedOutsideTheSamples) {
  const std::vector<float> positions = {1.0f, 2.0f, 4.0f};
  std::vector<float> w(3);
  blend_space_1d_weights(positions, -100.0f, w);
  EXPECT_EQ(w, (std::vector<float>{1, 0, 0}));
  blend_space_1d_weights(positions, 0.999f, w);
  EXPECT_EQ(w, (std::vector<float>{1, 0, 0}));
  blend_space_1d_weights(positions, 4.001f, w);
  EXPECT_EQ(w, (std::vector<float>{0, 0, 1}));
  blend_space_1d_weights(positions, 1e30f, w);
  EXPECT_EQ(w, (std::vector<float>{0, 0, 1}));
  // A non-finite parameter still gives weights summing to 1.
  blend_space_1d_weights(positions, std::nanf(""), w);
  EXPECT_EQ(sum(w), 1.0f);
}

TEST(BlendSpace1D, LinearBetweenNeighbours) {
  const std::vector<float> positions = {0.0f, 1.0f, 3.0f};
  std::vector<float> w(3);
  blend_space_1d_weights(positions, 2.5f, w);
  EXPECT_FLOAT_EQ(w[0], 0.0f);
  EXPECT_FLOAT_EQ(w[1], 0.25f);
  EXPECT_FLOAT_EQ(w[2], 0.75f);
  // Linear: the weighted mean of the sample positions is the parameter itself.
  for (float x = 0.0f; x <= 3.0f; x += 0.037f) {
    blend_space_1d_weights(positions, x, w);
    EXPECT_NEAR(w[0] * positions[0] + w[1] * positions[1] + w[2] * positions[2], x, 1e-6f);
  }
}

TEST(BlendSpace1D, SingleSampleAndEmpty) {
  const std::vector<float> one = {2.0f};
  std::vector<float> w(1);
  blend_space_1d_weights(one, -5.0f, w);
  EXPECT_EQ(w[0], 1.0f);
  blend_space_1d_weights(one, 5.0f, w);
  EXPECT_EQ(w[0], 1.0f);
  blend_space_1d_weights({}, 1.0f, {});  // nothing to write, no crash
}

TEST(SynchronizedDuration, IsTheWeightedMeanDuration) {
  const std::vector<float> durations = {1.2f, 0.8f, 0.6f};
  EXPECT_FLOAT_EQ(synchronized_duration(durations, std::vector<float>{1, 0, 0}), 1.2f);
  EXPECT_FLOAT_EQ(synchronized_duration(durations, std::vector<float>{0, 0, 1}), 0.6f);
  EXPECT_FLOAT_EQ(synchronized_duration(durations, std::vector<float>{0.5f, 0.5f, 0}), 1.0f);
  EXPECT_FLOAT_EQ(synchronized_duration(durations, std::vector<float>{0.25f, 0.25f, 0.5f}), 0.8f);
  // Weights that do not sum to 1 are normalized; no weight at all gives 0.
  EXPECT_FLOAT_EQ(synchronized_duration(durations, std::vector<float>{1, 1, 0}), 1.0f);
  EXPECT_EQ(synchronized_duration(durations, std::vector<float>{0, 0, 0}), 0.0f);
}

// Locomotion: walk / jog / run authored at 1.4, 3.0 and 5.5 m/s with different cycle lengths.
// Between two of them the blend moves at the parameter speed, and with each clip played at rate
// duration_i / synchronized_duration both clips are at the same point of their cycle (same
// normalized time: same foot down) at every moment.
TEST(BlendSpace1D, WalkJogRunStayInPhase) {
  const std::vector<float> speeds = {1.4f, 3.0f, 5.5f};
  const std::vector<float> durations = {1.2f, 0.8f, 0.6f};
  std::vector<float> w(3);
  blend_space_1d_weights(speeds, 2.2f, w);
  EXPECT_FLOAT_EQ(w[0], 0.5f);
  EXPECT_FLOAT_EQ(w[1], 0.5f);
  EXPECT_EQ(w[2], 0.0f);
  EXPECT_NEAR(w[0] * speeds[0] + w[1] * speeds[1] + w[2] * speeds[2], 2.2f, 1e-6f);

  for (float speed : {1.4f, 2.2f, 3.7f, 5.5f}) {
    blend_space_1d_weights(speeds, speed, w);
    const float cycle = synchronized_duration(durations, w);
    ASSERT_GT(cycle, 0.0f);
    EXPECT_NEAR(w[0] * speeds[0] + w[1] * speeds[1] + w[2] * speeds[2], speed, 1e-5f);
    // Play 3 s at 60 Hz; each clip's own time advances at its rate.
    double time[3] = {0, 0, 0};
    for (int step = 0; step < 180; ++step) {
      double phase = -1.0;
      for (int i = 0; i < 3; ++i) {
        if (w[static_cast<size_t>(i)] == 0.0f) continue;
        const double rate = durations[static_cast<size_t>(i)] / cycle;
        time[i] = std::fmod(time[i] + rate / 60.0, durations[static_cast<size_t>(i)]);
        const double normalized = time[i] / durations[static_cast<size_t>(i)];
        if (phase < 0.0) {
          phase = normalized;
        } else {
          // Same point of the cycle (modulo a wrap landing on either side of 0 / 1).
          const double d = std::abs(normalized - phase);
          EXPECT_LT(std::min(d, 1.0 - d), 1e-5) << speed << " step " << step;
        }
      }
    }
  }
}

// ---------------------------------------------------------------------------------------------
// 2D

/// Twice the signed area of the triangle (counter-clockwise > 0).
double area2(glm::vec2 a, glm::vec2 b, glm::vec2 c) {
  return (double(b.x) - a.x) * (double(c.y) - a.y) - (double(b.y) - a.y) * (double(c.x) - a.x);
}

/// Checks the triangulation is a Delaunay triangulation of the convex hull: triangles CCW and
/// non-degenerate, every sample used, total area = hull area (no gaps, no overlaps), and no
/// sample strictly inside any triangle's circumcircle (in the normalized units it is built in).
void expect_delaunay(const BlendSpace2D& s, double hull_area2) {
  std::vector<bool> used(s.points.size(), false);
  double total = 0.0;
  for (const auto& t : s.triangles) {
    const glm::vec2 a = s.points[t[0]], b = s.points[t[1]], c = s.points[t[2]];
    EXPECT_GT(area2(a, b, c), 0.0);
    total += area2(a, b, c);
    for (uint16_t i : t) used[i] = true;
    const glm::dvec2 k(s.axis_scale);
    const glm::dvec2 na = glm::dvec2(a) * k, nb = glm::dvec2(b) * k, nc = glm::dvec2(c) * k;
    for (size_t i = 0; i < s.points.size(); ++i) {
      if (i == t[0] || i == t[1] || i == t[2]) continue;
      const glm::dvec2 d = glm::dvec2(s.points[i]) * k;
      const glm::dvec2 ad = na - d, bd = nb - d, cd = nc - d;
      auto cr = [](glm::dvec2 u, glm::dvec2 v) { return u.x * v.y - u.y * v.x; };
      const double in = glm::dot(ad, ad) * cr(bd, cd) + glm::dot(bd, bd) * cr(cd, ad) + glm::dot(cd, cd) * cr(ad, bd);
      EXPECT_LE(in, 1e-9) << "sample " << i << " inside a triangle's circumcircle";
    }
  }
  for (size_t i = 0; i < used.size(); ++i) EXPECT_TRUE(used[i]) << "sample " << i << " not in any triangle";
  EXPECT_NEAR(total, hull_area2, 1e-6 * hull_area2);
}

glm::vec2 blended_point(const BlendSpace2D& s, const std::vector<float>& w) {
  glm::dvec2 p(0.0);
  for (size_t i = 0; i < w.size(); ++i) p += double(w[i]) * glm::dvec2(s.points[i]);
  return glm::vec2(p);
}

/// Speed (m/s) x direction (degrees): idle, walk and run in 4 directions; plenty of collinear
/// and co-circular points, and axes in very different units.
std::vector<glm::vec2> locomotion_points() {
  return {{0, 0}, {1.5f, -180}, {1.5f, -90}, {1.5f, 0}, {1.5f, 90}, {1.5f, 180}, {5, -180}, {5, -90},
          {5, 0}, {5, 90},      {5, 180},    {0, -180}, {0, 180},   {0, -90},    {0, 90}};
}

TEST(BlendSpace2D, TriangulationIsDelaunayOverTheHull) {
  {
    // Unit square with its centre: 4 triangles around the centre.
    const std::vector<glm::vec2> pts = {{0, 0}, {1, 0}, {1, 1}, {0, 1}, {0.5f, 0.5f}};
    auto s = make_blend_space_2d(pts);
    ASSERT_TRUE(s) << s.error().message;
    EXPECT_EQ(s->triangles.size(), 4u);
    expect_delaunay(*s, 2.0);
  }
  {
    // A 4 x 3 grid: co-circular everywhere, collinear points on every hull edge.
    std::vector<glm::vec2> pts;
    for (int y = 0; y < 3; ++y)
      for (int x = 0; x < 4; ++x) pts.push_back({float(x), float(y)});
    auto s = make_blend_space_2d(pts);
    ASSERT_TRUE(s) << s.error().message;
    EXPECT_EQ(s->triangles.size(), 12u);  // 2 (n - 1) - h with n = 12, h = 10 hull points
    expect_delaunay(*s, 12.0);
  }
  {
    auto s = make_blend_space_2d(locomotion_points());
    ASSERT_TRUE(s) << s.error().message;
    expect_delaunay(*s, 2.0 * 5.0 * 360.0);
  }
  {
    // Irregular points, including three nearly collinear ones on the hull.
    const std::vector<glm::vec2> pts = {{0, 0}, {4, -0.001f}, {8, 0}, {7, 3}, {3, 5}, {-1, 2}, {2, 1.5f}, {5, 2}};
    auto s = make_blend_space_2d(pts);
    ASSERT_TRUE(s) << s.error().message;
    // Hull: (0,0) (4,-0.001) (8,0) (7,3) (3,5) (-1,2); shoelace.
    const std::vector<glm::vec2> hull = {{0, 0}, {4, -0.001f}, {8, 0}, {7, 3}, {3, 5}, {-1, 2}};
    double a = 0.0;
    for (size_t i = 0; i < hull.size(); ++i) a += area2({0, 0}, hull[i], hull[(i + 1) % hull.size()]);
    expect_delaunay(*s, a);
  }
}

/// Twice the convex hull's area (Andrew's monotone chain), to check triangulations against.
double hull_area2(std::vector<glm::vec2> p) {
  std::sort(p.begin(), p.end(), [](glm::vec2 a, glm::vec2 b) { return a.x != b.x ? a.x < b.x : a.y < b.y; });
  std::vector<glm::vec2> h(2 * p.size());
  size_t k = 0;
  for (size_t i = 0; i < p.size(); ++i) {
    while (k >= 2 && area2(h[k - 2], h[k - 1], p[i]) <= 0.0) --k;
    h[k++] = p[i];
  }
  for (size_t i = p.size() - 1, t = k + 1; i-- > 0;) {
    while (k >= t && area2(h[k - 2], h[k - 1], p[i]) <= 0.0) --k;
    h[k++] = p[i];
  }
  double a = 0.0;
  for (size_t i = 0; i + 1 < k; ++i) a += area2({0, 0}, h[i], h[i + 1]);
  return a;
}

// Many point sets, random and snapped to coarse grids (co-circular and collinear everywhere):
// every one triangulates into a Delaunay triangulation of its hull, and weights stay exact at
// the samples.
TEST(BlendSpace2D, RandomAndGridSnappedPointSets) {
  uint32_t state = 12345u;
  auto next = [&]() {  // xorshift: deterministic and the same on every platform
    state ^= state << 13;
    state ^= state >> 17;
    state ^= state << 5;
    return float(state % 100000u) / 100000.0f;
  };
  for (int set = 0; set < 300; ++set) {
    const size_t n = 3 + size_t(next() * 30.0f);
    const float snap = set % 3 == 0 ? 0.0f : (set % 3 == 1 ? 0.25f : 0.125f);
    std::vector<glm::vec2> pts;
    while (pts.size() < n) {
      glm::vec2 p(next() * 6.0f, next() * 360.0f - 180.0f);
      if (snap > 0.0f)
        p = glm::vec2(std::round(p.x / (6.0f * snap)) * 6.0f * snap, std::round(p.y / (360.0f * snap)) * 360.0f * snap);
      bool dup = false;
      for (const auto& q : pts) dup = dup || q == p;
      if (!dup) pts.push_back(p);
      if (snap > 0.0f && pts.size() >= size_t((1.0f / snap + 1) * (1.0f / snap + 1))) break;
    }
    auto s = make_blend_space_2d(pts);
    const double hull = hull_area2(pts);
    if (!s) {
      EXPECT_EQ(hull, 0.0) << "set " << set << ": " << s.error().message;  // only collinear sets fail
      continue;
    }
    SCOPED_TRACE("set " + std::to_string(set));
    expect_delaunay(*s, hull);
    std::vector<float> w(pts.size());
    for (size_t i = 0; i < pts.size(); ++i) {
      blend_space_2d_weights(*s, pts[i], w);
      EXPECT_EQ(w[i], 1.0f);
      EXPECT_EQ(sum(w), 1.0f);
    }
  }
}

TEST(BlendSpace2D, DegenerateInputIsAnError) {
  using P = std::vector<glm::vec2>;
  const std::vector<std::pair<const char*, P>> bad = {
      {"no points", {}},
      {"one point", {{0, 0}}},
      {"two points", {{0, 0}, {1, 1}}},
      {"collinear, axis-aligned", {{0, 0}, {1, 0}, {2, 0}, {3, 0}}},
      {"collinear, diagonal", {{0, 0}, {1, 1}, {2, 2}, {-3, -3}, {0.5f, 0.5f}}},
      {"duplicate", {{0, 0}, {1, 0}, {0, 1}, {1, 0}}},
      {"near duplicate", {{0, 0}, {1, 0}, {0, 1}, {1e-8f, 1.0f}}},
      {"all the same point", {{1, 1}, {1, 1}, {1, 1}}},
      {"not finite", {{0, 0}, {1, 0}, {0, std::nanf("")}}},
  };
  for (const auto& [what, pts] : bad) {
    auto s = make_blend_space_2d(pts);
    ASSERT_FALSE(s) << what;
    EXPECT_EQ(s.error().message.rfind("blend space: ", 0), 0u) << s.error().message;
  }
}

TEST(BlendSpace2D, ExactAtEachSample) {
  for (const auto& pts :
       {locomotion_points(), std::vector<glm::vec2>{{0, 0}, {1, 0}, {0.3f, 2}, {2, 2}, {1.1f, 0.9f}}}) {
    auto s = make_blend_space_2d(pts);
    ASSERT_TRUE(s) << s.error().message;
    std::vector<float> w(pts.size());
    for (size_t i = 0; i < pts.size(); ++i) {
      blend_space_2d_weights(*s, pts[i], w);
      for (size_t j = 0; j < w.size(); ++j)
        EXPECT_EQ(w[j], i == j ? 1.0f : 0.0f) << "at sample " << i << ", weight " << j;
    }
  }
}

TEST(BlendSpace2D, BarycentricInsideATriangle) {
  const std::vector<glm::vec2> tri = {{0, 0}, {1, 0}, {0, 1}};
  auto s = make_blend_space_2d(tri);
  ASSERT_TRUE(s) << s.error().message;
  std::vector<float> w(3);
  blend_space_2d_weights(*s, {0.2f, 0.3f}, w);
  EXPECT_NEAR(w[0], 0.5f, 1e-6f);
  EXPECT_NEAR(w[1], 0.2f, 1e-6f);
  EXPECT_NEAR(w[2], 0.3f, 1e-6f);

  // Inside the hull of a bigger space, at most three samples (one triangle) carry weight, and
  // the weighted mean of the sample points is the parameter (barycentric = affine).
  auto loco = make_blend_space_2d(locomotion_points());
  ASSERT_TRUE(loco) << loco.error().message;
  std::vector<float> lw(loco->points.size());
  for (float speed = 0.0f; speed <= 5.0f; speed += 0.173f) {
    for (float dir = -180.0f; dir <= 180.0f; dir += 7.7f) {
      blend_space_2d_weights(*loco, {speed, dir}, lw);
      int non_zero = 0;
      for (float v : lw) {
        EXPECT_GE(v, 0.0f);
        non_zero += v != 0.0f;
      }
      EXPECT_LE(non_zero, 3);
      EXPECT_NEAR(sum(lw), 1.0f, 1e-6f);
      const glm::vec2 p = blended_point(*loco, lw);
      EXPECT_NEAR(p.x, speed, 1e-4f);
      EXPECT_NEAR(p.y, dir, 1e-2f);
    }
  }
}

TEST(BlendSpace2D, OutsideProjectsToTheNearestHullEdge) {
  // 3 x 3 grid on [0, 2]^2.
  std::vector<glm::vec2> pts;
  for (int y = 0; y < 3; ++y)
    for (int x = 0; x < 3; ++x) pts.push_back({float(x), float(y)});
  auto s = make_blend_space_2d(pts);
  ASSERT_TRUE(s) << s.error().message;
  std::vector<float> w(9);
  auto index = [](int x, int y) { return size_t(y * 3 + x); };

  blend_space_2d_weights(*s, {3.0f, 0.5f}, w);  // right of the hull: onto x = 2 at y = 0.5
  EXPECT_NEAR(w[index(2, 0)], 0.5f, 1e-6f);
  EXPECT_NEAR(w[index(2, 1)], 0.5f, 1e-6f);
  EXPECT_NEAR(sum(w), 1.0f, 1e-6f);

  blend_space_2d_weights(*s, {1.25f, -4.0f}, w);  // below: onto y = 0 at x = 1.25
  EXPECT_NEAR(w[index(1, 0)], 0.75f, 1e-6f);
  EXPECT_NEAR(w[index(2, 0)], 0.25f, 1e-6f);

  blend_space_2d_weights(*s, {5.0f, 7.0f}, w);  // beyond a corner: the corner sample alone
  EXPECT_EQ(w[index(2, 2)], 1.0f);
  EXPECT_NEAR(sum(w), 1.0f, 0.0f);

  // A skewed hull: the nearest point is the perpendicular foot on the slanted edge.
  const std::vector<glm::vec2> quad = {{0, 0}, {4, 0}, {4, 4}, {0, 2}};
  auto q = make_blend_space_2d(quad);
  ASSERT_TRUE(q) << q.error().message;
  std::vector<float> qw(4);
  // Edge (0,2)-(4,4): direction (2,1)/sqrt5; the point (1, 4) projects to (1.6, 2.8), 40 % along.
  blend_space_2d_weights(*q, {1.0f, 4.0f}, qw);
  EXPECT_NEAR(qw[3], 0.6f, 1e-5f);
  EXPECT_NEAR(qw[2], 0.4f, 1e-5f);
  const glm::vec2 p = blended_point(*q, qw);
  EXPECT_NEAR(p.x, 1.6f, 1e-5f);
  EXPECT_NEAR(p.y, 2.8f, 1e-5f);
}

TEST(BlendSpace2D, WeightsAreContinuousOutsideAndAlongTheHull) {
  auto s = make_blend_space_2d(locomotion_points());
  ASSERT_TRUE(s) << s.error().message;
  std::vector<float> w(s->points.size()), prev(s->points.size());
  // Circles around the space's centre (2.5, 0), in normalized units (axis_scale): one crossing
  // the hull, one outside it, one far outside; weights must change little per small step.
  const glm::vec2 centre(2.5f, 0.0f);
  for (double radius : {0.3, 0.6, 3.0}) {
    const int steps = 20000;
    for (int i = 0; i <= steps; ++i) {
      const double a = 2.0 * 3.14159265358979 * i / steps;
      const glm::vec2 p = centre + glm::vec2(float(radius * std::cos(a) / s->axis_scale.x),
                                             float(radius * std::sin(a) / s->axis_scale.y));
      blend_space_2d_weights(*s, p, w);
      EXPECT_NEAR(sum(w), 1.0f, 1e-6f);
      if (i > 0) {
        // Step length in normalized units is 2 pi r / steps; weights are Lipschitz in the
        // parameter with a constant ~ 1 / (shortest triangle height) ~ 4 here.
        float change = 0.0f;
        for (size_t j = 0; j < w.size(); ++j) change = std::max(change, std::abs(w[j] - prev[j]));
        EXPECT_LT(change, 20.0 * 2.0 * 3.1416 * radius / steps) << "radius " << radius << " step " << i;
      }
      prev = w;
    }
  }
}

TEST(BlendSpace2D, EvaluationDoesNotAllocate) {
  auto s = make_blend_space_2d(locomotion_points());
  ASSERT_TRUE(s) << s.error().message;
  std::vector<float> w(s->points.size());
  const std::vector<float> positions = {1.4f, 3.0f, 5.5f};
  std::vector<float> w1(3);
  float checksum = 0.0f;
  const size_t before = ossa::test::allocation_count();
  for (int i = 0; i < 1000; ++i) {
    const glm::vec2 p(-1.0f + 0.007f * float(i), -200.0f + 0.4f * float(i));
    blend_space_2d_weights(*s, p, w);
    blend_space_1d_weights(positions, p.x, w1);
    checksum += w[0] + w1[0];
  }
  const size_t after = ossa::test::allocation_count();
  EXPECT_EQ(after, before);
  EXPECT_TRUE(std::isfinite(checksum));
}

}  // namespace
}  // namespace ossa
