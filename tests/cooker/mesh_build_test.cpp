// mesh_build_test.cpp — the cooker's mesh stage (build_meshes) and writer (write_ossa) on synthetic
// SourceScenes: no importer, no files, so every expectation is computed from data the test states.
//
// Cooked vertices are reordered by the optimizers, so checks map each cooked vertex back to its
// source vertex by its decoded position (and normal, where positions repeat), then compare every
// attribute with the source within the precision its format promises.
#include <gtest/gtest.h>

#include <flatbuffers/flatbuffers.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <glm/gtc/matrix_transform.hpp>
#include <span>
#include <string>
#include <vector>

#include "cooker/clip/clip_compress.h"
#include "cooker/mesh/mesh_build.h"
#include "cooker/write/write_ossa.h"
#include <ossa/format/clip_codec.h>
#include <ossa/format/hash.h>
#include <ossa/format/vertex_codec.h>
#include <ossa/format/vertex_format.h>
#include <ossa/version.h>
#include <ossa/loader/asset.h>

namespace {

using namespace ossa;
using namespace ossa::cook;

// ---------------------------------------------------------------------------------------------
// Synthetic sources

// Deterministic pseudo-random numbers, independent of the standard library's distributions.
struct Lcg {
  uint64_t state;
  uint32_t next() {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return static_cast<uint32_t>(state >> 33);
  }
  float unit() { return static_cast<float>(next() & 0xffffff) / static_cast<float>(0x1000000); }
};

SourceSkeleton chain_skeleton(size_t joints) {
  SourceSkeleton s;
  for (size_t i = 0; i < joints; ++i) {
    SourceJoint j;
    j.name = "joint" + std::to_string(i);
    j.parent = static_cast<int>(i) - 1;
    j.translation = glm::vec3(0.0f, i == 0 ? 0.0f : 1.0f, 0.0f);
    j.inverse_bind = glm::translate(glm::mat4(1.0f), glm::vec3(0.0f, -static_cast<float>(i), 0.0f));
    s.joints.push_back(j);
  }
  return s;
}

// A box of 24 vertices (4 per face, so face normals are exact), 12 outward (CCW) triangles.
SourceMesh box_mesh(glm::vec3 center, glm::vec3 half, bool normals) {
  SourceMesh m;
  m.name = "Box";
  for (int axis = 0; axis < 3; ++axis) {
    for (int sign = -1; sign <= 1; sign += 2) {
      glm::vec3 n(0.0f), u(0.0f), v(0.0f);
      n[axis] = static_cast<float>(sign);
      u[(axis + 1) % 3] = 1.0f;
      v[(axis + 2) % 3] = 1.0f;
      if (sign < 0) std::swap(u, v);  // keeps u x v = n, so the quad winds CCW seen from outside
      const auto base = static_cast<uint32_t>(m.positions.size());
      const glm::vec2 corners[4] = {{-1, -1}, {1, -1}, {1, 1}, {-1, 1}};
      for (const glm::vec2& c : corners) {
        m.positions.push_back(center + half * (n + c.x * u + c.y * v));
        if (normals) m.normals.push_back(n);
        m.uv0.push_back(glm::vec2(c.x * 0.5f + 0.5f, c.y * 0.5f + 0.5f));
      }
      for (uint32_t i : {0u, 1u, 2u, 0u, 2u, 3u}) m.indices.push_back(base + i);
    }
  }
  return m;
}

// A box of 8 shared corners, 12 outward triangles: smooth normals point away from the centre.
SourceMesh shared_corner_box(glm::vec3 center, glm::vec3 half) {
  SourceMesh m;
  m.name = "SmoothBox";
  for (int i = 0; i < 8; ++i)
    m.positions.push_back(center + half * glm::vec3(i & 1 ? 1 : -1, i & 2 ? 1 : -1, i & 4 ? 1 : -1));
  // Corner index = x | y<<1 | z<<2; each face as two CCW triangles seen from outside.
  const uint32_t faces[6][4] = {{0, 4, 6, 2}, {1, 3, 7, 5}, {0, 1, 5, 4}, {2, 6, 7, 3}, {0, 2, 3, 1}, {4, 5, 7, 6}};
  for (const auto& f : faces)
    for (uint32_t i : {0, 1, 2, 0, 2, 3}) m.indices.push_back(f[i]);
  return m;
}

// Separate triangles, vertex i at a unique position: easy to map cooked vertices back.
SourceMesh triangle_soup(size_t triangles, const std::string& name = "Soup") {
  SourceMesh m;
  m.name = name;
  for (size_t t = 0; t < triangles; ++t) {
    const float x = static_cast<float>(t % 64) * 2.0f, y = static_cast<float>(t / 64) * 2.0f;
    for (const glm::vec3 p : {glm::vec3(x, y, 0), glm::vec3(x + 1, y, 0), glm::vec3(x, y + 1, 0)}) {
      m.indices.push_back(static_cast<uint32_t>(m.positions.size()));
      m.positions.push_back(p);
      m.normals.push_back(glm::vec3(0, 0, 1));
    }
  }
  return m;
}

// A cols x rows vertex grid, two triangles per cell, row by row.
SourceMesh grid(uint32_t cols, uint32_t rows) {
  SourceMesh m;
  m.name = "Grid";
  for (uint32_t y = 0; y < rows; ++y)
    for (uint32_t x = 0; x < cols; ++x) {
      m.positions.push_back(glm::vec3(static_cast<float>(x), static_cast<float>(y), 0.0f));
      m.normals.push_back(glm::vec3(0, 0, 1));
    }
  for (uint32_t y = 0; y + 1 < rows; ++y)
    for (uint32_t x = 0; x + 1 < cols; ++x) {
      const uint32_t a = y * cols + x, b = a + 1, c = a + cols, d = c + 1;
      for (uint32_t i : {a, b, d, a, d, c}) m.indices.push_back(i);
    }
  return m;
}

// Skins every vertex of `m` to the joints/weights given by pattern(i), with inverse binds from
// `bind` (joint -> matrix) for every joint the patterns use.
void skin(SourceMesh& m, const std::vector<std::pair<std::array<uint16_t, 4>, glm::vec4>>& patterns,
          const SourceSkeleton& skeleton) {
  m.joints.clear();
  m.weights.clear();
  std::vector<bool> used(skeleton.joints.size(), false);
  for (size_t v = 0; v < m.positions.size(); ++v) {
    const auto& [j, w] = patterns[v % patterns.size()];
    m.joints.push_back(j);
    m.weights.push_back(w);
    for (uint16_t joint : j) used[joint] = true;
  }
  m.bind.clear();
  for (size_t j = 0; j < used.size(); ++j)
    if (used[j]) m.bind.emplace_back(static_cast<uint16_t>(j), skeleton.joints[j].inverse_bind);
}

SourceScene scene_with(std::vector<SourceMesh> meshes, SourceSkeleton skeleton = {}) {
  SourceScene s;
  s.skeleton = std::move(skeleton);
  s.meshes = std::move(meshes);
  SourceMaterial mat;
  mat.name = "Default";
  s.materials.push_back(mat);
  s.materials.push_back(mat);
  s.materials.back().name = "Second";
  return s;
}

// ---------------------------------------------------------------------------------------------
// Decoding a cooked mesh (the reader's side of the layout)

struct Decoded {
  std::vector<glm::vec3> positions, normals;
  std::vector<glm::vec4> tangents;
  std::vector<glm::vec2> uv0;
  std::vector<std::array<uint32_t, 4>> slots;
  std::vector<glm::vec4> weights;                    // as floats in [0, 1]
  std::vector<std::array<uint32_t, 4>> weights_raw;  // Unorm8 values (quantized layout only)
  std::vector<glm::vec4> colors;
  std::vector<uint32_t> indices;
};

const fb::VertexAttribute* find(const CookedMesh& m, fb::VertexSemantic s) {
  for (const auto& a : m.layout)
    if (a.semantic() == s) return &a;
  return nullptr;
}

template <class T>
T read(const uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return v;
}

Decoded decode(const CookedMesh& m) {
  Decoded d;
  for (uint32_t v = 0; v < m.vertex_count; ++v) {
    const uint8_t* base = m.vertices.data() + static_cast<size_t>(v) * m.vertex_stride;
    for (const auto& a : m.layout) {
      const uint8_t* p = base + a.offset();
      switch (a.format()) {
        case fb::VertexFormat::Unorm16x4: {
          const glm::vec3 q(unorm16_to_float(read<uint16_t>(p)), unorm16_to_float(read<uint16_t>(p + 2)),
                            unorm16_to_float(read<uint16_t>(p + 4)));
          d.positions.push_back(m.position_offset + m.position_scale * q);
          break;
        }
        case fb::VertexFormat::Float32x3:
          (a.semantic() == fb::VertexSemantic::Position ? d.positions : d.normals).push_back(read<glm::vec3>(p));
          break;
        case fb::VertexFormat::Snorm16x2: {
          const Float3 n =
              octahedral_decode({snorm16_to_float(read<int16_t>(p)), snorm16_to_float(read<int16_t>(p + 2))});
          d.normals.push_back(glm::vec3(n.x, n.y, n.z));
          break;
        }
        case fb::VertexFormat::Snorm16x4: {
          const Float3 t =
              octahedral_decode({snorm16_to_float(read<int16_t>(p)), snorm16_to_float(read<int16_t>(p + 2))});
          d.tangents.push_back(glm::vec4(t.x, t.y, t.z, snorm16_to_float(read<int16_t>(p + 4))));
          break;
        }
        case fb::VertexFormat::Float32x4:
          (a.semantic() == fb::VertexSemantic::Tangent  ? d.tangents
           : a.semantic() == fb::VertexSemantic::Color0 ? d.colors
                                                        : d.weights)
              .push_back(read<glm::vec4>(p));
          break;
        case fb::VertexFormat::Float16x2:
          d.uv0.push_back(glm::vec2(half_to_float(read<uint16_t>(p)), half_to_float(read<uint16_t>(p + 2))));
          break;
        case fb::VertexFormat::Float32x2: d.uv0.push_back(read<glm::vec2>(p)); break;
        case fb::VertexFormat::Uint8x4: d.slots.push_back({p[0], p[1], p[2], p[3]}); break;
        case fb::VertexFormat::Uint16x4:
          d.slots.push_back({read<uint16_t>(p), read<uint16_t>(p + 2), read<uint16_t>(p + 4), read<uint16_t>(p + 6)});
          break;
        case fb::VertexFormat::Unorm8x4:
          if (a.semantic() == fb::VertexSemantic::Color0) {
            d.colors.push_back(glm::vec4(p[0], p[1], p[2], p[3]) / 255.0f);
            break;
          }
          d.weights_raw.push_back({p[0], p[1], p[2], p[3]});
          d.weights.push_back(glm::vec4(p[0], p[1], p[2], p[3]) / 255.0f);
          break;
      }
    }
  }
  const size_t size = m.index_format == fb::IndexFormat::Uint16 ? 2 : 4;
  for (size_t i = 0; i < m.indices.size(); i += size)
    d.indices.push_back(size == 2 ? read<uint16_t>(m.indices.data() + i) : read<uint32_t>(m.indices.data() + i));
  return d;
}

// The source vertex nearest to (p, n): positions first, normals to separate coincident corners.
size_t source_vertex(const SourceMesh& m, const std::vector<glm::vec3>& normals, glm::vec3 p, glm::vec3 n) {
  size_t best = 0;
  float best_d = INFINITY;
  for (size_t i = 0; i < m.positions.size(); ++i) {
    const glm::vec3 dp = m.positions[i] - p;
    const glm::vec3 dn = normals.empty() ? glm::vec3(0.0f) : normals[i] - n;
    const float d = glm::dot(dp, dp) * 1e4f + glm::dot(dn, dn);
    if (d < best_d) {
      best_d = d;
      best = i;
    }
  }
  return best;
}

// A 16-byte aligned copy: the verifier's alignment checks are relative to real addresses.
struct AlignedCopy {
  struct alignas(16) Block {
    uint8_t b[16];
  };
  std::vector<Block> blocks;
  size_t size = 0;
  explicit AlignedCopy(const std::vector<uint8_t>& bytes) : blocks((bytes.size() + 15) / 16), size(bytes.size()) {
    if (size) std::memcpy(blocks.data(), bytes.data(), size);
  }
  std::span<const uint8_t> span() const { return {reinterpret_cast<const uint8_t*>(blocks.data()), size}; }
};

std::vector<CookedMesh> build_ok(const SourceScene& scene, MeshOptions options = {}, MeshBuildStats* stats = nullptr,
                                 std::vector<std::string>* warnings = nullptr) {
  auto r = build_meshes(scene, options, stats, warnings);
  EXPECT_TRUE(r.ok()) << (r.ok() ? "" : r.error().message);
  return r.ok() ? std::move(r.value()) : std::vector<CookedMesh>{};
}

std::vector<uint8_t> write(const SourceScene& scene, const std::vector<CookedMesh>& meshes, WriteOptions options = {}) {
  WriteProvenance prov;
  prov.source_name = "synthetic.glb";
  prov.source_hash = 0x1234567890abcdefull;
  prov.options = "float_vertices=0";
  std::vector<CompressedClip> clips;
  for (const SourceClip& clip : scene.clips) {
    auto compressed = compress_clip(clip, scene.skeleton, scene.metres_per_unit, {});
    EXPECT_TRUE(compressed.ok()) << (compressed.ok() ? "" : compressed.error().message);
    if (compressed.ok()) clips.push_back(std::move(*compressed));
  }
  return write_ossa(scene, meshes, clips, prov, options);
}

const std::vector<std::pair<std::array<uint16_t, 4>, glm::vec4>> kSkinPatterns = {
    {{0, 0, 0, 0}, {1.0f, 0.0f, 0.0f, 0.0f}},
    {{1, 0, 0, 0}, {0.7f, 0.3f, 0.0f, 0.0f}},
    {{2, 1, 0, 0}, {1.0f / 3, 1.0f / 3, 1.0f / 3, 0.0f}},
    {{1, 2, 0, 0}, {0.5f, 0.5f, 0.0f, 0.0f}},
    {{0, 1, 2, 0}, {0.4f, 0.3f, 0.2f, 0.1f}},
};

// ---------------------------------------------------------------------------------------------
// build_meshes

TEST(MeshBuild, SkinnedBoxRoundTripsThroughTheQuantizedLayout) {
  const glm::vec3 center(0.25f, -1.0f, 3.0f), half(1.0f, 2.0f, 0.5f);
  SourceScene scene = scene_with({box_mesh(center, half, true)}, chain_skeleton(3));
  skin(scene.meshes[0], kSkinPatterns, scene.skeleton);
  const SourceMesh& src = scene.meshes[0];

  MeshBuildStats stats;
  const auto meshes = build_ok(scene, {}, &stats);
  ASSERT_EQ(meshes.size(), 1u);
  const CookedMesh& m = meshes[0];
  EXPECT_EQ(m.name, "Box");
  EXPECT_EQ(m.vertex_count, 24u);
  EXPECT_EQ(stats.source_vertices, 24u);
  EXPECT_EQ(stats.cooked_vertices, 24u);
  EXPECT_EQ(stats.triangles, 12u);
  EXPECT_EQ(stats.degenerate_triangles_removed, 0u);
  EXPECT_EQ(stats.meshes_with_generated_normals, 0u);
  EXPECT_GT(stats.acmr_before, 0.0f);
  EXPECT_LE(stats.acmr_after, stats.acmr_before);

  // Layout: Position, Normal, TexCoord0, Joints, Weights in the quantized formats; stride % 4 == 0.
  ASSERT_EQ(m.layout.size(), 5u);
  const fb::VertexSemantic order[] = {fb::VertexSemantic::Position, fb::VertexSemantic::Normal,
                                      fb::VertexSemantic::TexCoord0, fb::VertexSemantic::Joints,
                                      fb::VertexSemantic::Weights};
  const fb::VertexFormat formats[] = {fb::VertexFormat::Unorm16x4, fb::VertexFormat::Snorm16x2,
                                      fb::VertexFormat::Float16x2, fb::VertexFormat::Uint8x4,
                                      fb::VertexFormat::Unorm8x4};
  for (size_t i = 0; i < m.layout.size(); ++i) {
    EXPECT_EQ(m.layout[i].semantic(), order[i]);
    EXPECT_EQ(m.layout[i].format(), formats[i]);
    EXPECT_LE(m.layout[i].offset() + vertex_format_info(m.layout[i].format()).size, m.vertex_stride);
  }
  EXPECT_EQ(m.vertex_stride % 4, 0);
  EXPECT_EQ(m.vertices.size(), size_t{m.vertex_count} * m.vertex_stride);
  EXPECT_EQ(m.index_format, fb::IndexFormat::Uint16);

  // Bounds and the de-quantizing affine.
  for (int a = 0; a < 3; ++a) {
    EXPECT_FLOAT_EQ(m.bounds_min[a], center[a] - half[a]);
    EXPECT_FLOAT_EQ(m.bounds_max[a], center[a] + half[a]);
    EXPECT_FLOAT_EQ(m.position_offset[a], m.bounds_min[a]);
    EXPECT_FLOAT_EQ(m.position_scale[a], m.bounds_max[a] - m.bounds_min[a]);
  }

  // Palette: joints 0, 1, 2 with the skin's inverse binds.
  ASSERT_EQ(m.joints, (std::vector<uint16_t>{0, 1, 2}));
  ASSERT_EQ(m.inverse_bind.size(), 3u);
  for (size_t s = 0; s < 3; ++s) EXPECT_EQ(m.inverse_bind[s], scene.skeleton.joints[s].inverse_bind);

  const Decoded d = decode(m);
  ASSERT_EQ(d.positions.size(), 24u);
  std::vector<bool> seen(24, false);
  for (size_t v = 0; v < d.positions.size(); ++v) {
    const size_t s = source_vertex(src, src.normals, d.positions[v], d.normals[v]);
    EXPECT_FALSE(seen[s]) << "two cooked vertices map to source vertex " << s;
    seen[s] = true;
    for (int a = 0; a < 3; ++a) {
      EXPECT_NEAR(d.positions[v][a], src.positions[s][a], m.position_scale[a] / 65535.0f) << "vertex " << v;
      EXPECT_NEAR(d.normals[v][a], src.normals[s][a], 1e-3f) << "vertex " << v;
      EXPECT_GE(d.positions[v][a], m.bounds_min[a] - 1e-6f);
      EXPECT_LE(d.positions[v][a], m.bounds_max[a] + 1e-6f);
    }
    EXPECT_NEAR(d.uv0[v].x, src.uv0[s].x, 1e-3f);
    EXPECT_NEAR(d.uv0[v].y, src.uv0[s].y, 1e-3f);
    const auto& raw = d.weights_raw[v];
    EXPECT_EQ(raw[0] + raw[1] + raw[2] + raw[3], 255u) << "vertex " << v;
    for (int k = 0; k < 4; ++k) {
      EXPECT_NEAR(d.weights[v][k], src.weights[s][k], 1.0f / 255.0f + 1e-6f);
      if (src.weights[s][k] > 0.0f) {
        ASSERT_LT(d.slots[v][static_cast<size_t>(k)], m.joints.size());
        EXPECT_EQ(m.joints[d.slots[v][static_cast<size_t>(k)]], src.joints[s][static_cast<size_t>(k)])
            << "vertex " << v << " influence " << k;
      }
    }
  }

  // Submesh and indices: one submesh over every triangle, same triangles as the source (as sets
  // of source corners; the cache optimizer may rotate and reorder them).
  ASSERT_EQ(m.submeshes.size(), 1u);
  EXPECT_EQ(m.submeshes[0].first_index(), 0u);
  EXPECT_EQ(m.submeshes[0].index_count(), 36u);
  EXPECT_EQ(m.submeshes[0].material(), 0u);
  auto canonical = [](std::array<size_t, 3> t) {
    std::rotate(t.begin(), std::min_element(t.begin(), t.end()), t.end());  // keeps the winding
    return t;
  };
  std::vector<std::array<size_t, 3>> want, got;
  for (size_t i = 0; i < src.indices.size(); i += 3)
    want.push_back(canonical({src.indices[i], src.indices[i + 1], src.indices[i + 2]}));
  for (size_t i = 0; i < d.indices.size(); i += 3) {
    std::array<size_t, 3> t;
    for (size_t k = 0; k < 3; ++k) {
      const uint32_t v = d.indices[i + k];
      t[k] = source_vertex(src, src.normals, d.positions[v], d.normals[v]);
    }
    got.push_back(canonical(t));
  }
  std::sort(want.begin(), want.end());
  std::sort(got.begin(), got.end());
  EXPECT_EQ(got, want);
}

TEST(MeshBuild, VerticesMergedByQuantizationKeepTheInfluenceClassOrder) {
  // A skinned grid whose every interior vertex has a twin a rounding error away (1e-6 of a 15-unit
  // grid, far inside one unorm16 step), used by every other triangle: the twins are different
  // source vertices, so they survive the first weld and merge only in the last one, once quantized.
  // That weld must keep the vertices ordered by influence class (skin_cpu's range loops).
  const uint32_t cols = 16;
  SourceScene scene = scene_with({grid(cols, cols)}, chain_skeleton(3));
  SourceMesh& g = scene.meshes[0];
  skin(g, kSkinPatterns, scene.skeleton);
  const size_t n = g.positions.size();
  std::vector<uint32_t> twin(n);
  for (size_t v = 0; v < n; ++v) {
    twin[v] = static_cast<uint32_t>(v);
    const uint32_t x = static_cast<uint32_t>(v % cols), y = static_cast<uint32_t>(v / cols);
    if (x == 0 || y == 0 || x + 1 == cols || y + 1 == cols) continue;  // the bounds stay as they are
    twin[v] = static_cast<uint32_t>(g.positions.size());
    g.positions.push_back(g.positions[v] + glm::vec3(1e-6f, 1e-6f, 0.0f));
    g.normals.push_back(g.normals[v]);
    g.joints.push_back(g.joints[v]);
    g.weights.push_back(g.weights[v]);
  }
  for (size_t t = 0; t < g.indices.size() / 3; t += 2)
    for (size_t c = 0; c < 3; ++c) g.indices[3 * t + c] = twin[g.indices[3 * t + c]];
  const size_t triangles = g.indices.size() / 3;

  MeshBuildStats stats;
  const auto meshes = build_ok(scene, {}, &stats);
  ASSERT_EQ(meshes.size(), 1u);
  const CookedMesh& m = meshes[0];
  EXPECT_EQ(stats.source_vertices, g.positions.size());
  EXPECT_EQ(m.vertex_count, n) << "every twin merged with its vertex";
  const Decoded d = decode(m);
  ASSERT_EQ(d.weights_raw.size(), n);
  ASSERT_EQ(d.indices.size(), 3 * triangles);
  int last = 0;
  std::array<size_t, 5> per_class{};
  for (size_t v = 0; v < n; ++v) {
    const auto& w = d.weights_raw[v];
    const int c = influence_class(w[0] | w[1] << 8 | w[2] << 16 | w[3] << 24);
    ASSERT_GE(c, last) << "vertex " << v;
    ++per_class[static_cast<size_t>(c)];
    last = c;
  }
  EXPECT_GT(per_class[0], 0u);
  EXPECT_GT(per_class[4], 0u);
}

TEST(MeshBuild, WeightsSumTo255ByLargestRemainder) {
  SourceScene scene = scene_with({triangle_soup(40)}, chain_skeleton(4));
  SourceMesh& src = scene.meshes[0];
  // Hand-checked patterns first, then pseudo-random ones.
  std::vector<std::pair<std::array<uint16_t, 4>, glm::vec4>> patterns = {
      {{0, 1, 2, 3}, {1.0f / 3, 1.0f / 3, 1.0f / 3, 0.0f}},  // 85 85 85 0
      {{1, 2, 0, 0}, {0.5f, 0.5f, 0.0f, 0.0f}},              // 127.5 each: the tie goes to the first
      {{2, 0, 0, 0}, {0.0f, 0.0f, 0.0f, 0.0f}},              // no weight: all on the first influence
      {{0, 1, 2, 3}, {0.25f, 0.25f, 0.25f, 0.25f}},          // 63.75 each
      {{3, 2, 1, 0}, {0.9f, 0.05f, 0.03f, 0.02f}},           // 229.5 12.75 7.65 5.1
  };
  const std::array<uint32_t, 4> expected[] = {
      {85, 85, 85, 0}, {128, 127, 0, 0}, {255, 0, 0, 0}, {64, 64, 64, 63}, {229, 13, 8, 5}};
  Lcg rng{42};
  while (patterns.size() < src.positions.size()) {
    glm::vec4 w(rng.unit(), rng.unit(), rng.unit(), rng.unit());
    if (rng.next() % 3 == 0) w.w = 0.0f;
    w /= (w.x + w.y + w.z + w.w);
    patterns.push_back({{static_cast<uint16_t>(rng.next() % 4), static_cast<uint16_t>(rng.next() % 4),
                         static_cast<uint16_t>(rng.next() % 4), static_cast<uint16_t>(rng.next() % 4)},
                        w});
  }
  skin(src, patterns, scene.skeleton);

  std::vector<std::string> warnings;
  const auto meshes = build_ok(scene, {}, nullptr, &warnings);
  ASSERT_EQ(meshes.size(), 1u);
  const CookedMesh& m = meshes[0];
  const Decoded d = decode(m);
  ASSERT_EQ(d.positions.size(), src.positions.size());
  for (size_t v = 0; v < d.positions.size(); ++v) {
    const size_t s = source_vertex(src, {}, d.positions[v], {});
    const auto& raw = d.weights_raw[v];
    EXPECT_EQ(raw[0] + raw[1] + raw[2] + raw[3], 255u) << "source vertex " << s;
    if (s < std::size(expected)) {
      EXPECT_EQ(raw, expected[s]) << "source vertex " << s;
    } else {
      for (int k = 0; k < 4; ++k) EXPECT_LT(std::fabs(d.weights[v][k] - src.weights[s][k]), 1.0f / 255.0f);
    }
    // Slots name the right joints, including the weightless vertex's first influence.
    for (size_t k = 0; k < 4; ++k)
      if (raw[k] > 0) {
        EXPECT_EQ(m.joints[d.slots[v][k]], src.joints[s][k]) << "source vertex " << s;
      }
  }
  EXPECT_TRUE(std::any_of(warnings.begin(), warnings.end(),
                          [](const std::string& w) { return w.find("no skin weight") != std::string::npos; }));
}

TEST(MeshBuild, DegenerateTrianglesAreRemovedAndCounted) {
  SourceMesh m = triangle_soup(2, "Sliver");
  const auto n = static_cast<uint32_t>(m.positions.size());
  m.positions.push_back({10, 0, 0});  // n: on a line with n+1 and n+2
  m.positions.push_back({11, 0, 0});
  m.positions.push_back({12, 0, 0});
  m.positions.push_back({0, 0, 0});  // n+3: same position as vertex 0
  for (int i = 0; i < 4; ++i) m.normals.push_back({0, 0, 1});
  for (uint32_t i : {0u, 0u, 1u,       // repeated index
                     n, n + 1, n + 2,  // zero area: collinear
                     0u, n + 3, 1u})   // zero area: two corners at one position
    m.indices.push_back(i);
  MeshBuildStats stats;
  std::vector<std::string> warnings;
  const auto meshes = build_ok(scene_with({m}), {}, &stats, &warnings);
  ASSERT_EQ(meshes.size(), 1u);
  EXPECT_EQ(stats.degenerate_triangles_removed, 3u);
  EXPECT_EQ(stats.triangles, 2u);
  EXPECT_EQ(meshes[0].submeshes[0].index_count(), 6u);
  // Vertices only the degenerate triangles used are gone after the fetch optimizer.
  EXPECT_EQ(meshes[0].vertex_count, 6u);
  EXPECT_TRUE(std::any_of(warnings.begin(), warnings.end(), [](const std::string& w) {
    return w.find("'Sliver'") != std::string::npos && w.find("3 degenerate") != std::string::npos;
  }));

  // A mesh with nothing but degenerate triangles is skipped, with a warning.
  SourceMesh only_bad = m;
  only_bad.name = "AllBad";
  only_bad.indices.erase(only_bad.indices.begin(), only_bad.indices.begin() + 6);
  warnings.clear();
  const auto none = build_ok(scene_with({only_bad}), {}, &stats, &warnings);
  EXPECT_TRUE(none.empty());
  EXPECT_EQ(stats.degenerate_triangles_removed, 3u);
}

TEST(MeshBuild, MissingNormalsAreGeneratedUnitAndOutward) {
  const glm::vec3 center(1.0f, 2.0f, -3.0f), half(0.5f, 1.0f, 2.0f);
  for (const bool shared : {false, true}) {
    SCOPED_TRACE(shared ? "8 shared corners" : "24 face corners");
    SourceMesh src = shared ? shared_corner_box(center, half) : box_mesh(center, half, false);
    // Face corners stay apart only where they differ (welding merges equal ones): a UV island per
    // face, as a texture seam on every edge would have it.
    if (!shared)
      for (size_t v = 0; v < src.uv0.size(); ++v) src.uv0[v].x += static_cast<float>(v / 4);
    MeshOptions options;
    options.float_vertices = true;  // read the generated normals without octahedral rounding
    MeshBuildStats stats;
    const auto meshes = build_ok(scene_with({src}), options, &stats);
    ASSERT_EQ(meshes.size(), 1u);
    EXPECT_EQ(stats.meshes_with_generated_normals, 1u);
    const Decoded d = decode(meshes[0]);
    ASSERT_EQ(d.normals.size(), src.positions.size());
    for (size_t v = 0; v < d.normals.size(); ++v) {
      const glm::vec3 n = d.normals[v], p = d.positions[v] - center;
      EXPECT_NEAR(glm::length(n), 1.0f, 1e-5f);
      EXPECT_GT(glm::dot(n, p), 0.0f) << "normal points inward at vertex " << v;
      if (shared) {
        // Area weighting on a box: each corner's normal leans toward the faces with larger area,
        // but every component keeps the corner's sign.
        for (int a = 0; a < 3; ++a) EXPECT_GT(n[a] * p[a], 0.0f);
      } else {
        // A face corner touches only its face's two triangles: exactly that face's normal, an
        // axis the corner lies on the face of.
        int axis = 0;
        for (int a = 1; a < 3; ++a)
          if (std::fabs(n[a]) > std::fabs(n[axis])) axis = a;
        EXPECT_NEAR(std::fabs(n[axis]), 1.0f, 1e-6f);
        EXPECT_NEAR(std::fabs(p[axis]), half[axis], 1e-5f);
      }
    }
  }

  // Non-manifold input (three triangles on one edge) still gets unit normals, without an error.
  SourceMesh fin;
  fin.name = "Fin";
  fin.positions = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}};
  fin.indices = {0, 1, 2, 1, 0, 3, 0, 1, 4};
  MeshOptions options;
  options.float_vertices = true;
  const auto meshes = build_ok(scene_with({fin}), options);
  ASSERT_EQ(meshes.size(), 1u);
  for (const glm::vec3& n : decode(meshes[0]).normals) EXPECT_NEAR(glm::length(n), 1.0f, 1e-5f);
}

