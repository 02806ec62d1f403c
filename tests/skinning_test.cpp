// skinning_test.cpp — skinning_matrices and skin_cpu against a double-precision reference.
//
// The reference is written here from the definition, not from skinning.cpp: a vertex's position
// is sum_k w_k * model[joint(slot_k)] * inverse_bind[slot_k] * (offset + scale * q), its normal
// and tangent the normalized sum_k w_k * (model * inverse_bind)3x3 * direction, every stored value
// decoded in double (unorm16 / 65535, octahedral snorm16, unorm8 / 255). It therefore also checks
// what skinning.cpp folds away: D in the palette, 1 / position_scale on directions, the influence
// classes of the fast paths. Model matrices are computed in the test from the skeleton's bind
// transforms (and a seeded perturbation for posed tests), in float for the code under test and
// in double for the reference, so these tests do not depend on the pose operations.
//
// Every implementation the CPU has (portable, AVX2, AVX-512: set_skinning_isa) is run against
// the reference. Assets: CesiumMan, RiggedSimple, and Pab's arnaud cooked against Pab's skeleton
// (the benchmark mesh); synthetic files (tests/test_files.h) cover the layouts and cases the
// cooker does not write (tangents, 16-bit slots in a quantized layout, static meshes) and the
// dual quaternion cases built to order (identical rigid palettes, a twisted two-bone cylinder).
//
// Tolerances: the code under test works in float. Positions agree with the reference within
// 1e-5 of the mesh's distance from the origin (float rounding through a few matrix products;
// the observed error is ~1e-7 relative), unit vectors within 1e-5. The float and quantized cooks
// of one asset differ by quantization only: per vertex, |model * inverse_bind|3x3 times half a
// unorm16 step of the position bounds, plus the unorm8 weight rounding times the spread of the
// influences' transforms of that vertex.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <flatbuffers/flatbuffers.h>
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include "cooker/cook.h"
#include <ossa/format/vertex_codec.h>
#include <ossa/format/vertex_format.h>
#include <ossa/loader/asset.h>
#include <ossa/skinning/skinning.h>
#include "test_files.h"

namespace fs = std::filesystem;
using ossa::fb::VertexFormat;
using ossa::fb::VertexSemantic;

