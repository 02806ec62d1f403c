// cook_morph_test.cpp — morph targets through the real cooker (issue 12): a glTF the test writes,
// cooked by ossa-cook through Assimp, read back by the verifying loader and applied by the runtime.
//
// The source is built to tempt the classic failures:
// - two vertices equal in every attribute but one target's delta (corners 1 and 3): a weld that
//   ignores targets (Assimp's JoinIdenticalVertices) merges them and one corner loses its motion;
//   two corners equal in everything including deltas (2 and 5) must merge;
// - a delta below the bound (corner 0 under "smile") is dropped, one above it is kept;
// - glTF targets arrive from Assimp as absolute positions: the cooker must subtract the base;
// - a CUBICSPLINE weight curve (Assimp drops the tangents) with negative weights (Assimp clamps).
// Expected values are computed here from the source arrays and the glTF specification's Hermite
// formula, not read back from the cooker.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>
#include <tuple>
#include <vector>

#include <nlohmann/json.hpp>

#include <ossa/anim/morph.h>
#include <ossa/graph/graph.h>
#include <ossa/format/vertex_codec.h>
#include <ossa/loader/asset.h>
#include "blend_shape_fbx.h"
#include "test_files.h"

namespace fs = std::filesystem;
using ossa::test::run_command;

namespace {

std::string q(const fs::path& p) { return "'" + p.string() + "'"; }

/// Appends floats / bytes to a glTF buffer, recording a buffer view and an accessor for each.
struct GltfBuilder {
  std::string bin;
  nlohmann::json views = nlohmann::json::array(), accessors = nlohmann::json::array();
  int add(const void* data, size_t bytes, int component_type, size_t count, const char* type) {
    while (bin.size() % 4) bin.push_back('\0');
    views.push_back({{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", bytes}});
    bin.append(static_cast<const char*>(data), bytes);
    accessors.push_back(
        {{"bufferView", views.size() - 1}, {"componentType", component_type}, {"count", count}, {"type", type}});
    return static_cast<int>(accessors.size() - 1);
  }
  int floats(const std::vector<float>& v, size_t count, const char* type) {
    return add(v.data(), v.size() * 4, 5126, count, type);
  }
};

// Six corners of two triangles; 3 repeats 1, 5 repeats 2 (positions, normals, skin all equal).
const std::vector<glm::vec3> kBase = {{0, 0, 0}, {1, 0, 0}, {0, 1, 0}, {1, 0, 0}, {1, 1, 0}, {0, 1, 0}};
const std::vector<glm::vec3> kSmile = {{1e-6f, 0, 0}, {0, 0, 0.5f},       {0, 0.25f, 0},
                                       {0, 0, 0},     {0.1f, 0.2f, 0.3f}, {0, 0.25f, 0}};
const std::vector<glm::vec3> kFrown = {{-0.3f, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}};
const std::vector<glm::vec3> kSmileNormal = {{0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0, 0, 0}, {0.2f, 0, 0}, {0, 0, 0}};

// "talk": CUBICSPLINE at 0, 1, 2 s; per key (in-tangent, value, out-tangent), each 2 weights.
const std::vector<float> kTalkTimes = {0, 1, 2};
const std::vector<float> kTalk = {0,  0, /*v*/ 0, -0.5f, /*out*/ 2, 0.5f,  // key 0
                                  -1, 0, /*v*/ 1, 0.25f, /*out*/ 0, -1,    // key 1
                                  0,  1, /*v*/ 0, -0.5f, /*out*/ 0, 0};    // key 2
// "blink": LINEAR at 0, 0.5, 1 s.
const std::vector<float> kBlinkTimes = {0, 0.5f, 1};
const std::vector<float> kBlink = {0, -0.75f, 1, 0.5f, 0, -0.75f};

/// The glTF specification's cubic Hermite between two CUBICSPLINE keys (Appendix C).
float hermite(float v0, float b0, float v1, float a1, float dt, float u) {
  const float u2 = u * u, u3 = u2 * u;
  return (2 * u3 - 3 * u2 + 1) * v0 + (u3 - 2 * u2 + u) * dt * b0 + (-2 * u3 + 3 * u2) * v1 + (u3 - u2) * dt * a1;
}

/// The face, every length times `scale` (a glTF says metres; a model authored in other units, or
/// a large one, is as large as it says).
void write_face_gltf(const fs::path& path, float scale = 1.0f) {
  GltfBuilder b;
  std::vector<float> pos, nrm, smile, frown, smile_n, weights;
  std::vector<uint8_t> joints(6 * 4, 0);
  for (size_t v = 0; v < 6; ++v) {
    pos.insert(pos.end(), {scale * kBase[v].x, scale * kBase[v].y, scale * kBase[v].z});
    nrm.insert(nrm.end(), {0, 0, 1});
    // glTF targets are displacements; Assimp hands the cooker base + displacement.
    smile.insert(smile.end(), {scale * kSmile[v].x, scale * kSmile[v].y, scale * kSmile[v].z});
    frown.insert(frown.end(), {scale * kFrown[v].x, scale * kFrown[v].y, scale * kFrown[v].z});
    smile_n.insert(smile_n.end(), {kSmileNormal[v].x, kSmileNormal[v].y, kSmileNormal[v].z});
    weights.insert(weights.end(), {1, 0, 0, 0});
  }
  const int a_pos = b.floats(pos, 6, "VEC3");
  b.accessors[a_pos]["min"] = {0, 0, 0};
  b.accessors[a_pos]["max"] = {scale, scale, 0};
  const int a_nrm = b.floats(nrm, 6, "VEC3");
  const int a_joints = b.add(joints.data(), joints.size(), 5121, 6, "VEC4");
  const int a_weights = b.floats(weights, 6, "VEC4");
  const int a_smile = b.floats(smile, 6, "VEC3");
  const int a_smile_n = b.floats(smile_n, 6, "VEC3");
  const int a_frown = b.floats(frown, 6, "VEC3");
  std::vector<float> frown_n(18, 0.0f);
  const int a_frown_n = b.floats(frown_n, 6, "VEC3");
  const std::vector<uint16_t> indices = {0, 1, 2, 3, 4, 5};
  const int a_idx = b.add(indices.data(), indices.size() * 2, 5123, 6, "SCALAR");
  const int a_talk_t = b.floats(kTalkTimes, 3, "SCALAR");
  const int a_talk = b.floats(kTalk, kTalk.size(), "SCALAR");
  const int a_blink_t = b.floats(kBlinkTimes, 3, "SCALAR");
  const int a_blink = b.floats(kBlink, kBlink.size(), "SCALAR");
  // "nod": the root joint turns; no weights (a layer playing it must leave the face alone).
  const int a_nod_t = b.floats(kBlinkTimes, 3, "SCALAR");
  const std::vector<float> nod = {0, 0, 0, 1, 0.2588190f, 0, 0, 0.9659258f, 0, 0, 0, 1};
  const int a_nod = b.floats(nod, 3, "VEC4");
  b.accessors[a_nod_t]["min"] = {0};
  b.accessors[a_nod_t]["max"] = {1};
  for (int t : {a_talk_t, a_blink_t}) {
    b.accessors[t]["min"] = {0};
    b.accessors[t]["max"] = {t == a_talk_t ? 2 : 1};
  }
  const nlohmann::json j = {
      {"asset", {{"version", "2.0"}}},
      {"scene", 0},
      {"scenes", {{{"nodes", {0, 1}}}}},
      {"nodes", {{{"name", "root"}}, {{"name", "face"}, {"mesh", 0}, {"skin", 0}}}},
      {"skins", {{{"joints", {0}}}}},
      {"meshes",
       {{{"primitives",
          {{{"attributes", {{"POSITION", a_pos}, {"NORMAL", a_nrm}, {"JOINTS_0", a_joints}, {"WEIGHTS_0", a_weights}}},
            {"indices", a_idx},
            {"targets",
             {{{"POSITION", a_smile}, {"NORMAL", a_smile_n}}, {{"POSITION", a_frown}, {"NORMAL", a_frown_n}}}}}}},
         {"weights", {0.5, 0}},
         {"extras", {{"targetNames", {"smile", "frown"}}}}}}},
      {"animations",
       {{{"name", "talk"},
         {"samplers", {{{"input", a_talk_t}, {"output", a_talk}, {"interpolation", "CUBICSPLINE"}}}},
         {"channels", {{{"sampler", 0}, {"target", {{"node", 1}, {"path", "weights"}}}}}}},
        {{"name", "blink"},
         {"samplers", {{{"input", a_blink_t}, {"output", a_blink}, {"interpolation", "LINEAR"}}}},
         {"channels", {{{"sampler", 0}, {"target", {{"node", 1}, {"path", "weights"}}}}}}},
        {{"name", "nod"},
         {"samplers", {{{"input", a_nod_t}, {"output", a_nod}, {"interpolation", "LINEAR"}}}},
         {"channels", {{{"sampler", 0}, {"target", {{"node", 0}, {"path", "rotation"}}}}}}}}},
      {"buffers", {{{"uri", "face.bin"}, {"byteLength", b.bin.size()}}}},
      {"bufferViews", b.views},
      {"accessors", b.accessors}};
  ASSERT_TRUE(ossa::test::write_file(path.parent_path() / "face.bin", b.bin));
  ASSERT_TRUE(ossa::test::write_file(path, j.dump()));
}

/// De-quantized mesh-space positions of every cooked vertex.
std::vector<glm::vec3> positions_of(const ossa::MeshView& mesh) {
  namespace fb = ossa::fb;
  std::vector<glm::vec3> out;
  const fb::VertexAttribute* pos = mesh.attribute(fb::VertexSemantic::Position);
  const fb::Vec3* o = mesh.fb->position_offset();
  const fb::Vec3* sc = mesh.fb->position_scale();
  for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
    const uint8_t* p = mesh.vertex_bytes().data() + static_cast<size_t>(v) * mesh.vertex_stride() + pos->offset();
    glm::vec3 x;
    if (pos->format() == fb::VertexFormat::Unorm16x4) {
      uint16_t qv[3];
      std::memcpy(qv, p, sizeof qv);
      x = glm::vec3(o->x(), o->y(), o->z()) +
          glm::vec3(sc->x(), sc->y(), sc->z()) *
              glm::vec3(ossa::unorm16_to_float(qv[0]), ossa::unorm16_to_float(qv[1]), ossa::unorm16_to_float(qv[2]));
    } else {
      std::memcpy(&x, p, sizeof x);
    }
    out.push_back(x);
  }
  return out;
}

struct CookedFace {
  fs::path dir;
  std::string err;
  std::optional<ossa::Asset> asset;
};

CookedFace cook_face(const std::string& name, const std::string& extra = "") {
  CookedFace c;
  c.dir = ossa::test::make_temp_dir(name);
  write_face_gltf(c.dir / "face.gltf");
  const auto r = run_command((ossa::test::bin_dir() / "ossa-cook").string() + " " + q(c.dir / "face.gltf") + " -o " +
                             q(c.dir / "out") + " -v " + extra);
  c.err = r.err;
  EXPECT_EQ(r.exit_code, 0) << r.err;
  auto a = ossa::Asset::open((c.dir / "out" / "face.ossa").string());
  if (!a.ok()) {
    ADD_FAILURE() << a.error().message;
    return c;
  }
  c.asset.emplace(std::move(*a));
  return c;
}

/// Every corner's morphed position, as a sorted list, under weights (smile, frown).
std::vector<glm::vec3> expected_corners(float smile, float frown) {
  std::vector<glm::vec3> out;
  for (size_t v = 0; v < 6; ++v) out.push_back(kBase[v] + smile * kSmile[v] + frown * kFrown[v]);
  return out;
}

/// Whether every expected position has a cooked vertex within tol, and every cooked vertex an
/// expected position.
::testing::AssertionResult same_points(const std::vector<glm::vec3>& cooked, const std::vector<glm::vec3>& expected,
                                       float tol) {
  const auto near = [&](const glm::vec3& a, const std::vector<glm::vec3>& set) {
    return std::any_of(set.begin(), set.end(), [&](const glm::vec3& b) { return glm::length(a - b) <= tol; });
  };
  for (const glm::vec3& e : expected)
    if (!near(e, cooked))
      return ::testing::AssertionFailure() << "no cooked vertex at (" << e.x << ", " << e.y << ", " << e.z << ")";
  for (const glm::vec3& c : cooked)
    if (!near(c, expected))
      return ::testing::AssertionFailure()
             << "cooked vertex (" << c.x << ", " << c.y << ", " << c.z << ") expected nowhere";
  return ::testing::AssertionSuccess();
}

TEST(CookMorph, TargetsSurviveWeldingAndMorphTheCookedVerticesAsTheSourceDoes) {
  for (const char* extra : {"", "--float-vertices"}) {
    SCOPED_TRACE(extra);
    const CookedFace c = cook_face(std::string("morph-face") + (*extra ? "-f32" : ""), extra);
    ASSERT_TRUE(c.asset.has_value());
    ASSERT_EQ(c.asset->mesh_count(), 1u);
    const ossa::MeshView mesh = c.asset->mesh(0);
    // 2 and 5 are equal in everything and merge; 1 and 3 differ in smile's delta and stay apart.
    EXPECT_EQ(mesh.vertex_count(), 5u);
    ASSERT_EQ(mesh.morph_target_count(), 2u);
    EXPECT_EQ(flatbuffers::GetStringView(mesh.morph_target(0).name()), "smile");
    EXPECT_EQ(flatbuffers::GetStringView(mesh.morph_target(1).name()), "frown");
    EXPECT_FLOAT_EQ(mesh.morph_target(0).default_weight(), 0.5f);
    // smile lists 1, 2(=5) and 4 (0's 1e-6 is below the 0.02 mm bound); frown lists 0 only.
    EXPECT_EQ(mesh.morph_target(0).vertices()->size(), 3u);
    EXPECT_EQ(mesh.morph_target(1).vertices()->size(), 1u);
    EXPECT_LE(mesh.morph_target(0).position_error(), 2e-5f);
    EXPECT_LE(mesh.morph_target(1).position_error(), 2e-5f);
    const std::vector<glm::vec3> base = positions_of(mesh);
    const std::vector<std::string_view> channels = {"smile", "frown"};
    std::vector<int32_t> target_channel(2);
    ASSERT_TRUE(ossa::bind_morph_targets(mesh, channels, target_channel));
    for (const auto& [smile, frown] :
         std::vector<std::pair<float, float>>{{0, 0}, {1, 0}, {0, 1}, {1, 1}, {-0.5f, 2}}) {
      std::vector<glm::vec3> p = base;
      ASSERT_TRUE(ossa::apply_morphs(mesh, target_channel, std::vector<float>{smile, frown}, p));
      // Base quantization (1 / 65535 of the unit bounds) plus the deltas' bound, per weight.
      EXPECT_TRUE(same_points(p, expected_corners(smile, frown), 3e-5f * (1.0f + std::abs(smile) + std::abs(frown))))
          << "weights " << smile << ", " << frown;
    }
  }
}

// Morph error bounds stated and met at every size: 0.02 mm for a face a metre across, 2e-5 of
// the mesh's size for larger ones (issue 28: a horse 200 "metres" long erred by 3.14 mm against
// 0.02 mm, with a warning), never a warning for what 16-bit deltas of targets no larger than the
// mesh cannot miss.
TEST(CookMorph, PositionBoundsAreStatedAndMetAtEverySize) {
  for (const float scale : {1.0f, 100.0f, 1000.0f, 100000.0f}) {
    SCOPED_TRACE(scale);
    const fs::path dir = ossa::test::make_temp_dir("morph-scale");
    write_face_gltf(dir / "face.gltf", scale);
    const auto r = run_command((ossa::test::bin_dir() / "ossa-cook").string() + " " + q(dir / "face.gltf") + " -o " +
                               q(dir / "out") + " -v --report " + q(dir / "r.json"));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(r.err.find("past the bound"), std::string::npos) << r.err;
    const auto report = nlohmann::json::parse(*ossa::test::read_text(dir / "r.json"));
    const auto& morphs = report["records"][0]["morph_targets"];
    ASSERT_EQ(morphs.size(), 2u);
    const double diagonal_mm = 1000.0 * scale * std::sqrt(2.0);
    for (const auto& m : morphs) {
      const double bound = m["position_bound_mm"].get<double>();
      EXPECT_NEAR(bound, std::max(0.02, 2e-5 * diagonal_mm), 1e-3 * bound) << m;
      EXPECT_LE(m["position_error_mm"].get<double>(), bound * 1.0001) << m;
    }
  }
}

TEST(CookMorph, NormalDeltasAreKeptWhereTheyTurnTheNormal) {
  const CookedFace c = cook_face("morph-face-normals");
  ASSERT_TRUE(c.asset.has_value());
  const ossa::MeshView mesh = c.asset->mesh(0);
  const ossa::fb::MorphTarget& smile = mesh.morph_target(0);
  ASSERT_NE(smile.normal_deltas(), nullptr);
  ASSERT_EQ(smile.normal_deltas()->size(), 3u * smile.vertices()->size());
  // Corner 4's normal delta (0.2, 0, 0) is the only one: find it among the listed vertices.
  int found = 0;
  for (size_t i = 0; i < smile.vertices()->size(); ++i) {
    const float dx = smile.normal_deltas()->Get(static_cast<flatbuffers::uoffset_t>(3 * i)) * smile.normal_step()->x();
    if (std::abs(dx - 0.2f) < 1e-4f) ++found;
  }
  EXPECT_EQ(found, 1);
  EXPECT_LE(smile.normal_error(), 0.001745f);
}

TEST(CookMorph, WeightsAtTheSourceKeysEqualTheSourceAndCurvesAreHermite) {
  const CookedFace c = cook_face("morph-face-weights");
  ASSERT_TRUE(c.asset.has_value());
  ASSERT_EQ(c.asset->clip_count(), 3u);
  EXPECT_EQ(c.err.find("warning"), std::string::npos) << "nothing is dropped: " << c.err;
  EXPECT_EQ(c.asset->clip(2).name(), "nod");
  EXPECT_EQ(c.asset->clip(2).morph_track_count(), 0u) << "a clip without weight channels has no tracks";
  for (size_t i = 0; i < 2; ++i) {
    const ossa::ClipView clip = c.asset->clip(i);
    ASSERT_EQ(clip.morph_track_count(), 2u) << clip.name();
    // Sorted by name: frown, smile.
    ASSERT_EQ(flatbuffers::GetStringView(clip.morph_track(0).name()), "frown");
    ASSERT_EQ(flatbuffers::GetStringView(clip.morph_track(1).name()), "smile");
    const auto& frown = clip.morph_track(0);
    const auto& smile = clip.morph_track(1);
    EXPECT_LE(frown.max_error(), 1e-3f);
    EXPECT_LE(smile.max_error(), 1e-3f);
    const float tol = 1.001e-3f;
    if (clip.name() == "talk") {
      for (size_t k = 0; k < 3; ++k) {
        const float t = kTalkTimes[k];
        EXPECT_NEAR(ossa::sample_morph_track(clip, smile, t), kTalk[k * 6 + 2], tol) << t;
        EXPECT_NEAR(ossa::sample_morph_track(clip, frown, t), kTalk[k * 6 + 3], tol) << "negative weights kept " << t;
      }
      for (float t : {0.5f, 0.3f, 1.5f, 1.9f}) {
        const size_t k = t < 1.0f ? 0 : 1;
        const float u = t - kTalkTimes[k];
        const float want_smile =
            hermite(kTalk[k * 6 + 2], kTalk[k * 6 + 4], kTalk[(k + 1) * 6 + 2], kTalk[(k + 1) * 6 + 0], 1.0f, u);
        const float want_frown =
            hermite(kTalk[k * 6 + 3], kTalk[k * 6 + 5], kTalk[(k + 1) * 6 + 3], kTalk[(k + 1) * 6 + 1], 1.0f, u);
        EXPECT_NEAR(ossa::sample_morph_track(clip, smile, t), want_smile, tol) << t;
        EXPECT_NEAR(ossa::sample_morph_track(clip, frown, t), want_frown, tol) << t;
      }
    } else {
      EXPECT_EQ(clip.name(), "blink");
      for (float t : {0.0f, 0.25f, 0.5f, 0.8f, 1.0f}) {
        const size_t k = t < 0.5f ? 0 : (t < 1.0f ? 1 : 2);
        const float u = k == 2 ? 0.0f : (t - kBlinkTimes[k]) / 0.5f;
        const size_t k1 = std::min<size_t>(k + 1, 2);
        EXPECT_NEAR(ossa::sample_morph_track(clip, smile, t), kBlink[k * 2] + (kBlink[k1 * 2] - kBlink[k * 2]) * u,
                    tol);
        EXPECT_NEAR(ossa::sample_morph_track(clip, frown, t),
                    kBlink[k * 2 + 1] + (kBlink[k1 * 2 + 1] - kBlink[k * 2 + 1]) * u, tol);
      }
    }
  }
}

TEST(CookMorph, InspectReportsEveryTargetAndTrack) {
  const CookedFace c = cook_face("morph-face-inspect");
  const auto r =
      run_command((ossa::test::bin_dir() / "ossa-inspect").string() + " --json " + q(c.dir / "out" / "face.ossa"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const nlohmann::json d = nlohmann::json::parse(r.out);
  const nlohmann::json& targets = d["meshes"][0]["morph_targets"];
  ASSERT_EQ(targets.size(), 2u);
  EXPECT_EQ(targets[0]["name"], "smile");
  EXPECT_EQ(targets[0]["vertices"], 3);
  EXPECT_LE(targets[0]["position_error_mm"].get<double>(), 0.02);
  EXPECT_EQ(d["clips"][0]["morph_weights"].size(), 2u);
  // The cook report says the same per target.
  const auto rep = run_command((ossa::test::bin_dir() / "ossa-cook").string() + " --force " + q(c.dir / "face.gltf") +
                               " -o " + q(c.dir / "out") + " --report " + q(c.dir / "report.json"));
  ASSERT_EQ(rep.exit_code, 0) << rep.err;
  const auto report_bytes = ossa::test::read_file(c.dir / "report.json");
  ASSERT_TRUE(report_bytes.has_value());
  const nlohmann::json report = nlohmann::json::parse(report_bytes->begin(), report_bytes->end());
  const nlohmann::json& morphs = report["records"][0]["morph_targets"];
  ASSERT_EQ(morphs.size(), 2u);
  EXPECT_EQ(morphs[0]["name"], "smile");
  EXPECT_EQ(morphs[0]["vertices"], 3);
  EXPECT_EQ(morphs[0]["stored_bytes"], 3 * (4 + 6 + 6));  // positions and normals
  EXPECT_LE(morphs[0]["position_error_mm"].get<double>(), 0.02);
}

// ---------------------------------------------------------------------------------------------
// FBX blend shapes (tests/support/blend_shape_fbx.h): targets, and per-channel keys out of merged ones.

TEST(CookMorph, FbxBlendShapesAndTheirPerChannelKeysAreCarried) {
  const fs::path dir = ossa::test::make_temp_dir("morph-fbx");
  ASSERT_TRUE(ossa::test::write_file(dir / "face.fbx", ossa::test::kBlendShapeFbx));
  const auto r = run_command((ossa::test::bin_dir() / "ossa-cook").string() + " " + q(dir / "face.fbx") + " -o " +
                             q(dir / "out") + " -v");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_EQ(r.err.find("dropped"), std::string::npos) << r.err;
  auto asset = ossa::Asset::open((dir / "out" / "face.ossa").string());
  ASSERT_TRUE(asset.ok()) << asset.error().message;
  ASSERT_EQ(asset->mesh_count(), 1u);
  const ossa::MeshView mesh = asset->mesh(0);
  EXPECT_EQ(mesh.vertex_count(), 4u) << "FBX's per-corner vertices weld";
  ASSERT_EQ(mesh.morph_target_count(), 2u);
  const int smile = mesh.find_morph_target("smile"), frown = mesh.find_morph_target("frown");
  ASSERT_GE(smile, 0);
  ASSERT_GE(frown, 0);
  EXPECT_EQ(mesh.morph_target(static_cast<size_t>(smile)).vertices()->size(), 2u);
  EXPECT_EQ(mesh.morph_target(static_cast<size_t>(frown)).vertices()->size(), 1u);
  // The shape moves control points 1 and 3 by (0, 0, 0.5) and (0, 0.25, 0): at weight 1 the
  // cooked vertices are there.
  std::vector<glm::vec3> p = positions_of(mesh);
  std::vector<int32_t> channel(2, -1);
  channel[static_cast<size_t>(smile)] = 0;
  ASSERT_TRUE(ossa::apply_morphs(mesh, channel, std::vector<float>{1.0f}, p));
  EXPECT_TRUE(same_points(p, {{0, 0, 0}, {1, 0, 0.5f}, {0, 1, 0}, {1, 1.25f, 0}}, 1e-4f));

  ASSERT_EQ(asset->clip_count(), 1u);
  const ossa::ClipView clip = asset->clip(0);
  EXPECT_EQ(clip.joint_count(), 0u) << "a weights-only clip of a file without joints";
  ASSERT_EQ(clip.morph_track_count(), 2u);
  const auto& f = clip.morph_track(0);  // sorted: frown, smile
  const auto& s = clip.morph_track(1);
  ASSERT_EQ(flatbuffers::GetStringView(f.name()), "frown");
  ASSERT_EQ(flatbuffers::GetStringView(s.name()), "smile");
  const float tol = 1.001e-3f;
  for (const auto& [t, want_smile, want_frown] : std::vector<std::tuple<float, float, float>>{
           {0.0f, 0.0f, 0.5f}, {0.5f, 0.5f, -0.25f}, {1.0f, 1.0f, 0.0f}, {1.5f, 0.5f, 0.25f}, {2.0f, 0.0f, 0.5f}}) {
    EXPECT_NEAR(ossa::sample_morph_track(clip, s, t), want_smile, tol) << t;
    // At 1 s only smile is keyed: frown is its own keys' line there (-0.25 at 0.5 s to 0.5 at 2 s).
    EXPECT_NEAR(ossa::sample_morph_track(clip, f, t), want_frown, tol) << t;
  }
}

// ---------------------------------------------------------------------------------------------
// Morph weights through the animation graph

const char* kFaceGraph = R"({
  "ossa_graph": 1, "name": "face", "skeleton": "face.gltf",
  "clips": {"talk": {"source": "face.gltf", "clip": "talk"}, "blink": {"source": "face.gltf", "clip": "blink"},
            "nod": {"source": "face.gltf", "clip": "nod"}},
  "parameters": {"mix": {"type": "float", "default": 0, "min": 0, "max": 1},
                 "surprise": {"type": "float", "default": 0, "min": 0, "max": 1}},
  "root": {"morph": {"layered": {"blend": [{"clip": "talk"}, {"clip": "blink"}], "alpha": "mix"},
                     "layers": [{"node": {"clip": "nod"}, "mask": [{"joint": "root"}]}]},
           "drives": [{"target": "frown", "parameter": "surprise", "scale": 2}]}
})";

TEST(CookMorph, TheGraphBlendsWeightsLayersOnlyWhatALayerDrivesAndSetsThemFromParameters) {
  const fs::path dir = ossa::test::make_temp_dir("morph-graph");
  write_face_gltf(dir / "face.gltf");
  ASSERT_TRUE(ossa::test::write_file(dir / "face.graph.json", kFaceGraph));
  const auto r = run_command((ossa::test::bin_dir() / "ossa-cook").string() + " " + q(dir / "face.graph.json") +
                             " -o " + q(dir / "out"));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  auto asset = ossa::Asset::open((dir / "out" / "face.ossa").string());
  ASSERT_TRUE(asset.ok()) << asset.error().message;
  auto def = ossa::GraphDefinition::create(*asset, "face");
  ASSERT_TRUE(def.ok()) << def.error().message;
  ASSERT_EQ(def->morph_channels().size(), 2u);
  EXPECT_EQ(def->morph_channels()[0], "smile");
  EXPECT_EQ(def->morph_channels()[1], "frown");
  auto inst = ossa::GraphInstance::create(*def);
  ASSERT_TRUE(inst.ok()) << inst.error().message;
  EXPECT_FLOAT_EQ(inst->morph_weights()[0], 0.5f) << "before the first update: the defaults";
  const int mix = def->find_parameter("mix"), surprise = def->find_parameter("surprise");
  // The graph's clips are the file's: expected weights come from sampling them directly.
  const auto clip_named = [&](std::string_view name) {
    for (size_t i = 0; i < asset->clip_count(); ++i)
      if (asset->clip(i).name() == name) return asset->clip(i);
    ADD_FAILURE() << "no clip " << name;
    return asset->clip(0);
  };
  const ossa::ClipView talk = clip_named("talk"), blink = clip_named("blink");
  const auto smile_of = [&](const ossa::ClipView& clip, float t) {
    return ossa::sample_morph_track(clip, clip.morph_track(1), t);
  };
  // A clip advances only in the updates where it has weight (graph.h): track each one's time.
  float talk_time = 0.0f, blink_time = 0.0f;
  for (const auto& [m, s, dt] :
       std::vector<std::tuple<float, float, float>>{{0, 0, 0.25f}, {1, 0, 0.25f}, {0.3f, 0.4f, 0.3f}}) {
    ASSERT_TRUE(inst->set_float(mix, m));
    ASSERT_TRUE(inst->set_float(surprise, s));
    inst->update(dt);
    if (m < 1.0f) talk_time = std::fmod(talk_time + dt, talk.duration());
    if (m > 0.0f) blink_time = std::fmod(blink_time + dt, blink.duration());
    // talk lasts 2 s, blink 1 s (looping); the nod layer has no weight tracks and leaves them.
    const float want = smile_of(talk, talk_time) * (1 - m) + smile_of(blink, blink_time) * m;
    EXPECT_NEAR(inst->morph_weights()[0], want, 1e-5f) << "mix " << m << " at " << talk_time << " / " << blink_time;
    EXPECT_NEAR(inst->morph_weights()[1], 2.0f * s, 1e-6f) << "the drive sets frown";
  }

  // The same graph with the nod layer naming "smile" in its morph_targets: the layer (weight 1,
  // a clip without weight tracks, so the defaults) now owns smile: 0.5 whatever the face clips do.
  std::string named = kFaceGraph;
  const std::string mask = R"("mask": [{"joint": "root"}])";
  named.replace(named.find(mask), mask.size(), mask + R"(, "morph_targets": ["smile"])");
  ASSERT_TRUE(ossa::test::write_file(dir / "named.graph.json", named));
  const auto r2 = run_command((ossa::test::bin_dir() / "ossa-cook").string() + " " + q(dir / "named.graph.json") +
                              " -o " + q(dir / "out"));
  ASSERT_EQ(r2.exit_code, 0) << r2.err;
  auto named_asset = ossa::Asset::open((dir / "out" / "named.ossa").string());
  ASSERT_TRUE(named_asset.ok()) << named_asset.error().message;
  auto named_def = ossa::GraphDefinition::create(*named_asset, "face");
  ASSERT_TRUE(named_def.ok()) << named_def.error().message;
  auto named_inst = ossa::GraphInstance::create(*named_def);
  ASSERT_TRUE(named_inst.ok());
  for (float dt : {0.25f, 0.5f}) {
    named_inst->update(dt);
    EXPECT_NEAR(named_inst->morph_weights()[0], 0.5f, 1e-6f) << "the layer's named target";
  }
}

}  // namespace