TEST(MeshBuild, GroupsByAttributeSetInFirstAppearanceOrder) {
  SourceMesh a = triangle_soup(3, "A");
  a.uv0.assign(a.positions.size(), glm::vec2(0.25f));
  SourceMesh b = triangle_soup(4, "B");  // no uv0: another group
  SourceMesh c = triangle_soup(5, "C");
  c.uv0.assign(c.positions.size(), glm::vec2(0.75f));
  c.normals.clear();  // normals get generated, so C still joins A
  c.material = 1;
  const auto meshes = build_ok(scene_with({a, b, c}));
  ASSERT_EQ(meshes.size(), 2u);
  EXPECT_EQ(meshes[0].name, "A");
  EXPECT_EQ(meshes[1].name, "B");
  ASSERT_EQ(meshes[0].submeshes.size(), 2u);
  EXPECT_EQ(meshes[0].submeshes[0].first_index(), 0u);
  EXPECT_EQ(meshes[0].submeshes[0].index_count(), 9u);
  EXPECT_EQ(meshes[0].submeshes[0].material(), 0u);
  EXPECT_EQ(meshes[0].submeshes[1].first_index(), 9u);
  EXPECT_EQ(meshes[0].submeshes[1].index_count(), 15u);
  EXPECT_EQ(meshes[0].submeshes[1].material(), 1u);
  EXPECT_EQ(meshes[0].vertex_count, 24u);
  ASSERT_EQ(meshes[1].submeshes.size(), 1u);
  EXPECT_EQ(meshes[1].vertex_count, 12u);
  EXPECT_EQ(find(meshes[1], fb::VertexSemantic::TexCoord0), nullptr);
  EXPECT_EQ(find(meshes[1], fb::VertexSemantic::Joints), nullptr);
  EXPECT_TRUE(meshes[1].joints.empty());
  EXPECT_TRUE(meshes[1].inverse_bind.empty());

  // Each submesh's triangles use only that submesh's vertices (UVs tell A's from C's).
  const Decoded d = decode(meshes[0]);
  for (size_t k = 0; k < 2; ++k) {
    const auto& sm = meshes[0].submeshes[k];
    for (uint32_t i = sm.first_index(); i < sm.first_index() + sm.index_count(); ++i)
      EXPECT_FLOAT_EQ(d.uv0[d.indices[i]].x, k == 0 ? 0.25f : 0.75f);
  }
}

