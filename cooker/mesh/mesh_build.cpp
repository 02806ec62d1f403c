// mesh_build.cpp — SourceMesh list -> CookedMesh list: clean, merge, optimize, quantize (mesh_build.h);
// stages 1-4 here, stages 5-7 (one group into one CookedMesh) in mesh_group.cpp.
//
// The stages, in order, per scene:
//   1. validate each source mesh (stream sizes, indices < vertex count, finite positions, joints
//      inside the skeleton, material inside the scene) — an error names the mesh;
//   2. weld it: vertices equal in every stream become one (meshoptimizer's remap, bit for bit);
//   3. clean it: drop degenerate triangles (a repeated index, or no area at float precision), and
//      generate area-weighted vertex normals with OpenMesh when the source had none;
//   4. group meshes by attribute set (tangents, uv0, skinned) in order of first appearance and
//      concatenate each group into one vertex/index buffer, one submesh per source mesh (vertex
//      colours do not split a group: members without colours are white in it);
//   5. build the group's joint palette: the distinct (joint, inverse bind) pairs its vertices use;
//   6. reorder with meshoptimizer: vertex cache per submesh, then vertex fetch over the whole mesh,
//      then (skinned meshes) a stable partition by influence class, so CPU skinning runs over
//      uniform ranges (influence_class_order);
//   7. encode the interleaved quantized (or float32) layout.
//
// Decisions worth knowing, and why:
// - Grouping happens after normal generation, so every cooked mesh has normals and a source mesh
//   that lacked them still merges with its neighbours (fewer buffers, fewer draws).
// - Welding is the cooker's, not Assimp's: Assimp 5.2.5's JoinIdenticalVertices merges vertices
//   whose colours differ (a red and a blue quad sharing an edge come out blended), and is known
//   to desync morph targets. Here only vertices equal in every attribute merge, bit for bit, so
//   merging never changes what is drawn; FBX's per-corner vertices, which are exact copies, weld.
//   Welding comes before normal generation, whose area-weighted normals need shared corners.
// - Each source mesh owns a disjoint vertex range of its group, so the cache optimizer runs on
//   each submesh alone with local indices (keeping every submesh's triangles contiguous and its
//   cost proportional to that submesh). The fetch optimizer then renumbers the whole buffer in first
//   use order, which also drops vertices that only degenerate triangles referenced.
// - Positions are Unorm16 in the mesh bounds. An axis with zero extent gets position_scale 1: q is 0
//   on it and decodes exactly to the offset, and the de-quantizing affine stays invertible.
// - Weights are non-negative: a negative or non-finite weight counts as 0, and a vertex left with
//   no weight at all is bound fully to its first influence (weight 1 / 255), with a warning, so it
//   follows a joint instead of collapsing to the origin.
// - Vertex colours are Unorm8x4 (a colour needs no more than the 8 bits a texture gives it);
//   components outside [0, 1] are clamped, with a warning naming the mesh.
// - Influences with weight 0 write slot 0; they contribute nothing, and pointing them at a real
//   slot keeps every slot index valid for the validator and the shader.
//
// Everything iterates vectors or std::map in a fixed order: the output depends only on the input.
#include "cooker/mesh/mesh_build.h"

#include <meshoptimizer.h>

// OpenMesh's vectors are uninitialized when default-constructed, by design; GCC 12 with the
// sanitizers then warns (maybe-uninitialized) inside OpenMesh's property storage. Not ossa's code.
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#include <OpenMesh/Core/Mesh/TriMesh_ArrayKernelT.hh>
#if defined(__GNUC__) && !defined(__clang__)
#pragma GCC diagnostic pop
#endif
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <set>
#include <unordered_map>
#include <utility>

#include <ossa/format/vertex_codec.h>
#include <ossa/format/vertex_format.h>

#include "cooker/mesh/mesh_build_internal.h"