namespace {

// ---------------------------------------------------------------------------------------------
// Implementations

std::vector<ossa::SkinningIsa> available_isas() {
  const ossa::SkinningIsa previous = ossa::skinning_isa();
  std::vector<ossa::SkinningIsa> out;
  for (ossa::SkinningIsa isa : {ossa::SkinningIsa::Portable, ossa::SkinningIsa::Avx2, ossa::SkinningIsa::Avx512})
    if (ossa::set_skinning_isa(isa)) out.push_back(isa);
  ossa::set_skinning_isa(previous);
  return out;
}

const char* isa_name(ossa::SkinningIsa isa) {
  switch (isa) {
    case ossa::SkinningIsa::Portable: return "portable";
    case ossa::SkinningIsa::Avx2: return "avx2";
    case ossa::SkinningIsa::Avx512: return "avx512";
  }
  return "?";
}

/// Selects an implementation for a scope, and puts the previous one back.
/// The class the fast paths give these weight bytes: 0 one influence of weight 255, else 1 + the
/// index of the last non-zero weight (all zero: 1). The cooker orders vertices by it.
int influence_class(const std::array<uint8_t, 4>& w) {
  if (w[0] == 255 && w[1] == 0 && w[2] == 0 && w[3] == 0) return 0;
  for (int k = 3; k > 0; --k)
    if (w[static_cast<size_t>(k)] != 0) return k + 1;
  return 1;
}

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

glm::dmat4 to_d(const glm::mat4& m) { return glm::dmat4(m); }

/// Bind pose, each local rotation turned by up to `max_angle` radians about a seeded axis.
Poses make_pose(const ossa::SkeletonView& sk, float max_angle, uint32_t seed) {
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

glm::dvec3 oct_decode_d(double x, double y) {
  glm::dvec3 n(x, y, 1.0 - std::fabs(x) - std::fabs(y));
  const double t = n.z < 0.0 ? -n.z : 0.0;
  n.x += n.x >= 0.0 ? -t : t;
  n.y += n.y >= 0.0 ? -t : t;
  return glm::normalize(n);
}

double snorm_d(int16_t v) { return std::max(static_cast<double>(v) / 32767.0, -1.0); }

struct RefVertex {
  glm::dvec3 position;        // mesh space, de-quantized
  glm::dvec3 normal{0.0};
  glm::dvec4 tangent{0.0};    // xyz, sign
  uint32_t slots[4] = {0, 0, 0, 0};
  double weights[4] = {1.0, 0.0, 0.0, 0.0};
};

/// Decodes the layouts the cooker writes (quantized and float) and the synthetic variants.
std::vector<RefVertex> decode_reference(const ossa::MeshView& mesh) {
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

glm::dmat4 inverse_bind_d(const ossa::MeshView& mesh, size_t slot) {
  glm::mat4 m;
  std::memcpy(&m[0][0], mesh.inverse_bind()[slot].m()->data(), sizeof m);
  return to_d(m);
}

struct RefSkinned {
  std::vector<glm::dvec3> positions, normals;
  std::vector<glm::dvec4> tangents;
  double scale = 0.0;  // largest |position|: what "relative" is relative to
};

RefSkinned skin_reference(const ossa::MeshView& mesh, const std::vector<glm::dmat4>& model) {
  const std::vector<RefVertex> verts = decode_reference(mesh);
  const bool skinned = mesh.attribute(VertexSemantic::Joints) != nullptr;
  std::vector<glm::dmat4> slot_matrix;
  for (size_t s = 0; s < mesh.joints().size(); ++s) slot_matrix.push_back(model[mesh.joints()[s]] * inverse_bind_d(mesh, s));
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

std::vector<glm::mat4> palette_of(const ossa::MeshView& mesh, const std::vector<glm::mat4>& model) {
  std::vector<glm::mat4> palette(std::max<size_t>(1, mesh.joints().size()));
  ossa::skinning_matrices(mesh, model, palette);
  return palette;
}

/// Skins every stream the mesh has. NaN-filled outputs, so an unwritten value cannot pass.
Skinned skin(const ossa::MeshView& mesh, std::span<const glm::mat4> palette, ossa::SkinningMethod method,
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

Errors compare(const Skinned& s, const RefSkinned& ref) {
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

// ---------------------------------------------------------------------------------------------
// Cooked assets

struct AssetCase {
  const char* name;
  const char* source;    // under assets/
  const char* skeleton;  // a rig to cook against (bound), or null
};

struct Cooked {
  std::unique_ptr<ossa::Asset> asset;
  std::unique_ptr<ossa::Asset> rig;  // the bound rig, when there is one
  ossa::SkeletonView skeleton() const { return rig ? rig->skeleton() : asset->skeleton(); }
};

std::unique_ptr<ossa::Asset> open_or_fail(const fs::path& p) {
  auto a = ossa::Asset::open(p.string());
  if (!a) {
    ADD_FAILURE() << a.error().message;
    return nullptr;
  }
  return std::make_unique<ossa::Asset>(std::move(*a));
}

/// Cooks once per process and option set (cooking arnaud is the slow part of this suite).
const Cooked* cooked(const AssetCase& c, bool float_vertices) {
  static std::map<std::string, std::unique_ptr<Cooked>> cache;
  const std::string key = std::string(c.name) + (float_vertices ? "/float" : "/quantized");
  if (auto it = cache.find(key); it != cache.end()) return it->second.get();
  const fs::path assets = ossa::test::source_dir() / "assets";
  const fs::path dir = ossa::test::make_temp_dir("skinning");
  auto out = std::make_unique<Cooked>();
  ossa::cook::CookOptions options;
  options.float_vertices = float_vertices;
  ossa::Result<ossa::cook::SourceSkeleton> reference = ossa::Error{"unused"};
  if (c.skeleton != nullptr) {
    const auto rec = ossa::cook::cook_file(assets / c.skeleton, dir / "rig.ossa", {});
    if (!rec.ok) {
      ADD_FAILURE() << rec.error;
      return nullptr;
    }
    reference = ossa::cook::load_reference_skeleton(dir / "rig.ossa");
    if (!reference) {
      ADD_FAILURE() << reference.error().message;
      return nullptr;
    }
    options.reference = &*reference;
    options.reference_name = "rig.ossa";
    out->rig = open_or_fail(dir / "rig.ossa");
  }
  const auto rec = ossa::cook::cook_file(assets / c.source, dir / "mesh.ossa", options);
  if (!rec.ok) {
    ADD_FAILURE() << rec.error;
    return nullptr;
  }
  out->asset = open_or_fail(dir / "mesh.ossa");
  if (!out->asset || (c.skeleton != nullptr && !out->rig)) return nullptr;
  return (cache[key] = std::move(out)).get();
}

class SkinAsset : public ::testing::TestWithParam<AssetCase> {
 protected:
  void SetUp() override {
    data_ = cooked(GetParam(), false);
    ASSERT_NE(data_, nullptr);
    ASSERT_GT(data_->asset->mesh_count(), 0u);
    ASSERT_FALSE(data_->skeleton().empty());
  }
  const Cooked* data_ = nullptr;
};

TEST_P(SkinAsset, CookedVerticesAreOrderedByInfluenceClass) {
  // The cooker's promise to skin_cpu's range loops: classes never decrease along the vertex
  // buffer, so each class is one contiguous range (the loops check it anyway).
  for (size_t i = 0; i < data_->asset->mesh_count(); ++i) {
    const ossa::MeshView mesh = data_->asset->mesh(i);
    const ossa::fb::VertexAttribute* w = mesh.attribute(VertexSemantic::Weights);
    if (w == nullptr) continue;
    ASSERT_EQ(w->format(), VertexFormat::Unorm8x4);
    int last = 0, classes = 0;
    for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
      std::array<uint8_t, 4> q;
      std::memcpy(q.data(), mesh.vertex_bytes().data() + size_t(v) * mesh.vertex_stride() + w->offset(), 4);
      const int c = influence_class(q);
      ASSERT_GE(c, last) << GetParam().name << " mesh " << i << " vertex " << v;
      classes += c != last || v == 0;
      last = c;
    }
    EXPECT_GE(classes, 1);
  }
}

TEST_P(SkinAsset, BindPoseReproducesCookedMesh) {
  // In the bind pose every palette entry is the mesh's placement in model space (model *
  // inverse_bind, the identity for a mesh bound where it stands), so skinning gives the
  // de-quantized cooked positions placed in model space: float rounding only.
  const Poses pose = make_pose(data_->skeleton(), 0.0f, 0);
  for (size_t mi = 0; mi < data_->asset->mesh_count(); ++mi) {
    const ossa::MeshView mesh = data_->asset->mesh(mi);
    const RefSkinned ref = skin_reference(mesh, pose.model_d);
    const auto palette = palette_of(mesh, pose.model);
    for (ossa::SkinningIsa isa : available_isas()) {
      IsaScope scope(isa);
      const Errors e = compare(skin(mesh, palette, ossa::SkinningMethod::Linear), ref);
      EXPECT_LE(e.position, 1e-5 * ref.scale) << isa_name(isa) << " mesh " << mesh.name();
      EXPECT_LE(e.normal, 1e-5) << isa_name(isa) << " mesh " << mesh.name();
    }
  }
}

TEST_P(SkinAsset, PosedMatchesDoublePrecisionReference) {
  const Poses pose = make_pose(data_->skeleton(), 0.6f, 7);
  for (size_t mi = 0; mi < data_->asset->mesh_count(); ++mi) {
    const ossa::MeshView mesh = data_->asset->mesh(mi);
    const RefSkinned ref = skin_reference(mesh, pose.model_d);
    const auto palette = palette_of(mesh, pose.model);
    for (ossa::SkinningIsa isa : available_isas()) {
      IsaScope scope(isa);
      const Errors e = compare(skin(mesh, palette, ossa::SkinningMethod::Linear), ref);
      EXPECT_LE(e.position, 1e-5 * ref.scale) << isa_name(isa) << " mesh " << mesh.name();
      EXPECT_LE(e.normal, 1e-5) << isa_name(isa) << " mesh " << mesh.name();
      EXPECT_LE(e.tangent, 1e-5) << isa_name(isa) << " mesh " << mesh.name();
      RecordProperty(std::string("relative_position_error_") + isa_name(isa), std::to_string(e.position / ref.scale));
    }
  }
}

TEST_P(SkinAsset, UnnormalizedDirectionsAreTheNormalizedOnesScaled) {
  // renormalize = false skips only the final normalization: every implementation and method
  // gives the same positions, and directions that normalize to the renormalized ones. On a posed
  // character some come out measurably shorter than unit (blended rotations shrink vectors), so
  // the pass really was skipped.
  const Poses pose = make_pose(data_->skeleton(), 0.6f, 11);
  for (size_t mi = 0; mi < data_->asset->mesh_count(); ++mi) {
    const ossa::MeshView mesh = data_->asset->mesh(mi);
    const auto palette = palette_of(mesh, pose.model);
    for (ossa::SkinningIsa isa : available_isas()) {
      IsaScope scope(isa);
      for (ossa::SkinningMethod method : {ossa::SkinningMethod::Linear, ossa::SkinningMethod::DualQuaternion}) {
        const Skinned unit = skin(mesh, palette, method), raw = skin(mesh, palette, method, false);
        ASSERT_EQ(unit.positions, raw.positions) << isa_name(isa);
        double worst = 0.0, shortest = 1.0;
        for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
          const glm::vec3 r = raw.normal(v);
          const float len = glm::length(r);
          shortest = std::min(shortest, double(len));
          if (len > 0.0f) worst = std::max(worst, double(glm::length(r / len - unit.normal(v))));
        }
        EXPECT_LE(worst, 2e-6) << isa_name(isa) << " method " << int(method);
        if (method == ossa::SkinningMethod::Linear) {
          EXPECT_LT(shortest, 0.999) << isa_name(isa);
        }
      }
    }
  }
}

TEST_P(SkinAsset, NormalsStayUnit) {
  const Poses pose = make_pose(data_->skeleton(), 0.6f, 11);
  for (size_t mi = 0; mi < data_->asset->mesh_count(); ++mi) {
    const ossa::MeshView mesh = data_->asset->mesh(mi);
    const auto palette = palette_of(mesh, pose.model);
    for (ossa::SkinningIsa isa : available_isas()) {
      IsaScope scope(isa);
      for (ossa::SkinningMethod method : {ossa::SkinningMethod::Linear, ossa::SkinningMethod::DualQuaternion}) {
        const Skinned s = skin(mesh, palette, method);
        double worst = 0.0;
        for (uint32_t v = 0; v < mesh.vertex_count(); ++v) worst = std::max(worst, std::fabs(glm::length(s.normal(v)) - 1.0));
        EXPECT_LE(worst, 1e-5) << isa_name(isa) << " method " << int(method);
      }
    }
  }
}

TEST_P(SkinAsset, FloatAndQuantizedCooksAgreeWithinQuantization) {
  const Cooked* fl = cooked(GetParam(), true);
  ASSERT_NE(fl, nullptr);
  const Poses pose = make_pose(data_->skeleton(), 0.6f, 5);
  ASSERT_EQ(fl->asset->mesh_count(), data_->asset->mesh_count());
  for (size_t mi = 0; mi < data_->asset->mesh_count(); ++mi) {
    const ossa::MeshView q = data_->asset->mesh(mi), f = fl->asset->mesh(mi);
    ASSERT_EQ(f.attribute(VertexSemantic::Position)->format(), VertexFormat::Float32x3);
    ASSERT_EQ(q.vertex_count(), f.vertex_count()) << "the two cooks order vertices alike";
    ASSERT_TRUE(std::equal(q.joints().begin(), q.joints().end(), f.joints().begin(), f.joints().end()));
    const Skinned sq = skin(q, palette_of(q, pose.model), ossa::SkinningMethod::Linear);
    const Skinned sf = skin(f, palette_of(f, pose.model), ossa::SkinningMethod::Linear);
    // The bound, per vertex (see the file comment).
    const std::vector<RefVertex> vq = decode_reference(q), vf = decode_reference(f);
    const glm::dvec3 step(q.fb->position_scale()->x(), q.fb->position_scale()->y(), q.fb->position_scale()->z());
    const double half_step = 0.5 * glm::length(step) / 65535.0;
    std::vector<glm::dmat4> slot_matrix;
    for (size_t s = 0; s < q.joints().size(); ++s) slot_matrix.push_back(pose.model_d[q.joints()[s]] * inverse_bind_d(q, s));
    const RefSkinned ref = skin_reference(f, pose.model_d);
    size_t over = 0;
    for (uint32_t v = 0; v < q.vertex_count(); ++v) {
      double norm3 = 0.0, spread = 0.0, dw = 0.0;
      const glm::dvec3 p0 = glm::dvec3(slot_matrix[vf[v].slots[0]] * glm::dvec4(vf[v].position, 1.0));
      for (int k = 0; k < 4; ++k) {
        const glm::dmat4& m = slot_matrix[vf[v].slots[k]];
        if (vf[v].weights[k] > 0.0 || vq[v].weights[k] > 0.0) {
          for (int c = 0; c < 3; ++c) norm3 = std::max(norm3, glm::length(glm::dvec3(m[c])));
          spread = std::max(spread, glm::length(glm::dvec3(m * glm::dvec4(vf[v].position, 1.0)) - p0));
          dw += std::fabs(vf[v].weights[k] - vq[v].weights[k]);
        }
      }
      const double bound = std::sqrt(3.0) * norm3 * half_step + dw * spread + 2e-5 * ref.scale;
      if (glm::length(glm::dvec3(sq.position(v)) - glm::dvec3(sf.position(v))) > bound) ++over;
    }
    EXPECT_EQ(over, 0u) << "vertices of mesh " << q.name() << " beyond the quantization bound";
  }
}

TEST_P(SkinAsset, DualQuaternionEqualsLinearForOneInfluence) {
  const Poses pose = make_pose(data_->skeleton(), 0.6f, 13);
  for (size_t mi = 0; mi < data_->asset->mesh_count(); ++mi) {
    const ossa::MeshView mesh = data_->asset->mesh(mi);
    const auto palette = palette_of(mesh, pose.model);
    const Skinned lbs = skin(mesh, palette, ossa::SkinningMethod::Linear);
    const Skinned dqs = skin(mesh, palette, ossa::SkinningMethod::DualQuaternion);
    const std::vector<RefVertex> verts = decode_reference(mesh);
    const double scale = skin_reference(mesh, pose.model_d).scale;
    size_t single = 0;
    double worst_p = 0.0, worst_n = 0.0;
    for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
      int influences = 0;
      for (double w : verts[v].weights) influences += w > 0.0 ? 1 : 0;
      if (influences != 1) continue;
      ++single;
      worst_p = std::max(worst_p, double(glm::length(lbs.position(v) - dqs.position(v))));
      worst_n = std::max(worst_n, double(glm::length(lbs.normal(v) - dqs.normal(v))));
    }
    EXPECT_GT(single, 0u);
    EXPECT_LE(worst_p, 1e-5 * scale) << mesh.name();
    EXPECT_LE(worst_n, 1e-5) << mesh.name();
  }
}

const AssetCase kAssets[] = {
    {"CesiumMan", "CesiumMan/CesiumMan.glb", nullptr},
    {"RiggedSimple", "RiggedSimple/RiggedSimple.glb", nullptr},
    {"arnaud", "Pab/arnaud.fbx", "Pab/skeleton.fbx"},
};
INSTANTIATE_TEST_SUITE_P(Assets, SkinAsset, ::testing::ValuesIn(kAssets),
                         [](const ::testing::TestParamInfo<AssetCase>& p) { return std::string(p.param.name); });

// ---------------------------------------------------------------------------------------------
// Synthetic files

struct SyntheticAsset {
  std::unique_ptr<ossa::test::AlignedBytes> bytes;
  std::unique_ptr<ossa::Asset> asset;
};

SyntheticAsset load(const std::vector<uint8_t>& bytes) {
  SyntheticAsset s;
  s.bytes = std::make_unique<ossa::test::AlignedBytes>(bytes);
  auto a = ossa::Asset::from_bytes(s.bytes->span(), "synthetic");
  EXPECT_TRUE(a.ok()) << (a.ok() ? "" : a.error().message);
  if (a.ok()) s.asset = std::make_unique<ossa::Asset>(std::move(*a));
  return s;
}

/// The file with a Snorm16x4 tangent attribute (the synthetic writer leaves tangents zero) filled
/// in: octahedral xy of a direction perpendicular-ish to each normal, sign alternating.
std::vector<uint8_t> with_tangents(ossa::test::SyntheticSpec spec) {
  ossa::test::SyntheticMesh& m = spec.meshes[0];
  m.layout = {{VertexSemantic::Position, VertexFormat::Unorm16x4, 0}, {VertexSemantic::Normal, VertexFormat::Snorm16x2, 8},
              {VertexSemantic::Tangent, VertexFormat::Snorm16x4, 12}, {VertexSemantic::TexCoord0, VertexFormat::Float16x2, 20},
              {VertexSemantic::Joints, VertexFormat::Uint8x4, 24},    {VertexSemantic::Weights, VertexFormat::Unorm8x4, 28}};
  m.vertex_stride = 32;
  std::vector<uint8_t> bytes = ossa::test::make_valid_file(spec);
  const ossa::fb::File* file = ossa::fb::GetFile(bytes.data());
  const ossa::fb::Mesh* mesh = file->meshes()->Get(0);
  const size_t at = static_cast<size_t>(mesh->vertices()->Data() - bytes.data());
  for (size_t v = 0; v < m.vertices.size(); ++v) {
    const glm::vec3 t = glm::normalize(glm::vec3(1.0f, 0.3f * float(v), -0.2f));
    const ossa::Float2 e = ossa::octahedral_encode({t.x, t.y, t.z});
    const int16_t q[4] = {ossa::float_to_snorm16(e.x), ossa::float_to_snorm16(e.y), int16_t(v % 2 ? -32767 : 32767), 0};
    std::memcpy(bytes.data() + at + v * m.vertex_stride + 12, q, 8);
  }
  return bytes;
}

/// Synthetic variants: the cooker's layout, floats with 16-bit slots, a quantized layout with
/// 16-bit slots (the fast paths' wide variant), tangents, and a mesh of many vertices with every
/// influence class (so batches, list tails and padding are exercised).
std::vector<std::pair<std::string, std::vector<uint8_t>>> synthetic_files() {
  using S = VertexSemantic;
  using F = VertexFormat;
  std::vector<std::pair<std::string, std::vector<uint8_t>>> out;
  for (const auto& [name, spec] : ossa::test::valid_variants())
    if (name == "default" || name == "float32-layout" || name == "static-mesh") out.emplace_back(name, ossa::test::make_valid_file(spec));
  ossa::test::SyntheticSpec wide;
  wide.meshes[0].layout = {{S::Position, F::Unorm16x4, 0}, {S::Normal, F::Snorm16x2, 8}, {S::TexCoord0, F::Float16x2, 12},
                           {S::Joints, F::Uint16x4, 16},   {S::Weights, F::Unorm8x4, 24}};
  wide.meshes[0].vertex_stride = 28;
  out.emplace_back("quantized-wide-slots", ossa::test::make_valid_file(wide));
  out.emplace_back("tangents", with_tangents({}));

  // 1000 vertices (four batches and a tail) with every class: one full weight, weights summing to
  // 255 over 1-4 influences in any order, zeros in between, all zero.
  ossa::test::SyntheticSpec many;
  std::mt19937 gen(3);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  many.meshes[0].vertices.clear();
  for (int i = 0; i < 1000; ++i) {
    ossa::test::SyntheticVertex v;
    v.position = ossa::fb::Vec3(u(gen), 2.0f * u(gen) + 1.0f, u(gen));
    const glm::vec3 n = glm::normalize(glm::vec3(u(gen), u(gen), u(gen)) + glm::vec3(0.0f, 0.0f, 0.01f));
    v.normal = ossa::fb::Vec3(n.x, n.y, n.z);
    for (int k = 0; k < 4; ++k) v.slots[k] = static_cast<uint16_t>(gen() % 3);
    switch (i % 7) {
      case 0: v.weights = {255, 0, 0, 0}; break;
      case 1: v.weights = {0, 255, 0, 0}; break;
      case 2: v.weights = {100, 155, 0, 0}; break;
      case 3: v.weights = {50, 0, 205, 0}; break;
      case 4: v.weights = {10, 20, 30, 195}; break;
      case 5: v.weights = {0, 0, 0, 0}; break;
      default: v.weights = {60, 0, 0, 0}; break;  // one influence, not full weight
    }
    many.meshes[0].vertices.push_back(v);
  }
  out.emplace_back("many-vertices", ossa::test::make_valid_file(many));
  out.emplace_back("many-vertices-tangents", with_tangents(many));

  // The same vertices ordered by influence class, as the cooker orders them: the fast paths run
  // one loop per class range (no classification).
  ossa::test::SyntheticSpec ordered = many;
  std::vector<ossa::test::SyntheticVertex>& ov = ordered.meshes[0].vertices;
  std::stable_sort(ov.begin(), ov.end(), [](const auto& a, const auto& b) {
    return influence_class(a.weights) < influence_class(b.weights);
  });
  out.emplace_back("ordered-by-class", ossa::test::make_valid_file(ordered));
  out.emplace_back("ordered-by-class-tangents", with_tangents(ordered));
  // Ordered as far as the order probe looks, then broken: a four-influence vertex inside the
  // two-influence range (that range's loop must notice and hand the rest to the classified path),
  // and a rigid vertex inside the three-influence range (which blends it correctly as it is).
  ossa::test::SyntheticSpec broken = ordered;
  std::vector<ossa::test::SyntheticVertex>& bv = broken.meshes[0].vertices;
  const auto first_of = [&bv](int c) {
    return std::find_if(bv.begin(), bv.end(), [c](const auto& v) { return influence_class(v.weights) == c; });
  };
  std::iter_swap(first_of(2) + 40, first_of(4) + 3);
  std::iter_swap(first_of(3) + 10, first_of(0) + 100);
  out.emplace_back("ordered-then-broken", ossa::test::make_valid_file(broken));
  out.emplace_back("ordered-then-broken-tangents", with_tangents(broken));
  // The structure-of-arrays kernel (positions with normals, class-ordered) in the layouts it
  // reads differently from the cooker's: 16-bit slots, weights apart from the slots, and the normal
  // apart from the position (each read on its own); plus the broken order with it.
  ossa::test::SyntheticSpec ordered_wide = ordered;
  ordered_wide.meshes[0].layout = {{S::Position, F::Unorm16x4, 0}, {S::Normal, F::Snorm16x2, 8}, {S::TexCoord0, F::Float16x2, 12},
                                   {S::Joints, F::Uint16x4, 16},   {S::Weights, F::Unorm8x4, 24}};
  ordered_wide.meshes[0].vertex_stride = 28;
  out.emplace_back("ordered-wide-slots", ossa::test::make_valid_file(ordered_wide));
  ossa::test::SyntheticSpec ordered_apart = ordered;
  ordered_apart.meshes[0].layout = {{S::Position, F::Unorm16x4, 0}, {S::TexCoord0, F::Float16x2, 8}, {S::Joints, F::Uint8x4, 12},
                                    {S::Normal, F::Snorm16x2, 16},  {S::Weights, F::Unorm8x4, 20}};
  out.emplace_back("ordered-attributes-apart", ossa::test::make_valid_file(ordered_apart));
  ossa::test::SyntheticSpec tight = ordered;  // 12 bytes from the position to the end: no 16-byte load
  tight.meshes[0].layout = {{S::Joints, F::Uint8x4, 0}, {S::Weights, F::Unorm8x4, 4}, {S::Position, F::Unorm16x4, 8},
                            {S::Normal, F::Snorm16x2, 16}};
  tight.meshes[0].vertex_stride = 20;
  out.emplace_back("ordered-position-last", ossa::test::make_valid_file(tight));
  // Every vertex of one class but the last, which needs all four influences.
  ossa::test::SyntheticSpec last = ordered;
  std::vector<ossa::test::SyntheticVertex>& lv = last.meshes[0].vertices;
  lv.erase(std::remove_if(lv.begin(), lv.end(), [](const auto& v) { return influence_class(v.weights) != 2; }), lv.end());
  lv.back().weights = {10, 20, 30, 195};
  out.emplace_back("one-class-then-four", ossa::test::make_valid_file(last));
  return out;
}

TEST(Skinning, SyntheticLayoutsMatchReferenceInEveryImplementation) {
  for (const auto& [name, bytes] : synthetic_files()) {
    SyntheticAsset s = load(bytes);
    ASSERT_NE(s.asset, nullptr) << name;
    const ossa::MeshView mesh = s.asset->mesh(0);
    const ossa::SkeletonView sk = s.asset->skeleton();
    const Poses pose = sk.empty() ? Poses{} : make_pose(sk, 0.8f, 21);
    const RefSkinned ref = skin_reference(mesh, pose.model_d);
    const auto palette = palette_of(mesh, pose.model);
    for (ossa::SkinningIsa isa : available_isas()) {
      IsaScope scope(isa);
      const Skinned out = skin(mesh, palette, ossa::SkinningMethod::Linear);
      const Errors e = compare(out, ref);
      // All-zero weights: a zero matrix, position 0 and normal 0 (the reference's normalize of 0
      // is NaN, so those vertices are checked here and skipped below).
      const std::vector<RefVertex> verts = decode_reference(mesh);
      bool zero_weights = false;
      for (size_t v = 0; v < verts.size(); ++v) {
        if (verts[v].weights[0] + verts[v].weights[1] + verts[v].weights[2] + verts[v].weights[3] != 0.0 ||
            mesh.attribute(VertexSemantic::Joints) == nullptr)
          continue;
        zero_weights = true;
        EXPECT_EQ(out.position(v), glm::vec3(0.0f)) << name << " " << isa_name(isa);
        EXPECT_EQ(out.normal(v), glm::vec3(0.0f)) << name << " " << isa_name(isa);
      }
      if (!zero_weights) {
        EXPECT_LE(e.position, 1e-5 * ref.scale) << name << " " << isa_name(isa);
        EXPECT_LE(e.normal, 1e-5) << name << " " << isa_name(isa);
        EXPECT_LE(e.tangent, 1e-5) << name << " " << isa_name(isa);
      } else {
        Errors live;
        for (size_t v = 0; v < verts.size(); ++v) {
          if (verts[v].weights[0] + verts[v].weights[1] + verts[v].weights[2] + verts[v].weights[3] == 0.0) continue;
          live.position = std::max(live.position, glm::length(glm::dvec3(out.position(v)) - ref.positions[v]));
          live.normal = std::max(live.normal, glm::length(glm::dvec3(out.normal(v)) - ref.normals[v]));
          if (!out.tangents.empty())
            live.tangent = std::max(live.tangent, glm::length(glm::dvec4(out.tangent(v)) - ref.tangents[v]));
        }
        EXPECT_LE(live.position, 1e-5 * ref.scale) << name << " " << isa_name(isa);
        EXPECT_LE(live.normal, 1e-5) << name << " " << isa_name(isa);
        EXPECT_LE(live.tangent, 1e-5) << name << " " << isa_name(isa);
      }
    }
  }
}

TEST(Skinning, TangentsStayUnitWithSignedW) {
  SyntheticAsset s = load(with_tangents({}));
  ASSERT_NE(s.asset, nullptr);
  const ossa::MeshView mesh = s.asset->mesh(0);
  const Poses pose = make_pose(s.asset->skeleton(), 0.8f, 4);
  const auto palette = palette_of(mesh, pose.model);
  for (ossa::SkinningIsa isa : available_isas()) {
    IsaScope scope(isa);
    for (ossa::SkinningMethod method : {ossa::SkinningMethod::Linear, ossa::SkinningMethod::DualQuaternion}) {
      const Skinned out = skin(mesh, palette, method);
      for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
        EXPECT_NEAR(glm::length(glm::vec3(out.tangent(v))), 1.0f, 1e-5f) << isa_name(isa) << " vertex " << v;
        EXPECT_EQ(out.tangent(v).w, v % 2 ? -1.0f : 1.0f) << isa_name(isa) << " vertex " << v;
        EXPECT_NEAR(glm::length(out.normal(v)), 1.0f, 1e-5f) << isa_name(isa) << " vertex " << v;
      }
    }
  }
}

TEST(Skinning, PaletteFoldsDequantization) {
  SyntheticAsset s = load(ossa::test::make_valid_file());
  ASSERT_NE(s.asset, nullptr);
  const ossa::MeshView mesh = s.asset->mesh(0);
  const Poses pose = make_pose(s.asset->skeleton(), 0.5f, 2);
  const auto palette = palette_of(mesh, pose.model);
  ASSERT_EQ(palette.size(), mesh.joints().size());
  const auto& o = *mesh.fb->position_offset();
  const auto& sc = *mesh.fb->position_scale();
  const glm::dmat4 d = glm::scale(glm::translate(glm::dmat4(1.0), glm::dvec3(o.x(), o.y(), o.z())),
                                  glm::dvec3(sc.x(), sc.y(), sc.z()));
  for (size_t slot = 0; slot < palette.size(); ++slot) {
    const glm::dmat4 expected = pose.model_d[mesh.joints()[slot]] * inverse_bind_d(mesh, slot) * d;
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) EXPECT_NEAR(palette[slot][c][r], expected[c][r], 1e-5) << "slot " << slot;
  }
}

TEST_P(SkinAsset, PreparedPaletteEqualsThePaletteDefinition) {
  // prepare_bind_matrices once + skinning_matrices(joints, bind, ...) per frame must build the same
  // palette as the definition model * inverse_bind * D, computed here in double precision, in
  // every implementation (the AVX2 product with FMA, the SSE one without).
  const Poses pose = make_pose(data_->skeleton(), 0.6f, 11);
  for (size_t mi = 0; mi < data_->asset->mesh_count(); ++mi)
  for (ossa::SkinningIsa isa : available_isas()) {
    IsaScope scope(isa);
    const ossa::MeshView mesh = data_->asset->mesh(mi);
    ASSERT_FALSE(mesh.joints().empty());
    std::vector<glm::mat4> bind(mesh.joints().size()), palette(mesh.joints().size());
    ossa::prepare_bind_matrices(mesh, bind);
    ossa::skinning_matrices(mesh.joints(), bind, pose.model, palette);
    const auto& o = *mesh.fb->position_offset();
    const auto& sc = *mesh.fb->position_scale();
    const bool quantized = mesh.attribute(ossa::fb::VertexSemantic::Position)->format() ==
                           ossa::fb::VertexFormat::Unorm16x4;
    const glm::dmat4 d = quantized ? glm::scale(glm::translate(glm::dmat4(1.0), glm::dvec3(o.x(), o.y(), o.z())),
                                                glm::dvec3(sc.x(), sc.y(), sc.z()))
                                   : glm::dmat4(1.0);
    for (size_t slot = 0; slot < palette.size(); ++slot) {
      const glm::dmat4 expected = pose.model_d[mesh.joints()[slot]] * inverse_bind_d(mesh, slot) * d;
      double scale = 0.0;
      for (int c = 0; c < 4; ++c) scale = std::max(scale, glm::length(expected[c]));
      for (int c = 0; c < 4; ++c)
        for (int r = 0; r < 4; ++r)
          EXPECT_NEAR(palette[slot][c][r], expected[c][r], 1e-5 * scale) << mesh.name() << " slot " << slot << " "
                                                                         << isa_name(isa);
    }
  }
}

TEST(Skinning, PreparedPaletteOfAStaticMeshIsItsDequantization) {
  for (const auto& [name, spec] : ossa::test::valid_variants()) {
    if (name != "static-mesh") continue;
    SyntheticAsset s = load(ossa::test::make_valid_file(spec));
    ASSERT_NE(s.asset, nullptr);
    const ossa::MeshView mesh = s.asset->mesh(0);
    std::vector<glm::mat4> bind(1), prepared(1), direct(1);
    ossa::prepare_bind_matrices(mesh, bind);
    ossa::skinning_matrices(mesh.joints(), bind, {}, prepared);
    ossa::skinning_matrices(mesh, {}, direct);
    EXPECT_EQ(prepared[0], direct[0]);
  }
}

TEST(Skinning, StaticMeshIsItsDequantizedPositions) {
  for (const auto& [name, spec] : ossa::test::valid_variants()) {
    if (name != "static-mesh") continue;
    SyntheticAsset s = load(ossa::test::make_valid_file(spec));
    ASSERT_NE(s.asset, nullptr);
    const ossa::MeshView mesh = s.asset->mesh(0);
    std::vector<glm::mat4> palette(1);
    ossa::skinning_matrices(mesh, {}, palette);
    const auto& o = *mesh.fb->position_offset();
    const auto& sc = *mesh.fb->position_scale();
    EXPECT_EQ(palette[0], glm::scale(glm::translate(glm::mat4(1.0f), glm::vec3(o.x(), o.y(), o.z())),
                                     glm::vec3(sc.x(), sc.y(), sc.z())));
    const Skinned out = skin(mesh, palette, ossa::SkinningMethod::Linear);
    const Skinned dq = skin(mesh, palette, ossa::SkinningMethod::DualQuaternion);
    const float half_step = 0.5f * glm::length(glm::vec3(sc.x(), sc.y(), sc.z())) / 65535.0f;
    for (size_t v = 0; v < spec.meshes[0].vertices.size(); ++v) {
      const auto& p = spec.meshes[0].vertices[v].position;
      EXPECT_LE(glm::distance(out.position(v), glm::vec3(p.x(), p.y(), p.z())), half_step * 1.01f + 1e-6f);
      EXPECT_LE(glm::distance(dq.position(v), out.position(v)), 1e-5f);
      const auto& n = spec.meshes[0].vertices[v].normal;
      EXPECT_LE(glm::distance(out.normal(v), glm::vec3(n.x(), n.y(), n.z())), 1e-3f);  // octahedral snorm16
    }
  }
}

TEST(Skinning, DualQuaternionEqualsLinearForIdenticalRigidPalettes) {
  SyntheticAsset s = load(with_tangents({}));
  ASSERT_NE(s.asset, nullptr);
  const ossa::MeshView mesh = s.asset->mesh(0);
  const ossa::SkeletonView sk = s.asset->skeleton();
  // model[joint(slot)] = rigid * inverse(inverse_bind[slot]): every palette entry is rigid * D.
  const glm::mat4 rigid = glm::translate(glm::mat4(1.0f), glm::vec3(0.3f, -1.0f, 2.0f)) *
                          glm::mat4_cast(glm::angleAxis(1.1f, glm::normalize(glm::vec3(1.0f, 2.0f, -0.5f))));
  std::vector<glm::mat4> model(sk.joint_count(), glm::mat4(1.0f));
  for (size_t slot = 0; slot < mesh.joints().size(); ++slot) {
    glm::mat4 ib;
    std::memcpy(&ib[0][0], mesh.inverse_bind()[slot].m()->data(), sizeof ib);
    model[mesh.joints()[slot]] = rigid * glm::inverse(ib);
  }
  const auto palette = palette_of(mesh, model);
  const Skinned lbs = skin(mesh, palette, ossa::SkinningMethod::Linear);
  const Skinned dqs = skin(mesh, palette, ossa::SkinningMethod::DualQuaternion);
  for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    EXPECT_LE(glm::distance(lbs.position(v), dqs.position(v)), 1e-5f) << v;
    EXPECT_LE(glm::distance(lbs.normal(v), dqs.normal(v)), 1e-5f) << v;
    EXPECT_LE(glm::distance(lbs.tangent(v), dqs.tangent(v)), 1e-5f) << v;
  }
}

