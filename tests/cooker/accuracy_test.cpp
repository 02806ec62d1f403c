// accuracy_test.cpp — the cooked file against the source, as Assimp itself evaluates it.
//
// For each asset: (1) every cooked joint's bind model-space position equals where the skins say it
// was bound (global of the mesh's node x inverse offset) when they say a pose other than the nodes',
// else the global transform of the Assimp node of that name; (2) every de-quantized vertex lies
// within the quantization bound of a source vertex, and skinning it with the cooked palette in the
// bind pose lands on the source vertex as bound (Assimp's skinning at the node pose, or the mesh
// placed by its node when the skins' pose is the bind); (3) at the first, middle and last source key times of each
// clip, the model-space joint positions of the cooked clip sampled by ossa::sample() equal Assimp's
// node animation evaluated at that time, within the compression error the cooker reports
// (Clip.compression.max_error) plus 1e-3 of the rig's size for resampling onto the frame grid, and
// a pose one frame off fails that bound (so the bound can catch a wrong sampler). Assimp is asked
// with the cooker's own import flags.
#include <gtest/gtest.h>

#include <algorithm>
#include <bit>
#include <cctype>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <functional>
#include <map>
#include <memory>
#include <string>
#include <unordered_map>
#include <vector>

#include <assimp/Importer.hpp>
#include <assimp/config.h>
#include <assimp/scene.h>
#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>
#include <glm/gtc/type_ptr.hpp>

#include "cooker/cook.h"
#include "cooker/import/import_scene.h"
#include "cooker/import/tiny_values.h"
#include <ossa/format/vertex_codec.h>
#include <ossa/loader/asset.h>
#include <ossa/anim/pose.h>
#include <ossa/anim/sample.h>
#include "test_files.h"

namespace fs = std::filesystem;