namespace ossa::cook {
namespace mesh_detail {

std::string mesh_label(const SourceMesh& mesh, size_t index) {
  return "mesh " + std::to_string(index) + " '" + mesh.name + "'";
}

Error mesh_error(const SourceMesh& mesh, size_t index, const std::string& what) {
  return Error{mesh_label(mesh, index) + ": " + what};
}

// Non-negative finite weights; all-zero becomes full weight on the first influence.
glm::vec4 sanitize_weights(const glm::vec4& w, bool* was_empty) {
  glm::vec4 out;
  for (int k = 0; k < 4; ++k) out[k] = std::isfinite(w[k]) && w[k] > 0.0f ? w[k] : 0.0f;
  *was_empty = !(out.x > 0.0f || out.y > 0.0f || out.z > 0.0f || out.w > 0.0f);
  if (*was_empty) out = glm::vec4(1.0f, 0.0f, 0.0f, 0.0f);
  return out;
}

// Weights in unorm8 summing exactly to 255: floor each share of 255, then hand the remaining
// units to the largest fractional remainders (ties to the lower influence, for determinism).
std::array<uint8_t, 4> quantize_weights(const glm::vec4& w) {
  double sum = 0.0;
  for (int k = 0; k < 4; ++k) sum += w[k];
  std::array<uint8_t, 4> q{255, 0, 0, 0};
  if (!(sum > 0.0)) return q;
  std::array<double, 4> frac{};
  int total = 0;
  for (int k = 0; k < 4; ++k) {
    const double scaled = static_cast<double>(w[k]) / sum * 255.0;
    const double fl = std::min(255.0, std::floor(scaled));
    q[k] = static_cast<uint8_t>(fl);
    frac[k] = scaled - fl;
    total += q[k];
  }
  std::array<bool, 4> bumped{};
  while (total < 255) {
    int best = -1;
    for (int k = 0; k < 4; ++k)
      if (!bumped[k] && q[k] < 255 && (best < 0 || frac[k] > frac[best])) best = k;
    if (best < 0) {  // unreachable with sane floats; keep the sum exact anyway
      best = static_cast<int>(std::max_element(q.begin(), q.end()) - q.begin());
    } else {
      bumped[static_cast<size_t>(best)] = true;
    }
    ++q[static_cast<size_t>(best)];
    ++total;
  }
  while (total > 255) {  // unreachable: the floors sum to at most 255
    const auto it = std::max_element(q.begin(), q.end());
    --*it;
    --total;
  }
  return q;
}

/// A renumbering (remap[old] = new) that orders vertices by influence class, keeping the fetch
/// order inside each class (a stable partition): skin_cpu then runs one loop per class over a
/// contiguous range instead of sorting every batch into classes (ozz-animation splits its skinning
/// jobs by influence count the same way). The GPU's vertex fetch still walks each class in first-use
/// order; the index buffer now jumps between at most five ranges.
std::vector<unsigned> influence_class_order(const std::vector<glm::vec4>& weights) {
  std::array<unsigned, 6> start{};
  std::vector<uint8_t> cls(weights.size());
  for (size_t v = 0; v < weights.size(); ++v) {
    const std::array<uint8_t, 4> q = quantize_weights(weights[v]);
    const uint32_t word = q[0] | uint32_t{q[1]} << 8 | uint32_t{q[2]} << 16 | uint32_t{q[3]} << 24;
    cls[v] = static_cast<uint8_t>(influence_class(word));  // ossa/format/vertex_codec.h
    ++start[cls[v] + 1u];
  }
  for (size_t c = 1; c < start.size(); ++c) start[c] += start[c - 1];
  std::vector<unsigned> remap(weights.size());
  for (size_t v = 0; v < weights.size(); ++v) remap[v] = start[cls[v]]++;
  return remap;
}

}  // namespace mesh_detail

namespace {

using namespace mesh_detail;

// A triangle whose height is below this fraction of its longest edge has no area at float
// precision (float carries ~6e-8 relative): its normal is noise and it covers no pixels.
constexpr double kDegenerateRelativeHeight = 1e-7;

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// ---------------------------------------------------------------------------------------------
// Normals (OpenMesh)

struct NormalTraits : OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3d;  // double: sums of many small cross products stay exact enough
  using Normal = OpenMesh::Vec3d;
};
using NormalMesh = OpenMesh::TriMesh_ArrayKernelT<NormalTraits>;

// Whether OpenMesh's add_face would accept the triangle: its three topological checks (complex
// vertex, complex edge, patch re-linking), asked through its public API. Non-manifold triangles
// then take the private-corners path below quietly instead of add_face printing to std::cerr.
bool can_add_face(const NormalMesh& mesh, const std::array<NormalMesh::VertexHandle, 3>& v) {
  std::array<NormalMesh::HalfedgeHandle, 3> he;
  for (int i = 0; i < 3; ++i) {
    if (!mesh.is_boundary(v[i])) return false;  // its fan is already closed
    he[i] = mesh.find_halfedge(v[i], v[(i + 1) % 3]);
    if (he[i].is_valid() && !mesh.is_boundary(he[i])) return false;  // edge already has this side
  }
  for (int i = 0; i < 3; ++i) {
    const auto inner_prev = he[i];
    const auto inner_next = he[(i + 1) % 3];
    if (!inner_prev.is_valid() || !inner_next.is_valid()) continue;
    if (mesh.next_halfedge_handle(inner_prev) == inner_next) continue;
    // add_face would move the fan between them into another boundary gap around the vertex.
    auto boundary_prev = mesh.opposite_halfedge_handle(inner_next);
    do {
      boundary_prev = mesh.opposite_halfedge_handle(mesh.next_halfedge_handle(boundary_prev));
    } while (!mesh.is_boundary(boundary_prev));
    if (boundary_prev == inner_prev) return false;
  }
  return true;
}

// Area-weighted vertex normals: every triangle adds its corner's sector normal (the cross product
// of the two edges at that corner, |n| = twice the area) to the vertex. A triangle OpenMesh cannot
// hold (non-manifold) gets private copies of its corners, which still sum into the same source
// vertex. A vertex no triangle touches gets +z (it is dropped later by the fetch optimizer).
std::vector<glm::vec3> generate_normals(const std::vector<glm::vec3>& positions, const std::vector<uint32_t>& indices) {
  NormalMesh mesh;
  std::vector<uint32_t> source_of;  // OpenMesh vertex -> source vertex
  source_of.reserve(positions.size());
  for (size_t i = 0; i < positions.size(); ++i) {
    const glm::vec3& p = positions[i];
    mesh.add_vertex(NormalMesh::Point(p.x, p.y, p.z));
    source_of.push_back(static_cast<uint32_t>(i));
  }
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    std::array<NormalMesh::VertexHandle, 3> v{NormalMesh::VertexHandle(static_cast<int>(indices[t])),
                                              NormalMesh::VertexHandle(static_cast<int>(indices[t + 1])),
                                              NormalMesh::VertexHandle(static_cast<int>(indices[t + 2]))};
    NormalMesh::FaceHandle face;
    if (can_add_face(mesh, v)) face = mesh.add_face(v[0], v[1], v[2]);
    if (!face.is_valid()) {
      for (auto& vh : v) {
        const uint32_t source = source_of[static_cast<size_t>(vh.idx())];
        const NormalMesh::Point p = mesh.point(vh);
        vh = mesh.add_vertex(p);
        source_of.push_back(source);
      }
      mesh.add_face(v[0], v[1], v[2]);
    }
  }
  std::vector<glm::dvec3> sum(positions.size(), glm::dvec3(0.0));
  for (const auto face : mesh.faces()) {
    for (const auto heh : mesh.fh_range(face)) {
      NormalMesh::Normal n;
      mesh.calc_sector_normal(heh, n);  // the sector is centred on heh's target vertex
      sum[source_of[static_cast<size_t>(mesh.to_vertex_handle(heh).idx())]] += glm::dvec3(n[0], n[1], n[2]);
    }
  }
  std::vector<glm::vec3> normals(positions.size());
  for (size_t i = 0; i < sum.size(); ++i) {
    const double len = glm::length(sum[i]);
    normals[i] = len > 0.0 && std::isfinite(len) ? glm::vec3(sum[i] / len) : glm::vec3(0.0f, 0.0f, 1.0f);
  }
  return normals;
}