TEST(Skinning, DualQuaternionKeepsVolumeOnTwistedJoint) {
  // A cylinder of radius 0.2 along x from 0 to 2 over two bones (root at 0, tip at 1), blended
  // linearly between x = 0.5 and 1.5; the tip twisted 170 degrees about x. Linear blending pulls
  // the middle ring towards the axis (the candy wrapper); dual quaternions keep its radius.
  ossa::test::SyntheticSpec spec;
  ossa::test::SyntheticSkeleton& sk = *spec.skeleton;
  sk.names = {"root", "tip"};
  sk.parents = {-1, 0};
  sk.translations = {{0, 0, 0}, {1, 0, 0}};
  sk.rotations = {{0, 0, 0, 1}, {0, 0, 0, 1}};
  sk.scales = {{1, 1, 1}, {1, 1, 1}};
  spec.clips.clear();
  ossa::test::SyntheticMesh& m = spec.meshes[0];
  m.joints = {0, 1};
  m.vertices.clear();
  const float radius = 0.2f;
  const int rings = 9, around = 16;
  for (int r = 0; r < rings; ++r) {
    const float x = 2.0f * float(r) / float(rings - 1);
    const float t = std::clamp(x - 0.5f, 0.0f, 1.0f);  // tip weight
    const auto tip = static_cast<uint8_t>(std::lround(255.0f * t));
    for (int a = 0; a < around; ++a) {
      const float angle = 6.2831853f * float(a) / float(around);
      ossa::test::SyntheticVertex v;
      v.position = ossa::fb::Vec3(x, radius * std::cos(angle), radius * std::sin(angle));
      v.normal = ossa::fb::Vec3(0.0f, std::cos(angle), std::sin(angle));
      if (tip == 255) v.slots = {1, 0, 0, 0}, v.weights = {255, 0, 0, 0};
      else if (tip == 0) v.slots = {0, 0, 0, 0}, v.weights = {255, 0, 0, 0};
      else v.slots = {0, 1, 0, 0}, v.weights = {uint8_t(255 - tip), tip, 0, 0};
      m.vertices.push_back(v);
    }
  }
  m.indices = {0, 1, 2};
  m.submeshes = {{0, 3, 0}};
  SyntheticAsset s = load(ossa::test::make_valid_file(spec));
  ASSERT_NE(s.asset, nullptr);
  const ossa::MeshView mesh = s.asset->mesh(0);
  const std::vector<glm::mat4> model = {
      glm::mat4(1.0f), glm::translate(glm::mat4(1.0f), glm::vec3(1, 0, 0)) * glm::mat4_cast(glm::angleAxis(glm::radians(170.0f), glm::vec3(1, 0, 0)))};
  const auto palette = palette_of(mesh, model);
  const Skinned lbs = skin(mesh, palette, ossa::SkinningMethod::Linear);
  const Skinned dqs = skin(mesh, palette, ossa::SkinningMethod::DualQuaternion);
  const int middle = rings / 2;  // x = 1: half root, half tip
  float lbs_radius = INFINITY, dqs_radius = INFINITY;
  for (int a = 0; a < around; ++a) {
    const size_t v = size_t(middle * around + a);
    lbs_radius = std::min(lbs_radius, glm::length(glm::vec2(lbs.position(v).y, lbs.position(v).z)));
    dqs_radius = std::min(dqs_radius, glm::length(glm::vec2(dqs.position(v).y, dqs.position(v).z)));
    EXPECT_NEAR(dqs.position(v).x, 1.0f, 1e-4f);
  }
  EXPECT_GE(dqs_radius, 0.9f * radius);
  EXPECT_LE(lbs_radius, 0.2f * radius) << "linear blending should collapse here (the test's premise)";
  RecordProperty("middle_radius_lbs", std::to_string(lbs_radius));
  RecordProperty("middle_radius_dqs", std::to_string(dqs_radius));
  // Away from the blend, both methods are the same rigid motion.
  for (size_t v = 0; v < size_t(around); ++v) EXPECT_LE(glm::distance(lbs.position(v), dqs.position(v)), 1e-5f);
}

