// armature_names_test.cpp — several armatures whose joints share a name (issue 28).
//
// A file may hold two armatures that each have a joint called "Bone" (Quaternius exports a hat or a
// face on an armature of its own). Bones and channels name nodes, so the importer must tell the two
// apart by their place in the hierarchy, bind each mesh to its own armature's joint and give the
// cooked joints unique names with a warning. Checked on a glTF written here (two skins, two
// armatures, one joint name; one skin with an unambiguous sibling joint, one with the repeated
// name alone) and on Quaternius' Cowboy from ../shared/assets (its hat's armature), against the
// ground truth that holds for every skin: at the bind pose a skinned vertex lies where Assimp puts
// the unskinned vertex, the global transform of the node holding the mesh times its position.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <string>
#include <vector>

#include <assimp/Importer.hpp>
#include <assimp/scene.h>
#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <nlohmann/json.hpp>

#include "cooker/import/import_scene.h"
#include "test_files.h"

namespace fs = std::filesystem;

namespace {

glm::dmat4 to_dmat4(const aiMatrix4x4& m) {
  glm::dmat4 out(1.0);
  for (int r = 0; r < 4; ++r)
    for (int c = 0; c < 4; ++c) out[c][r] = static_cast<double>(m[r][c]);
  return out;
}

/// Per mesh of the import (in order), its vertices skinned at the cooked skeleton's bind pose.
std::vector<std::vector<glm::dvec3>> skinned_at_bind(const ossa::cook::SourceScene& scene) {
  const auto& joints = scene.skeleton.joints;
  std::vector<glm::dmat4> model(joints.size());
  for (size_t j = 0; j < joints.size(); ++j) {
    glm::dmat4 local = glm::mat4_cast(glm::dquat(joints[j].rotation));
    local[0] *= joints[j].scale.x;
    local[1] *= joints[j].scale.y;
    local[2] *= joints[j].scale.z;
    local[3] = glm::dvec4(glm::dvec3(joints[j].translation), 1.0);
    model[j] = joints[j].parent < 0 ? local : model[static_cast<size_t>(joints[j].parent)] * local;
  }
  std::vector<std::vector<glm::dvec3>> out;
  for (const auto& mesh : scene.meshes) {
    std::vector<glm::dvec3> verts;
    for (size_t v = 0; v < mesh.positions.size(); ++v) {
      glm::dvec3 p(0.0);
      for (int k = 0; k < 4 && !mesh.joints.empty(); ++k) {
        const double w = mesh.weights[v][k];
        if (w <= 0.0) continue;
        const uint16_t j = mesh.joints[v][k];
        const auto bind = std::find_if(mesh.bind.begin(), mesh.bind.end(), [&](const auto& b) { return b.first == j; });
        if (bind == mesh.bind.end()) continue;
        p += w * glm::dvec3(model[j] * glm::dmat4(bind->second) * glm::dvec4(glm::dvec3(mesh.positions[v]), 1.0));
      }
      verts.push_back(p);
    }
    out.push_back(std::move(verts));
  }
  return out;
}

/// Every vertex of the named Assimp meshes at the bind pose (the holding node's global x position).
std::vector<glm::dvec3> assimp_bind_vertices(const fs::path& path, const std::string& mesh_name) {
  Assimp::Importer importer;
  const aiScene* scene = importer.ReadFile(path.string(), ossa::cook::assimp_import_flags());
  EXPECT_NE(scene, nullptr) << importer.GetErrorString();
  std::vector<glm::dvec3> out;
  if (scene == nullptr) return out;
  std::vector<std::pair<const aiNode*, glm::dmat4>> stack{
      {scene->mRootNode, to_dmat4(scene->mRootNode->mTransformation)}};
  while (!stack.empty()) {
    const auto [node, global] = stack.back();
    stack.pop_back();
    for (unsigned i = 0; i < node->mNumMeshes; ++i) {
      const aiMesh* mesh = scene->mMeshes[node->mMeshes[i]];
      if (mesh_name != mesh->mName.C_Str() && mesh_name != node->mName.C_Str()) continue;
      for (unsigned v = 0; v < mesh->mNumVertices; ++v) {
        const aiVector3D& p = mesh->mVertices[v];
        out.push_back(glm::dvec3(global * glm::dvec4(p.x, p.y, p.z, 1.0)));
      }
    }
    for (unsigned c = 0; c < node->mNumChildren; ++c)
      stack.push_back({node->mChildren[c], global * to_dmat4(node->mChildren[c]->mTransformation)});
  }
  return out;
}

glm::dvec3 centre(const std::vector<glm::dvec3>& points) {
  glm::dvec3 sum(0.0);
  for (const auto& p : points) sum += p;
  return points.empty() ? sum : sum / static_cast<double>(points.size());
}

/// Two armatures, "ArmatureA" (Bone, Bone/Tip) and "ArmatureB" (Bone, moved to (3, 5, 0)); the body
/// skinned to A's Bone and Tip, the hat to B's Bone alone.
fs::path write_two_armatures(const fs::path& dir) {
  const float body[] = {0, 0, 0, 1, 0, 0, 0, 1, 0};
  const float hat[] = {3, 5, 0, 4, 5, 0, 3, 6, 0};
  const uint16_t body_joints[] = {0, 0, 0, 0, 0, 0, 0, 0, 1, 0, 0, 0};
  const uint16_t hat_joints[] = {0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};
  const float weights[] = {1, 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0};
  const float ibm_a[] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0,  0, 1,
                         1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -1, 0, 1};
  const float ibm_b[] = {1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, -3, -5, 0, 1};
  const float times[] = {0, 1};
  const float lift[] = {0, 0, 0, 0, 2, 0};
  const float wave_bone[] = {0, 0, 0, 1, 0, 0};
  const float wave_tip[] = {0, 1, 0, 0, 2, 0};
  std::vector<uint8_t> bin;
  nlohmann::json views = nlohmann::json::array();
  auto add = [&](const void* data, size_t size) {
    views.push_back({{"buffer", 0}, {"byteOffset", bin.size()}, {"byteLength", size}});
    const auto* p = static_cast<const uint8_t*>(data);
    bin.insert(bin.end(), p, p + size);
  };
  add(body, sizeof body);
  add(hat, sizeof hat);
  add(body_joints, sizeof body_joints);
  add(hat_joints, sizeof hat_joints);
  add(weights, sizeof weights);
  add(ibm_a, sizeof ibm_a);
  add(ibm_b, sizeof ibm_b);
  add(times, sizeof times);
  add(lift, sizeof lift);
  add(wave_bone, sizeof wave_bone);
  add(wave_tip, sizeof wave_tip);
  auto acc = [](int view, int type, int count, const char* kind) {
    return nlohmann::json{{"bufferView", view}, {"componentType", type}, {"count", count}, {"type", kind}};
  };
  nlohmann::json accessors = {acc(0, 5126, 3, "VEC3"), acc(1, 5126, 3, "VEC3"),   acc(2, 5123, 3, "VEC4"),
                              acc(3, 5123, 3, "VEC4"), acc(4, 5126, 3, "VEC4"),   acc(5, 5126, 2, "MAT4"),
                              acc(6, 5126, 1, "MAT4"), acc(7, 5126, 2, "SCALAR"), acc(8, 5126, 2, "VEC3"),
                              acc(9, 5126, 2, "VEC3"), acc(10, 5126, 2, "VEC3")};
  accessors[7]["min"] = {0};
  accessors[7]["max"] = {1};
  // "ArmatureB|Lift" keys only the repeated name: its armature is in the clip's name. "Wave" keys
  // A's Bone and Tip: Tip is A's alone, so its Bone is A's.
  auto channel = [](int sampler, int node) {
    return nlohmann::json{{"sampler", sampler}, {"target", {{"node", node}, {"path", "translation"}}}};
  };
  auto sampler = [](int output) {
    return nlohmann::json{{"input", 7}, {"output", output}, {"interpolation", "LINEAR"}};
  };
  const nlohmann::json animations = {
      {{"name", "ArmatureB|Lift"}, {"channels", {channel(0, 4)}}, {"samplers", {sampler(8)}}},
      {{"name", "Wave"}, {"channels", {channel(0, 1), channel(1, 2)}}, {"samplers", {sampler(9), sampler(10)}}}};
  accessors[0]["min"] = {0, 0, 0};
  accessors[0]["max"] = {1, 1, 0};
  accessors[1]["min"] = {3, 5, 0};
  accessors[1]["max"] = {4, 6, 0};
  auto prim = [](int pos, int joints) {
    return nlohmann::json{
        {"primitives", {{{"attributes", {{"POSITION", pos}, {"JOINTS_0", joints}, {"WEIGHTS_0", 4}}}}}}};
  };
  nlohmann::json meshes = {prim(0, 2), prim(1, 3)};
  meshes[0]["name"] = "Body";
  meshes[1]["name"] = "Hat";
  const nlohmann::json gltf = {
      {"asset", {{"version", "2.0"}}},
      {"scene", 0},
      {"scenes", {{{"nodes", {0, 3, 5, 6}}}}},
      {"nodes",
       {{{"name", "ArmatureA"}, {"children", {1}}},
        {{"name", "Bone"}, {"children", {2}}},
        {{"name", "Tip"}, {"translation", {0, 1, 0}}},
        {{"name", "ArmatureB"}, {"children", {4}}, {"translation", {3, 5, 0}}},
        {{"name", "Bone"}},
        {{"name", "BodyNode"}, {"mesh", 0}, {"skin", 0}},
        {{"name", "HatNode"}, {"mesh", 1}, {"skin", 1}}}},
      {"skins", {{{"joints", {1, 2}}, {"inverseBindMatrices", 5}}, {{"joints", {4}}, {"inverseBindMatrices", 6}}}},
      {"meshes", meshes},
      {"animations", animations},
      {"accessors", accessors},
      {"bufferViews", views},
      {"buffers", {{{"byteLength", bin.size()}, {"uri", "two.bin"}}}}};
  EXPECT_TRUE(ossa::test::write_file(dir / "two.bin", std::span<const uint8_t>(bin)));
  EXPECT_TRUE(ossa::test::write_file(dir / "two.gltf", gltf.dump(1)));
  return dir / "two.gltf";
}