// Colours do not split a group: a member without them is white in the merged mesh, and every
// colour stays with its vertex through the cache and fetch reordering, in both layouts.
TEST(MeshBuild, VertexColoursFollowTheirVerticesAndMembersWithoutAreWhite) {
  SourceMesh a = triangle_soup(40, "Painted");
  for (size_t v = 0; v < a.positions.size(); ++v)
    a.colors.push_back(glm::vec4(static_cast<float>(v % 7) / 6.0f, static_cast<float>(v % 5) / 4.0f, 0.5f, 1.0f));
  SourceMesh b = triangle_soup(10, "Plain");
  for (auto& p : b.positions) p.z = 3.0f;  // tell them apart
  for (const bool float_vertices : {false, true}) {
    MeshOptions options;
    options.float_vertices = float_vertices;
    const auto meshes = build_ok(scene_with({a, b}), options);
    ASSERT_EQ(meshes.size(), 1u) << "colours alone do not split the mesh";
    const fb::VertexAttribute* colour = find(meshes[0], fb::VertexSemantic::Color0);
    ASSERT_NE(colour, nullptr);
    EXPECT_EQ(colour->format(), float_vertices ? fb::VertexFormat::Float32x4 : fb::VertexFormat::Unorm8x4);
    const Decoded d = decode(meshes[0]);
    ASSERT_EQ(d.colors.size(), d.positions.size());
    const float e = float_vertices ? 0.0f : 0.5f / 255.0f + 1e-6f;
    for (size_t v = 0; v < d.positions.size(); ++v) {
      glm::vec4 want(1.0f);
      if (d.positions[v].z < 1.0f) {
        size_t s = 0;
        while (s < a.positions.size() && glm::length(a.positions[s] - d.positions[v]) > 1e-3f) ++s;
        ASSERT_LT(s, a.positions.size());
        // triangle_soup repeats positions per triangle only within one triangle: the first match
        // is this vertex's source when the soup's triangles do not share corners.
        want = a.colors[s];
      }
      for (int k = 0; k < 4; ++k) EXPECT_NEAR(d.colors[v][k], want[k], e) << "vertex " << v;
    }
  }
}