TEST(Skinning, OnlyRequestedStreamsAreWritten) {
  SyntheticAsset s = load(with_tangents({}));
  ASSERT_NE(s.asset, nullptr);
  const ossa::MeshView mesh = s.asset->mesh(0);
  const auto palette = palette_of(mesh, make_pose(s.asset->skeleton(), 0.3f, 1).model);
  const size_t n = mesh.vertex_count();
  for (ossa::SkinningIsa isa : available_isas()) {
    IsaScope scope(isa);
    const Skinned all = skin(mesh, palette, ossa::SkinningMethod::Linear);
    for (int mask = 1; mask < 8; ++mask) {
      std::vector<float> p(3 * n, NAN), nn(3 * n, NAN), t(4 * n, NAN);
      ossa::skin_cpu(mesh, palette, ossa::SkinningMethod::Linear,
                     {mask & 1 ? std::span<float>(p) : std::span<float>(), mask & 2 ? std::span<float>(nn) : std::span<float>(),
                      mask & 4 ? std::span<float>(t) : std::span<float>()});
      for (size_t i = 0; i < 3 * n; ++i) {
        if (mask & 1) EXPECT_EQ(p[i], all.positions[i]) << isa_name(isa) << " mask " << mask;
        else EXPECT_TRUE(std::isnan(p[i]));
        if (mask & 2) EXPECT_EQ(nn[i], all.normals[i]) << isa_name(isa) << " mask " << mask;
        else EXPECT_TRUE(std::isnan(nn[i]));
      }
      for (size_t i = 0; i < 4 * n; ++i) {
        if (mask & 4) EXPECT_EQ(t[i], all.tangents[i]) << isa_name(isa) << " mask " << mask;
        else EXPECT_TRUE(std::isnan(t[i]));
      }
    }
  }
}

