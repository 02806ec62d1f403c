// skinning.h — skinning palettes, and linear-blend skinning on the CPU: the reference the GPU
// path is tested against, and a fallback for tools.
//
// A mesh's palette folds in the vertex de-quantization (Mesh.position_offset/scale), so the GPU
// shader and skin_cpu both multiply the raw normalized position by the palette matrix with no
// special case for quantized meshes (the design's promise).
#pragma once
#include <array>
#include <cstdint>
#include <span>

#include <glm/glm.hpp>

#include <ossa/loader/asset.h>

namespace ossa {

/// palette[s] = model[mesh.joints()[s]] * mesh.inverse_bind()[s] * D, D the de-quantizing affine
/// (translate(position_offset) * scale(position_scale); identity for float positions).
/// palette.size() == mesh.joints().size(). For a mesh without joints (static), palette[0] = D
/// (palette.size() == 1). O(slots).
void skinning_matrices(const MeshView& mesh, std::span<const glm::mat4> model, std::span<glm::mat4> palette);

/// The per-mesh constant half of the palette: bind[s] = inverse_bind[s] * D (D as above; for a
/// static mesh bind[0] = D). Compute once per mesh (at load), then build each frame's palette with
/// skinning_matrices(joints, bind, model, palette): one matrix product per slot instead of two and
/// the de-quantization fold. bind.size() == max(1, slots). O(slots).
void prepare_bind_matrices(const MeshView& mesh, std::span<glm::mat4> bind);

/// palette[s] = model[joints[s]] * bind[s] (bind from prepare_bind_matrices; for a static mesh,
/// joints is empty and palette[0] = bind[0]). A joint index past model.size() uses identity.
/// O(slots), one 4x4 product each (AVX2 + FMA unless skinning_isa() is Portable, SSE then);
/// allocation-free.
void skinning_matrices(std::span<const uint16_t> joints, std::span<const glm::mat4> bind,
                       std::span<const glm::mat4> model, std::span<glm::mat4> palette);

enum class SkinningMethod : uint8_t {
  Linear,          // linear blend skinning: the classic, what the GPU shader does
  DualQuaternion,  // no candy-wrapper collapse on twisting joints: the rotation + translation of
                   // each palette matrix blends as a dual quaternion, its scale / shear linearly
};

/// Where skin_cpu writes: xyz per vertex for positions and normals, xyzw for tangents (w = the
/// bitangent sign). A span may be empty to skip that stream (the mesh must have the attribute
/// otherwise). Sizes: 3 * vertex_count, 3 * vertex_count, 4 * vertex_count.
struct SkinnedStreams {
  std::span<float> positions;
  std::span<float> normals;
  std::span<float> tangents;
  /// Normals and tangents come out unit length (true), or as the blended matrix transforms them
  /// (false: within a few percent of unit length where neighbouring joints' rotations differ, as
  /// blended rotations shrink vectors). A renderer that normalizes in its shaders anyway saves
  /// the pass (~0.1 ns a vertex with normals on arnaud, Zen 5, where the renormalization overlaps
  /// other work; ozz-animation's SkinningJob never normalizes).
  bool renormalize = true;
};

/// Skins every vertex of `mesh` with `palette` (from skinning_matrices), decoding the quantized
/// or float layout. Normals and tangents are transformed by the blended matrix's linear part and
/// renormalized (unless out.renormalize is false); since the palette holds D, directions are first divided by
/// position_scale, so they see model * inverse_bind only (a GPU shader must do the same). Tangent w is the stored
/// bitangent sign (+-1). All-zero weights give zero outputs. Sizes are preconditions (asserted;
/// a release build skips a stream that does not fit, or everything for a too-small palette).
/// Allocation-free. O(vertices * influences).
void skin_cpu(const MeshView& mesh, std::span<const glm::mat4> palette, SkinningMethod method, SkinnedStreams out);

/// Which implementation skin_cpu's linear blending uses for the cooker's quantized layout (other
/// layouts and dual quaternions always take the portable one). Default: the best the CPU has.
/// For tests and benchmarks that compare them; set_skinning_isa returns false and changes nothing
/// when the CPU lacks the instructions. Process-wide, thread-safe.
enum class SkinningIsa : uint8_t { Portable, Avx2, Avx512 };
SkinningIsa skinning_isa();
bool set_skinning_isa(SkinningIsa isa);

/// How skin_cpu walks a mesh with unorm8 weights: its vertices per influence class
/// (ossa/format/vertex_codec.h's influence_class: [0] one weight of 255, [c] up to c joints), the
/// runs of one class in vertex order, and whether classes never decrease along the vertex buffer
/// (the cooker's order: skin_cpu then skins each class as one range; otherwise it classifies the
/// vertices batch by batch, slower, with the same result). For tools and benchmarks. O(vertices).
struct InfluenceOrder {
  bool unorm8_weights = false;  // false: no Unorm8x4 Weights attribute, and the rest is zero
  std::array<uint32_t, 5> vertices_by_class{};
  uint32_t class_runs = 0;
  bool class_ordered = false;
};
InfluenceOrder influence_order(const MeshView& mesh);

}  // namespace ossa
