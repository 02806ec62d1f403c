// skinning_reference.h — the double-precision reference skin_cpu and skinning_matrices are tested
// against, and the ways of running the code under test in every implementation the CPU has; shared
// by tests/runtime/skinning_test.cpp (synthetic files) and tests/cooker/skinning_cooked_test.cpp
// (cooked samples); tests/cooker/golden_test.cpp checks every cook's class order with it.
//
// The reference is written here from the definition, not from skinning.cpp: a vertex's position
// is sum_k w_k * model[joint(slot_k)] * inverse_bind[slot_k] * (offset + scale * q), its normal
// and tangent the normalized sum_k w_k * (model * inverse_bind)3x3 * direction, every stored value
// decoded in double (unorm16 / 65535, octahedral snorm16, unorm8 / 255). It therefore also checks
// what skinning.cpp folds away: D in the palette, 1 / position_scale on directions, the influence
// classes of the fast paths. Model matrices are computed from the skeleton's bind transforms (and a
// seeded perturbation for posed tests), in float for the code under test and in double for the
// reference, so these tests do not depend on the pose operations. Included by one source of each
// test program, so its functions are inline.
#pragma once
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <random>
#include <span>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include <ossa/format/vertex_codec.h>
#include <ossa/format/vertex_format.h>
#include <ossa/loader/asset.h>
#include <ossa/skinning/skinning.h>

namespace ossa::test::skinning_reference {

using ossa::fb::VertexFormat;
using ossa::fb::VertexSemantic;

// ---------------------------------------------------------------------------------------------
// Implementations

inline std::vector<ossa::SkinningIsa> available_isas() {
  const ossa::SkinningIsa previous = ossa::skinning_isa();
  std::vector<ossa::SkinningIsa> out;
  for (ossa::SkinningIsa isa : {ossa::SkinningIsa::Portable, ossa::SkinningIsa::Avx2, ossa::SkinningIsa::Avx512})
    if (ossa::set_skinning_isa(isa)) out.push_back(isa);
  ossa::set_skinning_isa(previous);
  return out;
}

inline const char* isa_name(ossa::SkinningIsa isa) {
  switch (isa) {
    case ossa::SkinningIsa::Portable: return "portable";
    case ossa::SkinningIsa::Avx2: return "avx2";
    case ossa::SkinningIsa::Avx512: return "avx512";
  }
  return "?";
}

/// The class the fast paths give these weight bytes: 0 one influence of weight 255, else 1 + the
/// index of the last non-zero weight (all zero: 1). The cooker orders vertices by it.
inline int influence_class(const std::array<uint8_t, 4>& w) {
  if (w[0] == 255 && w[1] == 0 && w[2] == 0 && w[3] == 0) return 0;
  for (int k = 3; k > 0; --k)
    if (w[static_cast<size_t>(k)] != 0) return k + 1;
  return 1;
}

/// The first vertex of `mesh` whose influence class is lower than the one before it, or
/// vertex_count() when classes never decrease: the order the cooker promises skin_cpu's class
/// ranges. Reads the Weights attribute as Unorm8x4 (the caller checks its format).
inline uint32_t first_class_drop(const ossa::MeshView& mesh) {
  const ossa::fb::VertexAttribute* w = mesh.attribute(VertexSemantic::Weights);
  int last = 0;
  for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    std::array<uint8_t, 4> q;
    std::memcpy(q.data(), mesh.vertex_bytes().data() + size_t{v} * mesh.vertex_stride() + w->offset(), 4);
    const int c = influence_class(q);
    if (c < last) return v;
    last = c;
  }
  return mesh.vertex_count();
}

/// Selects an implementation for a scope, and puts the previous one back.
class IsaScope {
 public:
  explicit IsaScope(ossa::SkinningIsa isa) : previous_(ossa::skinning_isa()) { ossa::set_skinning_isa(isa); }
  ~IsaScope() { ossa::set_skinning_isa(previous_); }
  IsaScope(const IsaScope&) = delete;
  IsaScope& operator=(const IsaScope&) = delete;

 private:
  ossa::SkinningIsa previous_;
};

// ---------------------------------------------------------------------------------------------
// Poses: model matrices in float (for the code under test) and double (for the reference)

struct Poses {
  std::vector<glm::mat4> model;
  std::vector<glm::dmat4> model_d;
};

inline glm::dmat4 to_d(const glm::mat4& m) { return glm::dmat4(m); }