TEST(Skinning, RangeLoopsReadEveryWeightByteAsTheClassifiedLoopsDo) {
  // A class-ordered mesh runs one loop per class range, anything else classified batches; both
  // read the joint slots and weights their own way. Every byte value in every influence of every
  // class, skinned both ways (the same vertices class-ordered, and in reverse so that the order
  // probe fails), must give the same positions and tangents, bit for bit.
  ossa::test::SyntheticSpec spec;
  std::mt19937 gen(11);
  std::uniform_real_distribution<float> u(-1.0f, 1.0f);
  std::vector<ossa::test::SyntheticVertex>& vs = spec.meshes[0].vertices;
  vs.clear();
  for (int k = 1; k <= 4; ++k)
    for (int b = 0; b < 256; ++b) {
      ossa::test::SyntheticVertex v;
      v.position = ossa::fb::Vec3(u(gen), 2.0f * u(gen) + 1.0f, u(gen));
      v.normal = ossa::fb::Vec3(0.0f, 1.0f, 0.0f);
      for (int i = 0; i < 4; ++i) v.slots[i] = static_cast<uint16_t>(gen() % 3);
      v.weights = {0, 0, 0, 0};
      for (int i = 0; i < k; ++i) v.weights[i] = static_cast<uint8_t>((b + 37 * i) % 256);
      if (v.weights[k - 1] == 0) v.weights[k - 1] = 1;  // class k: its last influence is used
      vs.push_back(v);
    }
  std::stable_sort(vs.begin(), vs.end(),
                   [](const auto& a, const auto& b) { return influence_class(a.weights) < influence_class(b.weights); });
  ossa::test::SyntheticSpec reversed = spec;
  std::reverse(reversed.meshes[0].vertices.begin(), reversed.meshes[0].vertices.end());
  // Tangents from each vertex's own position, so that both files give a vertex the same one.
  const auto tangents = [](const ossa::test::SyntheticSpec& sp) {
    std::vector<uint8_t> bytes = with_tangents(sp);
    const ossa::fb::Mesh* mesh = ossa::fb::GetFile(bytes.data())->meshes()->Get(0);
    const size_t at = static_cast<size_t>(mesh->vertices()->Data() - bytes.data());
    const auto& v = sp.meshes[0].vertices;
    for (size_t i = 0; i < v.size(); ++i) {
      const glm::vec3 t = glm::normalize(glm::vec3(1.0f, v[i].position.x(), -0.2f));
      const ossa::Float2 e = ossa::octahedral_encode({t.x, t.y, t.z});
      const int16_t q[4] = {ossa::float_to_snorm16(e.x), ossa::float_to_snorm16(e.y), int16_t(v[i].position.z() < 0 ? -32767 : 32767), 0};
      std::memcpy(bytes.data() + at + i * 32 + 12, q, 8);
    }
    return bytes;
  };
  SyntheticAsset ordered = load(tangents(spec)), dealt = load(tangents(reversed));
  ASSERT_NE(ordered.asset, nullptr);
  ASSERT_NE(dealt.asset, nullptr);
  const size_t n = vs.size();
  const auto palette = palette_of(ordered.asset->mesh(0), make_pose(ordered.asset->skeleton(), 0.8f, 5).model);
  for (ossa::SkinningIsa isa : available_isas()) {
    IsaScope scope(isa);
    std::vector<float> p(3 * n), q(3 * n), t(4 * n), r(4 * n);
    ossa::skin_cpu(ordered.asset->mesh(0), palette, ossa::SkinningMethod::Linear, {p, {}, {}});
    ossa::skin_cpu(dealt.asset->mesh(0), palette, ossa::SkinningMethod::Linear, {q, {}, {}});
    ossa::skin_cpu(ordered.asset->mesh(0), palette, ossa::SkinningMethod::Linear, {{}, {}, t});
    ossa::skin_cpu(dealt.asset->mesh(0), palette, ossa::SkinningMethod::Linear, {{}, {}, r});
    size_t differ = 0;
    for (size_t v = 0; v < n; ++v) {
      differ += std::memcmp(&p[3 * v], &q[3 * (n - 1 - v)], 12) != 0;
      differ += std::memcmp(&t[4 * v], &r[4 * (n - 1 - v)], 16) != 0;
    }
    EXPECT_EQ(differ, 0u) << isa_name(isa);
  }
}