TEST(MeshBuild, SameJointWithDifferentInverseBindsGetsSeparateSlots) {
  const SourceSkeleton skeleton = chain_skeleton(3);
  SourceMesh a = triangle_soup(2, "A"), b = triangle_soup(2, "B");
  for (auto& p : b.positions) p.z = 5.0f;  // tell them apart
  skin(a, {{{2, 0, 0, 0}, {1, 0, 0, 0}}, {{1, 0, 0, 0}, {1, 0, 0, 0}}}, skeleton);
  skin(b, {{{1, 0, 0, 0}, {1, 0, 0, 0}}, {{2, 0, 0, 0}, {1, 0, 0, 0}}}, skeleton);
  const glm::mat4 other = glm::translate(glm::mat4(1.0f), glm::vec3(7, 0, 0));
  for (auto& [joint, matrix] : b.bind)
    if (joint == 1) matrix = other;  // B's skin places joint 1 differently; joint 2 is shared
  const auto meshes = build_ok(scene_with({a, b}, skeleton));
  ASSERT_EQ(meshes.size(), 1u);
  const CookedMesh& m = meshes[0];
  // Ordered by joint, then first appearance: (1, A's), (1, B's), (2, shared).
  ASSERT_EQ(m.joints, (std::vector<uint16_t>{1, 1, 2}));
  EXPECT_EQ(m.inverse_bind[0], skeleton.joints[1].inverse_bind);
  EXPECT_EQ(m.inverse_bind[1], other);
  EXPECT_EQ(m.inverse_bind[2], skeleton.joints[2].inverse_bind);
  const Decoded d = decode(m);
  for (size_t v = 0; v < d.positions.size(); ++v) {
    const bool in_b = d.positions[v].z > 1.0f;
    const SourceMesh& src = in_b ? b : a;
    const size_t s = source_vertex(src, {}, d.positions[v], {});
    const uint16_t joint = src.joints[s][0];
    const uint32_t slot = d.slots[v][0];
    EXPECT_EQ(m.joints[slot], joint);
    EXPECT_EQ(m.inverse_bind[slot], joint == 1 && in_b ? other : skeleton.joints[joint].inverse_bind);
  }
}

