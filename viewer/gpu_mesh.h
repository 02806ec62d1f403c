// gpu_mesh.h — a cooked mesh on the GPU: buffers made straight from the file's bytes.
//
// create_gpu_mesh hands MeshView::vertex_bytes() and index_bytes() to glBufferData as they are
// and sets one attribute pointer per layout entry from ossa/format/vertex_format.h's table (location =
// fb::VertexSemantic, integer formats through glVertexAttribIPointer). Nothing is decoded,
// converted or copied on the CPU: the skinned vertex shader reads the quantized layout itself.
//
// The CPU-skinning reference path (--cpu-skinning) needs a second vertex array: skin_cpu's float
// positions / normals / tangents streamed into their own buffers each frame, with texture
// coordinates and colours still read from the file's buffer. Those buffers are created empty
// here and filled by the renderer only when that path is used.
//
// A mesh with morph targets also gets its vertex-major entry lists (morphs.h) as two texture
// buffers, made once here: ranges (RG32I, one texel per vertex, read with gl_VertexID) and
// entries (RGBA32F, morph_texels per entry). A mesh without targets has neither, and the shader
// skips the morph loop for it (u_morph_channels = 0).
//
// A mesh with cooked cloth also gets its vertex -> particle map (R32I, one texel per vertex, read
// with gl_VertexID: -1 for a skinned vertex, else particle * 2 + 1 where the cooker flipped the
// vertex's normal), made once here, so the GPU path draws the mesh in one instanced call with its
// cloth vertices taken from the simulation's output (renderer.h) instead of skinning it on the CPU.
#pragma once
#include <cstdint>
#include <span>
#include <string_view>

#include <glm/glm.hpp>

#include <ossa/format/result.h>
#include <ossa/loader/asset.h>
#include "viewer/gl.h"

namespace ossa::view {

/// Vertex attribute locations in shaders/skinned.vert.glsl (= fb::VertexSemantic values).
enum AttributeLocation : GLuint {
  kPosition = 0,
  kNormal = 1,
  kTangent = 2,
  kTexCoord0 = 3,
  kColor0 = 4,
  kJoints = 5,
  kWeights = 6
};

/// How the shader must read directions (uniforms u_normal_encoding / u_tangent_encoding).
enum class NormalEncoding : int { Xyz = 0, Octahedral = 1 };
enum class TangentEncoding : int { None = 0, OctahedralSignZ = 1, XyzSignW = 2 };

struct GpuMesh {
  GLuint vao = 0, vertex_buffer = 0, index_buffer = 0;
  GLenum index_type = GL_UNSIGNED_SHORT;
  uint32_t index_size = 2;
  uint32_t vertex_count = 0;
  uint32_t palette_slots = 1;  // max(1, mesh joints): matrices in this mesh's palette
  NormalEncoding normal_encoding = NormalEncoding::Xyz;
  TangentEncoding tangent_encoding = TangentEncoding::None;
  glm::vec3 direction_prescale{1.0f};  // 1 / position_scale for quantized positions
  bool has_normals = false, has_tangents = false, has_joints = false, has_colors = false;

  // CPU-skinning path: float streams skinned by skin_cpu (empty until used).
  GLuint cpu_vao = 0, cpu_positions = 0, cpu_normals = 0, cpu_tangents = 0;

  // Morph targets (0 when the mesh has none bound to a channel).
  GLuint morph_range_buffer = 0, morph_range_texture = 0, morph_entry_buffer = 0, morph_entry_texture = 0;
  int morph_texels = 0;  // texels per entry: 1 positions, 2 + normals, 3 + tangents
  bool has_morphs() const { return morph_texels > 0; }

  // Cloth: the vertex -> particle map (0 when the mesh has no cloth).
  GLuint cloth_slot_buffer = 0, cloth_slot_texture = 0;
  uint32_t cloth_particles = 0;
  bool has_cloth() const { return cloth_slot_texture != 0; }
};

/// Uploads one mesh, and its morph targets bound through target_channel (target -> channel, as
/// bind_morph_targets; empty: none). Errors (naming `asset_name` and the mesh) for layouts the
/// shader cannot read: a format outside the table, integer joints missing or not integer; morph
/// entries past GL_MAX_TEXTURE_BUFFER_SIZE; a cloth whose vertices are past the mesh.
Result<GpuMesh> create_gpu_mesh(const MeshView& mesh, std::string_view asset_name,
                                std::span<const int32_t> target_channel = {});
void destroy_gpu_mesh(GpuMesh& mesh);

/// The constant attribute values the shader sees for arrays a mesh lacks: colour white, joint
/// slot 0 with weight 1 (palette[0]), +z normal, +x tangent. Call before drawing a mesh (they
/// are context state, not vertex array state).
void set_default_attributes();

}  // namespace ossa::view
