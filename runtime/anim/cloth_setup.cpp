// cloth_setup.cpp — a cloth's instance made, and the per-vertex glue between the solver's
// particles and skin_cpu-style vertex streams (see cloth.h; the solver is cloth_solve.cpp, the
// preconditions are check_cloth in runtime/loader/cloth_source.cpp, and skinning just the driving
// vertices is runtime/skinning/cloth_skin.cpp).
#include <ossa/anim/cloth.h>

#include <algorithm>
#include <cmath>
#include <cstdint>
#include <tuple>
#include <span>
#include <utility>
#include <string>
#include <vector>

#include "anim/cloth_kernels.h"
#include "common/message.h"

namespace ossa {
namespace {

using detail::format;

Error fail(const std::string& what) { return Error{"cloth: " + what}; }

struct Pair {
  uint32_t a, b;
  float rest;
};

/// The pair kinds' (cloth_kernels.h's WideKind: kPairs1, kPairs2) lanes' a ends from the group's
/// first, in the order the kernel's shuffle lines them up; b = a + 1 or a + 2.
constexpr uint32_t kPairOffsets[2][8] = {{0, 2, 8, 10, 4, 6, 12, 14}, {0, 1, 8, 9, 4, 5, 12, 13}};

/// A group needs this many of its eight lanes to be constraints; the others are idle lanes over
/// particles the pattern names and no lane of the group moves (inverse masses 0: the kernel writes
/// back what it read), cheaper than gathering the few a row's end leaves over.
constexpr uint32_t kMinLive = 3;

/// `pairs` (a run's: no particle in two; in order of b - a, then a) as a wide list's run: groups whose ends are two
/// blocks of eight consecutive particles, or sixteen consecutive ones joined in pairs 1 or 2 apart (a grid's rows and
/// columns, once edges are turned to a < b), are found first; the rest go eight at a time through the general
/// (gathering) kind, the last few alone. `turn`: edges are turned to a < b (tethers are not: only the particle moves).
/// `owner`: particles -> 0, left so.
void add_run(std::vector<Pair> pairs, bool turn, std::span<const float> w, std::vector<uint32_t>& owner,
             ClothWideList& out) {
  const size_t n = w.size();
  for (size_t k = 0; k < pairs.size(); ++k) owner[pairs[k].a] = owner[pairs[k].b] = static_cast<uint32_t>(k + 1);
  std::vector<bool> used(pairs.size(), false);
  const auto find = [&](uint32_t a, uint32_t b) -> size_t {  // the unused pair (a, b) + 1, or 0
    if (a >= n || b >= n || owner[a] == 0) return 0;
    const size_t k = owner[a] - 1;
    return !used[k] && pairs[k].a == a && pairs[k].b == b ? k + 1 : 0;
  };
  const auto lane = [&](const Pair& p, bool live) {
    out.a.push_back(p.a);
    out.b.push_back(p.b);
    out.rest.push_back(live ? p.rest : 0.0f);
    out.wa.push_back(live ? w[p.a] : 0.0f);
    out.wb.push_back(live ? w[p.b] : 0.0f);
  };
  std::vector<size_t> rest;
  for (size_t k = 0; k < pairs.size(); ++k) {
    if (used[k]) continue;
    const Pair& p = pairs[k];
    // The kinds' patterns: lane l's ends. A pattern fits when its sixteen ends are particles
    // (distinct by construction; blocks also need the two blocks apart) and enough lanes are pairs.
    const auto blocks = [&](uint32_t l) { return Pair{p.a + l, p.b + l, 0.0f}; };
    const auto pairs1 = [&](uint32_t l) { return Pair{p.a + kPairOffsets[0][l], p.a + kPairOffsets[0][l] + 1, 0.0f}; };
    const auto pairs2 = [&](uint32_t l) { return Pair{p.a + kPairOffsets[1][l], p.a + kPairOffsets[1][l] + 2, 0.0f}; };
    size_t group[8];
    const auto match = [&](auto ends) {
      uint32_t live = 0;
      for (uint32_t l = 0; l < 8; ++l) {
        const Pair e = ends(l);
        if (e.a >= n || e.b >= n) return false;
        const size_t f = find(e.a, e.b);
        group[l] = f == 0 ? SIZE_MAX : f - 1;
        live += f != 0;
      }
      return live >= kMinLive;
    };
    const auto take = [&](uint8_t kind, auto ends) {
      for (uint32_t l = 0; l < 8; ++l) {
        if (group[l] != SIZE_MAX) used[group[l]] = true;
        lane(group[l] != SIZE_MAX ? pairs[group[l]] : ends(l), group[l] != SIZE_MAX);
      }
      out.kinds.push_back(kind);
    };
    const uint32_t apart = p.b > p.a ? p.b - p.a : p.a - p.b;
    if (apart >= 8 && match(blocks)) take(detail::kBlocks, blocks);
    else if (turn && p.b == p.a + 1 && match(pairs1)) take(detail::kPairs1, pairs1);
    else if (turn && p.b == p.a + 2 && match(pairs2)) take(detail::kPairs2, pairs2);
    else rest.push_back(k);
  }
  size_t r = 0;
  for (; r + 8 <= rest.size(); r += 8) {
    for (size_t l = 0; l < 8; ++l) lane(pairs[rest[r + l]], true);
    out.kinds.push_back(detail::kGather);
  }
  out.runs.push_back(static_cast<uint32_t>(out.a.size()));
  for (; r < rest.size(); ++r) lane(pairs[rest[r]], true);
  out.runs.push_back(static_cast<uint32_t>(out.a.size()));
  for (const Pair& q : pairs) owner[q.a] = owner[q.b] = 0;
}

/// Where each run of consecutive constraints that share no particle ends (their order within a
/// run does not change the result: none reads what another writes).
template <typename Item, typename Ends>
std::vector<uint32_t> independent_runs(std::span<const Item> items, size_t particles, Ends ends_of) {
  std::vector<uint32_t> ends, run_of(particles, 0);
  uint32_t run = 1;
  for (size_t k = 0; k < items.size(); ++k) {
    const auto [a, b, rest] = ends_of(items[k]);
    if (run_of[a] == run || run_of[b] == run) {
      ends.push_back(static_cast<uint32_t>(k));
      ++run;
    }
    run_of[a] = run_of[b] = run;
  }
  if (!items.empty()) ends.push_back(static_cast<uint32_t>(items.size()));
  return ends;
}

/// The constraints as a wide list: each run of the stored order whose constraints share no
/// particle (the cooker's colours), edges turned to a < b, in order of b - a and then a, grouped
/// by add_run. Both paths run this order, which gives the stored order's bits.
template <typename Item, typename Ends>
ClothWideList wide_list(std::span<const Item> items, std::span<const float> w, bool turn, Ends ends_of) {
  ClothWideList out;
  std::vector<uint32_t> owner(w.size(), 0);
  size_t k = 0;
  for (const uint32_t end : independent_runs(items, w.size(), ends_of)) {
    std::vector<Pair> run;
    for (; k < end; ++k) {
      const auto [a, b, rest] = ends_of(items[k]);
      run.push_back(turn && a > b ? Pair{b, a, rest} : Pair{a, b, rest});
    }
    const auto apart = [](const Pair& p) { return static_cast<int64_t>(p.b) - static_cast<int64_t>(p.a); };
    std::sort(run.begin(), run.end(),
              [&](const Pair& x, const Pair& y) { return apart(x) != apart(y) ? apart(x) < apart(y) : x.a < y.a; });
    add_run(std::move(run), turn, w, owner, out);
  }
  return out;
}

}  // namespace

Result<ClothInstance> make_cloth_instance(const ClothSource& source, uint32_t vertex_count, size_t joint_count) {
  if (Status st = check_cloth(source, vertex_count, joint_count); !st) return st.error();
  const size_t n = source.particle_count();
  ClothInstance c;
  c.source = source;
  c.settings = source.settings;
  ClothParticles& ps = c.particles;
  for (std::vector<float>* plane : {&ps.x, &ps.y, &ps.z, &ps.px, &ps.py, &ps.pz}) plane->assign(n, 0.0f);
  ps.w.assign(source.inverse_masses.begin(), source.inverse_masses.end());
  c.skinned_before.assign(n, glm::vec3(0.0f));
  c.skinned_older.assign(n, glm::vec3(0.0f));
  c.skinned_normal_before.assign(n, glm::vec3(0.0f));
  c.out_positions.assign(n, glm::vec3(0.0f));
  c.out_normals.assign(n, glm::vec3(0.0f, 1.0f, 0.0f));
  c.colliders_before.assign(2 * source.colliders.size(), glm::vec3(0.0f));
  c.colliders_older.assign(2 * source.colliders.size(), glm::vec3(0.0f));
  c.colliders_now.assign(2 * source.colliders.size(), glm::vec3(0.0f));
  const auto edge = [](const fb::ClothEdge& e) {
    return std::tuple<uint32_t, uint32_t, float>(e.a(), e.b(), e.rest());
  };
  c.wide_stretch = wide_list(source.stretch, source.inverse_masses, true, edge);
  c.wide_bend = wide_list(source.bend, source.inverse_masses, true, edge);
  c.wide_tethers = wide_list(source.tethers, source.inverse_masses, false, [](const fb::ClothTether& t) {
    return std::tuple<uint32_t, uint32_t, float>(t.particle(), t.anchor(), t.length());
  });
  c.lambda.assign(c.wide_stretch.a.size() + c.wide_bend.a.size(), 0.0f);  // per lane, idle ones included
  c.collider_step.assign(3 * source.colliders.size(), glm::vec4(0.0f));
  // The wind acts along each particle's normal every substep: one triangle's, the first it is a
  // corner of (a particle in no triangle faces along a zero normal, and feels no wind).
  c.facing.assign(3 * n, 0);
  std::vector<bool> seen(n, false);
  for (size_t t = 0; t + 2 < source.triangles.size(); t += 3)
    for (size_t k = 0; k < 3; ++k) {
      const uint16_t p = source.triangles[t + k];
      if (seen[p]) continue;
      seen[p] = true;
      for (size_t j = 0; j < 3; ++j) c.facing[3 * p + j] = source.triangles[t + (k + j) % 3];
    }
  // Each particle's corners: the triangles it is a corner of, in order (once per corner).
  c.triangle_normals.assign(source.triangles.size() / 3, glm::vec3(0.0f));
  c.corner_start.assign(n + 1, 0);
  const size_t corners = 3 * c.triangle_normals.size();
  for (size_t k = 0; k < corners; ++k) ++c.corner_start[source.triangles[k] + 1];
  for (size_t i = 0; i < n; ++i) c.corner_start[i + 1] += c.corner_start[i];
  c.corners.assign(corners, 0);
  std::vector<uint32_t> next(c.corner_start.begin(), c.corner_start.end() - 1);
  for (size_t k = 0; k < corners; ++k) c.corners[next[source.triangles[k]]++] = static_cast<uint32_t>(k / 3);
  return c;
}

void reset_cloth(ClothInstance& cloth) { cloth.started = false; }

std::vector<fb::ClothEdge> colour_cloth_edges(std::span<const fb::ClothEdge> edges, size_t particle_count) {
  std::vector<fb::ClothEdge> out, left(edges.begin(), edges.end()), rest;
  out.reserve(edges.size());
  std::vector<uint32_t> used(particle_count, 0);
  for (uint32_t colour = 1; !left.empty(); ++colour) {
    rest.clear();
    for (const fb::ClothEdge& e : left) {
      if (used[e.a()] == colour || used[e.b()] == colour) {
        rest.push_back(e);
        continue;
      }
      used[e.a()] = used[e.b()] = colour;
      out.push_back(e);
    }
    left.swap(rest);
  }
  return out;
}

Status gather_cloth_particles(const ClothSource& source, std::span<const float> skinned_positions,
                              std::span<const float> skinned_normals, std::span<glm::vec3> positions,
                              std::span<glm::vec3> normals) {
  const size_t n = source.particle_count();
  if (positions.size() < n || (!skinned_normals.empty() && normals.size() < n))
    return fail(format("gather_cloth_particles needs %zu positions and normals", n));
  for (size_t i = 0; i < n; ++i) {
    const size_t v = source.particle_vertices[i];
    if (3 * v + 2 >= skinned_positions.size() || (!skinned_normals.empty() && 3 * v + 2 >= skinned_normals.size()))
      return fail(format("gather_cloth_particles: particle %zu's vertex %zu is past the skinned streams", i, v));
    positions[i] = glm::vec3(skinned_positions[3 * v], skinned_positions[3 * v + 1], skinned_positions[3 * v + 2]);
    if (!skinned_normals.empty())
      normals[i] = glm::vec3(skinned_normals[3 * v], skinned_normals[3 * v + 1], skinned_normals[3 * v + 2]);
  }
  return {};
}

Status write_cloth_vertices(const ClothInstance& cloth, std::span<float> positions, std::span<float> normals) {
  const ClothSource& s = cloth.source;
  for (size_t k = 0; k < s.vertices.size(); ++k) {
    const size_t v = s.vertices[k];
    const size_t p = s.vertex_particles[k];
    if ((!positions.empty() && 3 * v + 2 >= positions.size()) || (!normals.empty() && 3 * v + 2 >= normals.size()))
      return fail(format("write_cloth_vertices: vertex %zu is past the streams", v));
    if (p >= cloth.out_positions.size()) return fail("write_cloth_vertices: the instance does not match its source");
    if (!positions.empty()) {
      const glm::vec3& x = cloth.out_positions[p];
      positions[3 * v] = x.x;
      positions[3 * v + 1] = x.y;
      positions[3 * v + 2] = x.z;
    }
    if (!normals.empty()) {
      const glm::vec3 nrm = !s.flipped.empty() && s.flipped[k] ? -cloth.out_normals[p] : cloth.out_normals[p];
      normals[3 * v] = nrm.x;
      normals[3 * v + 1] = nrm.y;
      normals[3 * v + 2] = nrm.z;
    }
  }
  return {};
}

}  // namespace ossa
