// mesh_build_internal.h — what mesh_build.cpp (validate, weld, clean, group: mesh_build.cpp's
// stages 1-4) and mesh_group.cpp (one group merged, reordered and encoded: stages 5-7) share.
// Private to cooker/mesh/.
#pragma once
#include <meshoptimizer.h>

#include <array>
#include <cstddef>
#include <cstdint>
#include <string>
#include <unordered_map>
#include <vector>

#include <glm/glm.hpp>

#include "cooker/mesh/mesh_build.h"

namespace ossa::cook::mesh_detail {

inline constexpr unsigned kCacheSize = 16;  // ACMR reference cache, as MeshBuildStats documents

std::string mesh_label(const SourceMesh& mesh, size_t index);
Error mesh_error(const SourceMesh& mesh, size_t index, const std::string& what);

struct CleanMesh {
  size_t source = 0;  // index into scene.meshes
  SourceMesh mesh;    // welded, degenerate triangles removed, normals present
};

struct AttributeSet {
  bool tangents = false, uv0 = false, skinned = false;
  bool operator==(const AttributeSet&) const = default;
};

inline AttributeSet attribute_set(const SourceMesh& m) {
  return {!m.tangents.empty(), !m.uv0.empty(), !m.joints.empty()};
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

/// Non-negative finite weights; all-zero becomes full weight on the first influence.
glm::vec4 sanitize_weights(const glm::vec4& w, bool* was_empty);
/// Weights as Unorm8 summing to exactly 255.
std::array<uint8_t, 4> quantize_weights(const glm::vec4& w);
/// A stable order of the vertices by influence class (mesh_build.cpp says why).
std::vector<unsigned> influence_class_order(const std::vector<glm::vec4>& weights);

/// Builds the merged mesh of one group. `members` index `cleaned`, in scene order.
Result<CookedMesh> build_group(const SourceScene& scene, const std::vector<CleanMesh>& cleaned,
                               const std::vector<size_t>& members, const AttributeSet& attrs,
                               const MeshOptions& options, MeshBuildStats& stats, std::vector<std::string>& warnings,
                               double& misses_before, double& misses_after);

}  // namespace ossa::cook::mesh_detail
