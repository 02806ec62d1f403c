// mesh_build.cpp — SourceMesh list -> CookedMesh list: clean, merge, optimize, quantize (mesh_build.h).
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

namespace ossa::cook {
namespace {

// A triangle whose height is below this fraction of its longest edge has no area at float
// precision (float carries ~6e-8 relative): its normal is noise and it covers no pixels.
constexpr double kDegenerateRelativeHeight = 1e-7;
constexpr unsigned kCacheSize = 16;  // ACMR reference cache, as MeshBuildStats documents

std::string mesh_label(const SourceMesh& mesh, size_t index) {
  return "mesh " + std::to_string(index) + " '" + mesh.name + "'";
}

Error mesh_error(const SourceMesh& mesh, size_t index, const std::string& what) {
  return Error{mesh_label(mesh, index) + ": " + what};
}

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

// ---------------------------------------------------------------------------------------------
// Normals (OpenMesh)

struct NormalTraits : OpenMesh::DefaultTraits {
  using Point = OpenMesh::Vec3d;   // double: sums of many small cross products stay exact enough
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
std::vector<glm::vec3> generate_normals(const std::vector<glm::vec3>& positions,
                                        const std::vector<uint32_t>& indices) {
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
    return bad("has " + std::to_string(m.joints.size()) + " joint sets but " +
               std::to_string(m.weights.size()) + " weight sets");
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
    if (!t.tangents.empty() && t.tangents.size() != n) return bad(tl + " has a tangent delta count unlike its vertices'");
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

struct CleanMesh {
  size_t source = 0;                // index into scene.meshes
  SourceMesh mesh;                  // welded, degenerate triangles removed, normals present
};

template <class T>
void add_stream(std::vector<meshopt_Stream>& streams, const std::vector<T>& v) {
  if (!v.empty()) streams.push_back({v.data(), sizeof(T), sizeof(T)});
}

template <class T>
void compact(std::vector<T>& stream, const std::vector<unsigned>& remap, size_t unique) {
  if (stream.empty()) return;
  std::vector<T> out(unique);
  meshopt_remapVertexBuffer(out.data(), stream.data(), stream.size(), sizeof(T), remap.data());
  stream = std::move(out);
}

template <class T>
void append_bytes(std::string& key, const std::vector<T>& stream, size_t v) {
  if (!stream.empty()) key.append(reinterpret_cast<const char*>(&stream[v]), sizeof(T));
}

// Vertices with equal keys share one number, as meshoptimizer's remap numbers them: in first use
// order of the indices; unreferenced vertices get ~0u. append_key(key, v) appends vertex v's key
// bytes to an empty string. Returns the number of unique vertices. O(vertices + indices), hashed;
// for keys meshoptimizer's remap cannot take (its multi-stream remap has at most 16 streams, and a
// face has 52 morph targets, whose deltas must be part of the key).
template <class AppendKey>
size_t remap_by_key(const std::vector<uint32_t>& indices, size_t vertex_count, std::vector<unsigned>* remap,
                    AppendKey&& append_key) {
  std::unordered_map<std::string, unsigned> first;
  remap->assign(vertex_count, ~0u);
  unsigned next = 0;
  std::string key;
  for (const uint32_t i : indices) {
    if ((*remap)[i] != ~0u) continue;
    key.clear();
    append_key(key, static_cast<size_t>(i));
    const auto [it, inserted] = first.emplace(key, next);
    if (inserted) ++next;
    (*remap)[i] = it->second;
  }
  return next;
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

// ---------------------------------------------------------------------------------------------
// One merged mesh

struct AttributeSet {
  bool tangents = false, uv0 = false, skinned = false;
  bool operator==(const AttributeSet&) const = default;
};

AttributeSet attribute_set(const SourceMesh& m) {
  return {!m.tangents.empty(), !m.uv0.empty(), !m.joints.empty()};
}

struct Streams {
  std::vector<glm::vec3> positions, normals;
  std::vector<glm::vec4> tangents;
  std::vector<glm::vec2> uv0;
  std::vector<glm::vec4> colors;
  std::vector<std::array<uint16_t, 4>> slots;
  std::vector<glm::vec4> weights;
  std::vector<glm::vec4> cloth;       // cloth attributes; zeros where a member has none
  std::vector<MorphStreams> targets;  // merged by name over the members; zeros where a member lacks one
};

struct PaletteEntry {
  uint16_t joint = 0;
  glm::mat4 inverse_bind{1.0f};
};

bool same_matrix(const glm::mat4& a, const glm::mat4& b) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!(a[c][r] == b[c][r])) return false;
  return true;
}

template <class T>
void put(uint8_t* dst, const T& value) {
  std::memcpy(dst, &value, sizeof(T));
}

struct Layout {
  std::vector<fb::VertexAttribute> attributes;
  uint16_t stride = 0;
  uint16_t add(fb::VertexSemantic semantic, fb::VertexFormat format) {
    const uint16_t offset = stride;
    attributes.emplace_back(semantic, format, offset);
    stride = static_cast<uint16_t>(stride + vertex_format_info(format).size);
    return offset;
  }
};

// Builds the merged mesh of one group. `members` index `cleaned`, in scene order.
Result<CookedMesh> build_group(const SourceScene& scene, const std::vector<CleanMesh>& cleaned,
                               const std::vector<size_t>& members, const AttributeSet& attrs,
                               const MeshOptions& options, MeshBuildStats& stats,
                               std::vector<std::string>& warnings, double& misses_before,
                               double& misses_after) {
  const size_t joint_count = scene.skeleton.joints.size();
  CookedMesh out;
  out.name = cleaned[members.front()].mesh.name;

  // Sanitized weights per member, and the palette: distinct (joint, inverse bind) pairs, grouped
  // by joint (std::map order) and by first appearance within a joint.
  std::vector<std::vector<glm::vec4>> weights(members.size());
  std::map<uint16_t, std::vector<std::pair<glm::mat4, uint32_t>>> pairs;  // joint -> (matrix, id)
  std::vector<std::map<uint16_t, uint32_t>> member_ids(members.size());   // joint -> pair id
  uint32_t pair_count = 0;
  if (attrs.skinned) {
    for (size_t mi = 0; mi < members.size(); ++mi) {
      const size_t si = cleaned[members[mi]].source;
      const SourceMesh& m = cleaned[members[mi]].mesh;
      std::map<uint16_t, const glm::mat4*> bind;
      for (const auto& [joint, matrix] : m.bind) bind.emplace(joint, &matrix);  // first one wins
      std::vector<bool> used(joint_count, false);
      weights[mi].resize(m.weights.size());
      uint32_t empty_vertices = 0;
      for (size_t v = 0; v < m.weights.size(); ++v) {
        bool was_empty = false;
        weights[mi][v] = sanitize_weights(m.weights[v], &was_empty);
        empty_vertices += was_empty ? 1u : 0u;
        for (int k = 0; k < 4; ++k) {
          if (!(weights[mi][v][k] > 0.0f)) continue;
          const uint16_t joint = m.joints[v][static_cast<size_t>(k)];
          if (joint >= joint_count)
            return mesh_error(m, si, "vertex " + std::to_string(v) + " references joint " + std::to_string(joint) +
                                         ", not below the skeleton's joint count " + std::to_string(joint_count));
          used[joint] = true;
        }
      }
      if (empty_vertices > 0)
        warnings.push_back(mesh_label(m, si) + ": " + std::to_string(empty_vertices) +
                           " vertices had no skin weight; bound fully to their first influence");
      uint32_t unbound = 0;
      for (size_t j = 0; j < joint_count; ++j) {
        if (!used[j]) continue;
        const auto joint = static_cast<uint16_t>(j);
        const auto found = bind.find(joint);
        glm::mat4 matrix = scene.skeleton.joints[j].inverse_bind;
        if (found != bind.end()) {
          matrix = *found->second;
        } else {
          ++unbound;  // no skin entry: the skeleton's own inverse bind is the best guess
        }
        auto& candidates = pairs[joint];
        uint32_t id = pair_count;
        for (const auto& [existing, existing_id] : candidates)
          if (same_matrix(existing, matrix)) id = existing_id;
        if (id == pair_count) {
          candidates.emplace_back(matrix, pair_count);
          ++pair_count;
        }
        member_ids[mi].emplace(joint, id);
      }
      if (unbound > 0)
        warnings.push_back(mesh_label(m, si) + ": " + std::to_string(unbound) +
                           " skinned joints had no inverse bind in the skin; used the skeleton's");
    }
    if (pair_count > 65536u)
      return Error{"mesh '" + out.name + "': " + std::to_string(pair_count) +
                   " distinct joint slots, more than the 65536 a Uint16x4 joint index can address"};
  }
  std::vector<uint32_t> slot_of_pair(pair_count, 0);
  for (const auto& [joint, candidates] : pairs) {
    for (const auto& [matrix, id] : candidates) {
      slot_of_pair[id] = static_cast<uint32_t>(out.joints.size());
      out.joints.push_back(joint);
      out.inverse_bind.push_back(matrix);
    }
  }

  // Concatenate the members' streams and indices; one submesh each.
  bool colored = false;
  bool clothed = false;
  for (const size_t member : members) colored = colored || !cleaned[member].mesh.colors.empty();
  for (const size_t member : members) clothed = clothed || !cleaned[member].mesh.cloth.empty();
  Streams s;
  // Morph targets merge by name across members (a head split by material shares its "smile"); a
  // stream is present when any member's target of that name has it.
  for (const size_t member : members) {
    for (const SourceMorphTarget& t : cleaned[member].mesh.morph_targets) {
      auto it = std::find_if(s.targets.begin(), s.targets.end(), [&](const MorphStreams& m) { return m.name == t.name; });
      if (it == s.targets.end()) {
        s.targets.push_back({t.name, t.default_weight, {}, {}, {}});
        it = s.targets.end() - 1;
      }
      if (!t.normals.empty()) it->normals.resize(1);   // marks the stream present; filled below
      if (!t.tangents.empty() && attrs.tangents) it->tangents.resize(1);
    }
  }
  std::vector<bool> target_normals, target_tangents;
  for (MorphStreams& t : s.targets) {
    target_normals.push_back(!t.normals.empty());
    target_tangents.push_back(!t.tangents.empty());
    t.normals.clear();
    t.tangents.clear();
  }
  std::vector<unsigned> indices;
  std::vector<uint32_t> member_base(members.size());
  for (size_t mi = 0; mi < members.size(); ++mi) {
    const CleanMesh& c = cleaned[members[mi]];
    const SourceMesh& m = c.mesh;
    const size_t base = s.positions.size();
    if (base + m.positions.size() > std::numeric_limits<uint32_t>::max())
      return Error{"mesh '" + out.name + "': more than 2^32 - 1 vertices"};
    member_base[mi] = static_cast<uint32_t>(base);
    s.positions.insert(s.positions.end(), m.positions.begin(), m.positions.end());
    s.normals.insert(s.normals.end(), m.normals.begin(), m.normals.end());
    if (attrs.tangents) s.tangents.insert(s.tangents.end(), m.tangents.begin(), m.tangents.end());
    if (attrs.uv0) s.uv0.insert(s.uv0.end(), m.uv0.begin(), m.uv0.end());
    if (colored) {
      if (m.colors.empty()) {
        s.colors.insert(s.colors.end(), m.positions.size(), glm::vec4(1.0f));
      } else {
        uint32_t clamped = 0;
        for (const glm::vec4& col : m.colors) {
          const glm::vec4 in_range = glm::clamp(col, glm::vec4(0.0f), glm::vec4(1.0f));
          clamped += in_range != col ? 1u : 0u;
          s.colors.push_back(in_range);
        }
        if (clamped > 0)
          warnings.push_back(mesh_label(m, c.source) + ": " + std::to_string(clamped) +
                             " vertex colours outside [0, 1] were clamped");
      }
    }
    if (clothed) {
      if (m.cloth.empty()) s.cloth.insert(s.cloth.end(), m.positions.size(), glm::vec4(0.0f));
      else s.cloth.insert(s.cloth.end(), m.cloth.begin(), m.cloth.end());
    }
    if (attrs.skinned) {
      for (size_t v = 0; v < m.joints.size(); ++v) {
        std::array<uint16_t, 4> slots{0, 0, 0, 0};
        for (size_t k = 0; k < 4; ++k)
          if (weights[mi][v][static_cast<int>(k)] > 0.0f)
            slots[k] = static_cast<uint16_t>(slot_of_pair[member_ids[mi].at(m.joints[v][k])]);
        s.slots.push_back(slots);
        s.weights.push_back(weights[mi][v]);
      }
    }
    for (size_t k = 0; k < s.targets.size(); ++k) {
      MorphStreams& t = s.targets[k];
      const auto own = std::find_if(m.morph_targets.begin(), m.morph_targets.end(),
                                    [&](const SourceMorphTarget& mt) { return mt.name == t.name; });
      const bool has = own != m.morph_targets.end();
      const size_t nv = m.positions.size();
      const auto append = [&](std::vector<glm::vec3>& dst, const std::vector<glm::vec3>* src) {
        if (has && src && !src->empty()) dst.insert(dst.end(), src->begin(), src->end());
        else dst.insert(dst.end(), nv, glm::vec3(0.0f));
      };
      append(t.positions, has ? &own->positions : nullptr);
      if (target_normals[k]) append(t.normals, has ? &own->normals : nullptr);
      if (target_tangents[k]) append(t.tangents, has ? &own->tangents : nullptr);
    }
    if (indices.size() + m.indices.size() > std::numeric_limits<uint32_t>::max())
      return Error{"mesh '" + out.name + "': more than 2^32 - 1 indices"};
    fb::Submesh submesh(static_cast<uint32_t>(indices.size()), static_cast<uint32_t>(m.indices.size()), m.material);
    for (const uint32_t i : m.indices) indices.push_back(static_cast<unsigned>(base + i));
    out.submeshes.push_back(submesh);
  }
  size_t vertex_count = s.positions.size();

  const auto before = meshopt_analyzeVertexCache(indices.data(), indices.size(), vertex_count, kCacheSize, 0, 0);
  misses_before += before.vertices_transformed;

  if (options.optimize) {
    for (size_t mi = 0; mi < members.size(); ++mi) {
      const fb::Submesh& sub = out.submeshes[mi];
      const size_t count = cleaned[members[mi]].mesh.positions.size();
      const uint32_t base = member_base[mi];
      std::vector<unsigned> local(indices.begin() + sub.first_index(),
                                  indices.begin() + sub.first_index() + sub.index_count());
      for (unsigned& i : local) i -= base;
      std::vector<unsigned> optimized(local.size());
      meshopt_optimizeVertexCache(optimized.data(), local.data(), local.size(), count);
      for (size_t i = 0; i < optimized.size(); ++i) indices[sub.first_index() + i] = optimized[i] + base;
    }
    const auto renumber = [&](const std::vector<unsigned>& remap, size_t unique) {
      meshopt_remapIndexBuffer(indices.data(), indices.data(), indices.size(), remap.data());
      compact(s.positions, remap, unique);
      compact(s.normals, remap, unique);
      compact(s.tangents, remap, unique);
      compact(s.uv0, remap, unique);
      compact(s.colors, remap, unique);
      compact(s.slots, remap, unique);
      compact(s.weights, remap, unique);
      compact(s.cloth, remap, unique);
      for (MorphStreams& t : s.targets) {
        compact(t.positions, remap, unique);
        compact(t.normals, remap, unique);
        compact(t.tangents, remap, unique);
      }
    };
    std::vector<unsigned> remap(vertex_count);
    const size_t unique = meshopt_optimizeVertexFetchRemap(remap.data(), indices.data(), indices.size(), vertex_count);
    renumber(remap, unique);
    if (unique < vertex_count)
      warnings.push_back("mesh '" + out.name + "': dropped " + std::to_string(vertex_count - unique) +
                         " vertices only degenerate triangles used");
    vertex_count = unique;
    if (attrs.skinned) {
      remap = influence_class_order(s.weights);
      renumber(remap, vertex_count);
    }
  }

  const auto after = meshopt_analyzeVertexCache(indices.data(), indices.size(), vertex_count, kCacheSize, 0, 0);
  misses_after += after.vertices_transformed;

  // Bounds and the de-quantizing affine.
  glm::vec3 lo(0.0f), hi(0.0f);
  if (vertex_count > 0) {
    lo = hi = s.positions[0];
    for (const glm::vec3& p : s.positions) {
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
  }
  out.bounds_min = lo;
  out.bounds_max = hi;
  const bool quantized = !options.float_vertices;
  if (quantized) {
    out.position_offset = lo;
    for (int a = 0; a < 3; ++a) {
      const float extent = hi[a] - lo[a];
      out.position_scale[a] = extent > 0.0f && std::isfinite(extent) ? extent : 1.0f;
    }
  } else {
    out.position_offset = glm::vec3(0.0f);
    out.position_scale = glm::vec3(1.0f);
  }

  // Layout: Position, Normal, Tangent, TexCoord0, Color0, Joints, Weights; every size is a
  // multiple of 4.
  using Sem = fb::VertexSemantic;
  using Fmt = fb::VertexFormat;
  const bool wide_slots = out.joints.size() > 256;
  Layout layout;
  const uint16_t at_position = layout.add(Sem::Position, quantized ? Fmt::Unorm16x4 : Fmt::Float32x3);
  const uint16_t at_normal = layout.add(Sem::Normal, quantized ? Fmt::Snorm16x2 : Fmt::Float32x3);
  const uint16_t at_tangent = attrs.tangents ? layout.add(Sem::Tangent, quantized ? Fmt::Snorm16x4 : Fmt::Float32x4) : 0;
  const uint16_t at_uv0 = attrs.uv0 ? layout.add(Sem::TexCoord0, quantized ? Fmt::Float16x2 : Fmt::Float32x2) : 0;
  const uint16_t at_color = colored ? layout.add(Sem::Color0, quantized ? Fmt::Unorm8x4 : Fmt::Float32x4) : 0;
  const uint16_t at_joints =
      attrs.skinned ? layout.add(Sem::Joints, quantized && !wide_slots ? Fmt::Uint8x4 : Fmt::Uint16x4) : 0;
  const uint16_t at_weights = attrs.skinned ? layout.add(Sem::Weights, quantized ? Fmt::Unorm8x4 : Fmt::Float32x4) : 0;
  layout.stride = static_cast<uint16_t>((layout.stride + 3u) & ~3u);

  out.vertex_count = static_cast<uint32_t>(vertex_count);
  out.vertex_stride = layout.stride;
  out.layout = layout.attributes;
  out.vertices.assign(vertex_count * layout.stride, 0);
  for (size_t v = 0; v < vertex_count; ++v) {
    uint8_t* dst = out.vertices.data() + v * layout.stride;
    const glm::vec3& p = s.positions[v];
    const glm::vec3& n = s.normals[v];
    if (quantized) {
      const glm::vec3 q = (p - out.position_offset) / out.position_scale;
      put(dst + at_position,
          std::array<uint16_t, 4>{float_to_unorm16(q.x), float_to_unorm16(q.y), float_to_unorm16(q.z), 0});
      const Float2 e = octahedral_encode({n.x, n.y, n.z});
      put(dst + at_normal, std::array<int16_t, 2>{float_to_snorm16(e.x), float_to_snorm16(e.y)});
      if (attrs.tangents) {
        const glm::vec4& t = s.tangents[v];
        const Float2 te = octahedral_encode({t.x, t.y, t.z});
        const int16_t sign = t.w < 0.0f ? int16_t{-32767} : int16_t{32767};
        put(dst + at_tangent, std::array<int16_t, 4>{float_to_snorm16(te.x), float_to_snorm16(te.y), sign, 0});
      }
      if (attrs.uv0)
        put(dst + at_uv0, std::array<uint16_t, 2>{float_to_half(s.uv0[v].x), float_to_half(s.uv0[v].y)});
      if (colored) {
        const glm::vec4& c = s.colors[v];
        put(dst + at_color, std::array<uint8_t, 4>{float_to_unorm8(c.r), float_to_unorm8(c.g), float_to_unorm8(c.b),
                                                   float_to_unorm8(c.a)});
      }
      if (attrs.skinned) {
        const auto& slots = s.slots[v];
        if (wide_slots) {
          put(dst + at_joints, slots);
        } else {
          put(dst + at_joints, std::array<uint8_t, 4>{static_cast<uint8_t>(slots[0]), static_cast<uint8_t>(slots[1]),
                                                      static_cast<uint8_t>(slots[2]), static_cast<uint8_t>(slots[3])});
        }
        put(dst + at_weights, quantize_weights(s.weights[v]));
      }
    } else {
      put(dst + at_position, p);
      put(dst + at_normal, n);
      if (attrs.tangents) put(dst + at_tangent, s.tangents[v]);
      if (attrs.uv0) put(dst + at_uv0, s.uv0[v]);
      if (colored) put(dst + at_color, s.colors[v]);
      if (attrs.skinned) {
        put(dst + at_joints, s.slots[v]);
        put(dst + at_weights, s.weights[v]);
      }
    }
  }

  // Morph targets, quantized against the bounds in mesh units, still dense (morph_build.h).
  std::vector<DenseMorph> dense;
  if (!s.targets.empty()) {
    MorphBounds bounds;
    const float mpu = scene.metres_per_unit > 0.0f && std::isfinite(scene.metres_per_unit) ? scene.metres_per_unit : 1.0f;
    bounds.position = options.morph_position_bound_m / mpu;
    bounds.angle = options.morph_angle_bound;
    std::vector<glm::vec3> base_tangents;
    if (attrs.tangents)
      for (const glm::vec4& t : s.tangents) base_tangents.emplace_back(t);
    for (const MorphStreams& t : s.targets) {
      dense.push_back(quantize_morph(t, s.normals, base_tangents, bounds));
      if (dense.back().position_error > bounds.position * 1.0001f)
        warnings.push_back("mesh '" + out.name + "': morph target '" + t.name + "' moves vertices so far that its " +
                           "16-bit deltas err by " + std::to_string(dense.back().position_error) +
                           " units, past the bound " + std::to_string(bounds.position));
    }
  }

  // Vertices the quantized layout made identical (source vertices a rounding error apart, which
  // Assimp used to merge by epsilon) are one vertex: equal bytes draw exactly alike. The remap
  // numbers vertices in first use order, which the fetch optimizer already gave them, so the
  // fetch order is kept. With morph targets, the targets' quantized deltas are part of the key:
  // two vertices merge only when every target moves them alike.
  if (quantized && vertex_count > 0) {
    std::vector<unsigned> remap(vertex_count);
    size_t unique = 0;
    if (dense.empty() && s.cloth.empty()) {
      unique = meshopt_generateVertexRemap(remap.data(), indices.data(), indices.size(), out.vertices.data(),
                                           vertex_count, layout.stride);
    } else {
      unique = remap_by_key(indices, vertex_count, &remap, [&](std::string& key, size_t i) {
        key.append(reinterpret_cast<const char*>(out.vertices.data()) + i * layout.stride, layout.stride);
        append_bytes(key, s.cloth, i);
        for (const DenseMorph& d : dense) {
          append_bytes(key, d.positions, i);
          append_bytes(key, d.normals, i);
          append_bytes(key, d.tangents, i);
        }
      });
    }
    if (unique < vertex_count) {
      for (DenseMorph& d : dense) remap_morph(d, remap, unique);
      compact(s.cloth, remap, unique);
      std::vector<uint8_t> merged(unique * layout.stride);
      meshopt_remapVertexBuffer(merged.data(), out.vertices.data(), vertex_count, layout.stride, remap.data());
      meshopt_remapIndexBuffer(indices.data(), indices.data(), indices.size(), remap.data());
      out.vertices = std::move(merged);
      vertex_count = unique;
      out.vertex_count = static_cast<uint32_t>(unique);
    }
  }

  // Indices: 16-bit while every index fits (0xFFFF stays free for primitive restart).
  if (vertex_count <= 65535) {
    out.index_format = fb::IndexFormat::Uint16;
    out.indices.resize(indices.size() * 2);
    for (size_t i = 0; i < indices.size(); ++i) put(out.indices.data() + 2 * i, static_cast<uint16_t>(indices[i]));
  } else {
    out.index_format = fb::IndexFormat::Uint32;
    out.indices.resize(indices.size() * 4);
    if (!indices.empty()) std::memcpy(out.indices.data(), indices.data(), indices.size() * 4);
  }

  for (const DenseMorph& d : dense) out.morph_targets.push_back(sparsify(d));
  out.cloth_attributes = std::move(s.cloth);

  stats.cooked_vertices += out.vertex_count;
  stats.triangles += static_cast<uint32_t>(indices.size() / 3);
  return out;
}

}  // namespace

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
