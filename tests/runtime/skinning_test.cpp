// skinning_test.cpp — skinning_matrices and skin_cpu against a double-precision reference
// (tests/support/skinning_reference.h), on synthetic files.
//
// Every implementation the CPU has (portable, AVX2, AVX-512: set_skinning_isa) is run against
// the reference. Synthetic files (tests/support/test_files.h) cover the layouts and cases the
// cooker does not write (tangents, 16-bit slots in a quantized layout, static meshes) and the
// dual quaternion cases built to order (identical rigid palettes, a twisted two-bone cylinder);
// the cooked samples (CesiumMan, RiggedSimple, Pab's arnaud) are skinned against the same
// reference by tests/cooker/skinning_cooked_test.cpp.
//
// Tolerances: the code under test works in float. Positions agree with the reference within
// 1e-5 of the mesh's distance from the origin (float rounding through a few matrix products;
// the observed error is ~1e-7 relative), unit vectors within 1e-5.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <memory>
#include <random>
#include <string>
#include <vector>

#include <flatbuffers/flatbuffers.h>
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include <ossa/format/vertex_codec.h>
#include <ossa/format/vertex_format.h>
#include <ossa/loader/asset.h>
#include <ossa/skinning/skinning.h>
#include "skinning_reference.h"
#include "test_files.h"

using ossa::fb::VertexFormat;
using ossa::fb::VertexSemantic;
using namespace ossa::test::skinning_reference;