// ---------------------------------------------------------------------------------------------
// Validation and cleaning of one source mesh

Status validate_mesh(const SourceScene& scene, size_t index) {
  const SourceMesh& m = scene.meshes[index];
  const size_t n = m.positions.size();
  auto bad = [&](const std::string& what) { return mesh_error(m, index, what); };
  if (n > std::numeric_limits<uint32_t>::max()) return bad("too many vertices");
  auto check_size = [&](size_t size, const char* what) -> Status {
    if (size != 0 && size != n)
      return bad("has " + std::to_string(size) + " " + what + " for " + std::to_string(n) + " vertices");
    return {};
  };
  if (Status s = check_size(m.normals.size(), "normals"); !s) return s;
  if (Status s = check_size(m.tangents.size(), "tangents"); !s) return s;
  if (Status s = check_size(m.uv0.size(), "texture coordinates"); !s) return s;
  if (Status s = check_size(m.colors.size(), "colours"); !s) return s;
  if (Status s = check_size(m.cloth.size(), "cloth attributes"); !s) return s;
  if (Status s = check_size(m.joints.size(), "joint sets"); !s) return s;
  if (m.weights.size() != m.joints.size())
    return bad("has " + std::to_string(m.joints.size()) + " joint sets but " + std::to_string(m.weights.size()) +
               " weight sets");
  if (m.indices.size() % 3 != 0)
    return bad("index count " + std::to_string(m.indices.size()) + " is not a multiple of 3");
  for (size_t i = 0; i < m.indices.size(); ++i) {
    if (m.indices[i] >= n)
      return bad("index " + std::to_string(i) + " is " + std::to_string(m.indices[i]) +
                 ", not below the vertex count " + std::to_string(n));
  }
  for (size_t v = 0; v < n; ++v) {
    if (!finite(m.positions[v])) return bad("vertex " + std::to_string(v) + " has a non-finite position");
  }
  // As the loader's rule: material 0 is allowed in a file without materials (the default look).
  if (m.material >= std::max<size_t>(scene.materials.size(), 1))
    return bad("material " + std::to_string(m.material) + " is not below the material count " +
               std::to_string(scene.materials.size()));
  if (!m.joints.empty() && scene.skeleton.joints.empty()) return bad("is skinned but the scene has no skeleton");
  std::set<std::string> target_names;
  for (const SourceMorphTarget& t : m.morph_targets) {
    const std::string tl = "morph target '" + t.name + "'";
    if (t.name.empty()) return bad("has a morph target without a name");
    if (!target_names.insert(t.name).second) return bad("has two morph targets named '" + t.name + "'");
    if (t.positions.size() != n)
      return bad(tl + " has " + std::to_string(t.positions.size()) + " position deltas for " + std::to_string(n) +
                 " vertices");
    if (!t.normals.empty() && t.normals.size() != n) return bad(tl + " has a normal delta count unlike its vertices'");
    if (!t.tangents.empty() && t.tangents.size() != n)
      return bad(tl + " has a tangent delta count unlike its vertices'");
    for (const auto* stream : {&t.positions, &t.normals, &t.tangents})
      for (const glm::vec3& d : *stream)
        if (!finite(d)) return bad(tl + " has a non-finite delta");
    if (!std::isfinite(t.default_weight)) return bad(tl + " has a non-finite default weight");
  }
  return {};
}