TEST(MeshBuild, MoreThan256SlotsUseUint16Joints) {
  for (const size_t joints : {256u, 300u}) {
    SCOPED_TRACE(std::to_string(joints) + " joints");
    const SourceSkeleton skeleton = chain_skeleton(joints);
    SourceMesh src = triangle_soup(joints);
    std::vector<std::pair<std::array<uint16_t, 4>, glm::vec4>> patterns;
    for (size_t v = 0; v < src.positions.size(); ++v)
      patterns.push_back({{static_cast<uint16_t>(v / 3), 0, 0, 0}, {1, 0, 0, 0}});  // triangle t -> joint t
    skin(src, patterns, skeleton);
    for (const bool float_vertices : {false, true}) {
      MeshOptions options;
      options.float_vertices = float_vertices;
      const auto meshes = build_ok(scene_with({src}, skeleton), options);
      ASSERT_EQ(meshes.size(), 1u);
      const CookedMesh& m = meshes[0];
      ASSERT_EQ(m.joints.size(), joints);
      const fb::VertexAttribute* attr = find(m, fb::VertexSemantic::Joints);
      ASSERT_NE(attr, nullptr);
      EXPECT_EQ(attr->format(),
                joints > 256 || float_vertices ? fb::VertexFormat::Uint16x4 : fb::VertexFormat::Uint8x4);
      const Decoded d = decode(m);
      for (size_t v = 0; v < d.positions.size(); ++v) {
        const size_t s = source_vertex(src, {}, d.positions[v], {});
        ASSERT_LT(d.slots[v][0], m.joints.size());
        EXPECT_EQ(m.joints[d.slots[v][0]], s / 3);
      }
    }
  }
}