TEST(Skinning, EveryStreamSelectionGivesBitIdenticalResults) {
  // skin_cpu's fast paths differ by the streams asked for (positions with normals run eight
  // vertices at a time, structure-of-arrays; positions alone, or with tangents, one at a time) and
  // by the vertex order (class ranges or classified batches). They round alike: whatever is asked
  // for, every value is the same, bit for bit, in every implementation, renormalized or not. The
  // files cover range tails (class counts not multiples of 8), every class, the layouts the kernels
  // read differently, a broken class order, and a mesh shorter than one block.
  for (const auto& [name, bytes] : synthetic_files()) {
    SyntheticAsset s = load(bytes);
    ASSERT_NE(s.asset, nullptr) << name;
    const ossa::MeshView mesh = s.asset->mesh(0);
    if (mesh.attribute(VertexSemantic::Normal) == nullptr || s.asset->skeleton().empty()) continue;
    const auto palette = palette_of(mesh, make_pose(s.asset->skeleton(), 0.8f, 9).model);
    const size_t n = mesh.vertex_count();
    const bool has_tangents = mesh.attribute(VertexSemantic::Tangent) != nullptr;
    for (ossa::SkinningIsa isa : available_isas()) {
      IsaScope scope(isa);
      for (const bool unit : {true, false}) {
        const Skinned all = skin(mesh, palette, ossa::SkinningMethod::Linear, unit);
        std::vector<float> p(3 * n, NAN), nn(3 * n, NAN), p_only(3 * n, NAN), n_only(3 * n, NAN), t(has_tangents ? 4 * n : 0, NAN);
        ossa::skin_cpu(mesh, palette, ossa::SkinningMethod::Linear, {p, nn, {}, unit});
        ossa::skin_cpu(mesh, palette, ossa::SkinningMethod::Linear, {p_only, {}, {}, unit});
        ossa::skin_cpu(mesh, palette, ossa::SkinningMethod::Linear, {{}, n_only, {}, unit});
        if (has_tangents) ossa::skin_cpu(mesh, palette, ossa::SkinningMethod::Linear, {{}, {}, t, unit});
        const auto same = [](const std::vector<float>& a, const std::vector<float>& b) {
          return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
        };
        EXPECT_TRUE(same(p, all.positions)) << name << " " << isa_name(isa) << " unit " << unit;
        EXPECT_TRUE(same(p_only, all.positions)) << name << " " << isa_name(isa) << " unit " << unit;
        EXPECT_TRUE(same(nn, all.normals)) << name << " " << isa_name(isa) << " unit " << unit;
        EXPECT_TRUE(same(n_only, all.normals)) << name << " " << isa_name(isa) << " unit " << unit;
        if (has_tangents) {
          EXPECT_TRUE(same(t, all.tangents)) << name << " " << isa_name(isa) << " unit " << unit;
        }
      }
    }
  }
}

}  // namespace
