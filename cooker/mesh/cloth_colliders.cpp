// cloth_colliders.cpp — the colliders a cooked cloth is kept out of (cloth_build.h), and the bind
// pose of a cooked mesh's vertices, which the cloth's rest lengths are measured on.
//
// Fitting: every bone (a joint and one child) is a candidate capsule, owned by the joint. Its
// radius is the median distance from the bone of the body vertices that joint moves most (each
// given to the nearest of its joint's bones): the limb's own thickness, a little inside the skin
// where the cross-section is not round. It is then shrunk to stay clear of the cloth's bind pose
// (by the cloth's thickness and 2 mm), since a collider that starts inside the cloth would throw it
// off at the first update. The bones a free particle can reach (closer to it than its tether
// length) are kept, nearest first, at most max_colliders.
#include <algorithm>
#include <cmath>

#include "cooker/mesh/cloth_internal.h"
#include <ossa/format/vertex_codec.h>
#include <ossa/format/vertex_format.h>
#include <ossa/skinning/vertex_fetch.h>

namespace ossa::cook::detail {
namespace {

float segment_distance(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b) {
  const glm::vec3 ab = b - a;
  const float len2 = glm::dot(ab, ab);
  const float t = len2 > 0.0f ? std::clamp(glm::dot(p - a, ab) / len2, 0.0f, 1.0f) : 0.0f;
  return glm::distance(p, a + ab * t);
}

int joint_named(const SourceSkeleton& skeleton, const std::string& name) {
  for (size_t j = 0; j < skeleton.joints.size(); ++j)
    if (skeleton.joints[j].name == name) return static_cast<int>(j);
  return -1;
}

struct Bone {
  int joint = -1, child = -1;
  glm::vec3 a{0.0f}, b{0.0f};    // model space
  std::vector<float> distances;  // of the body vertices it owns
};

bool is_body_vertex(const SourceScene& scene, const ClothOptions& options, const SourceMesh& m, size_t v) {
  for (const ClothRegion& r : options.regions)
    if ((!r.mesh.empty() && m.name == r.mesh) ||
        (r.mesh.empty() && m.material < scene.materials.size() && scene.materials[m.material].name == r.material))
      return false;
  return !(options.paint && !m.cloth_paint.empty() && m.cloth_paint[v].r > 0.0f);
}

}  // namespace

DecodedMesh decode_bind_pose(const SourceScene& scene, const CookedMesh& mesh) {
  DecodedMesh out;
  const uint32_t n = mesh.vertex_count;
  out.positions.resize(n);
  out.normals.assign(n, glm::vec3(0.0f, 1.0f, 0.0f));
  const fb::VertexAttribute *pa = nullptr, *na = nullptr, *ja = nullptr, *wa = nullptr;
  for (const fb::VertexAttribute& a : mesh.layout) {
    if (a.semantic() == fb::VertexSemantic::Position) pa = &a;
    if (a.semantic() == fb::VertexSemantic::Normal) na = &a;
    if (a.semantic() == fb::VertexSemantic::Joints) ja = &a;
    if (a.semantic() == fb::VertexSemantic::Weights) wa = &a;
  }
  if (!pa) return out;
  const std::vector<glm::mat4> bind_model = bind_model_matrices(scene.skeleton);
  const bool quantized = pa->format() == fb::VertexFormat::Unorm16x4;
  for (uint32_t v = 0; v < n; ++v) {
    const uint8_t* vb = mesh.vertices.data() + static_cast<size_t>(v) * mesh.vertex_stride;
    const glm::vec4 q = fetch_vertex_attribute(vb + pa->offset(), pa->format());
    const glm::vec3 p = quantized ? mesh.position_offset + mesh.position_scale * glm::vec3(q) : glm::vec3(q);
    glm::mat4 m(1.0f);
    if (ja && wa && !mesh.joints.empty()) {
      const glm::vec4 slot = fetch_vertex_attribute(vb + ja->offset(), ja->format());
      const glm::vec4 w = fetch_vertex_attribute(vb + wa->offset(), wa->format());
      m = glm::mat4(0.0f);
      for (int k = 0; k < 4; ++k) {
        if (!(w[k] > 0.0f)) continue;
        const size_t s = static_cast<size_t>(slot[k]);
        const uint16_t j = mesh.joints[s];
        m += w[k] * (j < bind_model.size() ? bind_model[j] : glm::mat4(1.0f)) * mesh.inverse_bind[s];
      }
    }
    out.positions[v] = glm::vec3(m * glm::vec4(p, 1.0f));
    if (na) {
      const glm::vec4 e = fetch_vertex_attribute(vb + na->offset(), na->format());
      glm::vec3 d(e);
      if (na->format() == fb::VertexFormat::Snorm16x2) {
        const Float3 f = octahedral_decode(Float2{e.x, e.y});
        d = glm::vec3(f.x, f.y, f.z);
      }
      d = glm::mat3(m) * d;
      const float len = glm::length(d);
      out.normals[v] = len > 1e-20f ? d / len : glm::vec3(0.0f, 1.0f, 0.0f);
    }
  }
  return out;
}

Result<std::vector<fb::ClothCollider>> cloth_colliders(const SourceScene& scene, const ClothOptions& options,
                                                       const std::vector<glm::vec3>& rest,
                                                       const std::vector<float>& weight,
                                                       const std::vector<float>& reach, const std::string& label,
                                                       std::vector<std::string>* warnings) {
  std::vector<fb::ClothCollider> out;
  const SourceSkeleton& skeleton = scene.skeleton;
  const float unit = scene.metres_per_unit > 0.0f ? scene.metres_per_unit : 1.0f;
  const std::vector<glm::mat4> model = bind_model_matrices(skeleton);
  // Named colliders.
  for (const ClothColliderSetting& c : options.colliders) {
    const int j = joint_named(skeleton, c.joint);
    if (j < 0) return Error{label + "collider joint '" + c.joint + "' is not a joint of the skeleton"};
    const glm::vec3 offset = c.offset_m / unit;
    glm::vec3 tail = c.has_tail ? c.tail_m / unit : offset;
    if (!c.to.empty()) {
      const int t = joint_named(skeleton, c.to);
      if (t < 0) return Error{label + "collider '" + c.joint + "' ends at '" + c.to + "', not a joint of the skeleton"};
      tail = glm::vec3(glm::inverse(model[static_cast<size_t>(j)]) * model[static_cast<size_t>(t)][3]);
    }
    out.emplace_back(static_cast<uint16_t>(j), fb::Vec3(offset.x, offset.y, offset.z), fb::Vec3(tail.x, tail.y, tail.z),
                     c.radius_m / unit);
  }
  if (!options.colliders.empty() || !options.auto_colliders || skeleton.joints.empty() || options.max_colliders == 0)
    return out;

  // Fitted: a capsule per bone near the cloth.
  std::vector<Bone> bones;
  std::vector<std::vector<size_t>> bones_of(skeleton.joints.size());
  for (size_t j = 0; j < skeleton.joints.size(); ++j) {
    const int p = skeleton.joints[j].parent;
    if (p < 0) continue;
    Bone b;
    b.joint = p;
    b.child = static_cast<int>(j);
    b.a = glm::vec3(model[static_cast<size_t>(p)][3]);
    b.b = glm::vec3(model[j][3]);
    if (glm::distance(b.a, b.b) < 0.01f / unit) continue;  // a twist or end joint, not a limb
    bones_of[static_cast<size_t>(p)].push_back(bones.size());
    bones.push_back(b);
  }
  for (const SourceMesh& m : scene.meshes) {
    if (m.joints.empty()) continue;
    for (size_t v = 0; v < m.positions.size(); ++v) {
      if (!is_body_vertex(scene, options, m, v)) continue;
      int best = 0;
      for (int k = 1; k < 4; ++k)
        if (m.weights[v][k] > m.weights[v][best]) best = k;
      const uint16_t j = m.joints[v][static_cast<size_t>(best)];
      if (j >= bones_of.size() || bones_of[j].empty()) continue;
      const glm::vec3 p = bind_position(m, v, model);
      size_t nearest = bones_of[j].front();
      float d = INFINITY;
      for (const size_t b : bones_of[j]) {
        const float db = segment_distance(p, bones[b].a, bones[b].b);
        if (db < d) {
          d = db;
          nearest = b;
        }
      }
      bones[nearest].distances.push_back(d);
    }
  }
  const float margin = options.thickness_m / unit + 0.002f / unit;
  struct Candidate {
    float gap;  // from the capsule's surface to the nearest free particle
    size_t bone;
    float radius;
  };
  std::vector<Candidate> candidates;
  for (size_t b = 0; b < bones.size(); ++b) {
    std::vector<float>& d = bones[b].distances;
    if (d.size() < 8) continue;
    std::nth_element(d.begin(), d.begin() + static_cast<std::ptrdiff_t>(d.size() / 2), d.end());
    float radius = d[d.size() / 2];
    float clearance = INFINITY, gap = INFINITY;
    bool reachable = false;
    for (size_t p = 0; p < rest.size(); ++p) {
      const float dp = segment_distance(rest[p], bones[b].a, bones[b].b);
      clearance = std::min(clearance, dp - margin);
      if (weight[p] == 0.0f) continue;
      gap = std::min(gap, dp);
      reachable = reachable || dp < reach[p] + radius;
    }
    radius = std::min(radius, clearance);
    if (!reachable || !(radius > 0.01f / unit)) continue;
    candidates.push_back({gap - radius, b, radius});
  }
  std::stable_sort(candidates.begin(), candidates.end(),
                   [](const Candidate& x, const Candidate& y) { return x.gap < y.gap; });
  if (candidates.size() > options.max_colliders) candidates.resize(options.max_colliders);
  for (const Candidate& c : candidates) {
    const Bone& b = bones[c.bone];
    const glm::vec3 tail(glm::inverse(model[static_cast<size_t>(b.joint)]) * glm::vec4(b.b, 1.0f));
    out.emplace_back(static_cast<uint16_t>(b.joint), fb::Vec3(0.0f, 0.0f, 0.0f), fb::Vec3(tail.x, tail.y, tail.z),
                     c.radius);
  }
  if (out.empty() && warnings)
    warnings->push_back(label + "no limb is near enough to fit a collider to (name \"colliders\" in the settings)");
  return out;
}

}  // namespace ossa::cook::detail