// Degenerate: a repeated index, or no area at float precision (see kDegenerateRelativeHeight).
bool degenerate(const SourceMesh& m, uint32_t a, uint32_t b, uint32_t c) {
  if (a == b || b == c || a == c) return true;
  const glm::dvec3 pa(m.positions[a]), pb(m.positions[b]), pc(m.positions[c]);
  const glm::dvec3 ab = pb - pa, bc = pc - pb, ca = pa - pc;
  const double longest2 = std::max({glm::dot(ab, ab), glm::dot(bc, bc), glm::dot(ca, ca)});
  const double twice_area = glm::length(glm::cross(ab, -ca));
  // height = twice_area / longest; degenerate when height <= eps * longest.
  return !(twice_area > kDegenerateRelativeHeight * longest2);
}

template <class T>
void add_stream(std::vector<meshopt_Stream>& streams, const std::vector<T>& v) {
  if (!v.empty()) streams.push_back({v.data(), sizeof(T), sizeof(T)});
}

// weld's remap with morph targets: the key is every stream's bytes plus every target's deltas.
size_t remap_with_targets(const SourceMesh& m, std::vector<unsigned>* remap) {
  return remap_by_key(m.indices, m.positions.size(), remap, [&m](std::string& key, size_t i) {
    append_bytes(key, m.positions, i);
    append_bytes(key, m.normals, i);
    append_bytes(key, m.tangents, i);
    append_bytes(key, m.uv0, i);
    append_bytes(key, m.colors, i);
    append_bytes(key, m.joints, i);
    append_bytes(key, m.weights, i);
    append_bytes(key, m.cloth, i);
    for (const SourceMorphTarget& t : m.morph_targets) {
      append_bytes(key, t.positions, i);
      append_bytes(key, t.normals, i);
      append_bytes(key, t.tangents, i);
    }
  });
}