TEST(MeshBuild, IndexFormatFollowsVertexCount) {
  // 255 x 257 = 65535 vertices fit 16-bit indices; 256 x 256 = 65536 need 32-bit.
  for (const auto& [cols, rows, format] :
       {std::tuple{255u, 257u, fb::IndexFormat::Uint16}, std::tuple{256u, 256u, fb::IndexFormat::Uint32}}) {
    const auto meshes = build_ok(scene_with({grid(cols, rows)}));
    ASSERT_EQ(meshes.size(), 1u);
    const CookedMesh& m = meshes[0];
    EXPECT_EQ(m.vertex_count, cols * rows);
    EXPECT_EQ(m.index_format, format);
    const size_t index_count = size_t{cols - 1} * (rows - 1) * 6;
    EXPECT_EQ(m.indices.size(), index_count * (format == fb::IndexFormat::Uint16 ? 2 : 4));
    const Decoded d = decode(m);
    EXPECT_LT(*std::max_element(d.indices.begin(), d.indices.end()), m.vertex_count);
  }
}

TEST(MeshBuild, OptimizationLowersAcmrAndKeepsTriangles) {
  SourceMesh src = grid(64, 64);
  // Shuffle the triangles so the source order is cache-hostile.
  Lcg rng{7};
  const size_t tris = src.indices.size() / 3;
  for (size_t t = tris - 1; t > 0; --t) {
    const size_t o = rng.next() % (t + 1);
    for (size_t k = 0; k < 3; ++k) std::swap(src.indices[3 * t + k], src.indices[3 * o + k]);
  }
  MeshBuildStats optimized, plain;
  MeshOptions off;
  off.optimize = false;
  const auto a = build_ok(scene_with({src}), {}, &optimized);
  const auto b = build_ok(scene_with({src}), off, &plain);
  ASSERT_EQ(a.size(), 1u);
  ASSERT_EQ(b.size(), 1u);
  EXPECT_FLOAT_EQ(optimized.acmr_before, plain.acmr_before);
  EXPECT_FLOAT_EQ(plain.acmr_after, plain.acmr_before);
  EXPECT_LT(optimized.acmr_after, 0.8f * optimized.acmr_before);
  EXPECT_EQ(optimized.triangles, static_cast<uint32_t>(tris));
  // Vertex fetch order: vertices appear in the index buffer in increasing first-use order.
  const Decoded d = decode(a[0]);
  uint32_t next = 0;
  for (uint32_t i : d.indices) {
    EXPECT_LE(i, next);
    if (i == next) ++next;
  }
  EXPECT_EQ(next, a[0].vertex_count);
  std::printf("grid 64x64 shuffled: ACMR %.3f -> %.3f\n", optimized.acmr_before, optimized.acmr_after);
}