bool has_warning(const ossa::cook::SourceScene& scene, const std::string& text) {
  return std::any_of(scene.warnings.begin(), scene.warnings.end(),
                     [&](const std::string& w) { return w.find(text) != std::string::npos; });
}

TEST(ArmatureNames, TwoSkinsOneJointNameEachMeshOnItsOwnArmature) {
  const fs::path dir = ossa::test::make_temp_dir("armatures");
  const fs::path path = write_two_armatures(dir);
  const auto scene = ossa::cook::import_scene(path.string());
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  std::vector<std::string> names;
  for (const auto& j : scene->skeleton.joints) names.push_back(j.name);
  EXPECT_NE(std::find(names.begin(), names.end(), "Bone"), names.end());
  EXPECT_NE(std::find(names.begin(), names.end(), "ArmatureB/Bone"), names.end()) << testing::PrintToString(names);
  std::vector<std::string> sorted = names;
  std::sort(sorted.begin(), sorted.end());
  EXPECT_EQ(std::adjacent_find(sorted.begin(), sorted.end()), sorted.end()) << "joint names repeat";
  EXPECT_TRUE(has_warning(*scene, "'Bone' -> 'ArmatureB/Bone'")) << testing::PrintToString(scene->warnings);
  const auto skinned = skinned_at_bind(*scene);
  ASSERT_EQ(skinned.size(), 2u);
  for (size_t m = 0; m < 2; ++m) {
    const auto truth = assimp_bind_vertices(path, m == 0 ? "Body" : "Hat");
    ASSERT_EQ(truth.size(), skinned[m].size()) << "mesh " << m;
    for (size_t v = 0; v < truth.size(); ++v)
      EXPECT_LT(glm::distance(truth[v], skinned[m][v]), 1e-4) << "mesh " << m << " vertex " << v;
  }
}

