// gpu_mesh.cpp — see gpu_mesh.h.
#include "viewer/gpu_mesh.h"

#include <cstdint>
#include <string>
#include <vector>

#include <ossa/format/vertex_format.h>
#include <ossa/loader/cloth_source.h>
#include "viewer/gl_util.h"
#include "viewer/morphs.h"

namespace ossa::view {
namespace {

const void* byte_offset(size_t offset) { return reinterpret_cast<const void*>(static_cast<uintptr_t>(offset)); }

std::string where(const MeshView& mesh, std::string_view asset_name) {
  return std::string(asset_name) + ": mesh '" + std::string(mesh.name()) + "'";
}

/// Attribute pointers for the file's interleaved buffer (bound to GL_ARRAY_BUFFER). With
/// `skip_skinned` the position / normal / tangent / joints / weights entries are left out (the
/// CPU path supplies skinned streams for those).
Status set_layout_pointers(const MeshView& mesh, std::string_view asset_name, bool skip_skinned) {
  const auto stride = static_cast<GLsizei>(mesh.vertex_stride());
  for (const fb::VertexAttribute& a : mesh.layout()) {
    const auto location = static_cast<GLuint>(a.semantic());
    if (location > kWeights) continue;  // a semantic this viewer does not draw
    if (skip_skinned && location != kTexCoord0 && location != kColor0) continue;
    const VertexFormatInfo info = vertex_format_info(a.format());
    if (info.size == 0) {
      return Error{where(mesh, asset_name) + ": vertex format " + std::to_string(static_cast<int>(a.format())) +
                   " is not one the viewer can bind"};
    }
    if ((location == kJoints) != info.integer) {
      return Error{where(mesh, asset_name) + (info.integer ? ": an integer format on a non-joint attribute"
                                                           : ": joint slots are not an integer format")};
    }
    glEnableVertexAttribArray(location);
    if (info.integer) {
      glVertexAttribIPointer(location, info.components, info.gl_type, stride, byte_offset(a.offset()));
    } else {
      glVertexAttribPointer(location, info.components, info.gl_type, info.normalized ? GL_TRUE : GL_FALSE, stride,
                            byte_offset(a.offset()));
    }
  }
  return {};
}

GLuint make_buffer(GLenum target, std::span<const uint8_t> bytes, GLenum usage) {
  GLuint b = 0;
  glGenBuffers(1, &b);
  glBindBuffer(target, b);
  glBufferData(target, static_cast<GLsizeiptr>(bytes.size()), bytes.empty() ? nullptr : bytes.data(), usage);
  return b;
}

GLuint float_stream(GLuint location, int components) {
  GLuint b = 0;
  glGenBuffers(1, &b);
  glBindBuffer(GL_ARRAY_BUFFER, b);
  glEnableVertexAttribArray(location);
  glVertexAttribPointer(location, components, GL_FLOAT, GL_FALSE, 0, nullptr);
  return b;
}

/// The mesh's morph entry lists as two texture buffers (morphs.h build_morph_entries).
Status upload_morphs(GpuMesh& g, const MeshView& mesh, std::string_view asset_name,
                     std::span<const int32_t> target_channel) {
  const MorphEntries e = build_morph_entries(mesh, target_channel);
  if (e.empty()) return {};
  GLint max_texels = 0;
  glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &max_texels);
  const size_t texels = e.entry_count * static_cast<size_t>(e.texels_per_entry);
  if (texels > static_cast<size_t>(max_texels) || mesh.vertex_count() > static_cast<size_t>(max_texels)) {
    return Error{where(mesh, asset_name) + ": " + std::to_string(texels) +
                 " morph texels exceed this GL's texture buffer (" + std::to_string(max_texels) + " texels)"};
  }
  make_texture_buffer(GL_RG32I, e.ranges.data(), e.ranges.size() * sizeof(int32_t), GL_STATIC_DRAW,
                      g.morph_range_buffer, g.morph_range_texture);
  make_texture_buffer(GL_RGBA32F, e.texels.data(), e.texels.size() * sizeof(float), GL_STATIC_DRAW,
                      g.morph_entry_buffer, g.morph_entry_texture);
  g.morph_texels = e.texels_per_entry;
  return {};
}

/// The cloth's vertex -> particle map as a texture buffer (gpu_mesh.h). O(vertices).
Status upload_cloth_slots(GpuMesh& g, const MeshView& mesh, std::string_view asset_name) {
  if (!mesh.fb->cloth()) return {};
  const ClothSource source = cloth_source(mesh);
  GLint max_texels = 0;
  glGetIntegerv(GL_MAX_TEXTURE_BUFFER_SIZE, &max_texels);
  if (mesh.vertex_count() > static_cast<size_t>(max_texels))
    return Error{where(mesh, asset_name) + ": " + std::to_string(mesh.vertex_count()) +
                 " cloth vertices exceed this GL's texture buffer (" + std::to_string(max_texels) + " texels)"};
  std::vector<int32_t> slots(mesh.vertex_count(), -1);
  for (size_t k = 0; k < source.vertices.size() && k < source.vertex_particles.size(); ++k) {
    const uint32_t v = source.vertices[k], p = source.vertex_particles[k];
    if (v >= slots.size() || p >= source.particle_count())
      return Error{where(mesh, asset_name) + ": cloth vertex " + std::to_string(k) + " is past the mesh"};
    const bool flipped = k < source.flipped.size() && source.flipped[k] != 0;
    slots[v] = static_cast<int32_t>(2 * p + (flipped ? 1u : 0u));
  }
  make_texture_buffer(GL_R32I, slots.data(), slots.size() * sizeof(int32_t), GL_STATIC_DRAW, g.cloth_slot_buffer,
                      g.cloth_slot_texture);
  g.cloth_particles = static_cast<uint32_t>(source.particle_count());
  return {};
}

}  // namespace

