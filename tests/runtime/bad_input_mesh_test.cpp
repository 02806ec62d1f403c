// bad_input_mesh_test.cpp — the bad-input suite (bad_input_test.cpp) on the skeleton, mesh and
// morph target invariants of ossa/loader/validate.h: each case starts from the valid synthetic file
// and breaks exactly one, and must be rejected with a message naming the file and what is wrong.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <flatbuffers/flatbuffers.h>

#include "bad_input.h"
#include <ossa/anim/vector_isa.h>
#include <ossa/format/hash.h>
#include <ossa/loader/asset.h>
#include <ossa/loader/texture.h>
#include "test_files.h"

namespace ossa::test {
namespace {

// ---------------------------------------------------------------------------------------------
// Skeleton invariants

TEST(Skeleton, ParentNotBeforeChild) {
  for (int16_t parent : {int16_t{2}, int16_t{3}}) {  // itself, a later joint
    SyntheticSpec spec;
    spec.skeleton->parents[2] = parent;
    EXPECT_TRUE(rejects(spec, {{"parent"}})) << "parent " << parent;
  }
}

TEST(Skeleton, ParentBelowMinusOne) {
  SyntheticSpec spec;
  spec.skeleton->parents[1] = -2;
  EXPECT_TRUE(rejects(spec, {{"parent"}}));
}

TEST(Skeleton, HashMismatch) {
  SyntheticSpec spec;
  const SyntheticSkeleton& s = *spec.skeleton;
  const std::vector<std::string_view> names(s.names.begin(), s.names.end());
  spec.skeleton->hash = skeleton_hash(names, s.parents) ^ 1;
  EXPECT_TRUE(rejects(spec, {{"hash"}}));
}

TEST(Skeleton, PerJointArrayLengthMismatch) {
  const auto mismatched = [](auto edit, const char* word) {
    SyntheticSpec spec;
    edit(*spec.skeleton);
    EXPECT_TRUE(rejects(spec, {{word}})) << word;
  };
  mismatched([](SyntheticSkeleton& s) { s.parents.pop_back(); }, "parent");
  mismatched([](SyntheticSkeleton& s) { s.translations.pop_back(); }, "translation");
  mismatched([](SyntheticSkeleton& s) { s.rotations.pop_back(); }, "rotation");
  mismatched([](SyntheticSkeleton& s) { s.scales.push_back(fb::Vec3(1, 1, 1)); }, "scale");
  mismatched([](SyntheticSkeleton& s) { s.inverse_bind = std::vector<fb::Mat4>(3); }, "inverse");
}

/// The synthetic rig grown to 11 joints (a chain off the head), so the loader's whole-array scans
/// of the bind pose (8-float blocks and a scalar tail) see bad values in blocks and tails alike.
SyntheticSpec eleven_joints() {
  SyntheticSpec spec;
  SyntheticSkeleton& s = *spec.skeleton;
  for (int i = 4; i < 11; ++i) {
    s.names.push_back("extra" + std::to_string(i));
    s.parents.push_back(static_cast<int16_t>(i == 4 ? 2 : i - 1));
    s.translations.push_back(fb::Vec3(0, 0.1f, 0));
    s.rotations.push_back(fb::Quat(0, 0, 0, 1));
    s.scales.push_back(fb::Vec3(1, 1, 1));
  }
  return spec;
}

fb::Mat4 identity_mat4() {
  const float m[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  return fb::Mat4(flatbuffers::make_span(m));
}
fb::Mat4 identity_with(int k, float v) {
  float m[16] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1};
  m[k] = v;
  return fb::Mat4(flatbuffers::make_span(std::as_const(m)));
}

TEST(Skeleton, BadBindValueFoundAtEveryJointAndComponent) {
  // A valid file passes the array scans; a bad value at any joint and component, of each kind,
  // fails them and the per-joint walk then names that joint (both paths must agree on every value).
  ASSERT_TRUE(accepts(make_valid_file(eleven_joints())));
  const auto joint_words = [](size_t j, const char* what) {
    return Keywords{{"skeleton"}, {"joint " + std::to_string(j) + " "}, {what}};
  };
  for (size_t j = 0; j < 11; ++j) {
    for (int c = 0; c < 3; ++c)
      for (float bad : {kNaN, kInf, -kInf, 2e7f, -2e7f}) {
        float v[3] = {0, 0.1f, 0};
        v[c] = bad;
        SyntheticSpec t = eleven_joints();
        t.skeleton->translations[j] = fb::Vec3(v[0], v[1], v[2]);
        EXPECT_TRUE(rejects(t, joint_words(j, "translation"))) << j << " " << c << " " << bad;
        float w[3] = {1, 1, 1};
        w[c] = bad;
        SyntheticSpec sc = eleven_joints();
        sc.skeleton->scales[j] = fb::Vec3(w[0], w[1], w[2]);
        EXPECT_TRUE(rejects(sc, joint_words(j, "scale"))) << j << " " << c << " " << bad;
      }
    // Not normalizable: a non-finite component, a zero norm, a squared norm that underflows or
    // overflows float.
    for (int c = 0; c < 4; ++c)
      for (float bad : {kNaN, kInf, 1e20f}) {
        float q[4] = {0, 0, 0, 1};
        q[c] = bad;
        SyntheticSpec r = eleven_joints();
        r.skeleton->rotations[j] = fb::Quat(q[0], q[1], q[2], q[3]);
        EXPECT_TRUE(rejects(r, joint_words(j, "rotation"))) << j << " " << c << " " << bad;
      }
    for (const fb::Quat& bad : {fb::Quat(0, 0, 0, 0), fb::Quat(1e-25f, 0, 0, 0)}) {
      SyntheticSpec r = eleven_joints();
      r.skeleton->rotations[j] = bad;
      EXPECT_TRUE(rejects(r, joint_words(j, "rotation"))) << j;
    }
    for (int k = 0; k < 16; ++k) {
      SyntheticSpec m = eleven_joints();
      m.skeleton->inverse_bind = std::vector<fb::Mat4>(11, identity_mat4());
      (*m.skeleton->inverse_bind)[j] = identity_with(k, k % 2 ? kNaN : -kInf);
      m.meshes[0].inverse_bind = std::vector<fb::Mat4>(m.meshes[0].joints.size(), identity_mat4());
      EXPECT_TRUE(rejects(m, joint_words(j, "inverse bind"))) << j << " " << k;
    }
  }
  // The largest finite bind values the loader admits are admitted by both paths.
  SyntheticSpec edge = eleven_joints();
  edge.skeleton->translations[10] = fb::Vec3(1e7f, -1e7f, 0);
  edge.skeleton->rotations[10] = fb::Quat(0, 0, 2e-19f, 0);  // squared norm 4e-38 >= FLT_MIN
  EXPECT_TRUE(accepts(make_valid_file(edge)));
}

TEST(Mesh, InverseBindNotFiniteFoundAtEverySlot) {
  for (size_t slot = 0; slot < 3; ++slot)
    for (int k = 0; k < 16; ++k) {
      SyntheticSpec spec;
      spec.meshes[0].inverse_bind = std::vector<fb::Mat4>(3, identity_mat4());
      (*spec.meshes[0].inverse_bind)[slot] = identity_with(k, k % 2 ? kInf : kNaN);
      EXPECT_TRUE(rejects(spec, with(kMesh, {"joint slot " + std::to_string(slot)}, {"inverse bind"})))
          << slot << " " << k;
    }
}

// ---------------------------------------------------------------------------------------------
// Mesh invariants

TEST(Mesh, IndexPastVertexCount) {
  SyntheticSpec spec;
  spec.meshes[0].indices[4] = 6;  // 6 vertices: 0..5
  EXPECT_TRUE(rejects(spec, with(kMesh, {"index", "indices"})));
  spec.meshes[0].index_format = fb::IndexFormat::Uint32;
  spec.meshes[0].indices[4] = 0xFFFFFFFFu;
  EXPECT_TRUE(rejects(spec, with(kMesh, {"index", "indices"})));
}

TEST(Mesh, IndexPastVertexCountFoundAnywhereInEitherCopy) {
  // The index scan runs in whole 32-index blocks and a scalar tail, compiled for AVX2 and the
  // baseline (vector_isa.h): one bad index is found in a block's first or last lane, between
  // blocks and in the tail, in 16- and 32-bit buffers, by both copies; the same buffer without it
  // is accepted.
  std::vector<VectorIsa> isas = {VectorIsa::Baseline};
  if (best_vector_isa() == VectorIsa::Avx2) isas.push_back(VectorIsa::Avx2);
  for (const VectorIsa isa : isas) {
    ASSERT_TRUE(set_vector_isa(isa));
    for (const fb::IndexFormat format : {fb::IndexFormat::Uint16, fb::IndexFormat::Uint32}) {
      SyntheticSpec spec;
      spec.meshes[0].index_format = format;
      std::vector<uint32_t>& indices = spec.meshes[0].indices;
      const std::vector<uint32_t> triangle(indices.begin(), indices.begin() + 3);
      indices.clear();
      for (int t = 0; t < 100; ++t) indices.insert(indices.end(), triangle.begin(), triangle.end());  // 300
      EXPECT_TRUE(accepts(make_valid_file(spec)));
      for (const size_t at : {size_t(0), size_t(31), size_t(32), size_t(150), size_t(287), size_t(299)}) {
        SyntheticSpec bad = spec;
        bad.meshes[0].indices[at] = 6;  // 6 vertices: 0..5
        EXPECT_TRUE(rejects(bad, with(kMesh, {"index " + std::to_string(at) + " is 6"})))
            << "index " << at << (isa == VectorIsa::Avx2 ? " avx2" : " baseline");
      }
    }
  }
  set_vector_isa(best_vector_isa());
}

TEST(Mesh, IndexBytesNotMultipleOfIndexSize) {
  SyntheticSpec spec;
  spec.meshes[0].index_padding_bytes = 1;
  EXPECT_TRUE(rejects(spec, with(kMesh, {"index", "indices"})));
  spec.meshes[0].index_format = fb::IndexFormat::Uint32;
  spec.meshes[0].index_padding_bytes = 2;
  EXPECT_TRUE(rejects(spec, with(kMesh, {"index", "indices"})));
}

TEST(Mesh, IndexCountNotMultipleOf3) {
  SyntheticSpec spec;
  spec.meshes[0].indices.push_back(0);  // 13 indices; the submeshes still cover 0..11
  EXPECT_TRUE(rejects(spec, with(kMesh, {"index", "indices", "triangle"})));
}

TEST(Mesh, SubmeshPastIndexRange) {
  SyntheticSpec spec;
  spec.meshes[0].submeshes[1] = fb::Submesh(6, 9, 0);  // 15 > 12
  EXPECT_TRUE(rejects(spec, with(kMesh, {"submesh"})));
  spec.meshes[0].submeshes[1] = fb::Submesh(0xFFFFFFF0u, 0x20u, 0);  // wraps in 32 bits
  EXPECT_TRUE(rejects(spec, with(kMesh, {"submesh"})));
}

TEST(Mesh, SubmeshMaterialOutOfRange) {
  SyntheticSpec spec;
  spec.meshes[0].submeshes[1] = fb::Submesh(6, 6, 1);  // one material
  EXPECT_TRUE(rejects(spec, with(kMesh, {"material"})));
  // Without materials, material 0 means "the default material"; anything else is out of range.
  spec.materials.clear();
  EXPECT_TRUE(rejects(spec, with(kMesh, {"material"})));
}

TEST(Mesh, AttributePastStride) {
  SyntheticSpec spec;
  spec.meshes[0].layout[4] = fb::VertexAttribute(fb::VertexSemantic::Weights, fb::VertexFormat::Unorm8x4, 22);
  EXPECT_TRUE(rejects(spec, with(kMesh, {"stride", "offset"})));
  spec.meshes[0].layout[4] = fb::VertexAttribute(fb::VertexSemantic::Weights, fb::VertexFormat::Unorm8x4, 0xFFFF);
  EXPECT_TRUE(rejects(spec, with(kMesh, {"stride", "offset"})));
}

TEST(Mesh, UnknownVertexFormat) {
  SyntheticSpec spec;
  spec.meshes[0].layout[2] = fb::VertexAttribute(fb::VertexSemantic::TexCoord0, static_cast<fb::VertexFormat>(42), 12);
  EXPECT_TRUE(rejects(spec, with(kMesh, {"format"})));
}

TEST(Mesh, DuplicateSemantic) {
  SyntheticSpec spec;
  spec.meshes[0].layout[2] = fb::VertexAttribute(fb::VertexSemantic::Normal, fb::VertexFormat::Snorm16x2, 12);
  EXPECT_TRUE(rejects(spec, with(kMesh, {"two Normal", "duplicate", "twice", "more than once", "repeated"})));
}

TEST(Mesh, UnknownSemantic) {
  SyntheticSpec spec;
  spec.meshes[0].layout[2] = fb::VertexAttribute(static_cast<fb::VertexSemantic>(42), fb::VertexFormat::Float16x2, 12);
  EXPECT_TRUE(rejects(spec, with(kMesh, {"semantic"})));
}

TEST(Mesh, VertexBytesNotCountTimesStride) {
  for (uint32_t count : {5u, 7u}) {
    SyntheticSpec spec;
    spec.meshes[0].vertex_count = count;
    EXPECT_TRUE(rejects(spec, with(kMesh, {"vertex", "vertices"}))) << "vertex_count " << count;
  }
}

// count * stride wraps to the real byte size in 32-bit arithmetic; a loader that multiplies in
// 32 bits accepts a mesh that claims 2^27 more vertices than it holds.
TEST(Mesh, VertexCountOverflow) {
  SyntheticSpec spec;
  spec.meshes[0].vertex_stride = 32;
  spec.meshes[0].vertex_count = 6u + (1u << 27);
  EXPECT_TRUE(rejects(spec, with(kMesh, {"vertex", "vertices"})));
}

TEST(Mesh, JointSlotPastSlotCount) {
  SyntheticSpec spec;
  spec.meshes[0].vertices[5].slots[1] = 3;  // slots 0..2; weight 55 on that slot
  EXPECT_TRUE(rejects(spec, with(kMesh, {"slot"})));
}

TEST(Mesh, JointSlotPastSlotCountFoundAtEveryVertexStrideAndCopy) {
  // The 8-bit slot scan reads whole 64-byte chunks through a mask that repeats every
  // lcm(stride, 64) bytes, then the vertices of the last partial chunk one by one (a stride past
  // 256 bytes: one by one throughout); compiled for AVX2 and the baseline. Every valid mesh is
  // accepted (positions, normals and weights around the slots hold bytes up to 255, so a mask
  // that let them through would reject it) and slot 3 (of 0..2) is found in the first, a middle
  // and the last vertex, in each of the four components.
  std::vector<VectorIsa> isas = {VectorIsa::Baseline};
  if (best_vector_isa() == VectorIsa::Avx2) isas.push_back(VectorIsa::Avx2);
  const std::vector<SyntheticVertex> grid = SyntheticMesh::default_vertices();
  for (const VectorIsa isa : isas) {
    ASSERT_TRUE(set_vector_isa(isa));
    for (const uint16_t stride : {24, 28, 32, 40, 60, 64, 100, 260}) {
      for (const size_t count : {1, 2, 3, 5, 8, 11, 16, 33, 70}) {
        SyntheticSpec spec;
        SyntheticMesh& mesh = spec.meshes[0];
        mesh.vertex_stride = stride;
        mesh.vertices.clear();
        for (size_t v = 0; v < count; ++v) {
          SyntheticVertex x = grid[v % grid.size()];
          x.position = fb::Vec3(x.position.x() + 0.01f * static_cast<float>(v), x.position.y(), x.position.z());
          mesh.vertices.push_back(x);
        }
        const auto last = static_cast<uint32_t>(count - 1);
        mesh.indices = {0, std::min(1u, last), std::min(2u, last)};
        mesh.submeshes = {{0, 3, 0}};
        mesh.morph_targets.clear();
        ASSERT_TRUE(accepts(make_valid_file(spec))) << "stride " << stride << " count " << count;
        for (const size_t v : {size_t{0}, count / 2, count - 1})
          for (size_t k = 0; k < 4; ++k) {
            SyntheticSpec bad = spec;
            bad.meshes[0].vertices[v].slots[k] = 3;
            EXPECT_TRUE(rejects(bad, with(kMesh, {"vertex " + std::to_string(v) + " uses joint slot 3"})))
                << "stride " << stride << " count " << count << " vertex " << v << " slot " << k;
          }
      }
    }
  }
  ASSERT_TRUE(set_vector_isa(best_vector_isa()));
}

TEST(Mesh, MeshJointPastSkeletonJointCount) {
  SyntheticSpec spec;
  spec.meshes[0].joints[2] = 4;  // 4 joints: 0..3
  EXPECT_TRUE(rejects(spec, with(kMesh, {"joint"})));
  // Skinned mesh in a file without a skeleton: every slot is out of range.
  spec.meshes[0].joints[2] = 3;
  spec.skeleton.reset();
  spec.clips.clear();
  EXPECT_TRUE(rejects(spec, with(kMesh, {"joint", "skeleton"})));
}

TEST(Mesh, JointsInverseBindLengthMismatch) {
  SyntheticSpec spec;
  spec.meshes[0].inverse_bind = std::vector<fb::Mat4>(2);  // 3 slots
  EXPECT_TRUE(rejects(spec, with(kMesh, {"inverse"})));
}

// ---------------------------------------------------------------------------------------------
// Morph targets and weight tracks (format v5): the "morph" variant of test_files.h is valid; each
// case breaks one thing apply_morphs or sample_morph_weights would otherwise index with.

SyntheticSpec morph_spec() {
  for (auto& [name, spec] : valid_variants())
    if (name == "morph") return spec;
  ADD_FAILURE() << "no morph variant";
  return {};
}

TEST(Morph, TheMorphVariantIsAccepted) {
  const std::vector<uint8_t> bytes = make_valid_file(morph_spec());
  const auto asset = Asset::from_bytes(bytes, "morph.ossa");
  ASSERT_TRUE(asset.ok()) << asset.error().message;
  EXPECT_EQ(asset->mesh(0).morph_target_count(), 2u);
  EXPECT_EQ(asset->clip(0).morph_track_count(), 2u);
}

TEST(Morph, TargetVertexPastVertexCount) {
  SyntheticSpec spec = morph_spec();
  spec.meshes[0].morph_targets[0].vertices = {4, 6};  // 6 vertices: 0..5
  EXPECT_TRUE(rejects(spec, with(kMesh, {"morph target 0 'smile'"}, {"vertex 6", "past the vertex count"})));
}

TEST(Morph, TargetVerticesNotIncreasing) {
  SyntheticSpec spec = morph_spec();
  spec.meshes[0].morph_targets[1].vertices = {2, 4, 3};
  EXPECT_TRUE(rejects(spec, with(kMesh, {"frown"}, {"strictly increase"})));
  spec.meshes[0].morph_targets[1].vertices = {2, 2, 3};
  EXPECT_TRUE(rejects(spec, with(kMesh, {"frown"}, {"strictly increase"})));
}

TEST(Morph, DeltaCountNotThreePerVertex) {
  SyntheticSpec spec = morph_spec();
  spec.meshes[0].morph_targets[0].position_deltas.pop_back();
  EXPECT_TRUE(rejects(spec, with(kMesh, {"position deltas"}, {"3 per vertex"})));
  spec = morph_spec();
  spec.meshes[0].morph_targets[1].normal_deltas.resize(12, 0);
  EXPECT_TRUE(rejects(spec, with(kMesh, {"normal deltas"}, {"3 per vertex"})));
}

TEST(Morph, StepOrWeightNotFinite) {
  for (float bad : {kNaN, kInf, -1.0f, 1e9f}) {
    SyntheticSpec spec = morph_spec();
    spec.meshes[0].morph_targets[0].position_step = fb::Vec3(0.001f, bad, 0.001f);
    EXPECT_TRUE(rejects(spec, with(kMesh, {"position step"})));
  }
  for (float bad : {kNaN, kInf, 1e6f}) {
    SyntheticSpec spec = morph_spec();
    spec.meshes[0].morph_targets[0].default_weight = bad;
    EXPECT_TRUE(rejects(spec, with(kMesh, {"default weight"})));
  }
}

TEST(Morph, TargetNamesEmptyOrRepeated) {
  SyntheticSpec spec = morph_spec();
  spec.meshes[0].morph_targets[1].name = "";
  EXPECT_TRUE(rejects(spec, with(kMesh, {"empty name"})));
  spec.meshes[0].morph_targets[1].name = "smile";
  EXPECT_TRUE(rejects(spec, with(kMesh, {"two morph targets named 'smile'"})));
}

TEST(Morph, WeightTrackValuesNotOnePerKey) {
  SyntheticSpec spec = morph_spec();
  spec.clips[0].morph_weights[1].values = {0};  // 2 key frames
  EXPECT_TRUE(rejects(spec, with(kClip, {"morph weight track 1 'smile'"}, {"2 key frames but 1 values"})));
  spec = morph_spec();
  spec.clips[0].morph_weights[0].values.clear();
  spec.clips[0].morph_weights[0].key_frames.clear();
  EXPECT_TRUE(rejects(spec, with(kClip, {"frown"}, {"no keys"})));
}

TEST(Morph, WeightTrackKeysOffTheClip) {
  SyntheticSpec spec = morph_spec();
  spec.clips[0].morph_weights[1].key_frames = {0, 31};  // 31 frames: 0..30
  EXPECT_TRUE(rejects(spec, with(kClip, {"smile"}, {"last key"})));
  spec.clips[0].morph_weights[1].key_frames = {1, 30};
  EXPECT_TRUE(rejects(spec, with(kClip, {"smile"}, {"first key"})));
  spec.clips[0].morph_weights[1].key_frames = {15, 15};
  EXPECT_TRUE(rejects(spec, with(kClip, {"smile"}, {"first key", "strictly increase"})));
}

TEST(Morph, WeightTracksNotSortedOrRangeUnbounded) {
  SyntheticSpec spec = morph_spec();
  std::swap(spec.clips[0].morph_weights[0], spec.clips[0].morph_weights[1]);
  EXPECT_TRUE(rejects(spec, with(kClip, {"sorted by name"})));
  for (float bad : {kNaN, kInf, 1e5f}) {
    spec = morph_spec();
    spec.clips[0].morph_weights[1].range_min = bad;
    EXPECT_TRUE(rejects(spec, with(kClip, {"weight range"})));
  }
  spec = morph_spec();
  spec.clips[0].morph_weights[1].range_extent = -1.0f;
  EXPECT_TRUE(rejects(spec, with(kClip, {"weight range"})));
}

}  // namespace
}  // namespace ossa::test