/// Bind pose, each local rotation turned by up to `max_angle` radians about a seeded axis.
inline Poses make_pose(const ossa::SkeletonView& sk, float max_angle, uint32_t seed) {
  std::mt19937 gen(seed);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  Poses p;
  const size_t n = sk.joint_count();
  p.model.resize(n);
  p.model_d.resize(n);
  for (size_t i = 0; i < n; ++i) {
    const auto& t = sk.bind_translations()[i];
    const auto& r = sk.bind_rotations()[i];
    const auto& s = sk.bind_scales()[i];
    glm::quat q(r.w(), r.x(), r.y(), r.z());
    if (max_angle > 0.0f) {
      const glm::vec3 axis = glm::normalize(glm::vec3(u(gen), u(gen), u(gen)) + glm::vec3(0.0f, 0.0f, 1e-3f));
      q = glm::normalize(q * glm::angleAxis(max_angle * u(gen), axis));
    }
    const glm::vec3 tv(t.x(), t.y(), t.z()), sv(s.x(), s.y(), s.z());
    const glm::mat4 local = glm::translate(glm::mat4(1.0f), tv) * glm::mat4_cast(q) * glm::scale(glm::mat4(1.0f), sv);
    const glm::dmat4 local_d = glm::translate(glm::dmat4(1.0), glm::dvec3(tv)) * glm::mat4_cast(glm::dquat(q)) *
                               glm::scale(glm::dmat4(1.0), glm::dvec3(sv));
    const int parent = sk.parents()[i];
    p.model[i] = parent < 0 ? local : p.model[static_cast<size_t>(parent)] * local;
    p.model_d[i] = parent < 0 ? local_d : p.model_d[static_cast<size_t>(parent)] * local_d;
  }
  return p;
}

// ---------------------------------------------------------------------------------------------
// The double-precision reference

inline glm::dvec3 oct_decode_d(double x, double y) {
  glm::dvec3 n(x, y, 1.0 - std::fabs(x) - std::fabs(y));
  const double t = n.z < 0.0 ? -n.z : 0.0;
  n.x += n.x >= 0.0 ? -t : t;
  n.y += n.y >= 0.0 ? -t : t;
  return glm::normalize(n);
}

inline double snorm_d(int16_t v) { return std::max(static_cast<double>(v) / 32767.0, -1.0); }

struct RefVertex {
  glm::dvec3 position;  // mesh space, de-quantized
  glm::dvec3 normal{0.0};
  glm::dvec4 tangent{0.0};  // xyz, sign
  uint32_t slots[4] = {0, 0, 0, 0};
  double weights[4] = {1.0, 0.0, 0.0, 0.0};
};

/// Decodes the layouts the cooker writes (quantized and float) and the synthetic variants.
inline std::vector<RefVertex> decode_reference(const ossa::MeshView& mesh) {
  const auto* pos = mesh.attribute(VertexSemantic::Position);
  const auto* nrm = mesh.attribute(VertexSemantic::Normal);
  const auto* tan = mesh.attribute(VertexSemantic::Tangent);
  const auto* jnt = mesh.attribute(VertexSemantic::Joints);
  const auto* wgt = mesh.attribute(VertexSemantic::Weights);
  const auto& o = *mesh.fb->position_offset();
  const auto& s = *mesh.fb->position_scale();
  const glm::dvec3 offset(o.x(), o.y(), o.z()), scale(s.x(), s.y(), s.z());
  std::vector<RefVertex> out(mesh.vertex_count());
  for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    const uint8_t* vx = mesh.vertex_bytes().data() + size_t(v) * mesh.vertex_stride();
    RefVertex& r = out[v];
    if (pos->format() == VertexFormat::Unorm16x4) {
      uint16_t q[3];
      std::memcpy(q, vx + pos->offset(), 6);
      r.position = offset + scale * glm::dvec3(q[0] / 65535.0, q[1] / 65535.0, q[2] / 65535.0);
    } else {
      float p[3];
      std::memcpy(p, vx + pos->offset(), 12);
      r.position = glm::dvec3(p[0], p[1], p[2]);
    }
    if (nrm != nullptr) {
      if (nrm->format() == VertexFormat::Snorm16x2) {
        int16_t e[2];
        std::memcpy(e, vx + nrm->offset(), 4);
        r.normal = oct_decode_d(snorm_d(e[0]), snorm_d(e[1]));
      } else {
        float n[3];
        std::memcpy(n, vx + nrm->offset(), 12);
        r.normal = glm::dvec3(n[0], n[1], n[2]);
      }
    }
    if (tan != nullptr) {
      if (tan->format() == VertexFormat::Snorm16x4) {
        int16_t e[4];
        std::memcpy(e, vx + tan->offset(), 8);
        r.tangent = glm::dvec4(oct_decode_d(snorm_d(e[0]), snorm_d(e[1])), e[2] < 0 ? -1.0 : 1.0);
      } else {
        float t[4];
        std::memcpy(t, vx + tan->offset(), 16);
        r.tangent = glm::dvec4(t[0], t[1], t[2], t[3] < 0.0f ? -1.0 : 1.0);
      }
    }
    if (jnt != nullptr) {
      for (int k = 0; k < 4; ++k) {
        if (jnt->format() == VertexFormat::Uint8x4) {
          r.slots[k] = vx[jnt->offset() + k];
        } else {
          uint16_t s16;
          std::memcpy(&s16, vx + jnt->offset() + 2 * k, 2);
          r.slots[k] = s16;
        }
        if (wgt->format() == VertexFormat::Unorm8x4) {
          r.weights[k] = vx[wgt->offset() + k] / 255.0;
        } else {
          float w;
          std::memcpy(&w, vx + wgt->offset() + 4 * k, 4);
          r.weights[k] = w;
        }
      }
    }
  }
  return out;
}