/// The last translation key of `joint` in `clip`, or (0,0,0) when the clip does not key it.
glm::vec3 last_translation(const ossa::cook::SourceScene& scene, const std::string& clip, const std::string& joint) {
  for (const auto& c : scene.clips) {
    if (c.name != clip && c.source_name != clip) continue;
    for (const auto& t : c.tracks)
      if (scene.skeleton.joints[t.joint].name == joint && !t.translations.empty()) return t.translations.back();
  }
  return glm::vec3(0.0f);
}

TEST(ArmatureNames, EachClipDrivesItsOwnArmature) {
  const fs::path dir = ossa::test::make_temp_dir("armatures");
  const auto scene = ossa::cook::import_scene(write_two_armatures(dir).string());
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  ASSERT_EQ(scene->clips.size(), 2u);
  EXPECT_LT(glm::distance(last_translation(*scene, "ArmatureB|Lift", "ArmatureB/Bone"), glm::vec3(0, 2, 0)), 1e-5f);
  EXPECT_LT(glm::length(last_translation(*scene, "ArmatureB|Lift", "Bone")), 1e-5f);
  EXPECT_LT(glm::distance(last_translation(*scene, "Wave", "Bone"), glm::vec3(1, 0, 0)), 1e-5f);
  EXPECT_LT(glm::distance(last_translation(*scene, "Wave", "Tip"), glm::vec3(0, 2, 0)), 1e-5f);
  EXPECT_LT(glm::length(last_translation(*scene, "Wave", "ArmatureB/Bone")), 1e-5f);
}

