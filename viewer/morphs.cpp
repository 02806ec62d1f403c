// morphs.cpp — see morphs.h.
//
// Attribute decoding follows what OpenGL fetches and what skin_cpu decodes (runtime/skinning):
// normalized formats scaled to [0, 1] / [-1, 1], two-component directions are octahedral,
// Snorm16x4 tangents are octahedral xy with the bitangent sign in z, joint slots are integers.
#include "viewer/morphs.h"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <string>

#include <ossa/anim/morph.h>
#include <ossa/format/vertex_codec.h>
#include <ossa/format/vertex_format.h>
#include <ossa/skinning/vertex_fetch.h>

namespace ossa::view {
namespace {

glm::vec3 to_vec3(const fb::Vec3* v) { return v ? glm::vec3(v->x(), v->y(), v->z()) : glm::vec3(0.0f); }

glm::vec3 octahedral(float x, float y) {
  const Float3 n = octahedral_decode({x, y});
  return {n.x, n.y, n.z};
}

glm::vec3 normalize_or_zero(glm::vec3 v) {
  const float len2 = glm::dot(v, v);
  return len2 > 0.0f ? v * (1.0f / std::sqrt(len2)) : glm::vec3(0.0f);
}

}  // namespace

MorphEntries build_morph_entries(const MeshView& mesh, std::span<const int32_t> target_channel) {
  MorphEntries e;
  const size_t targets = std::min(mesh.morph_target_count(), target_channel.size());
  const size_t vertices = mesh.vertex_count();
  bool normals = false, tangents = false;
  for (size_t t = 0; t < targets; ++t) {
    if (target_channel[t] < 0) continue;
    const fb::MorphTarget& target = mesh.morph_target(t);
    e.entry_count += target.vertices()->size();
    normals = normals || (target.normal_deltas() && target.normal_deltas()->size() != 0);
    tangents = tangents || (target.tangent_deltas() && target.tangent_deltas()->size() != 0);
  }
  if (e.entry_count == 0) return MorphEntries{};
  e.texels_per_entry = tangents ? 3 : (normals ? 2 : 1);

  // Counting sort by vertex: count, prefix-sum into `first`, then place in target order.
  e.ranges.assign(2 * vertices, 0);
  for (size_t t = 0; t < targets; ++t) {
    if (target_channel[t] < 0) continue;
    for (uint32_t v : *mesh.morph_target(t).vertices()) ++e.ranges[2 * v + 1];
  }
  int32_t next = 0;
  for (size_t v = 0; v < vertices; ++v) {
    e.ranges[2 * v] = next;
    next += e.ranges[2 * v + 1];
  }
  std::vector<int32_t> fill(vertices, 0);
  const size_t stride = 4 * static_cast<size_t>(e.texels_per_entry);
  e.texels.assign(e.entry_count * stride, 0.0f);
  for (size_t t = 0; t < targets; ++t) {
    if (target_channel[t] < 0) continue;
    const fb::MorphTarget& target = mesh.morph_target(t);
    const auto* listed = target.vertices();
    const int16_t* dp = target.position_deltas()->data();
    const int16_t* dn =
        target.normal_deltas() && target.normal_deltas()->size() ? target.normal_deltas()->data() : nullptr;
    const int16_t* dt =
        target.tangent_deltas() && target.tangent_deltas()->size() ? target.tangent_deltas()->data() : nullptr;
    const glm::vec3 sp = to_vec3(target.position_step()), sn = to_vec3(target.normal_step()),
                    st = to_vec3(target.tangent_step());
    for (size_t i = 0; i < listed->size(); ++i) {
      const uint32_t v = listed->Get(static_cast<flatbuffers::uoffset_t>(i));
      const size_t entry = static_cast<size_t>(e.ranges[2 * v] + fill[v]++);
      float* out = e.texels.data() + entry * stride;
      for (int a = 0; a < 3; ++a) out[a] = sp[a] * static_cast<float>(dp[3 * i + static_cast<size_t>(a)]);
      out[3] = static_cast<float>(target_channel[t]);
      if (dn && e.texels_per_entry > 1)
        for (int a = 0; a < 3; ++a) out[4 + a] = sn[a] * static_cast<float>(dn[3 * i + static_cast<size_t>(a)]);
      if (dt && e.texels_per_entry > 2)
        for (int a = 0; a < 3; ++a) out[8 + a] = st[a] * static_cast<float>(dt[3 * i + static_cast<size_t>(a)]);
    }
  }
  return e;
}

Result<MorphBase> decode_morph_base(const MeshView& mesh) {
  const std::string where = "mesh '" + std::string(mesh.name()) + "'";
  const fb::VertexAttribute* position = mesh.attribute(fb::VertexSemantic::Position);
  const fb::VertexAttribute* normal = mesh.attribute(fb::VertexSemantic::Normal);
  const fb::VertexAttribute* tangent = mesh.attribute(fb::VertexSemantic::Tangent);
  const fb::VertexAttribute* joints = mesh.attribute(fb::VertexSemantic::Joints);
  const fb::VertexAttribute* weights = mesh.attribute(fb::VertexSemantic::Weights);
  if (position == nullptr) return Error{where + ": has no positions"};
  if (joints == nullptr || weights == nullptr) joints = weights = nullptr;
  for (const fb::VertexAttribute* a : {position, normal, tangent, joints, weights}) {
    if (a != nullptr && vertex_format_info(a->format()).size == 0)
      return Error{where + ": vertex format " + std::to_string(static_cast<int>(a->format())) + " cannot be decoded"};
  }

  MorphBase b;
  const size_t n = mesh.vertex_count();
  const size_t stride = mesh.vertex_stride();
  const uint8_t* bytes = mesh.vertex_bytes().data();
  b.dequantize = vertex_format_info(position->format()).normalized;
  if (b.dequantize) {
    b.offset = mesh.fb->position_offset() ? to_vec3(mesh.fb->position_offset()) : glm::vec3(0.0f);
    b.scale = mesh.fb->position_scale() ? to_vec3(mesh.fb->position_scale()) : glm::vec3(1.0f);
    for (int a = 0; a < 3; ++a) b.direction_prescale[a] = b.scale[a] != 0.0f ? 1.0f / b.scale[a] : 0.0f;
  }
  b.positions.resize(n);
  b.slots.resize(n, glm::uvec4(0));
  b.weights.resize(n, glm::vec4(1.0f, 0.0f, 0.0f, 0.0f));
  if (normal) b.normals.resize(n);
  if (tangent) b.tangents.resize(n);
  const bool normal_octahedral = normal && vertex_format_info(normal->format()).components == 2;
  const bool tangent_octahedral = tangent && (tangent->format() == fb::VertexFormat::Snorm16x4 ||
                                              vertex_format_info(tangent->format()).components == 2);
  for (size_t v = 0; v < n; ++v) {
    const uint8_t* vertex = bytes + v * stride;
    b.positions[v] = glm::vec3(fetch_vertex_attribute(vertex + position->offset(), position->format()));
    if (normal) {
      const glm::vec4 f = fetch_vertex_attribute(vertex + normal->offset(), normal->format());
      b.normals[v] = normal_octahedral ? octahedral(f.x, f.y) : glm::vec3(f);
    }
    if (tangent) {
      const glm::vec4 f = fetch_vertex_attribute(vertex + tangent->offset(), tangent->format());
      if (tangent_octahedral)
        b.tangents[v] = glm::vec4(octahedral(f.x, f.y),
                                  tangent->format() == fb::VertexFormat::Snorm16x4 && f.z < 0.0f ? -1.0f : 1.0f);
      else b.tangents[v] = glm::vec4(glm::vec3(f), f.w < 0.0f ? -1.0f : 1.0f);
    }
    if (joints) {
      b.slots[v] = glm::uvec4(fetch_vertex_attribute(vertex + joints->offset(), joints->format()));
      b.weights[v] = fetch_vertex_attribute(vertex + weights->offset(), weights->format());
    }
  }
  return b;
}

bool morph_and_skin_cpu(const MeshView& mesh, const MorphBase& base, std::span<const int32_t> target_channel,
                        std::span<const float> weights, std::span<const glm::mat4> palette, MorphScratch& scratch,
                        SkinnedStreams out) {
  const size_t n = base.positions.size();
  if (out.positions.size() < 3 * n) return false;
  const bool normals = !out.normals.empty() && !base.normals.empty();
  const bool tangents = !out.tangents.empty() && !base.tangents.empty();
  if ((normals && out.normals.size() < 3 * n) || (tangents && out.tangents.size() < 4 * n)) return false;

  // apply_morphs on mesh-unit values: the positions' weighted deltas (accumulated from zero and
  // added to the stored position divided by position_scale, as the shader does, so that zero
  // weights give skin_cpu's input exactly), and the unit directions themselves.
  scratch.positions.assign(n, glm::vec3(0.0f));
  if (normals) scratch.normals.assign(base.normals.begin(), base.normals.end());
  else scratch.normals.clear();
  scratch.tangents.resize(tangents ? n : 0);
  for (size_t v = 0; v < scratch.tangents.size(); ++v) scratch.tangents[v] = glm::vec3(base.tangents[v]);
  if (!apply_morphs(mesh, target_channel, weights, scratch.positions, scratch.normals, scratch.tangents)) return false;

  for (size_t v = 0; v < n; ++v) {
    // Columns of the blended matrix; all four influences, as skin_cpu's linear path.
    glm::mat4 m(0.0f);
    for (int k = 0; k < 4; ++k) {
      const uint32_t s = base.slots[v][k];
      if (s < palette.size()) m += palette[s] * base.weights[v][k];
    }
    const glm::vec3 c0(m[0]), c1(m[1]), c2(m[2]), c3(m[3]);
    const glm::vec3 q = base.positions[v] + scratch.positions[v] * base.direction_prescale;
    const glm::vec3 p = c0 * q.x + c1 * q.y + c2 * q.z + c3;
    std::memcpy(out.positions.data() + 3 * v, &p[0], 12);
    if (normals) {
      const glm::vec3 d = scratch.normals[v] * base.direction_prescale;
      const glm::vec3 r = normalize_or_zero(c0 * d.x + c1 * d.y + c2 * d.z);
      std::memcpy(out.normals.data() + 3 * v, &r[0], 12);
    }
    if (tangents) {
      const glm::vec3 d = scratch.tangents[v] * base.direction_prescale;
      const glm::vec4 r(normalize_or_zero(c0 * d.x + c1 * d.y + c2 * d.z), base.tangents[v].w);
      std::memcpy(out.tangents.data() + 4 * v, &r[0], 16);
    }
  }
  return true;
}

}  // namespace ossa::view