// The mesh with every set of vertices equal in all streams (bit for bit) merged into one, and
// vertices no triangle references dropped (counted in *unused). O(vertices + indices), hashed.
SourceMesh weld(const SourceMesh& m, size_t* unused) {
  SourceMesh out = m;
  const size_t n = m.positions.size();
  std::vector<unsigned> remap(n);
  size_t unique = 0;
  if (!m.morph_targets.empty()) {
    unique = remap_with_targets(m, &remap);
  } else {
    std::vector<meshopt_Stream> streams;
    add_stream(streams, m.positions);
    add_stream(streams, m.normals);
    add_stream(streams, m.tangents);
    add_stream(streams, m.uv0);
    add_stream(streams, m.colors);
    add_stream(streams, m.joints);
    add_stream(streams, m.weights);
    add_stream(streams, m.cloth);
    unique = meshopt_generateVertexRemapMulti(remap.data(), m.indices.data(), m.indices.size(), n, streams.data(),
                                              streams.size());
  }
  std::vector<bool> referenced(n, false);
  for (const uint32_t i : m.indices) referenced[i] = true;
  *unused = static_cast<size_t>(std::count(referenced.begin(), referenced.end(), false));
  meshopt_remapIndexBuffer(out.indices.data(), m.indices.data(), m.indices.size(), remap.data());
  compact(out.positions, remap, unique);
  compact(out.normals, remap, unique);
  compact(out.tangents, remap, unique);
  compact(out.uv0, remap, unique);
  compact(out.colors, remap, unique);
  compact(out.joints, remap, unique);
  compact(out.weights, remap, unique);
  compact(out.cloth, remap, unique);
  for (SourceMorphTarget& t : out.morph_targets) {
    compact(t.positions, remap, unique);
    compact(t.normals, remap, unique);
    compact(t.tangents, remap, unique);
  }
  return out;
}

}  // namespace

using namespace mesh_detail;