TEST(MeshBuild, FloatVerticesAreExact) {
  SourceScene scene = scene_with({box_mesh({0.1f, 0.2f, 0.3f}, {1.5f, 0.25f, 2.0f}, true)}, chain_skeleton(3));
  SourceMesh& src = scene.meshes[0];
  skin(src, kSkinPatterns, scene.skeleton);
  for (size_t v = 0; v < src.positions.size(); ++v)
    src.tangents.push_back(glm::vec4(0.0f, 0.6f, 0.8f, v % 2 ? 1.0f : -1.0f));
  MeshOptions options;
  options.float_vertices = true;
  const auto meshes = build_ok(scene, options);
  ASSERT_EQ(meshes.size(), 1u);
  const CookedMesh& m = meshes[0];
  EXPECT_EQ(m.position_offset, glm::vec3(0.0f));
  EXPECT_EQ(m.position_scale, glm::vec3(1.0f));
  const fb::VertexFormat formats[] = {fb::VertexFormat::Float32x3, fb::VertexFormat::Float32x3,
                                      fb::VertexFormat::Float32x4, fb::VertexFormat::Float32x2,
                                      fb::VertexFormat::Uint16x4,  fb::VertexFormat::Float32x4};
  ASSERT_EQ(m.layout.size(), 6u);
  for (size_t i = 0; i < 6; ++i) EXPECT_EQ(m.layout[i].format(), formats[i]);
  const Decoded d = decode(m);
  for (size_t v = 0; v < d.positions.size(); ++v) {
    const size_t s = source_vertex(src, src.normals, d.positions[v], d.normals[v]);
    EXPECT_EQ(d.positions[v], src.positions[s]);
    EXPECT_EQ(d.normals[v], src.normals[s]);
    EXPECT_EQ(d.tangents[v], src.tangents[s]);
    EXPECT_EQ(d.uv0[v], src.uv0[s]);
    EXPECT_EQ(d.weights[v], src.weights[s]);
    for (size_t k = 0; k < 4; ++k)
      if (src.weights[s][static_cast<int>(k)] > 0.0f) {
        EXPECT_EQ(m.joints[d.slots[v][k]], src.joints[s][k]);
      }
  }

  // The same mesh quantized: tangent direction through the octahedral code, sign in z.
  const auto quantized = build_ok(scene);
  ASSERT_EQ(quantized.size(), 1u);
  const fb::VertexAttribute* tangent = find(quantized[0], fb::VertexSemantic::Tangent);
  ASSERT_NE(tangent, nullptr);
  EXPECT_EQ(tangent->format(), fb::VertexFormat::Snorm16x4);
  const Decoded q = decode(quantized[0]);
  for (size_t v = 0; v < q.positions.size(); ++v) {
    const size_t s = source_vertex(src, src.normals, q.positions[v], q.normals[v]);
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(q.tangents[v][a], src.tangents[s][a], 1e-3f);
    EXPECT_EQ(q.tangents[v].w, src.tangents[s].w);  // ±32767 decodes to exactly ±1
  }
}

TEST(MeshBuild, ZeroExtentAxisUsesScaleOne) {
  SourceMesh quad;
  quad.name = "Quad";
  quad.positions = {{-1, -2, 0.5f}, {1, -2, 0.5f}, {1, 2, 0.5f}, {-1, 2, 0.5f}};
  quad.normals.assign(4, glm::vec3(0, 0, 1));
  quad.indices = {0, 1, 2, 0, 2, 3};
  const auto meshes = build_ok(scene_with({quad}));
  ASSERT_EQ(meshes.size(), 1u);
  EXPECT_EQ(meshes[0].position_offset, glm::vec3(-1, -2, 0.5f));
  EXPECT_EQ(meshes[0].position_scale, glm::vec3(2, 4, 1));
  for (const glm::vec3& p : decode(meshes[0]).positions) EXPECT_EQ(p.z, 0.5f);
}

TEST(MeshBuild, BadInputIsAnErrorNamingTheMesh) {
  SourceMesh m = triangle_soup(2, "Broken");
  m.indices[4] = 99;
  auto r = build_meshes(scene_with({m}), {}, nullptr, nullptr);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("'Broken'"), std::string::npos) << r.error().message;
  EXPECT_NE(r.error().message.find("99"), std::string::npos) << r.error().message;

  SourceMesh short_normals = triangle_soup(2, "ShortNormals");
  short_normals.normals.pop_back();
  r = build_meshes(scene_with({short_normals}), {}, nullptr, nullptr);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("'ShortNormals'"), std::string::npos) << r.error().message;

  SourceMesh outside = triangle_soup(1, "OutsideRig");
  const SourceSkeleton two = chain_skeleton(2);
  skin(outside, {{{0, 0, 0, 0}, {1, 0, 0, 0}}}, two);
  outside.joints[1] = {5, 0, 0, 0};
  r = build_meshes(scene_with({outside}, two), {}, nullptr, nullptr);
  ASSERT_FALSE(r.ok());
  EXPECT_NE(r.error().message.find("'OutsideRig'"), std::string::npos) << r.error().message;
}

// ---------------------------------------------------------------------------------------------
// write_ossa

SourceScene full_scene() {
  SourceScene scene =
      scene_with({box_mesh({0, 1, 0}, {0.5f, 1, 0.25f}, true), triangle_soup(3, "Soup")}, chain_skeleton(3));
  skin(scene.meshes[0], kSkinPatterns, scene.skeleton);
  scene.meshes[1].material = 1;
  scene.metres_per_unit = 0.01f;
  SourceClip clip;
  clip.name = "Wave";
  clip.duration = 1.0f;
  clip.sample_rate = 30.0f;
  SourceTrack track;
  track.joint = 1;
  track.rotation_times = {0.0f, 1.0f};
  track.rotations = {glm::quat(1, 0, 0, 0), glm::quat(0.7071068f, 0, 0, 0.7071068f)};
  clip.tracks.push_back(track);
  scene.clips.push_back(clip);
  SourceTexture embedded;
  embedded.mime = "image/png";
  embedded.data = {0x89, 'P', 'N', 'G', 1, 2, 3, 4, 5, 6, 7, 8, 9};  // 13 bytes: alignment must be forced
  SourceTexture external;
  external.role = TextureRole::Normal;
  external.path = "textures/normal.png";
  scene.materials[0].textures = {embedded, external};
  return scene;
}