inline glm::dmat4 inverse_bind_d(const ossa::MeshView& mesh, size_t slot) {
  glm::mat4 m;
  std::memcpy(&m[0][0], mesh.inverse_bind()[slot].m()->data(), sizeof m);
  return to_d(m);
}

struct RefSkinned {
  std::vector<glm::dvec3> positions, normals;
  std::vector<glm::dvec4> tangents;
  double scale = 0.0;  // largest |position|: what "relative" is relative to
};

inline RefSkinned skin_reference(const ossa::MeshView& mesh, const std::vector<glm::dmat4>& model) {
  const std::vector<RefVertex> verts = decode_reference(mesh);
  const bool skinned = mesh.attribute(VertexSemantic::Joints) != nullptr;
  std::vector<glm::dmat4> slot_matrix;
  for (size_t s = 0; s < mesh.joints().size(); ++s)
    slot_matrix.push_back(model[mesh.joints()[s]] * inverse_bind_d(mesh, s));
  RefSkinned out;
  for (const RefVertex& r : verts) {
    glm::dmat4 m(skinned ? 0.0 : 1.0);
    if (skinned)
      for (int k = 0; k < 4; ++k) m += slot_matrix[r.slots[k]] * r.weights[k];
    const glm::dmat3 m3(m);
    out.positions.push_back(glm::dvec3(m * glm::dvec4(r.position, 1.0)));
    out.normals.push_back(glm::normalize(m3 * r.normal));
    out.tangents.push_back(glm::dvec4(glm::normalize(m3 * glm::dvec3(r.tangent)), r.tangent.w));
    out.scale = std::max(out.scale, glm::length(out.positions.back()));
  }
  out.scale = std::max(out.scale, 1e-6);
  return out;
}

// ---------------------------------------------------------------------------------------------
// Running the code under test

struct Skinned {
  std::vector<float> positions, normals, tangents;
  glm::vec3 position(size_t v) const { return {positions[3 * v], positions[3 * v + 1], positions[3 * v + 2]}; }
  glm::vec3 normal(size_t v) const { return {normals[3 * v], normals[3 * v + 1], normals[3 * v + 2]}; }
  glm::vec4 tangent(size_t v) const {
    return {tangents[4 * v], tangents[4 * v + 1], tangents[4 * v + 2], tangents[4 * v + 3]};
  }
};

inline std::vector<glm::mat4> palette_of(const ossa::MeshView& mesh, const std::vector<glm::mat4>& model) {
  std::vector<glm::mat4> palette(std::max<size_t>(1, mesh.joints().size()));
  ossa::skinning_matrices(mesh, model, palette);
  return palette;
}

/// Skins every stream the mesh has. NaN-filled outputs, so an unwritten value cannot pass.
inline Skinned skin(const ossa::MeshView& mesh, std::span<const glm::mat4> palette, ossa::SkinningMethod method,
                    bool renormalize = true) {
  const size_t n = mesh.vertex_count();
  Skinned s;
  s.positions.assign(3 * n, NAN);
  if (mesh.attribute(VertexSemantic::Normal)) s.normals.assign(3 * n, NAN);
  if (mesh.attribute(VertexSemantic::Tangent)) s.tangents.assign(4 * n, NAN);
  ossa::skin_cpu(mesh, palette, method, {s.positions, s.normals, s.tangents, renormalize});
  return s;
}

/// Largest position / normal / tangent error against the reference.
struct Errors {
  double position = 0.0, normal = 0.0, tangent = 0.0;
};

inline Errors compare(const Skinned& s, const RefSkinned& ref) {
  Errors e;
  for (size_t v = 0; v < ref.positions.size(); ++v) {
    const double dp = glm::length(glm::dvec3(s.position(v)) - ref.positions[v]);
    e.position = std::max(e.position, std::isnan(dp) ? INFINITY : dp);
    if (!s.normals.empty()) {
      const double dn = glm::length(glm::dvec3(s.normal(v)) - ref.normals[v]);
      e.normal = std::max(e.normal, std::isnan(dn) ? INFINITY : dn);
    }
    if (!s.tangents.empty()) {
      const double dt = glm::length(glm::dvec4(s.tangent(v)) - ref.tangents[v]);
      e.tangent = std::max(e.tangent, std::isnan(dt) ? INFINITY : dt);
    }
  }
  return e;
}

}  // namespace ossa::test::skinning_reference
