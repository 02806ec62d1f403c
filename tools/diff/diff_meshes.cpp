// diff_meshes.cpp — the mesh section of ossa-diff: meshes matched by name, their topology, their
// attribute layout, and the largest bind-pose vertex displacement.
//
// Positions are decoded from the vertex bytes with the format's own codecs (<ossa/format/vertex_codec.h>,
// <ossa/format/vertex_format.h>) into mesh-space coordinates — a normalized position format through the
// mesh's de-quantizing affine (position_offset + position_scale * q), as skin_cpu and the shader
// apply it — so a quantized cook and a float32 cook of one mesh compare by where their vertices
// are, not by their bytes. Displacement pairs vertex i with vertex i, which means something only
// when the topology is the same (same counts, same index values); otherwise the topology change
// is reported and the displacement skipped. Indices are compared as values, so a mesh that moved
// from 16-bit to 32-bit indices with the same triangles keeps the same topology.
#include <algorithm>
#include <cstring>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include <ossa/format/vertex_codec.h>
#include <ossa/format/vertex_format.h>
#include "common/message.h"
#include "tools/diff/diff_internal.h"

namespace ossa::diff::internal {
namespace {

constexpr const char* kSection = "meshes";

std::vector<uint32_t> decode_indices(const MeshView& m) {
  const auto bytes = m.index_bytes();
  std::vector<uint32_t> out(m.index_count());
  if (m.index_format() == fb::IndexFormat::Uint16) {
    for (size_t i = 0; i < out.size(); ++i) {
      uint16_t v;
      std::memcpy(&v, bytes.data() + 2 * i, 2);
      out[i] = v;
    }
  } else {
    std::memcpy(out.data(), bytes.data(), 4 * out.size());
  }
  return out;
}

/// One attribute value as OpenGL fetches it (normalized formats scaled to [0, 1] / [-1, 1]).
glm::dvec3 fetch3(const uint8_t* p, fb::VertexFormat format) {
  double v[4] = {0.0, 0.0, 0.0, 0.0};
  const unsigned n = vertex_format_info(format).components;
  for (unsigned i = 0; i < n && i < 3; ++i) {
    switch (format) {
      case fb::VertexFormat::Float32x2:
      case fb::VertexFormat::Float32x3:
      case fb::VertexFormat::Float32x4: {
        float f;
        std::memcpy(&f, p + 4 * i, 4);
        v[i] = f;
        break;
      }
      case fb::VertexFormat::Unorm16x4:
      case fb::VertexFormat::Uint16x4: {
        uint16_t q;
        std::memcpy(&q, p + 2 * i, 2);
        v[i] = format == fb::VertexFormat::Unorm16x4 ? unorm16_to_float(q) : q;
        break;
      }
      case fb::VertexFormat::Snorm16x2:
      case fb::VertexFormat::Snorm16x4: {
        int16_t q;
        std::memcpy(&q, p + 2 * i, 2);
        v[i] = snorm16_to_float(q);
        break;
      }
      case fb::VertexFormat::Float16x2: {
        uint16_t h;
        std::memcpy(&h, p + 2 * i, 2);
        v[i] = half_to_float(h);
        break;
      }
      case fb::VertexFormat::Uint8x4: v[i] = p[i]; break;
      case fb::VertexFormat::Unorm8x4: v[i] = p[i] / 255.0; break;
    }
  }
  return {v[0], v[1], v[2]};
}

/// Mesh-space positions in file units; empty when the mesh has no position attribute.
std::vector<glm::dvec3> decode_positions(const MeshView& m) {
  const fb::VertexAttribute* pos = m.attribute(fb::VertexSemantic::Position);
  if (pos == nullptr) return {};
  glm::dvec3 offset(0.0), scale(1.0);
  if (vertex_format_info(pos->format()).normalized) {
    if (const fb::Vec3* o = m.fb->position_offset()) offset = {o->x(), o->y(), o->z()};
    if (const fb::Vec3* s = m.fb->position_scale()) scale = {s->x(), s->y(), s->z()};
  }
  std::vector<glm::dvec3> out(m.vertex_count());
  const uint8_t* p = m.vertex_bytes().data() + pos->offset();
  for (size_t i = 0; i < out.size(); ++i, p += m.vertex_stride()) out[i] = offset + scale * fetch3(p, pos->format());
  return out;
}

MeshShape shape_of(const MeshView& m) {
  MeshShape s;
  s.vertex_count = m.vertex_count();
  s.index_count = m.index_count();
  s.submesh_count = static_cast<uint32_t>(m.submeshes().size());
  s.vertex_stride = m.vertex_stride();
  for (const fb::VertexAttribute& a : m.layout())
    s.layout += (s.layout.empty() ? "" : ", ") + std::string(fb::EnumNameVertexSemantic(a.semantic())) + " " +
                fb::EnumNameVertexFormat(a.format()) + " @" + std::to_string(a.offset());
  return s;
}

bool same_submeshes(const MeshView& a, const MeshView& b) {
  const auto x = a.submeshes(), y = b.submeshes();
  if (x.size() != y.size()) return false;
  for (size_t i = 0; i < x.size(); ++i)
    if (x[i].first_index() != y[i].first_index() || x[i].index_count() != y[i].index_count() ||
        x[i].material() != y[i].material())
      return false;
  return true;
}

std::string counts_text(const MeshShape& s) {
  return std::to_string(s.vertex_count) + " vertices, " + std::to_string(s.index_count) + " indices, " +
         std::to_string(s.submesh_count) + " submeshes";
}

MeshItem compare_mesh(Context& c, const std::string& label, const MeshView& a, const MeshView& b) {
  MeshItem item;
  item.name = label;
  item.old_shape = shape_of(a);
  item.new_shape = shape_of(b);
  item.layout_same =
      item.old_shape.layout == item.new_shape.layout && item.old_shape.vertex_stride == item.new_shape.vertex_stride;
  item.index_data_same = decode_indices(a) == decode_indices(b);
  item.topology_same = a.vertex_count() == b.vertex_count() && item.index_data_same && same_submeshes(a, b);
  if (!item.layout_same)
    c.add_text(kSection, label, "layout",
               "stride " + std::to_string(item.old_shape.vertex_stride) + " -> " +
                   std::to_string(item.new_shape.vertex_stride),
               item.old_shape.layout + " -> " + item.new_shape.layout);
  if (!item.topology_same) {
    const bool counts_same = item.old_shape.vertex_count == item.new_shape.vertex_count &&
                             item.old_shape.index_count == item.new_shape.index_count &&
                             item.old_shape.submesh_count == item.new_shape.submesh_count;
    c.add_text(kSection, label, "topology",
               counts_same
                   ? std::string(item.index_data_same ? "submesh ranges or materials changed" : "index data changed")
                   : counts_text(item.old_shape) + " -> " + counts_text(item.new_shape));
    item.note = "topology changed: vertex displacement not measured";
    return item;
  }
  const std::vector<glm::dvec3> pa = decode_positions(a), pb = decode_positions(b);
  if (pa.empty() != pb.empty() || (pa.empty() && a.vertex_count() > 0)) {
    item.note = "no position attribute on one side: vertex displacement not measured";
    if (pa.empty() != pb.empty()) c.add_text(kSection, label, "positions", pa.empty() ? "added" : "removed");
    return item;
  }
  double worst = 0.0;
  for (size_t i = 0; i < pa.size(); ++i) {
    const double d = glm::length(pa[i] * c.old_mm() - pb[i] * c.new_mm());
    if (d > worst) {
      worst = d;
      item.worst_vertex = static_cast<uint32_t>(i);
    }
  }
  item.max_displacement_mm = worst;
  if (worst > c.tolerance_mm)
    c.add_figure(kSection, label, "vertex displacement", worst, "mm", c.tolerance_mm,
                 "vertex " + std::to_string(item.worst_vertex));
  return item;
}

}  // namespace

void compare_meshes(Context& c) {
  MeshSection& out = c.report.meshes;
  out.old_count = c.old_asset.mesh_count();
  out.new_count = c.new_asset.mesh_count();
  std::vector<std::string> old_names, new_names;
  for (size_t i = 0; i < out.old_count; ++i) old_names.emplace_back(c.old_asset.mesh(i).name());
  for (size_t k = 0; k < out.new_count; ++k) new_names.emplace_back(c.new_asset.mesh(k).name());
  const NameMatch m = match_by_name(old_names, new_names);
  report_added_removed(c, kSection, m, old_names, new_names, out.added, out.removed);
  for (const auto& [i, k] : m.pairs) {
    MeshItem item = compare_mesh(c, item_label(old_names, i), c.old_asset.mesh(i), c.new_asset.mesh(k));
    if (item.max_displacement_mm)
      out.max_displacement_mm = std::max(out.max_displacement_mm, *item.max_displacement_mm);
    if (!item.note.empty()) c.report.notes.push_back("mesh '" + item.name + "': " + item.note);
    out.items.push_back(std::move(item));
  }
}

}  // namespace ossa::diff::internal
