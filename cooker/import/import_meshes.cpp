// import_meshes.cpp — Assimp meshes -> SourceMesh: one per (mesh, node instance), always skinned
// when the file has a skeleton, so the runtime has one vertex path.
//
//   skinned  (the mesh has bones): vertices stay in mesh space; each joint's inverse bind is the
//            bone's offset matrix; influences capped at 4 here (not by Assimp's LimitBoneWeights)
//            so the cooker can count the vertices that lost weight;
//   rigid    (no bones, node at or under a joint): weight 1 on the nearest joint, inverse bind =
//            inverse(joint's global) x node's global, vertices stay in the node's space;
//   static   (no joint above it, or no skeleton): the node's global transform is baked in and
//            joints/weights stay empty.
// Normals are copied as unit vectors (missing ones are generated later, by the mesh stage); a
// normal Assimp left at zero or NaN is replaced by its faces' normal rather than dropping all.
#include <algorithm>
#include <array>
#include <cmath>
#include <set>

#include <assimp/scene.h>

#include "cooker/import/import_internal.h"

namespace ossa::cook::detail {
namespace {

// The material Assimp's SkeletonMeshBuilder gives the mesh it invents for files that hold only a
// skeleton (BVH, animation-only Collada): that mesh is a display aid, not content.
constexpr const char* kGeneratedSkeletonMaterial = "SkeletonMaterial";

std::string material_name(const aiScene& scene, unsigned index) {
  if (index >= scene.mNumMaterials || !scene.mMaterials[index]) return {};
  aiString name;
  if (scene.mMaterials[index]->Get(AI_MATKEY_NAME, name) != AI_SUCCESS) return {};
  return name.C_Str();
}

glm::vec3 to_vec3(const aiVector3D& v) { return {v.x, v.y, v.z}; }

bool finite(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

struct Influence {
  uint16_t joint;
  float weight;
};

/// Largest 4, renormalized, largest first, unused slots (joint 0, weight 0). false when no weight.
bool cap_influences(std::vector<Influence>* list, std::array<uint16_t, 4>* joints, glm::vec4* weights, bool* lost) {
  std::sort(list->begin(), list->end(), [](const Influence& a, const Influence& b) { return a.joint < b.joint; });
  std::vector<Influence> merged;  // a joint named by two bones counts once
  for (const Influence& in : *list) {
    if (!merged.empty() && merged.back().joint == in.joint) {
      merged.back().weight += in.weight;
    } else {
      merged.push_back(in);
    }
  }
  std::stable_sort(merged.begin(), merged.end(),
                   [](const Influence& a, const Influence& b) { return a.weight > b.weight; });
  *lost = merged.size() > 4;
  if (merged.size() > 4) merged.resize(4);
  float sum = 0.0f;
  for (const Influence& in : merged) sum += in.weight;
  if (!(sum > 0.0f) || !std::isfinite(sum)) return false;
  *joints = {0, 0, 0, 0};
  *weights = glm::vec4(0.0f);
  for (size_t i = 0; i < merged.size(); ++i) {
    (*joints)[i] = merged[i].joint;
    (*weights)[i] = merged[i].weight / sum;
  }
  return true;
}

/// Nearest node at or above n that is a joint of the rig, -1 if none.
int attached_joint(const NodeGraph& graph, const Rig& rig, int n) {
  for (; n >= 0; n = graph.nodes[n].parent) {
    if (rig.node_joint[n] >= 0) return rig.node_joint[n];
  }
  return -1;
}

/// inverse(joint's bind global) x node's global: puts node-space vertices on the joint.
glm::mat4 rigid_bind(const NodeGraph& graph, const Rig& rig, int joint, int node) {
  const int jn = rig.joint_node[joint];
  glm::dmat4 inverse;
  if (jn >= 0 && try_inverse(graph.nodes[jn].global, &inverse)) {
    return to_float(inverse * graph.nodes[node].global);
  }
  // A reference joint the file lacks: the reference's own bind is the best estimate.
  return rig.skeleton.joints[joint].inverse_bind * to_float(graph.nodes[node].global);
}

void repair_normals(SourceMesh* mesh, size_t* repaired) {
  std::vector<bool> bad(mesh->normals.size(), false);
  bool any = false;
  for (size_t v = 0; v < mesh->normals.size(); ++v) {
    const float len = glm::length(mesh->normals[v]);
    if (std::isfinite(len) && len > 1e-12f) {
      mesh->normals[v] /= len;
    } else {
      bad[v] = any = true;
      mesh->normals[v] = glm::vec3(0.0f);
    }
  }
  if (!any) return;
  for (size_t i = 0; i + 2 < mesh->indices.size(); i += 3) {
    const uint32_t a = mesh->indices[i], b = mesh->indices[i + 1], c = mesh->indices[i + 2];
    const glm::vec3 face = glm::cross(mesh->positions[b] - mesh->positions[a], mesh->positions[c] - mesh->positions[a]);
    for (uint32_t v : {a, b, c}) {
      if (bad[v]) mesh->normals[v] += face;
    }
  }
  for (size_t v = 0; v < mesh->normals.size(); ++v) {
    if (!bad[v]) continue;
    ++*repaired;
    const float len = glm::length(mesh->normals[v]);
    mesh->normals[v] = len > 0.0f && std::isfinite(len) ? mesh->normals[v] / len : glm::vec3(0, 0, 1);
  }
}

/// A colour component at least this large is stored as Unorm8 255, i.e. white.
constexpr float kWhite = 1.0f - 0.5f / 255.0f;

/// Geometry as Assimp has it, in mesh space. false when positions are not finite.
/// Assimp 5.2.5's glTF importer copies a VEC3 COLOR_0 into aiColor4D leaving alpha 0 (the
/// specification's implied alpha is 1); an all-zero alpha in a glTF file is read as that.
bool copy_geometry(const aiMesh& in, SourceFormat format, SourceMesh* out, size_t* dropped_faces) {
  const unsigned nv = in.mNumVertices;
  out->positions.reserve(nv);
  for (unsigned v = 0; v < nv; ++v) {
    out->positions.push_back(to_vec3(in.mVertices[v]));
    if (!finite(out->positions.back())) return false;
  }
  if (in.mNormals) {
    for (unsigned v = 0; v < nv; ++v) out->normals.push_back(to_vec3(in.mNormals[v]));
  }
  if (in.mTangents && in.mBitangents && in.mNormals) {
    for (unsigned v = 0; v < nv; ++v) {
      const glm::vec3 n = to_vec3(in.mNormals[v]), t = to_vec3(in.mTangents[v]);
      const glm::vec3 b = to_vec3(in.mBitangents[v]);
      const float sign = glm::dot(glm::cross(n, t), b) < 0.0f ? -1.0f : 1.0f;
      const float len = glm::length(t);
      out->tangents.emplace_back(len > 0.0f && std::isfinite(len) ? t / len : glm::vec3(1, 0, 0), sign);
    }
  }
  if (in.mTextureCoords[0]) {
    for (unsigned v = 0; v < nv; ++v) {
      out->uv0.emplace_back(in.mTextureCoords[0][v].x, in.mTextureCoords[0][v].y);
    }
  }
  if (in.mColors[0]) {
    // All white (as Unorm8 stores it) draws exactly as no colours: keep no stream then, so the
    // many exporters that write white colours by default cost no vertex bytes.
    bool all_white = true;
    out->colors.reserve(nv);
    for (unsigned v = 0; v < nv; ++v) {
      const aiColor4D& c = in.mColors[0][v];
      out->colors.emplace_back(c.r, c.g, c.b, c.a);
      for (int k = 0; k < 4; ++k) all_white = all_white && !(out->colors.back()[k] < kWhite);
    }
    const bool alpha_lost = format == SourceFormat::Gltf && std::all_of(out->colors.begin(), out->colors.end(),
                                                                        [](const glm::vec4& c) { return c.a == 0.0f; });
    if (alpha_lost) {
      all_white = true;
      for (glm::vec4& c : out->colors) {
        c.a = 1.0f;
        all_white = all_white && !(c.r < kWhite || c.g < kWhite || c.b < kWhite);
      }
    }
    if (all_white) out->colors.clear();
  }
  if (in.mColors[1]) {  // cloth paint (docs/CLOTH.md), read by cooker/mesh/cloth_build.h
    out->cloth_paint.reserve(nv);
    for (unsigned v = 0; v < nv; ++v) {
      const aiColor4D& c = in.mColors[1][v];
      out->cloth_paint.emplace_back(c.r, c.g, c.b, c.a);
    }
  }
  for (unsigned f = 0; f < in.mNumFaces; ++f) {
    const aiFace& face = in.mFaces[f];
    if (face.mNumIndices != 3 || face.mIndices[0] >= nv || face.mIndices[1] >= nv || face.mIndices[2] >= nv) {
      ++*dropped_faces;
      continue;
    }
    out->indices.insert(out->indices.end(), face.mIndices, face.mIndices + 3);
  }
  return true;
}

/// The mesh's morph targets as deltas. Assimp 5.2.5 hands glTF and FBX targets over as absolute
/// values (its aiAnimMesh starts as a copy of the base and adds the source's offsets), so the base
/// is subtracted here; the cooker's own welding and reordering then carry each target with its
/// vertices (mesh_build.cpp). Names are Assimp's (glTF `extras.targetNames`, FBX shape names), or
/// "target<i>" for an unnamed one, made unique within the mesh. The default weight is glTF's
/// mesh.weights; FBX targets start at 0, since Assimp reports 1 for every single-shape FBX channel
/// whatever its DeformPercent. Targets whose vertex count differs from the mesh's are dropped.
void copy_morph_targets(const aiMesh& in, SourceFormat format, SourceMesh* out, std::vector<std::string>* dropped) {
  const unsigned nv = in.mNumVertices;
  std::set<std::string> used;
  for (unsigned t = 0; t < in.mNumAnimMeshes; ++t) {
    const aiAnimMesh* am = in.mAnimMeshes[t];
    const std::string given = am && am->mName.length ? am->mName.C_Str() : "target" + std::to_string(t);
    if (!am || am->mNumVertices != nv || !am->mVertices) {
      dropped->push_back(given);
      continue;
    }
    SourceMorphTarget target;
    target.name = given;
    for (int n = 2; used.count(target.name); ++n) target.name = given + " (" + std::to_string(n) + ")";
    used.insert(target.name);
    target.default_weight = format == SourceFormat::Gltf && std::isfinite(am->mWeight) ? am->mWeight : 0.0f;
    bool finite_deltas = true;
    target.positions.reserve(nv);
    for (unsigned v = 0; v < nv; ++v) {
      target.positions.push_back(to_vec3(am->mVertices[v]) - to_vec3(in.mVertices[v]));
      finite_deltas = finite_deltas && finite(target.positions.back());
    }
    if (am->mNormals && in.mNormals) {
      for (unsigned v = 0; v < nv; ++v) {
        target.normals.push_back(to_vec3(am->mNormals[v]) - to_vec3(in.mNormals[v]));
        finite_deltas = finite_deltas && finite(target.normals.back());
      }
    }
    if (am->mTangents && in.mTangents && !out->tangents.empty()) {
      for (unsigned v = 0; v < nv; ++v) {
        target.tangents.push_back(to_vec3(am->mTangents[v]) - to_vec3(in.mTangents[v]));
        finite_deltas = finite_deltas && finite(target.tangents.back());
      }
    }
    if (!finite_deltas) {
      dropped->push_back(given);
      continue;
    }
    out->morph_targets.push_back(std::move(target));
  }
}

/// Bakes the node's global transform into a mesh that no joint carries.
void bake(const glm::dmat4& global, SourceMesh* mesh) {
  const glm::mat4 m = to_float(global);
  const glm::mat3 linear(m);
  const glm::mat3 normal_matrix = glm::transpose(glm::inverse(linear));
  const float mirror = glm::determinant(linear) < 0.0f ? -1.0f : 1.0f;
  for (auto& p : mesh->positions) p = glm::vec3(m * glm::vec4(p, 1.0f));
  for (auto& n : mesh->normals) n = normal_matrix * n;  // renormalized by repair_normals
  for (auto& t : mesh->tangents) {
    const glm::vec3 d = linear * glm::vec3(t);
    const float len = glm::length(d);
    t = glm::vec4(len > 0.0f ? d / len : glm::vec3(1, 0, 0), t.w * mirror);
  }
  // Deltas are differences of positions (directions): the linear part alone moves them.
  for (SourceMorphTarget& target : mesh->morph_targets) {
    for (auto& d : target.positions) d = linear * d;
    for (auto& d : target.normals) d = normal_matrix * d;
    for (auto& d : target.tangents) d = linear * d;
  }
}

struct MeshStats {
  size_t dropped_faces = 0, repaired_normals = 0, unweighted = 0, bad_offsets = 0;
  uint32_t over_4 = 0;
  std::vector<std::string> empty, non_finite, dropped_targets;
};

/// Influences from the mesh's bones; false when none of its bones is a joint.
bool skin(const aiMesh& in, const NodeGraph& graph, const Rig& rig, int node, SourceMesh* out, MeshStats* stats) {
  const unsigned nv = in.mNumVertices;
  std::vector<std::vector<Influence>> per_vertex(nv);
  std::map<uint16_t, glm::mat4> bind;  // sorted by joint; a joint named twice keeps its first bone
  const std::vector<int> nodes = bone_nodes(graph, in, node);
  for (unsigned b = 0; b < in.mNumBones; ++b) {
    const aiBone* bone = in.mBones[b];
    if (!bone) continue;
    const int n = nodes[b];
    if (n < 0 || rig.node_joint[n] < 0) continue;  // warned (or refused) by the rig stage
    const glm::dmat4 offset = to_dmat4(bone->mOffsetMatrix);
    if (!is_finite(offset)) {
      ++stats->bad_offsets;
      continue;
    }
    const auto joint = static_cast<uint16_t>(rig.node_joint[n]);
    bind.emplace(joint, to_float(offset));
    for (unsigned w = 0; w < bone->mNumWeights; ++w) {
      const aiVertexWeight& vw = bone->mWeights[w];
      if (vw.mVertexId < nv && std::isfinite(vw.mWeight) && vw.mWeight > 0.0f) {
        per_vertex[vw.mVertexId].push_back({joint, vw.mWeight});
      }
    }
  }
  if (bind.empty()) return false;
  const int fallback = attached_joint(graph, rig, node) >= 0 ? attached_joint(graph, rig, node) : 0;
  out->joints.resize(nv);
  out->weights.resize(nv);
  // Counted by distinct position: importers that keep one vertex per face corner (FBX; nothing is
  // welded before the mesh stage) would otherwise count each corner of one vertex.
  std::set<std::array<float, 3>> lost_at, unweighted_at;
  const auto at = [&](unsigned v) {
    const glm::vec3& p = out->positions[v];
    return std::array<float, 3>{p.x, p.y, p.z};
  };
  for (unsigned v = 0; v < nv; ++v) {
    bool lost = false;
    if (!cap_influences(&per_vertex[v], &out->joints[v], &out->weights[v], &lost)) {
      // No weight at all: carried rigidly by the joint the mesh hangs under.
      unweighted_at.insert(at(v));
      out->joints[v] = {static_cast<uint16_t>(fallback), 0, 0, 0};
      out->weights[v] = glm::vec4(1, 0, 0, 0);
      if (!bind.count(static_cast<uint16_t>(fallback))) {
        bind.emplace(static_cast<uint16_t>(fallback), rigid_bind(graph, rig, fallback, node));
      }
    }
    if (lost) lost_at.insert(at(v));
  }
  stats->unweighted += unweighted_at.size();
  stats->over_4 += static_cast<uint32_t>(lost_at.size());
  out->bind.assign(bind.begin(), bind.end());
  return true;
}

void import_instance(const Context& ctx, const NodeGraph& graph, const Rig& rig, unsigned mesh_index, int node,
                     std::vector<SourceMesh>* meshes, MeshStats* stats) {
  const aiMesh& in = *ctx.scene->mMeshes[mesh_index];
  SourceMesh out;
  out.name = in.mName.length ? in.mName.C_Str() : graph.nodes[node].name;
  out.material = in.mMaterialIndex;
  if (!copy_geometry(in, ctx.format, &out, &stats->dropped_faces)) {
    stats->non_finite.push_back(out.name);
    return;
  }
  if (out.indices.empty()) {
    stats->empty.push_back(out.name);
    return;
  }
  copy_morph_targets(in, ctx.format, &out, &stats->dropped_targets);
  const bool skinned = in.mNumBones > 0 && skin(in, graph, rig, node, &out, stats);
  if (!skinned) {
    const int joint = attached_joint(graph, rig, node);
    if (joint >= 0) {
      out.joints.assign(out.positions.size(), {static_cast<uint16_t>(joint), 0, 0, 0});
      out.weights.assign(out.positions.size(), glm::vec4(1, 0, 0, 0));
      out.bind = {{static_cast<uint16_t>(joint), rigid_bind(graph, rig, joint, node)}};
    } else {
      bake(graph.nodes[node].global, &out);
    }
  }
  repair_normals(&out, &stats->repaired_normals);
  meshes->push_back(std::move(out));
}

void report(const Context& ctx, const MeshStats& stats) {
  if (stats.dropped_faces) {
    ctx.warn(std::to_string(stats.dropped_faces) + " faces that are not triangles are dropped");
  }
  for (const auto& name : stats.non_finite) {
    ctx.warn("mesh '" + name + "' has non-finite positions and is dropped");
  }
  for (const auto& name : stats.empty) ctx.warn("mesh '" + name + "' has no triangles, dropped");
  if (stats.repaired_normals) {
    ctx.warn(std::to_string(stats.repaired_normals) + " zero or non-finite normals replaced by their faces' normal");
  }
  if (stats.unweighted) {
    ctx.warn(std::to_string(stats.unweighted) +
             " skinned vertices with no weight are carried by the joint their mesh hangs under");
  }
  if (!stats.dropped_targets.empty()) {
    std::string list;
    for (size_t i = 0; i < stats.dropped_targets.size(); ++i) list += (i ? ", " : "") + stats.dropped_targets[i];
    ctx.warn("morph targets whose vertices do not match their mesh's or are not finite are dropped: " + list);
  }
  if (stats.bad_offsets) {
    ctx.warn(std::to_string(stats.bad_offsets) + " bones with a non-finite offset matrix dropped");
  }
}

}  // namespace

bool is_generated_skeleton_mesh(const aiScene& scene, unsigned m) {
  const aiMesh* mesh = scene.mMeshes[m];
  return mesh != nullptr && material_name(scene, mesh->mMaterialIndex) == kGeneratedSkeletonMaterial;
}

std::vector<bool> select_meshes(const Context& ctx) {
  const aiScene& scene = *ctx.scene;
  std::vector<bool> kept(scene.mNumMeshes, false);
  std::vector<std::string> lines;
  bool generated = false;
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh* mesh = scene.mMeshes[m];
    if (!mesh || !mesh->mNumVertices || !mesh->mVertices) continue;
    if (is_generated_skeleton_mesh(scene, m)) {
      generated = true;
      continue;
    }
    if (!(mesh->mPrimitiveTypes & aiPrimitiveType_TRIANGLE)) {
      lines.push_back(mesh->mName.length ? mesh->mName.C_Str() : "mesh " + std::to_string(m));
      continue;
    }
    kept[m] = true;
  }
  if (generated) {
    ctx.warn("the skeleton display mesh Assimp generates for skeleton-only files is dropped");
  }
  if (!lines.empty()) {
    std::string list;
    for (size_t i = 0; i < lines.size(); ++i) list += (i ? ", " : "") + lines[i];
    ctx.warn("meshes of points or lines are dropped: " + list);
  }
  return kept;
}

Result<std::vector<SourceMesh>> import_meshes(const Context& ctx, const NodeGraph& graph, const Rig& rig,
                                              uint32_t* vertices_over_4_influences) {
  std::vector<SourceMesh> meshes;
  MeshStats stats;
  for (size_t n = 0; n < graph.nodes.size(); ++n) {
    const aiNode& node = *graph.nodes[n].ai;
    for (unsigned i = 0; i < node.mNumMeshes; ++i) {
      const unsigned m = node.mMeshes[i];
      if (m >= ctx.mesh_kept.size() || !ctx.mesh_kept[m]) continue;
      if (!is_finite(graph.nodes[n].global)) {
        return ctx.error("node '" + graph.nodes[n].name + "' has a non-finite transform");
      }
      import_instance(ctx, graph, rig, m, static_cast<int>(n), &meshes, &stats);
    }
  }
  report(ctx, stats);
  *vertices_over_4_influences += stats.over_4;
  return meshes;
}

}  // namespace ossa::cook::detail
