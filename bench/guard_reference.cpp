// guard_reference.cpp — the guard's plain scalar references (guard_reference.h).
#include "bench/guard_reference.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstdlib>

#include <ossa/anim/pose.h>
#include <ossa/anim/sample.h>
#include <ossa/format/vertex_codec.h>
#include <ossa/format/vertex_format.h>
#include <ossa/skinning/vertex_fetch.h>

namespace ossa::bench {

PlainClip plain_clip(const ClipView& clip, const SkeletonView& skeleton) {
  PlainClip c;
  c.joints = static_cast<uint32_t>(skeleton.joint_count());
  c.frames = clip.frame_count();
  c.sample_rate = clip.sample_rate();
  c.duration = clip.duration();
  c.keys.resize(size_t(c.frames) * c.joints);
  auto cache = make_sampling_cache(clip, skeleton);
  if (!cache) {
    std::fprintf(stderr, "guard reference: %s\n", cache.error().message.c_str());
    std::exit(1);
  }
  Pose pose(c.joints);
  for (uint32_t f = 0; f < c.frames; ++f) {
    sample(clip, static_cast<float>(f) / c.sample_rate, {}, *cache, pose);
    for (uint32_t j = 0; j < c.joints; ++j) {
      const Transform t = get_transform(pose, j);
      c.keys[size_t(f) * c.joints + j] = {{t.translation.x, t.translation.y, t.translation.z},
                                          {t.rotation.x, t.rotation.y, t.rotation.z, t.rotation.w},
                                          {t.scale.x, t.scale.y, t.scale.z}};
    }
  }
  return c;
}

void plain_sample(const PlainClip& clip, float time, PlainTransform* out) {
  float t = time;
  if (!(t >= 0.0f && t < clip.duration)) t = clip.duration > 0.0f ? std::fmod(std::fabs(t), clip.duration) : 0.0f;
  const float position = std::min(t * clip.sample_rate, static_cast<float>(clip.frames - 1));
  const auto f0 = static_cast<uint32_t>(position);
  const uint32_t f1 = std::min(f0 + 1, clip.frames - 1);
  const float b = position - static_cast<float>(f0), a = 1.0f - b;
  const PlainTransform* k0 = &clip.keys[size_t(f0) * clip.joints];
  const PlainTransform* k1 = &clip.keys[size_t(f1) * clip.joints];
  for (uint32_t j = 0; j < clip.joints; ++j) {
    const PlainTransform &p = k0[j], &q = k1[j];
    PlainTransform& o = out[j];
    for (int c = 0; c < 3; ++c) {
      o.t[c] = p.t[c] * a + q.t[c] * b;
      o.s[c] = p.s[c] * a + q.s[c] * b;
    }
    const float dot = p.r[0] * q.r[0] + p.r[1] * q.r[1] + p.r[2] * q.r[2] + p.r[3] * q.r[3];
    const float bq = dot < 0.0f ? -b : b;
    float r[4], n = 0.0f;
    for (int c = 0; c < 4; ++c) {
      r[c] = p.r[c] * a + q.r[c] * bq;
      n += r[c] * r[c];
    }
    const float inv = 1.0f / std::sqrt(n);
    for (int c = 0; c < 4; ++c) o.r[c] = r[c] * inv;
  }
}

void plain_blend(std::span<const PlainTransform* const> poses, std::span<const float> weights, uint32_t joints,
                 PlainTransform* out) {
  for (uint32_t j = 0; j < joints; ++j) {
    PlainTransform o = {};
    const PlainTransform& first = poses[0][j];
    for (size_t k = 0; k < poses.size(); ++k) {
      const PlainTransform& p = poses[k][j];
      const float w = weights[k];
      const float dot = first.r[0] * p.r[0] + first.r[1] * p.r[1] + first.r[2] * p.r[2] + first.r[3] * p.r[3];
      const float wr = dot < 0.0f ? -w : w;
      for (int c = 0; c < 3; ++c) {
        o.t[c] += w * p.t[c];
        o.s[c] += w * p.s[c];
      }
      for (int c = 0; c < 4; ++c) o.r[c] += wr * p.r[c];
    }
    const float inv = 1.0f / std::sqrt(o.r[0] * o.r[0] + o.r[1] * o.r[1] + o.r[2] * o.r[2] + o.r[3] * o.r[3]);
    for (int c = 0; c < 4; ++c) o.r[c] *= inv;
    out[j] = o;
  }
}

void plain_model(std::span<const int16_t> parents, const PlainTransform* local, glm::mat4* out) {
  for (size_t j = 0; j < parents.size(); ++j) {
    const PlainTransform& l = local[j];
    const float x = l.r[0], y = l.r[1], z = l.r[2], w = l.r[3];
    glm::mat4 m(1.0f);
    m[0] = glm::vec4(1.0f - 2.0f * (y * y + z * z), 2.0f * (x * y + w * z), 2.0f * (x * z - w * y), 0.0f) * l.s[0];
    m[1] = glm::vec4(2.0f * (x * y - w * z), 1.0f - 2.0f * (x * x + z * z), 2.0f * (y * z + w * x), 0.0f) * l.s[1];
    m[2] = glm::vec4(2.0f * (x * z + w * y), 2.0f * (y * z - w * x), 1.0f - 2.0f * (x * x + y * y), 0.0f) * l.s[2];
    m[3] = glm::vec4(l.t[0], l.t[1], l.t[2], 1.0f);
    const int p = parents[j];
    out[j] = p >= 0 && size_t(p) < j ? out[p] * m : m;
  }
}

void plain_palette(std::span<const uint16_t> joints, std::span<const glm::mat4> bind, const glm::mat4* model,
                   glm::mat4* palette) {
  for (size_t s = 0; s < joints.size(); ++s) palette[s] = model[joints[s]] * bind[s];
}

PlainMesh plain_mesh(const MeshView& mesh) {
  PlainMesh m;
  m.vertices = mesh.vertex_count();
  const fb::VertexAttribute* position = mesh.attribute(fb::VertexSemantic::Position);
  const fb::VertexAttribute* normal = mesh.attribute(fb::VertexSemantic::Normal);
  const fb::VertexAttribute* joints = mesh.attribute(fb::VertexSemantic::Joints);
  const fb::VertexAttribute* weights = mesh.attribute(fb::VertexSemantic::Weights);
  if (position == nullptr || normal == nullptr || joints == nullptr || weights == nullptr) {
    std::fprintf(stderr, "guard reference: the mesh lacks positions, normals or influences\n");
    std::exit(1);
  }
  // Directions are transformed by the palette, which holds the positions' dequantization D: the
  // runtime pre-scales them by 1 / D's scale; so does this copy.
  glm::vec3 prescale(1.0f);
  if (vertex_format_info(position->format()).normalized && mesh.fb->position_scale() != nullptr) {
    const fb::Vec3* s = mesh.fb->position_scale();
    const float scale[3] = {s->x(), s->y(), s->z()};
    for (int a = 0; a < 3; ++a) prescale[a] = scale[a] != 0.0f ? 1.0f / scale[a] : 0.0f;
  }
  const uint8_t* base = mesh.vertex_bytes().data();
  const size_t stride = mesh.vertex_stride();
  for (uint32_t v = 0; v < m.vertices; ++v) {
    const uint8_t* at = base + v * stride;
    const glm::vec4 p = fetch_vertex_attribute(at + position->offset(), position->format());
    glm::vec4 n = fetch_vertex_attribute(at + normal->offset(), normal->format());
    if (vertex_format_info(normal->format()).components == 2) {
      const Float3 d = octahedral_decode({n.x, n.y});
      n = glm::vec4(d.x, d.y, d.z, 0.0f);
    }
    const glm::vec4 s = fetch_vertex_attribute(at + joints->offset(), joints->format());
    const glm::vec4 w = fetch_vertex_attribute(at + weights->offset(), weights->format());
    for (int c = 0; c < 3; ++c) {
      m.positions.push_back(p[c]);
      m.normals.push_back(n[c] * prescale[c]);
    }
    for (int k = 0; k < 4; ++k) {
      m.slots.push_back(static_cast<uint16_t>(s[k]));
      m.weights.push_back(w[k]);
    }
  }
  return m;
}

void plain_skin(const PlainMesh& mesh, const glm::mat4* palette, float* positions, float* normals) {
  for (uint32_t v = 0; v < mesh.vertices; ++v) {
    glm::mat4 m(0.0f);
    for (int k = 0; k < 4; ++k) m += palette[mesh.slots[4 * v + k]] * mesh.weights[4 * v + k];
    const float* p = &mesh.positions[3 * v];
    const float* n = &mesh.normals[3 * v];
    const glm::vec3 rp = glm::vec3(m[0]) * p[0] + glm::vec3(m[1]) * p[1] + glm::vec3(m[2]) * p[2] + glm::vec3(m[3]);
    glm::vec3 rn = glm::vec3(m[0]) * n[0] + glm::vec3(m[1]) * n[1] + glm::vec3(m[2]) * n[2];
    rn *= 1.0f / std::sqrt(glm::dot(rn, rn));
    for (int c = 0; c < 3; ++c) {
      positions[3 * v + c] = rp[c];
      normals[3 * v + c] = rn[c];
    }
  }
}

}  // namespace ossa::bench
