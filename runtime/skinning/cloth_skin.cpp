// cloth_skin.cpp — skin_cloth_particles (ossa/anim/cloth.h): a cloth's driving vertices skinned
// as skin_cpu would skin them, for hosts that skin the rest on the GPU. In the skinning room
// because it decodes vertices with ossa/skinning/vertex_fetch.h, which comes after anim.
#include <ossa/anim/cloth.h>

#include <algorithm>
#include <string>

#include <ossa/format/vertex_codec.h>
#include <ossa/skinning/vertex_fetch.h>
#include "common/message.h"

namespace ossa {
namespace {

using detail::format;

Error fail(const std::string& what) { return Error{"cloth: " + what}; }

}  // namespace

Status skin_cloth_particles(const ClothSource& source, const MeshView& mesh, std::span<const glm::mat4> palette,
                            std::span<glm::vec3> positions, std::span<glm::vec3> normals) {
  const size_t n = source.particle_count();
  if (positions.size() < n || normals.size() < n)
    return fail(format("skin_cloth_particles needs %zu positions and normals, got %zu and %zu", n, positions.size(),
                       normals.size()));
  const fb::VertexAttribute* pa = mesh.attribute(fb::VertexSemantic::Position);
  const fb::VertexAttribute* na = mesh.attribute(fb::VertexSemantic::Normal);
  const fb::VertexAttribute* ja = mesh.attribute(fb::VertexSemantic::Joints);
  const fb::VertexAttribute* wa = mesh.attribute(fb::VertexSemantic::Weights);
  if (!pa) return fail("skin_cloth_particles: the mesh has no positions");
  const size_t slots = std::max<size_t>(1, mesh.joints().size());
  if (palette.size() < slots)
    return fail(
        format("skin_cloth_particles: the palette has %zu matrices, the mesh needs %zu", palette.size(), slots));
  // Directions must not see the de-quantization folded into the palette (skinning.h).
  glm::vec3 prescale(1.0f);
  if (pa->format() == fb::VertexFormat::Unorm16x4 && mesh.fb->position_scale()) {
    const fb::Vec3* s = mesh.fb->position_scale();
    prescale = glm::vec3(1.0f / s->x(), 1.0f / s->y(), 1.0f / s->z());
  }
  const uint8_t* bytes = mesh.vertex_bytes().data();
  const uint32_t stride = mesh.vertex_stride();
  for (size_t i = 0; i < n; ++i) {
    const uint32_t v = source.particle_vertices[i];
    if (v >= mesh.vertex_count())
      return fail(
          format("skin_cloth_particles: particle %zu's vertex %u is past the mesh's %u", i, v, mesh.vertex_count()));
    const uint8_t* vb = bytes + static_cast<size_t>(v) * stride;
    glm::mat4 m = palette[0];
    if (ja && wa) {
      const glm::vec4 slot = fetch_vertex_attribute(vb + ja->offset(), ja->format());
      const glm::vec4 weight = fetch_vertex_attribute(vb + wa->offset(), wa->format());
      m = glm::mat4(0.0f);
      for (int k = 0; k < 4; ++k)
        if (weight[k] != 0.0f) m += weight[k] * palette[static_cast<size_t>(slot[k])];
    }
    const glm::vec4 p = fetch_vertex_attribute(vb + pa->offset(), pa->format());
    positions[i] = glm::vec3(m * glm::vec4(p.x, p.y, p.z, 1.0f));
    glm::vec3 nrm(0.0f, 1.0f, 0.0f);
    if (na) {
      const glm::vec4 e = fetch_vertex_attribute(vb + na->offset(), na->format());
      if (na->format() == fb::VertexFormat::Snorm16x2) {
        const Float3 d = octahedral_decode(Float2{e.x, e.y});
        nrm = glm::vec3(d.x, d.y, d.z);
      } else {
        nrm = glm::vec3(e);
      }
      nrm = glm::mat3(m) * (nrm * prescale);
      const float len = glm::length(nrm);
      nrm = len > 1e-20f ? nrm / len : glm::vec3(0.0f, 1.0f, 0.0f);
    }
    normals[i] = nrm;
  }
  return {};
}

}  // namespace ossa