namespace {

glm::mat4 to_glm(const aiMatrix4x4& m) { return glm::transpose(glm::make_mat4(&m.a1)); }
glm::mat4 to_glm(const ossa::fb::Mat4& m) {
  glm::mat4 r;
  for (int i = 0; i < 16; ++i) glm::value_ptr(r)[i] = m.m()->Get(static_cast<flatbuffers::uoffset_t>(i));
  return r;
}
glm::mat4 trs(glm::vec3 t, glm::quat r, glm::vec3 s) {
  return glm::translate(glm::mat4(1.0f), t) * glm::mat4_cast(r) * glm::scale(glm::mat4(1.0f), s);
}

/// Every node with this name: names are not unique in every file (Blender exports an object and
/// a bone of the same name), so the tests accept the one that matches best.
void find_nodes(const aiNode* n, const std::string& name, std::vector<const aiNode*>* out) {
  if (name == n->mName.C_Str()) out->push_back(n);
  for (unsigned c = 0; c < n->mNumChildren; ++c) find_nodes(n->mChildren[c], name, out);
}

glm::mat4 node_global(const aiNode* n) {
  glm::mat4 m(1.0f);
  for (; n != nullptr; n = n->mParent) m = to_glm(n->mTransformation) * m;
  return m;
}

/// The node a bone names: of several with its name, one holding no mesh (as the cooker resolves it).
const aiNode* bone_node(const aiScene* scene, const std::string& name) {
  std::vector<const aiNode*> nodes;
  find_nodes(scene->mRootNode, name, &nodes);
  if (nodes.empty()) return nullptr;
  for (const aiNode* n : nodes)
    if (n->mNumMeshes == 0) return n;
  return nodes[0];
}

/// Where the skins say each bone was bound: global(mesh's node) x inverse(offset), the first
/// triangle mesh in depth-first node order naming the bone deciding (the cooker's rule), and
/// whether that pose differs from the node pose (max entry difference over max(1, max entry)
/// above 1e-4, the cooker's threshold) anywhere: then the cooked bind pose is the skins'.
struct SkinBind {
  std::map<std::string, glm::mat4> bound;
  bool differs_from_nodes = false;
  bool gltf = false;
};

SkinBind skin_bind(const aiScene* scene, const fs::path& source) {
  std::string ext = source.extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  const bool gltf = ext == ".gltf" || ext == ".glb";  // glTF keeps its node pose (the cooker's rule)
  SkinBind out;
  out.gltf = gltf;
  std::vector<const aiNode*> order;
  std::vector<const aiNode*> stack{scene->mRootNode};
  while (!stack.empty()) {  // preorder, children in the file's order
    const aiNode* n = stack.back();
    stack.pop_back();
    order.push_back(n);
    for (unsigned c = n->mNumChildren; c-- > 0;) stack.push_back(n->mChildren[c]);
  }
  for (const aiNode* n : order)
    for (unsigned k = 0; k < n->mNumMeshes; ++k) {
      const aiMesh* m = scene->mMeshes[n->mMeshes[k]];
      if (!(m->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) continue;
      aiString material;
      if (m->mMaterialIndex < scene->mNumMaterials &&
          scene->mMaterials[m->mMaterialIndex]->Get(AI_MATKEY_NAME, material) == AI_SUCCESS &&
          std::string(material.C_Str()) == "SkeletonMaterial")
        continue;  // the bone display mesh Assimp builds for files without a mesh
      for (unsigned b = 0; b < m->mNumBones; ++b) {
        const std::string name = m->mBones[b]->mName.C_Str();
        const aiNode* bn = bone_node(scene, name);
        if (bn == nullptr || out.bound.count(name)) continue;
        const glm::mat4 bound = node_global(n) * glm::inverse(to_glm(m->mBones[b]->mOffsetMatrix));
        out.bound[name] = bound;
        const glm::mat4 node = node_global(bn);
        float diff = 0.0f, scale = 1.0f;
        for (int c = 0; c < 4; ++c)
          for (int r = 0; r < 4; ++r) {
            diff = std::max(diff, std::abs(bound[c][r] - node[c][r]));
            scale = std::max(scale, std::abs(node[c][r]));
          }
        out.differs_from_nodes = out.differs_from_nodes || (!gltf && diff / scale > 2e-4f);
      }
    }
  return out;
}

/// Points for nearest-neighbour queries: a uniform hash grid.
class PointSet {
 public:
  explicit PointSet(float cell) : cell_(std::max(cell, 1e-6f)) {}
  void add(glm::vec3 p) {
    points_.push_back(p);
    grid_[key(cell_of(p))].push_back(static_cast<uint32_t>(points_.size() - 1));
  }
  /// Distance to the nearest point within one cell's reach (infinity when none).
  float nearest(glm::vec3 p) const {
    const glm::ivec3 c = cell_of(p);
    float best = INFINITY;
    for (int dz = -1; dz <= 1; ++dz)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dx = -1; dx <= 1; ++dx) {
          auto it = grid_.find(key(c + glm::ivec3(dx, dy, dz)));
          if (it == grid_.end()) continue;
          for (uint32_t i : it->second) best = std::min(best, glm::distance(p, points_[i]));
        }
    return best;
  }

 private:
  glm::ivec3 cell_of(glm::vec3 p) const { return glm::ivec3(glm::floor(p / cell_)); }
  static int64_t key(glm::ivec3 c) {
    return (int64_t(c.x) * 73856093) ^ (int64_t(c.y) * 19349663) ^ (int64_t(c.z) * 83492791);
  }
  float cell_;
  std::vector<glm::vec3> points_;
  std::unordered_map<int64_t, std::vector<uint32_t>> grid_;
};

struct Sampled {
  glm::vec3 t;
  glm::quat r;
  glm::vec3 s;
};

template <class Key>
double key_time(const Key& k) {
  return k.mTime;
}

/// Assimp's channel value at `ticks`, interpolated linearly (slerp for rotations), clamped.
glm::vec3 eval_vec(const aiVectorKey* keys, unsigned n, double ticks, glm::vec3 fallback) {
  if (n == 0) return fallback;
  if (ticks <= keys[0].mTime) return {keys[0].mValue.x, keys[0].mValue.y, keys[0].mValue.z};
  for (unsigned i = 0; i + 1 < n; ++i)
    if (ticks < keys[i + 1].mTime) {
      const float a = static_cast<float>((ticks - keys[i].mTime) / (keys[i + 1].mTime - keys[i].mTime));
      const aiVector3D v = keys[i].mValue * (1 - a) + keys[i + 1].mValue * a;
      return {v.x, v.y, v.z};
    }
  const aiVector3D& v = keys[n - 1].mValue;
  return {v.x, v.y, v.z};
}
glm::quat eval_quat(const aiQuatKey* keys, unsigned n, double ticks, glm::quat fallback) {
  auto q = [](const aiQuaternion& a) { return glm::quat(a.w, a.x, a.y, a.z); };
  if (n == 0) return fallback;
  if (ticks <= keys[0].mTime) return q(keys[0].mValue);
  for (unsigned i = 0; i + 1 < n; ++i)
    if (ticks < keys[i + 1].mTime) {
      const float a = static_cast<float>((ticks - keys[i].mTime) / (keys[i + 1].mTime - keys[i].mTime));
      return glm::slerp(q(keys[i].mValue), q(keys[i + 1].mValue), a);
    }
  return q(keys[n - 1].mValue);
}

std::vector<glm::mat4> bind_models(const ossa::SkeletonView& sk) {
  std::vector<glm::mat4> model(sk.joint_count());
  for (size_t i = 0; i < sk.joint_count(); ++i) {
    const auto& t = sk.bind_translations()[i];
    const auto& r = sk.bind_rotations()[i];
    const auto& s = sk.bind_scales()[i];
    const glm::mat4 local = trs({t.x(), t.y(), t.z()}, glm::quat(r.w(), r.x(), r.y(), r.z()), {s.x(), s.y(), s.z()});
    const int p = sk.parents()[i];
    model[i] = p < 0 ? local : model[static_cast<size_t>(p)] * local;
  }
  return model;
}

float skeleton_extent(const std::vector<glm::mat4>& model) {
  glm::vec3 lo(INFINITY), hi(-INFINITY);
  for (const glm::mat4& m : model) {
    lo = glm::min(lo, glm::vec3(m[3]));
    hi = glm::max(hi, glm::vec3(m[3]));
  }
  return model.empty() ? 1.0f : std::max(glm::length(hi - lo), 1e-3f);
}

struct AccuracyCase {
  const char* name;
  const char* path;  // relative to the repo (assets/...) or to ../shared/assets (shared:...)
};

fs::path resolve(const AccuracyCase& c) {
  const std::string p = c.path;
  if (p.rfind("shared:", 0) == 0) return ossa::test::shared_assets() / p.substr(7);
  return ossa::test::source_dir() / p;
}

class Accuracy : public ::testing::TestWithParam<AccuracyCase> {
 protected:
  void SetUp() override {
    source_ = resolve(GetParam());
    if (!fs::exists(source_)) GTEST_SKIP() << "notice: " << source_ << " is absent";
    const fs::path out = ossa::test::make_temp_dir("accuracy") / "out.ossa";
    const auto rec = ossa::cook::cook_file(source_, out, {});
    ASSERT_TRUE(rec.ok) << rec.error;
    auto a = ossa::Asset::open(out.string());
    ASSERT_TRUE(a.ok()) << a.error().message;
    asset_ = std::make_unique<ossa::Asset>(std::move(*a));
    importer_.SetPropertyBool(AI_CONFIG_IMPORT_FBX_PRESERVE_PIVOTS, false);
    scene_ = importer_.ReadFile(source_.string(), ossa::cook::assimp_import_flags());
    ASSERT_NE(scene_, nullptr) << importer_.GetErrorString();
  }
  fs::path source_;
  std::unique_ptr<ossa::Asset> asset_;
  Assimp::Importer importer_;
  const aiScene* scene_ = nullptr;
};

// The bind pose is the pose the skins were bound in where they say one that differs from the
// node pose (sources exported mid-animation; Fox, Pab's fingers, Quaternius): each bone a skin
// names sits where global(mesh node) x inverse(offset) puts it, and each other joint keeps its
// node-pose place relative to its parent. Elsewhere it is the node pose, Assimp's node globals.
TEST_P(Accuracy, BindPoseIsTheSkinsPoseOrTheNodePose) {
  const ossa::SkeletonView sk = asset_->skeleton();
  if (sk.empty()) GTEST_SKIP() << "no skeleton";
  const auto model = bind_models(sk);
  const float tol = 1e-4f * skeleton_extent(model) + 1e-5f;
  const SkinBind skins = skin_bind(scene_, source_);
  if (skins.differs_from_nodes) {
    size_t bound = 0;
    for (size_t i = 0; i < sk.joint_count(); ++i) {
      const std::string name(sk.joint_name(i));
      const auto it = skins.bound.find(name);
      glm::mat4 expected;
      if (it != skins.bound.end()) {
        expected = it->second;
        ++bound;
      } else {
        const aiNode* n = bone_node(scene_, name);
        ASSERT_NE(n, nullptr) << "cooked joint " << name << " is no node of the source";
        const int p = sk.parents()[i];
        const glm::mat4 node_local =
            p < 0 ? node_global(n)
                  : glm::inverse(node_global(bone_node(scene_, std::string(sk.joint_name(static_cast<size_t>(p)))))) *
                        node_global(n);
        expected = p < 0 ? node_local : model[static_cast<size_t>(p)] * node_local;
      }
      EXPECT_LE(glm::distance(glm::vec3(expected[3]), glm::vec3(model[i][3])), tol) << "joint " << i << " " << name;
      for (int c = 0; c < 3; ++c)
        EXPECT_LE(glm::distance(glm::vec3(expected[c]), glm::vec3(model[i][c])),
                  2e-4f * glm::length(glm::vec3(expected[c])) + 1e-5f)
            << "joint " << name << " axis " << c;
    }
    EXPECT_GT(bound, 0u);
    return;
  }
  for (size_t i = 0; i < sk.joint_count(); ++i) {
    const std::string name(sk.joint_name(i));
    std::vector<const aiNode*> nodes;
    find_nodes(scene_->mRootNode, name, &nodes);
    ASSERT_FALSE(nodes.empty()) << "cooked joint " << name << " is no node of the source";
    glm::mat4 g = node_global(nodes[0]);
    for (const aiNode* n : nodes)
      if (glm::distance(glm::vec3(node_global(n)[3]), glm::vec3(model[i][3])) <
          glm::distance(glm::vec3(g[3]), glm::vec3(model[i][3])))
        g = node_global(n);
    EXPECT_LE(glm::distance(glm::vec3(g[3]), glm::vec3(model[i][3])), tol) << "joint " << i << " " << name;
    for (int c = 0; c < 3; ++c)
      EXPECT_LE(glm::distance(glm::vec3(g[c]), glm::vec3(model[i][c])), 2e-4f * glm::length(glm::vec3(g[c])) + 1e-5f)
          << "joint " << name << " axis " << c;
    // The stored inverse bind is the inverse of that model matrix.
    const glm::mat4 ib = to_glm(sk.inverse_bind()[i]);
    const glm::mat4 id = ib * model[i];
    for (int c = 0; c < 4; ++c)
      for (int r = 0; r < 4; ++r) EXPECT_NEAR(id[c][r], c == r ? 1.0f : 0.0f, 1e-3f) << name;
  }
}

TEST_P(Accuracy, DequantizedVerticesMatchSource) {
  if (asset_->mesh_count() == 0) GTEST_SKIP() << "no mesh";
  // Candidate source positions: each mesh in its own space and placed by its node (static files
  // are baked into model space).
  std::vector<glm::vec3> mesh_space, skinned_bind;
  const SkinBind skins = skin_bind(scene_, source_);
  const ossa::SkeletonView sk_all = asset_->skeleton();
  const auto bind_model = sk_all.empty() ? std::vector<glm::mat4>{} : bind_models(sk_all);
  std::vector<const aiNode*> stack{scene_->mRootNode};
  while (!stack.empty()) {
    const aiNode* n = stack.back();
    stack.pop_back();
    for (unsigned c = 0; c < n->mNumChildren; ++c) stack.push_back(n->mChildren[c]);
    const glm::mat4 g = node_global(n);
    for (unsigned k = 0; k < n->mNumMeshes; ++k) {
      const aiMesh* m = scene_->mMeshes[n->mMeshes[k]];
      // Assimp's node-pose skinning, limited like the cooker to the 4 largest influences; where the
      // skins' bind pose differs from the node pose, the cooked bind pose is the skins', where
      // skinning gives the mesh as it was bound: its vertices placed by its node.
      std::vector<std::vector<std::pair<float, glm::mat4>>> influences(m->mNumVertices);
      for (unsigned b = 0; b < m->mNumBones; ++b) {
        const aiBone* bone = m->mBones[b];
        std::vector<const aiNode*> bone_nodes;
        find_nodes(scene_->mRootNode, bone->mName.C_Str(), &bone_nodes);
        if (bone_nodes.empty()) continue;
        const aiNode* bn = bone_nodes[0];
        for (const aiNode* cand : bone_nodes)
          if (cand->mNumMeshes == 0) {
            bn = cand;
            break;
          }
        const glm::mat4 palette = node_global(bn) * to_glm(bone->mOffsetMatrix);
        for (unsigned w = 0; w < bone->mNumWeights; ++w) {
          const auto& vw = bone->mWeights[w];
          if (vw.mVertexId < m->mNumVertices && vw.mWeight > 0.0f)
            influences[vw.mVertexId].push_back({vw.mWeight, palette});
        }
      }
      // A mesh without bones rides on the joint above it: where the bind pose is the skins', it sits
      // where that joint's cooked bind puts it, as it sat relative to the joint's node.
      glm::mat4 rigid = g;
      if (skins.differs_from_nodes && m->mNumBones == 0 && !bind_model.empty())
        for (const aiNode* a = n; a != nullptr; a = a->mParent) {
          const int j = sk_all.find_joint(a->mName.C_Str());
          // A mesh object can share its name with a bone (Quaternius' "Torso"): the joint is the
          // bone's node, as the cooker resolves names.
          if (j < 0 || bone_node(scene_, a->mName.C_Str()) != a) continue;
          rigid = bind_model[static_cast<size_t>(j)] * glm::inverse(node_global(a)) * g;
          break;
        }
      std::vector<glm::mat4> skin(m->mNumVertices, glm::mat4(0.0f));
      std::vector<float> wsum(m->mNumVertices, 0.0f);
      for (unsigned v = 0; v < m->mNumVertices; ++v) {
        auto& inf = influences[v];
        std::stable_sort(inf.begin(), inf.end(), [](const auto& a, const auto& b) { return a.first > b.first; });
        for (size_t i = 0; i < inf.size() && i < 4; ++i) {
          skin[v] += inf[i].second * inf[i].first;
          wsum[v] += inf[i].first;
        }
      }
      for (unsigned v = 0; v < m->mNumVertices; ++v) {
        const glm::vec3 p(m->mVertices[v].x, m->mVertices[v].y, m->mVertices[v].z);
        mesh_space.push_back(p);
        mesh_space.push_back(glm::vec3(g * glm::vec4(p, 1.0f)));
        skinned_bind.push_back(wsum[v] > 0 && !skins.differs_from_nodes
                                   ? glm::vec3(skin[v] * glm::vec4(p, 1.0f) / wsum[v])
                                   : glm::vec3(rigid * glm::vec4(p, 1.0f)));
      }
    }
  }
  const ossa::SkeletonView sk = asset_->skeleton();
  const auto model = sk.empty() ? std::vector<glm::mat4>{} : bind_models(sk);
  size_t checked = 0;
  for (size_t mi = 0; mi < asset_->mesh_count(); ++mi) {
    const ossa::MeshView mesh = asset_->mesh(mi);
    const auto* pos = mesh.attribute(ossa::fb::VertexSemantic::Position);
    ASSERT_NE(pos, nullptr);
    const auto* jnt = mesh.attribute(ossa::fb::VertexSemantic::Joints);
    const auto* wgt = mesh.attribute(ossa::fb::VertexSemantic::Weights);
    const auto& off = *mesh.fb->position_offset();
    const auto& scl = *mesh.fb->position_scale();
    const glm::vec3 offset(off.x(), off.y(), off.z()), scale(scl.x(), scl.y(), scl.z());
    const float extent = glm::length(scale);
    const float tol = pos->format() == ossa::fb::VertexFormat::Float32x3
                          ? 1e-6f * (extent + glm::length(offset)) + 1e-7f
                          : 0.5f * extent / 65535.0f * 1.01f + 1e-6f * (extent + glm::length(offset));
    PointSet source_points(std::max(tol * 4.0f, extent / 512.0f));
    for (const glm::vec3& p : mesh_space) source_points.add(p);
    const float skin_tol = 5e-3f * std::max(extent, model.empty() ? 0.0f : skeleton_extent(model)) + tol;
    PointSet skinned_points(std::max(skin_tol * 2.0f, extent / 512.0f));
    for (const glm::vec3& p : skinned_bind) skinned_points.add(p);

    const uint8_t* base = mesh.vertex_bytes().data();
    float worst = 0.0f, worst_skin = 0.0f;
    for (uint32_t v = 0; v < mesh.vertex_count(); ++v) {
      const uint8_t* vx = base + size_t(v) * mesh.vertex_stride();
      glm::vec3 p;
      if (pos->format() == ossa::fb::VertexFormat::Float32x3) {
        std::memcpy(&p, vx + pos->offset(), 12);
      } else {
        uint16_t q[3];
        std::memcpy(q, vx + pos->offset(), 6);
        p = offset +
            scale * glm::vec3(ossa::unorm16_to_float(q[0]), ossa::unorm16_to_float(q[1]), ossa::unorm16_to_float(q[2]));
      }
      worst = std::max(worst, source_points.nearest(p));
      if (jnt != nullptr && wgt != nullptr && !model.empty()) {
        glm::mat4 skin(0.0f);
        float wsum = 0.0f;
        for (int k = 0; k < 4; ++k) {
          uint32_t slot;
          if (jnt->format() == ossa::fb::VertexFormat::Uint8x4) slot = vx[jnt->offset() + k];
          else {
            uint16_t s16;
            std::memcpy(&s16, vx + jnt->offset() + 2 * k, 2);
            slot = s16;
          }
          float w;
          if (wgt->format() == ossa::fb::VertexFormat::Unorm8x4) w = vx[wgt->offset() + k] / 255.0f;
          else std::memcpy(&w, vx + wgt->offset() + 4 * k, 4);
          if (w == 0.0f) continue;
          skin += (model[mesh.joints()[slot]] * to_glm(mesh.inverse_bind()[slot])) * w;
          wsum += w;
        }
        ASSERT_NEAR(wsum, 1.0f, 1e-5f) << "weights of vertex " << v;
        worst_skin = std::max(worst_skin, skinned_points.nearest(glm::vec3(skin * glm::vec4(p, 1.0f))));
      }
      ++checked;
    }
    EXPECT_LE(worst, tol) << "mesh " << mesh.name() << ": worst distance to a source vertex";
    if (jnt != nullptr && !model.empty()) {
      EXPECT_LE(worst_skin, skin_tol) << "mesh " << mesh.name() << ": bind-pose skinning vs Assimp";
    }
    RecordProperty("worst_position_error_" + std::to_string(mi), std::to_string(worst));
  }
  EXPECT_GT(checked, 0u);
}

/// Model-space joint positions of a sampled local pose (an independent forward loop, so this test
/// does not lean on pose_ops' local_to_model).
std::vector<glm::vec3> model_positions(const ossa::SkeletonView& sk, const ossa::Pose& pose) {
  std::vector<glm::mat4> model(sk.joint_count());
  std::vector<glm::vec3> out(sk.joint_count());
  for (size_t j = 0; j < sk.joint_count(); ++j) {
    const ossa::Transform x = ossa::get_transform(pose, static_cast<uint32_t>(j));
    const glm::mat4 local = trs(x.translation, x.rotation, x.scale);
    const int p = sk.parents()[j];
    model[j] = p < 0 ? local : model[static_cast<size_t>(p)] * local;
    out[j] = glm::vec3(model[j][3]);
  }
  return out;
}

TEST_P(Accuracy, ClipSamplesMatchAssimpAtFirstMiddleLastSourceTimes) {
  const ossa::SkeletonView sk = asset_->skeleton();
  if (sk.empty() || asset_->clip_count() == 0) GTEST_SKIP() << "no clip";
  ASSERT_EQ(asset_->clip_count(), scene_->mNumAnimations);
  const float extent = skeleton_extent(bind_models(sk));
  const auto joints = static_cast<uint32_t>(sk.joint_count());
  ossa::Pose pose(joints);
  bool negative_control_ran = false;
  for (unsigned ci = 0; ci < scene_->mNumAnimations; ++ci) {
    const aiAnimation* anim = scene_->mAnimations[ci];
    const ossa::ClipView clip = asset_->clip(ci);
    // The cooker's stated bound: the compression error it measured against the resampled source
    // (in source units), plus 1e-3 of the rig's size for what resampling onto the frame grid and
    // Assimp's slerp-vs-nlerp evaluation add between grid frames.
    const float max_error = clip.compression() ? clip.compression()->max_error() : 0.0f;
    const float tol = max_error + 1e-3f * extent + 1e-5f;
    auto cache = ossa::make_sampling_cache(clip, sk);
    ASSERT_TRUE(cache.ok()) << cache.error().message;
    std::vector<double> ticks;
    std::map<std::string, const aiNodeAnim*> channels;
    for (unsigned c = 0; c < anim->mNumChannels; ++c) {
      const aiNodeAnim* ch = anim->mChannels[c];
      channels[ch->mNodeName.C_Str()] = ch;
      for (unsigned k = 0; k < ch->mNumPositionKeys; ++k) ticks.push_back(ch->mPositionKeys[k].mTime);
      for (unsigned k = 0; k < ch->mNumRotationKeys; ++k) ticks.push_back(ch->mRotationKeys[k].mTime);
    }
    if (ticks.empty() || clip.duration() <= 0.0f) continue;
    std::sort(ticks.begin(), ticks.end());
    ticks.erase(std::unique(ticks.begin(), ticks.end()), ticks.end());
    const double ticks_per_second = anim->mDuration / clip.duration();
    ASSERT_GT(ticks_per_second, 0.0);
    // Assimp: every node's local, animated where a channel drives it; global at `tk` ticks.
    const auto assimp_positions = [&](double tk) {
      std::function<glm::mat4(const aiNode*)> global = [&](const aiNode* n) -> glm::mat4 {
        glm::mat4 local = to_glm(n->mTransformation);
        auto it = channels.find(n->mName.C_Str());
        if (it != channels.end()) {
          const aiNodeAnim* ch = it->second;
          aiVector3D s0, t0;
          aiQuaternion r0;
          n->mTransformation.Decompose(s0, r0, t0);
          local = trs(eval_vec(ch->mPositionKeys, ch->mNumPositionKeys, tk, {t0.x, t0.y, t0.z}),
                      eval_quat(ch->mRotationKeys, ch->mNumRotationKeys, tk, glm::quat(r0.w, r0.x, r0.y, r0.z)),
                      eval_vec(ch->mScalingKeys, ch->mNumScalingKeys, tk, {s0.x, s0.y, s0.z}));
        }
        return n->mParent ? global(n->mParent) * local : local;
      };
      // Every candidate node per joint (names are not always unique): the test takes the nearest.
      std::vector<std::vector<glm::vec3>> out(sk.joint_count());
      for (size_t j = 0; j < sk.joint_count(); ++j) {
        std::vector<const aiNode*> nodes;
        find_nodes(scene_->mRootNode, std::string(sk.joint_name(j)), &nodes);
        for (const aiNode* n : nodes) out[j].push_back(glm::vec3(global(n)[3]));
      }
      return out;
    };
    const auto error_of = [&](const std::vector<glm::vec3>& cooked, const std::vector<glm::vec3>& source, size_t j) {
      float err = INFINITY;
      for (const glm::vec3& p : source) err = std::min(err, glm::distance(p, cooked[j]));
      return err;
    };
    for (double tk : {ticks.front(), ticks[ticks.size() / 2], ticks.back()}) {
      const auto t = static_cast<float>(tk / ticks_per_second);
      const auto source = assimp_positions(tk);
      ossa::sample(clip, t, ossa::SampleOptions{.loop = false}, *cache, pose);
      const std::vector<glm::vec3> cooked = model_positions(sk, pose);
      for (size_t j = 0; j < sk.joint_count(); ++j) {
        ASSERT_FALSE(source[j].empty()) << "cooked joint " << sk.joint_name(j) << " is no node of the source";
        EXPECT_LE(error_of(cooked, source[j], j), tol) << "clip '" << clip.name() << "' t=" << t << "s joint "
                                                       << sk.joint_name(j) << " (max_error " << max_error << ")";
      }
      // Negative control: a pose one frame off must fail the same comparison wherever the clip
      // moves more than twice the tolerance in that frame; otherwise the bound could not catch a
      // sampler that is a frame late. (Motion is measured on the cooked clip, not on Assimp: for
      // glTF STEP samplers Assimp's linear evaluation between keys is not the source's.)
      const float step = 1.0f / clip.sample_rate();
      const float shifted = t + step <= clip.duration() ? t + step : t - step;
      ossa::sample(clip, shifted, ossa::SampleOptions{.loop = false}, *cache, pose);
      const std::vector<glm::vec3> wrong = model_positions(sk, pose);
      float moved = 0.0f, worst = 0.0f;
      for (size_t j = 0; j < sk.joint_count(); ++j) {
        moved = std::max(moved, glm::distance(wrong[j], cooked[j]));
        worst = std::max(worst, error_of(wrong, source[j], j));
      }
      if (moved > 2.0f * tol) {
        EXPECT_GT(worst, tol) << "clip '" << clip.name() << "': a pose one frame off still passes the tolerance";
        negative_control_ran = true;
      }
    }
  }
  RecordProperty("negative_control", negative_control_ran ? "ran" : "no clip moved enough");
}

// No rest or constant value is cooked in (0, kTinyValue): rest values rebuilt from matrices carry
// noise like 7.7e-34 where 0 is meant (Pab's skins put five in its hand and finger rotations),
// which the runtime's interpolation would square into subnormals (cooker/import/tiny_values.h).
// Checked: bind transforms, inverse binds of skeleton and meshes, clip constants. Animated keys
// are the encoder's choice (a quantized key lands anywhere in its range, a rotation key's solved
// component anywhere near its source) and may come near zero: the runtime's flush-to-zero covers
// those (runtime/internal/float_env.h, tests/float_env_test.cpp).
TEST_P(Accuracy, NoTinyValueIsCooked) {
  size_t checked = 0;
  // what, then where: a joint, mesh or clip index and an element index.
  const auto check = [&](float v, const char* what, size_t at, size_t sub) {
    ++checked;
    EXPECT_FALSE(v != 0.0f && std::fabs(v) < ossa::cook::kTinyValue) << what << " " << at << "/" << sub << " = " << v;
  };
  const auto check_matrix = [&](const ossa::fb::Mat4& m, const char* what, size_t at) {
    for (int i = 0; i < 16; ++i) check(m.m()->Get(static_cast<flatbuffers::uoffset_t>(i)), what, at, size_t(i));
  };
  const ossa::SkeletonView sk = asset_->skeleton();
  for (size_t j = 0; j < sk.joint_count(); ++j) {
    const auto& t = sk.bind_translations()[j];
    const auto& r = sk.bind_rotations()[j];
    const auto& sc = sk.bind_scales()[j];
    for (float v : {t.x(), t.y(), t.z()}) check(v, "bind translation of joint", j, 0);
    for (float v : {r.x(), r.y(), r.z(), r.w()}) check(v, "bind rotation of joint", j, 0);
    for (float v : {sc.x(), sc.y(), sc.z()}) check(v, "bind scale of joint", j, 0);
    check_matrix(sk.inverse_bind()[j], "inverse bind of joint", j);
  }
  for (size_t m = 0; m < asset_->mesh_count(); ++m)
    for (const ossa::fb::Mat4& ib : asset_->mesh(m).inverse_bind()) check_matrix(ib, "inverse bind of mesh", m);
  for (size_t c = 0; c < asset_->clip_count(); ++c) {
    const ossa::ClipView clip = asset_->clip(c);
    for (const ossa::fb::ConstantChannel& k : clip.constants())
      for (float v : {k.value().x(), k.value().y(), k.value().z()}) check(v, "constant of clip", c, 0);
  }
  EXPECT_GT(checked, 0u);
}

// flush_tiny_values on every field the runtime computes with: below the bound (subnormals and -0
// included) becomes +0, the bound itself and everything above it stay.
TEST(TinyValues, EveryRuntimeFloatBelowTheBoundIsFlushedAndNothingElse) {
  using ossa::cook::kTinyValue;
  const float below[] = {0.99f * kTinyValue, -0.5f * kTinyValue, 7.7e-34f, -1.97e-31f, 1e-40f, -0.0f};
  const float kept[] = {kTinyValue, -kTinyValue, 1e-18f, 1.0f, -3.5f, 0.0f};
  ossa::cook::SourceScene scene;
  std::vector<float*> low, high;  // where each kind of value was put
  const auto fill = [&](float* v, size_t n) {
    for (size_t i = 0; i < n; ++i) {
      const bool is_low = i % 2 == 0;
      v[i] = is_low ? below[(i / 2) % 6] : kept[(i / 2) % 6];
      (is_low ? low : high).push_back(&v[i]);
    }
  };
  ossa::cook::SourceJoint& joint = scene.skeleton.joints.emplace_back();
  ossa::cook::SourceMesh& mesh = scene.meshes.emplace_back();
  mesh.positions.resize(2);
  mesh.normals.resize(2);
  mesh.tangents.resize(2);
  mesh.bind.emplace_back(uint16_t(0), glm::mat4(1.0f));
  ossa::cook::SourceMorphTarget& target = mesh.morph_targets.emplace_back();
  target.positions.resize(2);
  target.normals.resize(2);
  target.tangents.resize(2);
  ossa::cook::SourceClip& clip = scene.clips.emplace_back();
  ossa::cook::SourceTrack& track = clip.tracks.emplace_back();
  track.translations.resize(2);
  track.rotations.resize(2);
  track.scales.resize(2);
  clip.root_motion.translations.resize(2);
  clip.root_motion.yaws.resize(4);
  clip.morph_weights.emplace_back().weights.resize(4);
  fill(&joint.translation.x, 3);
  fill(&joint.rotation.x, 4);
  fill(&joint.scale.x, 3);
  fill(&joint.inverse_bind[0][0], 16);
  fill(&mesh.positions[0].x, 6);
  fill(&mesh.normals[0].x, 6);
  fill(&mesh.tangents[0].x, 8);
  fill(&mesh.bind[0].second[0][0], 16);
  fill(&target.positions[0].x, 6);
  fill(&target.normals[0].x, 6);
  fill(&target.tangents[0].x, 6);
  fill(&track.translations[0].x, 6);
  fill(&track.rotations[0].x, 8);
  fill(&track.scales[0].x, 6);
  fill(&clip.root_motion.translations[0].x, 6);
  fill(clip.root_motion.yaws.data(), 4);
  fill(clip.morph_weights[0].weights.data(), 4);
  std::vector<float> before;
  for (float* v : high) before.push_back(*v);
  EXPECT_EQ(ossa::cook::flush_tiny_values(scene), low.size());
  for (float* v : low) EXPECT_TRUE(*v == 0.0f && !std::signbit(*v)) << *v;
  for (size_t i = 0; i < high.size(); ++i)
    EXPECT_EQ(std::bit_cast<uint32_t>(*high[i]), std::bit_cast<uint32_t>(before[i]));
  EXPECT_EQ(ossa::cook::flush_tiny_values(scene), 0u);  // nothing left to flush
}

const AccuracyCase kCases[] = {
    {"CesiumMan", "assets/CesiumMan/CesiumMan.glb"},
    {"Fox", "assets/Fox/Fox.glb"},
    {"RiggedSimple", "assets/RiggedSimple/RiggedSimple.glb"},
    {"PabSkeleton", "assets/Pab/skeleton.fbx"},
    {"PabArnaud", "assets/Pab/arnaud.fbx"},
    {"PabSkeletonDae", "shared:Pab/skeleton.dae"},
    {"RobotExpressive", "shared:RobotExpressive/RobotExpressive.glb"},
    {"QuaterniusRobot", "shared:Quaternius_Robot/Robot.fbx"},
    {"QuaterniusMale", "shared:Quaternius_Male/Smooth_Male_Casual.fbx"},
    {"QuaterniusEagle", "shared:Quaternius_Eagle/Eagle.fbx"},
    {"AnimeBoy", "shared:AnimeBoy/scene.gltf"},
    {"CmuBvh", "shared:CMU_BVH/01_03.bvh"},
    {"InterpolationTest", "shared:Khronos_embedded/interpolation_test.gltf"},
    {"BoxAnimated", "shared:Khronos_embedded/box_animated.gltf"},
};

INSTANTIATE_TEST_SUITE_P(Assets, Accuracy, ::testing::ValuesIn(kCases),
                         [](const ::testing::TestParamInfo<AccuracyCase>& i) { return std::string(i.param.name); });

}  // namespace