TEST(ArmatureNames, CowboyHatOnHisHead) {
  const fs::path path = ossa::test::shared_assets() / "Quaternius_Cowboy" / "Cowboy.fbx";
  if (!fs::exists(path)) GTEST_SKIP() << path << " is absent";
  const auto scene = ossa::cook::import_scene(path.string());
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  EXPECT_TRUE(has_warning(*scene, "'Bone' -> 'HatArmature/Bone'")) << testing::PrintToString(scene->warnings);
  const auto skinned = skinned_at_bind(*scene);
  // The hat is Assimp's "Cylinder" meshes (on node "Hat"): compare them with Assimp's bind pose.
  const auto truth = assimp_bind_vertices(path, "Hat");
  ASSERT_FALSE(truth.empty());
  std::vector<glm::dvec3> hat;
  for (size_t m = 0; m < scene->meshes.size(); ++m)
    if (scene->meshes[m].name.find("Cylinder") != std::string::npos ||
        scene->meshes[m].name.find("Hat") != std::string::npos)
      hat.insert(hat.end(), skinned[m].begin(), skinned[m].end());
  ASSERT_EQ(hat.size(), truth.size());
  double size = 0.0, worst = 0.0;
  for (const auto& p : truth) size = std::max(size, glm::length(p - centre(truth)));
  for (size_t v = 0; v < truth.size(); ++v) worst = std::max(worst, glm::distance(truth[v], hat[v]));
  std::printf(
      "Cowboy hat: %zu vertices, centre %.3f %.3f %.3f (Assimp %.3f %.3f %.3f), worst vertex %.6f (hat radius %.3f)\n",
      hat.size(), centre(hat).x, centre(hat).y, centre(hat).z, centre(truth).x, centre(truth).y, centre(truth).z, worst,
      size);
  EXPECT_LT(worst, 1e-3 * size);
}

}  // namespace