namespace {

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
  m.layout = {
      {VertexSemantic::Position, VertexFormat::Unorm16x4, 0}, {VertexSemantic::Normal, VertexFormat::Snorm16x2, 8},
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

/// 1000 vertices (four batches and a tail) with every class: one full weight, weights summing to
/// 255 over 1-4 influences in any order, zeros in between, all zero.
ossa::test::SyntheticSpec many_vertices() {
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
  return many;
}

/// spec's vertices in influence-class order, as the cooker orders them (stable).
ossa::test::SyntheticSpec ordered_by_class(ossa::test::SyntheticSpec spec) {
  std::vector<ossa::test::SyntheticVertex>& v = spec.meshes[0].vertices;
  std::stable_sort(v.begin(), v.end(), [](const auto& a, const auto& b) {
    return influence_class(a.weights) < influence_class(b.weights);
  });
  return spec;
}

/// Synthetic variants: the cooker's layout, floats with 16-bit slots, a quantized layout with
/// 16-bit slots (the fast paths' wide variant), tangents, and a mesh of many vertices with every
/// influence class (so batches, list tails and padding are exercised).
std::vector<std::pair<std::string, std::vector<uint8_t>>> synthetic_files() {
  using S = VertexSemantic;
  using F = VertexFormat;
  std::vector<std::pair<std::string, std::vector<uint8_t>>> out;
  for (const auto& [name, spec] : ossa::test::valid_variants())
    if (name == "default" || name == "float32-layout" || name == "static-mesh")
      out.emplace_back(name, ossa::test::make_valid_file(spec));
  // The cooker's quantized layout with 16-bit joint slots.
  const auto wide_slots = [](ossa::test::SyntheticSpec spec) {
    spec.meshes[0].layout = {{S::Position, F::Unorm16x4, 0},
                             {S::Normal, F::Snorm16x2, 8},
                             {S::TexCoord0, F::Float16x2, 12},
                             {S::Joints, F::Uint16x4, 16},
                             {S::Weights, F::Unorm8x4, 24}};
    spec.meshes[0].vertex_stride = 28;
    return spec;
  };
  out.emplace_back("quantized-wide-slots", ossa::test::make_valid_file(wide_slots({})));
  out.emplace_back("tangents", with_tangents({}));

  const ossa::test::SyntheticSpec many = many_vertices();
  out.emplace_back("many-vertices", ossa::test::make_valid_file(many));
  out.emplace_back("many-vertices-tangents", with_tangents(many));

  // The same vertices ordered by influence class, as the cooker orders them: the fast paths run
  // one loop per class range (no classification).
  const ossa::test::SyntheticSpec ordered = ordered_by_class(many);
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
  out.emplace_back("ordered-wide-slots", ossa::test::make_valid_file(wide_slots(ordered)));
  ossa::test::SyntheticSpec ordered_apart = ordered;
  ordered_apart.meshes[0].layout = {{S::Position, F::Unorm16x4, 0},
                                    {S::TexCoord0, F::Float16x2, 8},
                                    {S::Joints, F::Uint8x4, 12},
                                    {S::Normal, F::Snorm16x2, 16},
                                    {S::Weights, F::Unorm8x4, 20}};
  out.emplace_back("ordered-attributes-apart", ossa::test::make_valid_file(ordered_apart));
  ossa::test::SyntheticSpec tight = ordered;  // 12 bytes from the position to the end: no 16-byte load
  tight.meshes[0].layout = {{S::Joints, F::Uint8x4, 0},
                            {S::Weights, F::Unorm8x4, 4},
                            {S::Position, F::Unorm16x4, 8},
                            {S::Normal, F::Snorm16x2, 16}};
  tight.meshes[0].vertex_stride = 20;
  out.emplace_back("ordered-position-last", ossa::test::make_valid_file(tight));
  // Every vertex of one class but the last, which needs all four influences.
  ossa::test::SyntheticSpec last = ordered;
  std::vector<ossa::test::SyntheticVertex>& lv = last.meshes[0].vertices;
  lv.erase(std::remove_if(lv.begin(), lv.end(), [](const auto& v) { return influence_class(v.weights) != 2; }),
           lv.end());
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
  const glm::dmat4 d =
      glm::scale(glm::translate(glm::dmat4(1.0), glm::dvec3(o.x(), o.y(), o.z())), glm::dvec3(sc.x(), sc.y(), sc.z()));
  for (size_t slot = 0; slot < palette.size(); ++slot) {
    const glm::dmat4 expected = pose.model_d[mesh.joints()[slot]] * inverse_bind_d(mesh, slot) * d;
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) EXPECT_NEAR(palette[slot][c][r], expected[c][r], 1e-5) << "slot " << slot;
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
  const std::vector<glm::mat4> model = {glm::mat4(1.0f),
                                        glm::translate(glm::mat4(1.0f), glm::vec3(1, 0, 0)) *
                                            glm::mat4_cast(glm::angleAxis(glm::radians(170.0f), glm::vec3(1, 0, 0)))};
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
      ossa::skin_cpu(
          mesh, palette, ossa::SkinningMethod::Linear,
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

TEST(Skinning, NothingIsWrittenPastTheOutputs) {
  // The kernels store wider than a vertex where another follows (16 bytes for 12; four or eight
  // vertices a step) and must not past the last. The mesh of every class, in class order and not,
  // cut so that its last range ends 0-7 vertices past a multiple of 8; every stream selection,
  // renormalized or not, in every implementation; each output followed by guard floats that must
  // keep their bits, and every float of each requested output written.
  constexpr uint32_t kGuard = 0x7fc0dead;  // a NaN no kernel computes
  constexpr size_t kExtra = 16;
  const auto bits = [](float f) {
    uint32_t b;
    std::memcpy(&b, &f, 4);
    return b;
  };
  float guard;
  std::memcpy(&guard, &kGuard, 4);
  const ossa::test::SyntheticSpec many = many_vertices();
  int checked = 0;
  for (const bool ordered : {true, false}) {
    for (size_t cut = 0; cut < 8; ++cut) {
      for (const bool tangents : {false, true}) {
        ossa::test::SyntheticSpec spec = ordered ? ordered_by_class(many) : many;
        spec.meshes[0].vertices.resize(spec.meshes[0].vertices.size() - cut);
        SyntheticAsset s = load(tangents ? with_tangents(spec) : ossa::test::make_valid_file(spec));
        ASSERT_NE(s.asset, nullptr);
        const ossa::MeshView mesh = s.asset->mesh(0);
        const auto palette = palette_of(mesh, make_pose(s.asset->skeleton(), 0.6f, 5).model);
        const size_t n = mesh.vertex_count();
        for (ossa::SkinningIsa isa : available_isas()) {
          IsaScope scope(isa);
          for (int mask = 1; mask < 8; ++mask) {
            if ((mask & 4) && !tangents) continue;
            for (const bool unit : {true, false}) {
              std::vector<float> p(3 * n + kExtra, guard), nn(3 * n + kExtra, guard), t(4 * n + kExtra, guard);
              const auto part = [](std::vector<float>& v, size_t count, bool asked) {
                return asked ? std::span<float>(v.data(), count) : std::span<float>();
              };
              ossa::skin_cpu(mesh, palette, ossa::SkinningMethod::Linear,
                             {part(p, 3 * n, mask & 1), part(nn, 3 * n, mask & 2), part(t, 4 * n, mask & 4), unit});
              const auto check = [&](const std::vector<float>& v, size_t count, bool asked, const char* stream) {
                for (size_t i = 0; i < v.size(); ++i) {
                  const bool inside = asked && i < count;
                  ASSERT_EQ(bits(v[i]) != kGuard, inside)
                      << stream << " float " << i << " of " << count << ", " << isa_name(isa) << ", mask " << mask
                      << ", cut " << cut << (ordered ? ", ordered" : ", unordered") << (unit ? ", unit" : "");
                }
              };
              check(p, 3 * n, mask & 1, "positions");
              check(nn, 3 * n, mask & 2, "normals");
              check(t, 4 * n, mask & 4, "tangents");
              ++checked;
            }
          }
        }
      }
    }
  }
  EXPECT_GE(checked, 2 * 8 * (3 + 7) * 2);  // at least the portable implementation's runs
}

TEST(Skinning, RangeLoopsReadEveryWeightByteAsTheClassifiedLoopsDo) {
  // A class-ordered mesh runs one loop per class range, anything else classified batches; both
  // read the joint slots and weights their own way. Every byte value in every influence of every
  // class, skinned both ways (the same vertices class-ordered, and in reverse so that the order
  // probe fails), must give the same positions, normals and tangents, bit for bit.
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
  std::stable_sort(vs.begin(), vs.end(), [](const auto& a, const auto& b) {
    return influence_class(a.weights) < influence_class(b.weights);
  });
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
      const int16_t q[4] = {ossa::float_to_snorm16(e.x), ossa::float_to_snorm16(e.y),
                            int16_t(v[i].position.z() < 0 ? -32767 : 32767), 0};
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
    // With normals and no tangents the class ranges run the eight-vertex kernel (soa_kernel.h).
    std::vector<float> pn(3 * n), qn(3 * n), pp(3 * n), qp(3 * n);
    ossa::skin_cpu(ordered.asset->mesh(0), palette, ossa::SkinningMethod::Linear, {pp, pn, {}});
    ossa::skin_cpu(dealt.asset->mesh(0), palette, ossa::SkinningMethod::Linear, {qp, qn, {}});
    size_t differ = 0;
    for (size_t v = 0; v < n; ++v) {
      differ += std::memcmp(&p[3 * v], &q[3 * (n - 1 - v)], 12) != 0;
      differ += std::memcmp(&t[4 * v], &r[4 * (n - 1 - v)], 16) != 0;
      differ += std::memcmp(&pp[3 * v], &qp[3 * (n - 1 - v)], 12) != 0;
      differ += std::memcmp(&pn[3 * v], &qn[3 * (n - 1 - v)], 12) != 0;
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
        std::vector<float> p(3 * n, NAN), nn(3 * n, NAN), p_only(3 * n, NAN), n_only(3 * n, NAN),
            t(has_tangents ? 4 * n : 0, NAN);
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