TEST(WriteOssa, WritesAFileTheRuntimeAccepts) {
  const SourceScene scene = full_scene();
  const auto meshes = build_ok(scene);
  ASSERT_EQ(meshes.size(), 2u);
  const std::vector<uint8_t> bytes = write(scene, meshes);
  const AlignedCopy copy(bytes);

  flatbuffers::Verifier verifier(copy.span().data(), copy.span().size());
  ASSERT_TRUE(fb::VerifyFileBuffer(verifier));
  ASSERT_TRUE(flatbuffers::BufferHasIdentifier(bytes.data(), kFileIdentifier));
  const Status verified = verify_buffer(copy.span(), "synthetic");
  ASSERT_TRUE(verified.ok()) << verified.message();
  auto asset = Asset::from_bytes(bytes, "synthetic");
  ASSERT_TRUE(asset.ok()) << asset.error().message;

  const fb::File& file = asset->file();
  EXPECT_EQ(file.version(), kFormatVersion);
  EXPECT_FLOAT_EQ(file.metres_per_unit(), 0.01f);

  // Skeleton: names, parents, bind pose, column-major inverse binds, hash.
  const SkeletonView sk = asset->skeleton();
  ASSERT_FALSE(sk.empty());
  ASSERT_EQ(sk.joint_count(), 3u);
  for (size_t j = 0; j < 3; ++j) {
    EXPECT_EQ(sk.joint_name(j), scene.skeleton.joints[j].name);
    EXPECT_EQ(sk.parents()[j], scene.skeleton.joints[j].parent);
    EXPECT_FLOAT_EQ(sk.bind_translations()[j].y(), scene.skeleton.joints[j].translation.y);
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r)
        EXPECT_EQ(sk.inverse_bind()[j].m()->Get(static_cast<flatbuffers::uoffset_t>(c * 4 + r)),
                  scene.skeleton.joints[j].inverse_bind[c][r]);
  }
  std::vector<std::string_view> names;
  std::vector<int16_t> parents;
  for (const auto& j : scene.skeleton.joints) {
    names.push_back(j.name);
    parents.push_back(static_cast<int16_t>(j.parent));
  }
  EXPECT_EQ(sk.hash(), skeleton_hash(names, parents));
  EXPECT_EQ(sk.hash(), skeleton_hash_of(scene.skeleton));

  // Meshes: the cooked bytes, verbatim, at 16-byte aligned offsets from the buffer start.
  ASSERT_EQ(asset->mesh_count(), 2u);
  for (size_t i = 0; i < 2; ++i) {
    const fb::Mesh& fm = *file.meshes()->Get(static_cast<flatbuffers::uoffset_t>(i));
    const CookedMesh& cm = meshes[i];
    EXPECT_EQ(fm.name()->str(), cm.name);
    EXPECT_EQ(fm.vertex_count(), cm.vertex_count);
    EXPECT_EQ(fm.vertex_stride(), cm.vertex_stride);
    EXPECT_EQ(fm.index_format(), cm.index_format);
    ASSERT_EQ(fm.vertices()->size(), cm.vertices.size());
    EXPECT_EQ(std::memcmp(fm.vertices()->Data(), cm.vertices.data(), cm.vertices.size()), 0);
    ASSERT_EQ(fm.indices()->size(), cm.indices.size());
    EXPECT_EQ(std::memcmp(fm.indices()->Data(), cm.indices.data(), cm.indices.size()), 0);
    EXPECT_EQ(fm.submeshes()->size(), cm.submeshes.size());
    EXPECT_EQ(fm.layout()->size(), cm.layout.size());
    EXPECT_EQ(fm.joints()->size(), cm.joints.size());
    EXPECT_EQ(fm.inverse_bind()->size(), cm.inverse_bind.size());
    EXPECT_FLOAT_EQ(fm.position_scale()->x(), cm.position_scale.x);
    EXPECT_FLOAT_EQ(fm.bounds_max()->y(), cm.bounds_max.y);

    const uint8_t* start = asset->bytes().data();
    EXPECT_EQ((fm.vertices()->Data() - start) % 16, 0) << "mesh " << i << " vertices";
    EXPECT_EQ((fm.indices()->Data() - start) % 16, 0) << "mesh " << i << " indices";
    // The same offsets in the writer's own output, independent of where the runtime copied it.
    const auto* raw = fb::GetFile(bytes.data())->meshes()->Get(static_cast<flatbuffers::uoffset_t>(i));
    EXPECT_EQ((raw->vertices()->Data() - bytes.data()) % 16, 0);
    EXPECT_EQ((raw->indices()->Data() - bytes.data()) % 16, 0);
  }

  // Clip: tagged with the rig it addresses; only joint 1's rotation moves, everything else is the
  // bind pose and stored as nothing; key values 16-byte aligned and padded for 64-bit reads.
  ASSERT_EQ(asset->clip_count(), 1u);
  const ClipView clip = asset->clip(0);
  EXPECT_EQ(clip.name(), "Wave");
  EXPECT_EQ(clip.skeleton_hash(), sk.hash());
  EXPECT_EQ(clip.joint_count(), 3u);
  EXPECT_EQ(clip.frame_count(), 31u);
  EXPECT_FLOAT_EQ(clip.sample_rate(), 30.0f);
  EXPECT_FLOAT_EQ(clip.duration(), 1.0f);
  EXPECT_TRUE(clip.constants().empty());
  ASSERT_EQ(clip.animated().size(), 1u);
  EXPECT_EQ(clip.animated()[0].joint(), 1u);
  EXPECT_EQ(clip.animated()[0].channel(), fb::Channel::Rotation);
  EXPECT_GE(clip.animated()[0].key_count(), 2u);
  EXPECT_GE(clip.key_values().size(), kKeyValuePadding);
  EXPECT_EQ((clip.key_values().data() - asset->bytes().data()) % 16, 0);
  ASSERT_NE(clip.compression(), nullptr);
  EXPECT_LE(clip.compression()->max_error(), clip.compression()->tolerance());
  EXPECT_EQ(clip.compression()->raw_bytes(), 10u * 4u * 3u * 31u);
  EXPECT_EQ(clip.root_motion(), nullptr);
  EXPECT_TRUE(check_clip_binding(clip, sk, "synthetic").ok());

  // Materials and textures: embedded data aligned, external path kept.
  ASSERT_EQ(asset->material_count(), 2u);
  const fb::Material& mat = asset->material(0);
  EXPECT_EQ(mat.name()->str(), "Default");
  ASSERT_EQ(mat.textures()->size(), 2u);
  const fb::Texture& tex = *mat.textures()->Get(0);
  EXPECT_EQ(tex.mime()->str(), "image/png");
  ASSERT_EQ(tex.data()->size(), 13u);
  EXPECT_EQ((tex.data()->Data() - asset->bytes().data()) % 16, 0);
  EXPECT_EQ(mat.textures()->Get(1)->role(), fb::TextureRole::Normal);
  EXPECT_EQ(mat.textures()->Get(1)->path()->str(), "textures/normal.png");
  EXPECT_EQ(mat.textures()->Get(1)->data(), nullptr);

  // Provenance.
  ASSERT_NE(file.provenance(), nullptr);
  EXPECT_EQ(file.provenance()->source_name()->str(), "synthetic.glb");
  EXPECT_EQ(file.provenance()->source_hash(), 0x1234567890abcdefull);
  EXPECT_EQ(file.provenance()->cooker_version()->str(), kCookerVersion);
  EXPECT_EQ(file.provenance()->options()->str(), "float_vertices=0");
}

TEST(WriteOssa, SameInputGivesSameBytes) {
  for (const bool float_vertices : {false, true}) {
    const SourceScene scene = full_scene();
    MeshOptions options;
    options.float_vertices = float_vertices;
    const std::vector<uint8_t> first = write(scene, build_ok(scene, options));
    const SourceScene again = full_scene();
    const std::vector<uint8_t> second = write(again, build_ok(again, options));
    EXPECT_EQ(first, second);
    EXPECT_FALSE(first.empty());
  }
}

TEST(WriteOssa, ClipOnlyFileOmitsTheSkeletonButKeepsTheRigHash) {
  SourceScene scene = full_scene();
  scene.meshes.clear();
  scene.materials.clear();
  WriteOptions options;
  options.include_skeleton = false;
  const std::vector<uint8_t> bytes = write(scene, {}, options);
  const AlignedCopy copy(bytes);
  flatbuffers::Verifier verifier(copy.span().data(), copy.span().size());
  ASSERT_TRUE(fb::VerifyFileBuffer(verifier));
  const fb::File* file = fb::GetFile(copy.span().data());
  EXPECT_EQ(file->skeleton(), nullptr);
  ASSERT_EQ(file->clips()->size(), 1u);
  EXPECT_EQ(file->clips()->Get(0)->skeleton_hash(), skeleton_hash_of(scene.skeleton));
  EXPECT_EQ(file->clips()->Get(0)->joint_count(), 3u);
  const Status verified = verify_buffer(copy.span(), "clip-only");
  EXPECT_TRUE(verified.ok()) << verified.message();
}

TEST(WriteOssa, LargeMeshWithUint32IndicesVerifies) {
  const SourceScene scene = scene_with({grid(300, 300)});
  const auto meshes = build_ok(scene);
  ASSERT_EQ(meshes.size(), 1u);
  EXPECT_EQ(meshes[0].vertex_count, 90000u);
  EXPECT_EQ(meshes[0].index_format, fb::IndexFormat::Uint32);
  const std::vector<uint8_t> bytes = write(scene, meshes);
  const AlignedCopy copy(bytes);
  const Status verified = verify_buffer(copy.span(), "grid");
  EXPECT_TRUE(verified.ok()) << verified.message();
}

}  // namespace
