// cloth_grid.h — a cape made in memory for the cloth solver's tests (ossa/anim/cloth.h): a grid
// of particles hanging from its fixed top row, with the constraints the cooker would make for it
// (triangle edges, bending across triangle pairs, tethers to the top row, greedy colouring), so the
// runtime-only suites can drive the solver without a cooked file.
//
// Layout: `columns` x `rows` particles, `spacing` apart, in the plane z = `z`, the top row at
// height `top`, centred on x = 0; particle (c, r) is index r * columns + c; row 0 is fixed.
// Its "skinned" pose is the rest grid moved by the test (ClothRig::skin).
#pragma once
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <vector>

#include <glm/glm.hpp>

#include <ossa/anim/cloth.h>

namespace ossa::test {

struct GridCloth {
  uint32_t columns = 0, rows = 0;
  float spacing = 0.0f;
  std::vector<glm::vec3> rest;
  std::vector<uint32_t> particle_vertices, vertices;
  std::vector<float> inverse_masses, max_distances, backstops;
  std::vector<uint16_t> vertex_particles, triangles;
  std::vector<fb::ClothEdge> stretch, bend;
  std::vector<fb::ClothTether> tethers;
  std::vector<fb::ClothCollider> colliders;
  ClothSettings settings;

  ClothSource source() const {
    ClothSource s;
    s.particle_vertices = particle_vertices;
    s.inverse_masses = inverse_masses;
    s.max_distances = max_distances;
    s.backstops = backstops;
    s.vertices = vertices;
    s.vertex_particles = vertex_particles;
    s.triangles = triangles;
    s.stretch = stretch;
    s.bend = bend;
    s.tethers = tethers;
    s.colliders = colliders;
    s.settings = settings;
    return s;
  }
};

inline GridCloth make_grid_cloth(uint32_t columns, uint32_t rows, float spacing, float top = 1.5f, float z = -0.15f) {
  GridCloth g;
  g.columns = columns;
  g.rows = rows;
  g.spacing = spacing;
  const auto id = [&](uint32_t c, uint32_t r) { return static_cast<uint16_t>(r * columns + c); };
  const float x0 = -0.5f * spacing * static_cast<float>(columns - 1);
  for (uint32_t r = 0; r < rows; ++r)
    for (uint32_t c = 0; c < columns; ++c) {
      g.rest.emplace_back(x0 + spacing * static_cast<float>(c), top - spacing * static_cast<float>(r), z);
      g.particle_vertices.push_back(id(c, r));
      g.vertices.push_back(id(c, r));
      g.vertex_particles.push_back(id(c, r));
      g.inverse_masses.push_back(r == 0 ? 0.0f : 1.0f);
    }
  const size_t n = g.rest.size();
  const auto edge = [&](uint16_t a, uint16_t b) { return fb::ClothEdge(a, b, glm::distance(g.rest[a], g.rest[b])); };
  std::vector<fb::ClothEdge> stretch, bend;
  for (uint32_t r = 0; r + 1 < rows; ++r)
    for (uint32_t c = 0; c + 1 < columns; ++c) {
      const uint16_t a = id(c, r), b = id(c + 1, r), d = id(c, r + 1), e = id(c + 1, r + 1);
      g.triangles.insert(g.triangles.end(), {a, d, b, b, d, e});  // normals towards +z
    }
  for (uint32_t r = 0; r < rows; ++r)
    for (uint32_t c = 0; c < columns; ++c) {
      if (c + 1 < columns) stretch.push_back(edge(id(c, r), id(c + 1, r)));
      if (r + 1 < rows) stretch.push_back(edge(id(c, r), id(c, r + 1)));
      if (c + 1 < columns && r + 1 < rows) stretch.push_back(edge(id(c + 1, r), id(c, r + 1)));
      // Bending: across each interior edge, the two far corners (for a grid: two along each line
      // and one across each quad pair).
      if (c + 2 < columns) bend.push_back(edge(id(c, r), id(c + 2, r)));
      if (r + 2 < rows) bend.push_back(edge(id(c, r), id(c, r + 2)));
    }
  g.stretch = colour_cloth_edges(stretch, n);
  g.bend = colour_cloth_edges(bend, n);
  for (uint32_t r = 1; r < rows; ++r)
    for (uint32_t c = 0; c < columns; ++c) g.tethers.emplace_back(id(c, r), id(c, 0), spacing * static_cast<float>(r));
  g.settings.gravity = glm::vec3(0.0f, -9.81f, 0.0f);
  g.settings.damping = 0.5f;
  g.settings.bend_compliance = 1e-3f;
  return g;
}

}  // namespace ossa::test
