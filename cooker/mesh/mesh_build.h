// mesh_build.h — SourceMesh list -> GPU-ready meshes: welded, optimized, quantized, interleaved.
//
// Source meshes with the same attribute set are merged into one vertex/index buffer with one
// submesh per source mesh (per material), so a character is few buffers and few draws. Each source
// mesh is welded (vertices equal in every attribute merged: the importer leaves that to this stage)
// and cleaned (degenerate triangles dropped and counted), given normals by OpenMesh when it has none
// (area-weighted vertex normals: the one job where OpenMesh earns its place), reordered with
// meshoptimizer (vertex cache per submesh, then vertex fetch over the whole mesh; skinned meshes
// then ordered by influence class, fetch order kept inside each class), and written in the
// quantized layout of the design (positions unorm16 in the bounds, octahedral normals/tangents,
// half-float UVs, 8-bit joint slots where <= 256 joints, unorm8 weights summing to 255) or float32
// with MeshOptions::float_vertices.
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "cooker/mesh/cloth_build.h"
#include "cooker/model/source_scene.h"
#include "cooker/mesh/morph_build.h"
#include <ossa/format/ossa_generated.h>
#include <ossa/format/result.h>

namespace ossa::cook {

struct MeshOptions {
  bool float_vertices = false;  // float32 layout for exact round trips
  bool optimize = true;         // meshoptimizer vertex cache + fetch reordering
  /// Morph targets: largest position error in metres (converted into mesh units with the scene's
  /// metres_per_unit) and largest normal / tangent turn in radians.
  float morph_position_bound_m = 2e-5f;
  float morph_angle_bound = 0.001745f;
  /// Cloth (cloth_build.h): paint and regions become each cooked mesh's CookedMesh::cloth.
  ClothOptions cloth;
};

struct CookedMesh {
  std::string name;
  uint32_t vertex_count = 0;
  uint16_t vertex_stride = 0;
  std::vector<fb::VertexAttribute> layout;
  std::vector<uint8_t> vertices;  // vertex_count * vertex_stride
  fb::IndexFormat index_format = fb::IndexFormat::Uint16;
  std::vector<uint8_t> indices;
  std::vector<fb::Submesh> submeshes;
  glm::vec3 bounds_min{0.0f}, bounds_max{0.0f};
  glm::vec3 position_offset{0.0f}, position_scale{1.0f};
  std::vector<uint16_t> joints;                  // skeleton joint per slot
  std::vector<glm::mat4> inverse_bind;           // per slot
  std::vector<CookedMorphTarget> morph_targets;  // names unique, in first-appearance order
  std::vector<glm::vec4> cloth_attributes;       // per vertex (cloth_build.h), empty without cloth
  CookedCloth cloth;                             // empty() without cloth
};

struct MeshBuildStats {
  uint32_t source_vertices = 0;
  uint32_t cooked_vertices = 0;
  uint32_t triangles = 0;
  uint32_t degenerate_triangles_removed = 0;
  uint32_t meshes_with_generated_normals = 0;
  float acmr_before = 0.0f;  // average cache miss ratio (meshoptimizer, cache 16)
  float acmr_after = 0.0f;
};

/// Builds all meshes of a scene. Errors name the mesh at fault. Deterministic. Cost: O(vertices +
/// triangles) for validation, quantization and meshoptimizer's passes; OpenMesh's normal pass only
/// for meshes without normals.
Result<std::vector<CookedMesh>> build_meshes(const SourceScene& scene, const MeshOptions& options,
                                             MeshBuildStats* stats, std::vector<std::string>* warnings);

}  // namespace ossa::cook