Result<std::vector<CookedMesh>> build_meshes(const SourceScene& scene, const MeshOptions& options,
                                             MeshBuildStats* stats_out, std::vector<std::string>* warnings_out) {
  MeshBuildStats stats;
  std::vector<std::string> warnings;

  // Cloth attributes from paint and settings (cloth_build.h), carried like any stream.
  auto cloth = cloth_attributes(scene, options.cloth, &warnings);
  if (!cloth) return cloth.error();

  // Validate and clean every source mesh.
  std::vector<CleanMesh> cleaned;
  for (size_t si = 0; si < scene.meshes.size(); ++si) {
    if (Status s = validate_mesh(scene, si); !s) return s.error();
    stats.source_vertices += static_cast<uint32_t>(scene.meshes[si].positions.size());
    CleanMesh c;
    c.source = si;
    size_t unused = 0;
    if ((*cloth)[si].empty()) {
      c.mesh = weld(scene.meshes[si], &unused);
    } else {
      SourceMesh with_cloth = scene.meshes[si];
      with_cloth.cloth = std::move((*cloth)[si]);
      c.mesh = weld(with_cloth, &unused);
    }
    SourceMesh& m = c.mesh;
    if (unused > 0)
      warnings.push_back(mesh_label(m, si) + ": dropped " + std::to_string(unused) + " vertices no triangle uses");
    std::vector<uint32_t> kept;
    kept.reserve(m.indices.size());
    uint32_t dropped = 0;
    for (size_t t = 0; t < m.indices.size(); t += 3) {
      const uint32_t a = m.indices[t], b = m.indices[t + 1], cc = m.indices[t + 2];
      if (degenerate(m, a, b, cc)) {
        ++dropped;
        continue;
      }
      kept.insert(kept.end(), {a, b, cc});
    }
    m.indices = std::move(kept);
    stats.degenerate_triangles_removed += dropped;
    if (dropped > 0)
      warnings.push_back(mesh_label(m, si) + ": removed " + std::to_string(dropped) + " degenerate triangles");
    if (m.indices.empty()) {
      warnings.push_back(mesh_label(m, si) + ": no triangles left; mesh skipped");
      continue;
    }
    if (m.normals.empty()) {
      m.normals = generate_normals(m.positions, m.indices);
      ++stats.meshes_with_generated_normals;
      warnings.push_back(mesh_label(m, si) + ": had no normals; generated area-weighted normals");
    }
    cleaned.push_back(std::move(c));
  }

  // Group by attribute set, in order of first appearance.
  std::vector<std::pair<AttributeSet, std::vector<size_t>>> groups;
  for (size_t ci = 0; ci < cleaned.size(); ++ci) {
    const AttributeSet attrs = attribute_set(cleaned[ci].mesh);
    auto it = std::find_if(groups.begin(), groups.end(), [&](const auto& g) { return g.first == attrs; });
    if (it == groups.end()) {
      groups.emplace_back(attrs, std::vector<size_t>{});
      it = groups.end() - 1;
    }
    it->second.push_back(ci);
  }

  std::vector<CookedMesh> meshes;
  double misses_before = 0.0, misses_after = 0.0;
  for (const auto& [attrs, members] : groups) {
    auto mesh = build_group(scene, cleaned, members, attrs, options, stats, warnings, misses_before, misses_after);
    if (!mesh) return mesh.error();
    if (!mesh->cloth_attributes.empty()) {
      auto built = build_cloth(scene, options.cloth, *mesh, mesh->cloth_attributes, &warnings);
      if (!built) return built.error();
      mesh->cloth = std::move(*built);
    }
    meshes.push_back(std::move(*mesh));
  }
  if (stats.triangles > 0) {
    // Over all meshes: transformed vertices per triangle, i.e. the triangle-weighted mean ACMR.
    stats.acmr_before = static_cast<float>(misses_before / stats.triangles);
    stats.acmr_after = static_cast<float>(misses_after / stats.triangles);
  }

  if (stats_out) *stats_out = stats;
  if (warnings_out) warnings_out->insert(warnings_out->end(), warnings.begin(), warnings.end());
  return meshes;
}

}  // namespace ossa::cook
