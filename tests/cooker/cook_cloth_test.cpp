// cook_cloth_test.cpp — cloth from authoring to simulation (issue 29, docs/CLOTH.md): a skinned cape
// written as glTF with its cloth painted in colour set 1 (COLOR_1) is cooked by ossa-cook through
// Assimp, accepted by the verifying loader, and simulated by ossa/anim/cloth.h; the same cape with
// the region named in `<stem>.cook.json` instead; and bad cloth settings refused naming the file.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <nlohmann/json.hpp>

#include <ossa/anim/cloth.h>
#include <ossa/anim/pose.h>
#include <ossa/anim/pose_ops.h>
#include <ossa/anim/sample.h>
#include <ossa/skinning/skinning.h>
#include <ossa/loader/asset.h>
#include "test_files.h"

namespace fs = std::filesystem;
using ossa::test::run_command;

namespace {

std::string q(const fs::path& p) { return "'" + p.string() + "'"; }

constexpr int kColumns = 3, kRows = 6;

/// A cape: kColumns x kRows vertices 0.1 m apart hanging from y = 1.5 behind the spine (z = -0.2),
/// skinned wholly to "Spine" (joint 1, at y = 1); colour set 1's red is 0 on the top row (pinned)
/// and 1 below (simulated) when `painted`.
void write_cape_gltf(const fs::path& file, bool painted) {
  std::vector<float> positions, colours, weights;
  std::vector<uint16_t> joints;
  std::vector<uint16_t> indices;
  for (int r = 0; r < kRows; ++r)
    for (int c = 0; c < kColumns; ++c) {
      const float x = 0.1f * static_cast<float>(c) - 0.1f, y = 1.5f - 0.1f * static_cast<float>(r);
      positions.insert(positions.end(), {x, y, -0.2f});
      colours.insert(colours.end(), {r == 0 ? 0.0f : 1.0f, 1.0f, 1.0f, 1.0f});
      joints.insert(joints.end(), {1, 0, 0, 0});
      weights.insert(weights.end(), {1.0f, 0.0f, 0.0f, 0.0f});
    }
  for (int r = 0; r + 1 < kRows; ++r)
    for (int c = 0; c + 1 < kColumns; ++c) {
      const auto v = static_cast<uint16_t>(r * kColumns + c);
      indices.insert(indices.end(), {v, static_cast<uint16_t>(v + kColumns), static_cast<uint16_t>(v + 1),
                                     static_cast<uint16_t>(v + 1), static_cast<uint16_t>(v + kColumns),
                                     static_cast<uint16_t>(v + kColumns + 1)});
    }
  // Inverse bind of Hips (origin) and Spine (y = 1), column-major.
  const std::vector<float> inverse_bind = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0,  0, 1,
                                           1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -1, 0, 1};
  std::string bin;
  nlohmann::json views = nlohmann::json::array(), accessors = nlohmann::json::array();
  const auto add = [&](const void* data, size_t bytes, int type, size_t count, const char* shape) {
    while (bin.size() % 4) bin.push_back('\0');
    views.push_back({{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", bytes}});
    bin.append(static_cast<const char*>(data), bytes);
    accessors.push_back({{"bufferView", views.size() - 1}, {"componentType", type}, {"count", count}, {"type", shape}});
    return static_cast<int>(accessors.size() - 1);
  };
  const size_t n = kColumns * kRows;
  const int pos = add(positions.data(), positions.size() * 4, 5126, n, "VEC3");
  accessors[static_cast<size_t>(pos)]["min"] = {-0.1f, 1.0f, -0.2f};
  accessors[static_cast<size_t>(pos)]["max"] = {0.1f, 1.5f, -0.2f};
  const int col = add(colours.data(), colours.size() * 4, 5126, n, "VEC4");
  const int jnt = add(joints.data(), joints.size() * 2, 5123, n, "VEC4");
  const int wgt = add(weights.data(), weights.size() * 4, 5126, n, "VEC4");
  const int idx = add(indices.data(), indices.size() * 2, 5123, indices.size(), "SCALAR");
  const int ibm = add(inverse_bind.data(), inverse_bind.size() * 4, 5126, 2, "MAT4");
  nlohmann::json attributes = {{"POSITION", pos}, {"JOINTS_0", jnt}, {"WEIGHTS_0", wgt}};
  const std::vector<float> white(4 * n, 1.0f);  // glTF numbers colour sets from 0: set 0 is the drawn one
  const int drawn = add(white.data(), white.size() * 4, 5126, n, "VEC4");
  if (painted) {
    attributes["COLOR_0"] = drawn;
    attributes["COLOR_1"] = col;
  }
  const fs::path bin_file = fs::path(file).replace_extension(".bin");
  const nlohmann::json j = {
      {"asset", {{"version", "2.0"}}},
      {"scene", 0},
      {"scenes", {{{"nodes", {0, 2}}}}},
      {"nodes",
       {{{"name", "Hips"}, {"children", {1}}},
        {{"name", "Spine"}, {"translation", {0, 1, 0}}},
        {{"name", "Cape"}, {"mesh", 0}, {"skin", 0}}}},
      {"skins", {{{"joints", {0, 1}}, {"inverseBindMatrices", ibm}}}},
      {"meshes", {{{"name", "Cape"}, {"primitives", {{{"attributes", attributes}, {"indices", idx}}}}}}},
      {"buffers", {{{"uri", bin_file.filename().string()}, {"byteLength", bin.size()}}}},
      {"bufferViews", views},
      {"accessors", accessors}};
  ASSERT_TRUE(ossa::test::write_file(file, j.dump()));
  ASSERT_TRUE(ossa::test::write_file(bin_file, std::string_view(bin)));
}

struct Cooked {
  ossa::test::CommandResult run;
  std::optional<ossa::Asset> asset;
};

Cooked cook(const fs::path& dir) {
  Cooked c;
  c.run = run_command((ossa::test::bin_dir() / "ossa-cook").string() + " " + q(dir / "cape.gltf") + " -o " +
                      q(dir / "out"));
  if (c.run.exit_code != 0) return c;
  auto a = ossa::Asset::open((dir / "out" / "cape.ossa").string());
  if (!a.ok()) {
    ADD_FAILURE() << a.error().message;
    return c;
  }
  c.asset.emplace(std::move(*a));
  return c;
}

/// The cooked cape hangs: simulated 1 s at 60 Hz from the bind pose, the pinned row stays at its
/// skinned positions exactly and the rest stays within its rest length of it (tethers), finite.
void expect_cape_simulates(const ossa::Asset& asset) {
  ASSERT_GE(asset.mesh_count(), 1u);
  const ossa::MeshView mesh = asset.mesh(0);
  const ossa::ClothSource source = ossa::cloth_source(mesh);
  ASSERT_EQ(source.particle_vertices.size(), static_cast<size_t>(kColumns * kRows));
  size_t fixed = 0;
  for (float w : source.inverse_masses) fixed += w == 0.0f ? 1 : 0;
  EXPECT_EQ(fixed, static_cast<size_t>(kColumns));
  EXPECT_FALSE(source.stretch.empty());
  EXPECT_EQ(source.tethers.size(), static_cast<size_t>(kColumns * (kRows - 1)));
  const size_t joint_count = asset.skeleton().joint_count();
  auto cloth = ossa::make_cloth_instance(source, mesh.vertex_count(), joint_count);
  ASSERT_TRUE(cloth.ok()) << cloth.error().message;
  // The bind pose, skinned as a host skins it: the palette carries the cooked positions'
  // dequantization (prepare_bind_matrices), so the particles are in the model's metres.
  ossa::Pose local(static_cast<uint32_t>(joint_count));
  ossa::set_bind_pose(asset.skeleton(), local);
  std::vector<glm::mat4> model(joint_count);
  ossa::local_to_model(asset.skeleton().parents(), local, model);
  std::vector<glm::mat4> bind(mesh.joints().size()), palette(bind.size());
  ossa::prepare_bind_matrices(mesh, bind);
  ossa::skinning_matrices(mesh.joints(), bind, model, palette);
  std::vector<glm::vec3> pos(source.particle_vertices.size()), nrm(pos.size());
  ASSERT_TRUE(ossa::skin_cloth_particles(source, mesh, palette, pos, nrm).ok());
  for (const glm::vec3& p : pos) {  // the cape as authored: x in [-0.1, 0.1], y in [1, 1.5], z = -0.2
    EXPECT_NEAR(p.z, -0.2f, 1e-4f);
    EXPECT_TRUE(p.x > -0.1001f && p.x < 0.1001f && p.y > 0.9999f && p.y < 1.5001f) << p.x << " " << p.y;
  }
  for (int f = 0; f < 60; ++f) {
    ossa::ClothInput in;
    in.skinned_positions = pos;
    in.skinned_normals = nrm;
    in.model = model;
    in.dt = 1.0f / 60.0f;
    ASSERT_TRUE(ossa::update_cloth(*cloth, in).ok());
  }
  for (size_t i = 0; i < pos.size(); ++i) {
    const glm::vec3 p = cloth->positions()[i];
    ASSERT_TRUE(std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z)) << i;
    if (source.inverse_masses[i] == 0.0f) {
      EXPECT_EQ(p, pos[i]) << i;
    }
    // It hangs where it was authored (a vertical sheet under gravity): within 2 cm.
    EXPECT_LT(glm::length(p - pos[i]), 0.02f) << i;
  }
  // Tethers: every free particle within its path length of its anchor (1 % for the last substep's
  // collision push), the path lengths being the sheet's 0.1 m grid.
  for (const ossa::fb::ClothTether& t : source.tethers) {
    EXPECT_LE(glm::distance(cloth->positions()[t.particle()], cloth->positions()[t.anchor()]), 1.01f * t.length());
    EXPECT_NEAR(std::fmod(t.length() + 1e-4f, 0.1f), 1e-4f, 2e-4f) << t.length();
  }
}

TEST(CookCloth, PaintedCapeCooksLoadsAndSimulates) {
  const fs::path dir = ossa::test::make_temp_dir("cloth-paint");
  write_cape_gltf(dir / "cape.gltf", true);
  const Cooked c = cook(dir);
  ASSERT_EQ(c.run.exit_code, 0) << c.run.err;
  ASSERT_TRUE(c.asset);
  expect_cape_simulates(*c.asset);
}

TEST(CookCloth, UnpaintedCapeHasNoCloth) {
  const fs::path dir = ossa::test::make_temp_dir("cloth-none");
  write_cape_gltf(dir / "cape.gltf", false);
  const Cooked c = cook(dir);
  ASSERT_EQ(c.run.exit_code, 0) << c.run.err;
  ASSERT_TRUE(c.asset);
  EXPECT_EQ(c.asset->mesh(0).fb->cloth(), nullptr);
}

TEST(CookCloth, BadClothSettingsAreRefusedNamingTheFile) {
  const fs::path dir = ossa::test::make_temp_dir("cloth-bad");
  write_cape_gltf(dir / "cape.gltf", true);
  const std::vector<std::string> cases = {R"({"cloth": {"dampnig": 1}})", R"({"cloth": {"damping": -3}})",
                                          R"({"cloth": {"regions": [{"mesh": "Cloak"}]}})"};
  for (const std::string& bad : cases) {
    ASSERT_TRUE(ossa::test::write_file(dir / "cape.cook.json", std::string_view(bad)));
    const Cooked c = cook(dir);
    EXPECT_NE(c.run.exit_code, 0) << bad;
    EXPECT_NE(c.run.err.find("cape"), std::string::npos) << bad << ": " << c.run.err;
    EXPECT_NE(c.run.err.find("cloth"), std::string::npos) << bad << ": " << c.run.err;
  }
}

}  // namespace

namespace {

/// Distance from p to the segment a-b.
float segment_distance(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b) {
  const glm::vec3 d = b - a;
  const float len2 = glm::dot(d, d);
  const float t = len2 > 0.0f ? glm::clamp(glm::dot(p - a, d) / len2, 0.0f, 1.0f) : 0.0f;
  return glm::distance(p, a + t * d);
}

struct SampleRun {
  std::vector<glm::vec3> final_positions;
  float largest_swing = 0.0f;        // furthest any particle got from its skinned position
  float deepest_penetration = 0.0f;  // deepest any particle was inside a collider after an update
  bool finite = true;
  float worst_tether = 0.0f;  // largest distance to a tether's anchor over its length
};

/// No world motion: the character stays where its clip puts it.
glm::mat4 standing(double) { return glm::mat4(1.0f); }

/// Running along +z, up to 3.5 m/s in 0.5 s, then a quarter turn left between 1.0 and 1.3 s,
/// running on.
glm::mat4 run_and_turn(double t) {
  const double start = 1.0, end = 1.3, speed = 3.5;
  const auto yaw_at = [&](double s) {
    const double u = std::clamp((s - start) / (end - start), 0.0, 1.0);
    return 0.5 * 3.14159265358979 * (u * u * (3.0 - 2.0 * u));
  };
  glm::dvec3 p(0.0);
  const int steps = 1000;
  for (int k = 0; k < steps; ++k) {
    const double s = t * (k + 0.5) / steps, yaw = yaw_at(s);
    const double v = speed * std::min(1.0, s / 0.5);  // up to speed in 0.5 s
    p += glm::dvec3(std::sin(yaw), 0.0, std::cos(yaw)) * (v * t / steps);
  }
  glm::mat4 m = glm::rotate(glm::mat4(1.0f), static_cast<float>(yaw_at(t)), glm::vec3(0, 1, 0));
  m[3] = glm::vec4(glm::vec3(p), 1.0f);
  return m;
}

/// Plays `clip` (the cooked CapedMan's own walk, or a clip cooked onto its rig) for `seconds` at
/// `hz`, the cloth updated every frame and the character moved by `world`, and measures the cloth
/// against the colliders.
SampleRun play_caped(const ossa::Asset& asset, const ossa::ClipView& clip, float hz, float seconds,
                     glm::mat4 (*world)(double) = standing) {
  SampleRun run;
  const ossa::SkeletonView skeleton = asset.skeleton();
  const size_t joints = skeleton.joint_count();
  size_t cape = SIZE_MAX;
  for (size_t m = 0; m < asset.mesh_count(); ++m)
    if (asset.mesh(m).fb->cloth()) cape = m;
  EXPECT_NE(cape, SIZE_MAX) << "no mesh has cloth";
  if (cape == SIZE_MAX) return run;
  const ossa::MeshView mesh = asset.mesh(cape);
  const ossa::ClothSource source = ossa::cloth_source(mesh);
  auto cloth = ossa::make_cloth_instance(source, mesh.vertex_count(), joints);
  EXPECT_TRUE(cloth.ok());
  if (!cloth.ok()) return run;
  auto cache = ossa::make_sampling_cache(clip, skeleton);
  EXPECT_TRUE(cache.ok());
  if (!cache.ok()) return run;
  ossa::Pose local(static_cast<uint32_t>(joints));
  std::vector<glm::mat4> model(joints), bind(mesh.joints().size()), palette(bind.size());
  ossa::prepare_bind_matrices(mesh, bind);
  std::vector<glm::vec3> pos(source.particle_count()), nrm(pos.size());
  const int frames = static_cast<int>(std::lround(seconds * hz));
  for (int f = 0; f <= frames; ++f) {
    const float t = static_cast<float>(f) / hz;
    ossa::sample(clip, std::fmod(t, clip.duration()), {}, *cache, local);
    ossa::local_to_model(skeleton.parents(), local, model);
    ossa::skinning_matrices(mesh.joints(), bind, model, palette);
    EXPECT_TRUE(ossa::skin_cloth_particles(source, mesh, palette, pos, nrm).ok());
    ossa::ClothInput in;
    in.skinned_positions = pos;
    in.skinned_normals = nrm;
    in.model = model;
    in.model_to_world = world(static_cast<double>(f) / hz);
    in.dt = f == 0 ? 0.0f : 1.0f / hz;
    EXPECT_TRUE(ossa::update_cloth(*cloth, in).ok());
    for (const ossa::fb::ClothTether& th : source.tethers)
      run.worst_tether =
          std::max(run.worst_tether,
                   glm::distance(cloth->positions()[th.particle()], cloth->positions()[th.anchor()]) / th.length());
    for (size_t i = 0; i < pos.size(); ++i) {
      const glm::vec3 p = cloth->positions()[i];
      run.finite = run.finite && std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z);
      run.largest_swing = std::max(run.largest_swing, glm::distance(p, pos[i]));
      if (source.inverse_masses[i] == 0.0f) continue;
      for (const ossa::fb::ClothCollider& c : source.colliders) {
        const glm::mat4& m = model[c.joint()];
        const glm::vec3 a(m * glm::vec4(c.offset().x(), c.offset().y(), c.offset().z(), 1.0f));
        const glm::vec3 b(m * glm::vec4(c.tail().x(), c.tail().y(), c.tail().z(), 1.0f));
        run.deepest_penetration = std::max(run.deepest_penetration, c.radius() - segment_distance(p, a, b));
      }
    }
  }
  run.final_positions.assign(cloth->positions().begin(), cloth->positions().end());
  return run;
}

/// The bundled cloth sample (scripts/make-caped-man.py: CesiumMan with a painted cape) is what
/// its generator writes, cooks with cloth and colliders, and its cape swings during the walk
/// without entering the body's colliders, alike at 30, 60 and 144 Hz.
TEST(CookCloth, CapedManSampleWalks) {
  const fs::path root = ossa::test::source_dir();
  const auto check = run_command("python3 " + q(root / "scripts" / "make-caped-man.py") + " --source " +
                                 q(root / "assets" / "CesiumMan" / "CesiumMan.glb") + " --out " +
                                 q(root / "assets" / "CapedMan" / "CapedMan.glb") + " --check");
  EXPECT_EQ(check.exit_code, 0) << check.err;

  const fs::path dir = ossa::test::make_temp_dir("cloth-sample");
  const auto cooked = run_command((ossa::test::bin_dir() / "ossa-cook").string() + " " +
                                  q(root / "assets" / "CapedMan" / "CapedMan.glb") + " -o " + q(dir));
  ASSERT_EQ(cooked.exit_code, 0) << cooked.err;
  auto asset = ossa::Asset::open((dir / "CapedMan.ossa").string());
  ASSERT_TRUE(asset.ok()) << asset.error().message;
  ASSERT_GE(asset->clip_count(), 1u);

  const SampleRun at60 = play_caped(*asset, asset->clip(0), 60.0f, 2.0f);
  ASSERT_FALSE(at60.final_positions.empty());
  EXPECT_TRUE(at60.finite);
  EXPECT_GT(at60.largest_swing, 0.05f) << "the cape never left its skinned pose: nothing was simulated";
  EXPECT_LE(at60.deepest_penetration, 0.001f);
  for (const float hz : {30.0f, 144.0f, 240.0f}) {
    const SampleRun other = play_caped(*asset, asset->clip(0), hz, 2.0f);
    ASSERT_EQ(other.final_positions.size(), at60.final_positions.size());
    EXPECT_LE(other.deepest_penetration, 0.001f) << hz;
    float worst = 0.0f;
    for (size_t i = 0; i < other.final_positions.size(); ++i)
      worst = std::max(worst, glm::distance(other.final_positions[i], at60.final_positions[i]));
    // 30 Hz frames sample the clip at half the points, so its input differs (the solver itself
    // holds 1 cm across rates on exactly the same motion: cloth_test's SameMotionAtAnyFrameRate).
    EXPECT_LT(worst, hz < 60.0f ? 0.02f : 0.01f) << hz << " Hz against 60 Hz after 2 s of the walk";
    std::printf("%g Hz worst %g m swing %g pen %g\n", hz, worst, other.largest_swing, other.deepest_penetration);
  }
}

/// The issue's run and sudden turn on the sample: Pab's run cooked onto CapedMan's rig
/// (--retarget-to; --root-motion takes the hips' travel out of the clip, as a game moving the
/// character itself would, so the loop does not snap the body back a metre), played while the character runs at 3.5 m/s
/// and turns a quarter left in 0.3 s; at 30, 60, 144 and 240 Hz the cape swings, never enters a collider, and its
/// tethers hold.
TEST(CookCloth, CapedManSampleRunsAndTurns) {
  const fs::path root = ossa::test::source_dir();
  const fs::path dir = ossa::test::make_temp_dir("cloth-run");
  const std::string cook = (ossa::test::bin_dir() / "ossa-cook").string();
  const auto caped = run_command(cook + " " + q(root / "assets" / "CapedMan" / "CapedMan.glb") + " -o " + q(dir));
  ASSERT_EQ(caped.exit_code, 0) << caped.err;
  const auto run = run_command(
      cook + " " + q(root / "assets" / "Pab" / "run.fbx") + " --retarget-to " + q(dir / "CapedMan.ossa") + " --map " +
      q(root / "assets" / "CesiumMan" / "CesiumMan.humanoid.json") + " --root-motion -o " + q(dir));
  ASSERT_EQ(run.exit_code, 0) << run.err;
  auto asset = ossa::Asset::open((dir / "CapedMan.ossa").string());
  ASSERT_TRUE(asset.ok()) << asset.error().message;
  auto clips = ossa::Asset::open((dir / "run.ossa").string());
  ASSERT_TRUE(clips.ok()) << clips.error().message;
  ASSERT_GE(clips->clip_count(), 1u);

  // A cape in a 3.5 m/s stream of air flutters, and flutter is chaotic: runs whose inputs differ
  // by the clip's sampling at another frame rate part ways within a second (the same motion at
  // any rate is asserted on the walk above and on cloth_test's walk and turn, where the cape trails
  // without fluttering). What must hold at every rate here is what the issue asks of a run.
  std::vector<SampleRun> runs;
  for (const float hz : {30.0f, 60.0f, 144.0f, 240.0f}) {
    runs.push_back(play_caped(*asset, clips->clip(0), hz, 2.0f, run_and_turn));
    const SampleRun& r = runs.back();
    ASSERT_FALSE(r.final_positions.empty());
    EXPECT_TRUE(r.finite) << hz;
    EXPECT_GT(r.largest_swing, 0.05f) << hz << " Hz: the cape never left its skinned pose";
    EXPECT_LE(r.deepest_penetration, 0.001f) << hz << " Hz: a particle inside a collider";
    EXPECT_LE(r.worst_tether, 1.10f) << hz << " Hz: a tether stretched past 10 %";
    float spread = 0.0f;
    for (size_t i = 0; i < r.final_positions.size(); ++i)
      spread = std::max(spread, glm::distance(r.final_positions[i], runs.front().final_positions[i]));
    std::printf("run+turn: %g Hz swing %.3f m, penetration %.4f m, tether %.3f, %.3f m from 30 Hz at 2 s\n", hz,
                r.largest_swing, r.deepest_penetration, r.worst_tether, spread);
  }
}

}  // namespace
