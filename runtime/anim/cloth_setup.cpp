// cloth_setup.cpp — a cloth's instance made, and the per-vertex glue between the solver's
// particles and skin_cpu-style vertex streams (see cloth.h; the solver is cloth_solve.cpp, the
// preconditions are check_cloth in runtime/loader/cloth_source.cpp, and skinning just the driving
// vertices is runtime/skinning/cloth_skin.cpp).
#include <ossa/anim/cloth.h>

#include <cmath>
#include <span>
#include <utility>
#include <string>
#include <vector>

#include "common/message.h"

namespace ossa {
namespace {

using detail::format;

Error fail(const std::string& what) { return Error{"cloth: " + what}; }

/// Where each run of consecutive edges (or tethers) that share no particle ends: the solver
/// projects a run eight at a time (the cooker's colouring makes the runs long; any order is correct).
template <typename Pair, typename Ends>
std::vector<uint32_t> independent_runs(std::span<const Pair> edges, size_t particles, Ends ends_of) {
  std::vector<uint32_t> ends, run_of(particles, 0);
  uint32_t run = 1;
  for (size_t k = 0; k < edges.size(); ++k) {
    const auto [a, b] = ends_of(edges[k]);
    if (run_of[a] == run || run_of[b] == run) {
      ends.push_back(static_cast<uint32_t>(k));
      ++run;
    }
    run_of[a] = run_of[b] = run;
  }
  if (!edges.empty()) ends.push_back(static_cast<uint32_t>(edges.size()));
  return ends;
}

}  // namespace

Result<ClothInstance> make_cloth_instance(const ClothSource& source, uint32_t vertex_count, size_t joint_count) {
  if (Status st = check_cloth(source, vertex_count, joint_count); !st) return st.error();
  const size_t n = source.particle_count();
  ClothInstance c;
  c.source = source;
  c.settings = source.settings;
  c.current.assign(n, glm::vec4(0.0f));
  c.previous.assign(n, glm::vec4(0.0f));
  for (size_t i = 0; i < n; ++i) c.current[i].w = c.previous[i].w = source.inverse_masses[i];
  c.skinned_before.assign(n, glm::vec3(0.0f));
  c.skinned_older.assign(n, glm::vec3(0.0f));
  c.skinned_normal_before.assign(n, glm::vec3(0.0f));
  c.out_positions.assign(n, glm::vec3(0.0f));
  c.out_normals.assign(n, glm::vec3(0.0f, 1.0f, 0.0f));
  c.colliders_before.assign(2 * source.colliders.size(), glm::vec3(0.0f));
  c.colliders_older.assign(2 * source.colliders.size(), glm::vec3(0.0f));
  c.colliders_now.assign(2 * source.colliders.size(), glm::vec3(0.0f));
  c.lambda.assign(source.stretch.size() + source.bend.size(), 0.0f);
  const auto edge_ends = [](const fb::ClothEdge& e) { return std::pair<uint16_t, uint16_t>(e.a(), e.b()); };
  c.stretch_runs = independent_runs(source.stretch, n, edge_ends);
  c.bend_runs = independent_runs(source.bend, n, edge_ends);
  c.tether_runs = independent_runs(source.tethers, n, [](const fb::ClothTether& t) {
    return std::pair<uint16_t, uint16_t>(t.particle(), t.anchor());
  });
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
