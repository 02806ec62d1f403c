// skinning_cooked_test.cpp — skinning_matrices and skin_cpu on cooked samples, against the
// double-precision reference (tests/support/skinning_reference.h).
//
// CesiumMan, RiggedSimple, and Pab's arnaud cooked against Pab's skeleton (the benchmark mesh),
// each cooked here by the cooker in quantized and float32 layouts: the cooker's promise to the
// fast paths (vertices ordered by influence class) and every implementation the CPU has against
// the reference on real meshes. The runtime's own suite (tests/runtime/skinning_test.cpp) covers
// the layouts the cooker does not write, on synthetic files.
//
// Tolerances: positions within 1e-5 of the mesh's distance from the origin, unit vectors within
// 1e-5. The float and quantized cooks of one asset differ by quantization only: per vertex,
// |model * inverse_bind|3x3 times half a unorm16 step of the position bounds, plus the unorm8
// weight rounding times the spread of the influences' transforms of that vertex.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <map>
#include <memory>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include "cooker/cook.h"
#include <ossa/format/vertex_format.h>
#include <ossa/loader/asset.h>
#include <ossa/skinning/skinning.h>
#include "skinning_reference.h"
#include "test_files.h"

namespace fs = std::filesystem;
using ossa::fb::VertexFormat;
using ossa::fb::VertexSemantic;
using namespace ossa::test::skinning_reference;

namespace {

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
    ASSERT_GT(mesh.vertex_count(), 0u);
    const uint32_t drop = first_class_drop(mesh);
    EXPECT_EQ(drop, mesh.vertex_count()) << GetParam().name << " mesh " << i << " vertex " << drop;
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
        for (uint32_t v = 0; v < mesh.vertex_count(); ++v)
          worst = std::max(worst, std::fabs(glm::length(s.normal(v)) - 1.0));
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
    for (size_t s = 0; s < q.joints().size(); ++s)
      slot_matrix.push_back(pose.model_d[q.joints()[s]] * inverse_bind_d(q, s));
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
      const bool quantized =
          mesh.attribute(ossa::fb::VertexSemantic::Position)->format() == ossa::fb::VertexFormat::Unorm16x4;
      const glm::dmat4 d = quantized ? glm::scale(glm::translate(glm::dmat4(1.0), glm::dvec3(o.x(), o.y(), o.z())),
                                                  glm::dvec3(sc.x(), sc.y(), sc.z()))
                                     : glm::dmat4(1.0);
      for (size_t slot = 0; slot < palette.size(); ++slot) {
        const glm::dmat4 expected = pose.model_d[mesh.joints()[slot]] * inverse_bind_d(mesh, slot) * d;
        double scale = 0.0;
        for (int c = 0; c < 4; ++c) scale = std::max(scale, glm::length(expected[c]));
        for (int c = 0; c < 4; ++c)
          for (int r = 0; r < 4; ++r)
            EXPECT_NEAR(palette[slot][c][r], expected[c][r], 1e-5 * scale)
                << mesh.name() << " slot " << slot << " " << isa_name(isa);
      }
    }
}

}  // namespace