Result<GpuMesh> create_gpu_mesh(const MeshView& mesh, std::string_view asset_name,
                                std::span<const int32_t> target_channel) {
  GpuMesh g;
  g.vertex_count = mesh.vertex_count();
  g.index_type = mesh.index_format() == fb::IndexFormat::Uint32 ? GL_UNSIGNED_INT : GL_UNSIGNED_SHORT;
  g.index_size = mesh.index_format() == fb::IndexFormat::Uint32 ? 4 : 2;
  g.palette_slots = mesh.joints().empty() ? 1u : static_cast<uint32_t>(mesh.joints().size());

  const fb::VertexAttribute* position = mesh.attribute(fb::VertexSemantic::Position);
  const fb::VertexAttribute* normal = mesh.attribute(fb::VertexSemantic::Normal);
  const fb::VertexAttribute* tangent = mesh.attribute(fb::VertexSemantic::Tangent);
  if (position == nullptr) return Error{where(mesh, asset_name) + ": has no positions"};
  g.has_normals = normal != nullptr;
  g.has_tangents = tangent != nullptr;
  g.has_joints =
      mesh.attribute(fb::VertexSemantic::Joints) != nullptr && mesh.attribute(fb::VertexSemantic::Weights) != nullptr;
  g.has_colors = mesh.attribute(fb::VertexSemantic::Color0) != nullptr;
  if (normal)
    g.normal_encoding =
        vertex_format_info(normal->format()).components == 2 ? NormalEncoding::Octahedral : NormalEncoding::Xyz;
  if (tangent) {
    const bool octahedral =
        tangent->format() == fb::VertexFormat::Snorm16x4 || vertex_format_info(tangent->format()).components == 2;
    g.tangent_encoding = octahedral ? TangentEncoding::OctahedralSignZ : TangentEncoding::XyzSignW;
  }
  // Directions are divided by the per-axis position scale that the palette folds in (skinning.h).
  if (vertex_format_info(position->format()).normalized) {
    if (const fb::Vec3* s = mesh.fb->position_scale()) {
      const glm::vec3 scale(s->x(), s->y(), s->z());
      for (int a = 0; a < 3; ++a) g.direction_prescale[a] = scale[a] != 0.0f ? 1.0f / scale[a] : 0.0f;
    }
  }

  // The file's bytes, as they are.
  glGenVertexArrays(1, &g.vao);
  glBindVertexArray(g.vao);
  g.vertex_buffer = make_buffer(GL_ARRAY_BUFFER, mesh.vertex_bytes(), GL_STATIC_DRAW);
  g.index_buffer = make_buffer(GL_ELEMENT_ARRAY_BUFFER, mesh.index_bytes(), GL_STATIC_DRAW);
  if (Status s = set_layout_pointers(mesh, asset_name, false); !s) {
    destroy_gpu_mesh(g);
    return s.error();
  }

  // The CPU-skinning vertex array: skinned float streams + the file's UVs / colours.
  glGenVertexArrays(1, &g.cpu_vao);
  glBindVertexArray(g.cpu_vao);
  glBindBuffer(GL_ARRAY_BUFFER, g.vertex_buffer);
  if (Status s = set_layout_pointers(mesh, asset_name, true); !s) {
    destroy_gpu_mesh(g);
    return s.error();
  }
  glBindBuffer(GL_ELEMENT_ARRAY_BUFFER, g.index_buffer);
  g.cpu_positions = float_stream(kPosition, 3);
  if (g.has_normals) g.cpu_normals = float_stream(kNormal, 3);
  if (g.has_tangents) g.cpu_tangents = float_stream(kTangent, 4);
  glBindVertexArray(0);
  if (Status s = upload_morphs(g, mesh, asset_name, target_channel); !s) {
    destroy_gpu_mesh(g);
    return s.error();
  }
  if (Status s = upload_cloth_slots(g, mesh, asset_name); !s) {
    destroy_gpu_mesh(g);
    return s.error();
  }
  return g;
}

void destroy_gpu_mesh(GpuMesh& g) {
  const GLuint buffers[] = {g.vertex_buffer, g.index_buffer,       g.cpu_positions,      g.cpu_normals,
                            g.cpu_tangents,  g.morph_range_buffer, g.morph_entry_buffer, g.cloth_slot_buffer};
  for (GLuint b : buffers) {
    if (b != 0) glDeleteBuffers(1, &b);
  }
  const GLuint textures[] = {g.morph_range_texture, g.morph_entry_texture, g.cloth_slot_texture};
  for (GLuint t : textures) {
    if (t != 0) glDeleteTextures(1, &t);
  }
  const GLuint arrays[] = {g.vao, g.cpu_vao};
  for (GLuint a : arrays) {
    if (a != 0) glDeleteVertexArrays(1, &a);
  }
  g = GpuMesh{};
}

void set_default_attributes() {
  glVertexAttrib4f(kNormal, 0.0f, 0.0f, 1.0f, 0.0f);
  glVertexAttrib4f(kTangent, 1.0f, 0.0f, 0.0f, 1.0f);
  glVertexAttrib4f(kTexCoord0, 0.0f, 0.0f, 0.0f, 1.0f);
  glVertexAttrib4f(kColor0, 1.0f, 1.0f, 1.0f, 1.0f);
  glVertexAttribI4ui(kJoints, 0, 0, 0, 0);
  glVertexAttrib4f(kWeights, 1.0f, 0.0f, 0.0f, 0.0f);
}

}  // namespace ossa::view
