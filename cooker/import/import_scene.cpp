// import_scene.cpp — the cooker's door to Assimp: read a source file with fixed settings, then
// convert the aiScene into a SourceScene (the stages live in the other import_*.cpp files).
//
// The import flags are the few post-steps whose result the cooker wants from Assimp and cannot
// cheaply do better itself: triangles only (Triangulate, and SortByPType so point and line meshes
// come out separate, to be dropped with a warning), and ValidateDataStructure so the converter can
// trust indices. Deliberately absent: JoinIdenticalVertices (5.2.5's merges vertices whose colours
// differ; the mesh stage welds exactly instead, cooker/mesh/mesh_build.cpp),
// LimitBoneWeights (the cooker caps at 4 itself and counts the vertices that lose weight),
// GenNormals (the mesh stage generates missing normals with OpenMesh), and the
// PreTransform/Optimize steps, which would destroy the node tree the skeleton comes from.
// FBX pivots are not preserved, so Assimp folds pivot chains into one node transform wherever it
// can; the converter still folds any `$AssimpFbx$` helper nodes that remain.
//
// Nothing escapes as an exception: Assimp throws from some importers, the standard library may
// throw bad_alloc, and both become an Error naming the file.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <exception>
#include <filesystem>
#include <set>

#include <assimp/Importer.hpp>
#include <assimp/config.h>
#include <assimp/postprocess.h>
#include <assimp/scene.h>

#include "cooker/import/import_internal.h"
#include "cooker/import/import_io.h"
#include "cooker/import/import_scene.h"
#include "cooker/import/tiny_values.h"
#include "cooker/import/value_check.h"

namespace ossa::cook {
namespace detail {

SourceFormat format_of(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (ext == ".fbx") return SourceFormat::Fbx;
  if (ext == ".gltf" || ext == ".glb") return SourceFormat::Gltf;
  if (ext == ".dae") return SourceFormat::Collada;
  if (ext == ".bvh") return SourceFormat::Bvh;
  return SourceFormat::Other;
}

/// Materials no mesh uses are left out (Assimp's "SkeletonMaterial" for BVH and rig-only files, a
/// glTF importer's default, an FBX's leftovers), and mesh indices renumbered; the order of those
/// kept is the source's.
void drop_unused_materials(SourceScene* scene) {
  std::vector<int> remap(scene->materials.size(), -1);
  for (const SourceMesh& mesh : scene->meshes) remap[mesh.material] = 0;
  std::vector<SourceMaterial> kept;
  for (size_t i = 0; i < scene->materials.size(); ++i) {
    if (remap[i] < 0) continue;
    remap[i] = static_cast<int>(kept.size());
    kept.push_back(std::move(scene->materials[i]));
  }
  scene->materials = std::move(kept);
  for (SourceMesh& mesh : scene->meshes) mesh.material = static_cast<uint32_t>(remap[mesh.material]);
}

Result<SourceScene> convert_scene(const aiScene& scene, const std::string& path, SourceFormat format,
                                  const ImportOptions& options) {
  SourceScene out;
  Context ctx;
  ctx.scene = &scene;
  ctx.path = path;
  ctx.format = format;
  ctx.options = &options;
  ctx.warnings = &out.warnings;
  std::string failure;
  ctx.failure = &failure;
  if (!scene.mRootNode) return ctx.error("the file has no node tree");
  ctx.mesh_kept = select_meshes(ctx);
  const NodeGraph graph = build_node_graph(ctx);
  Result<Rig> rig = build_rig(ctx, graph);
  if (!rig) return rig.error();
  out.clips = import_clips(ctx, graph, *rig);
  Result<std::vector<SourceMesh>> meshes = import_meshes(ctx, graph, *rig, &out.vertices_over_4_influences);
  if (!meshes) return meshes.error();
  out.meshes = std::move(*meshes);
  out.materials = import_materials(ctx);
  if (!failure.empty()) return ctx.error(failure);
  if (out.materials.empty() && !out.meshes.empty()) out.materials.emplace_back();
  for (SourceMesh& mesh : out.meshes) {
    if (mesh.material >= out.materials.size()) {
      ctx.warn("mesh '" + mesh.name + "' names a material the file does not have, uses material 0");
      mesh.material = 0;
    }
  }
  drop_unused_materials(&out);
  out.metres_per_unit = options.metres_per_unit > 0.0f ? options.metres_per_unit : metres_per_unit(ctx);
  out.skeleton = std::move(rig->skeleton);
  if (out.skeleton.joints.empty() && out.meshes.empty() && out.clips.empty()) {
    unsigned open_meshes = 0;
    for (unsigned m = 0; m < scene.mNumMeshes; ++m)
      if (scene.mMeshes[m] && scene.mMeshes[m]->mNumVertices &&
          !(scene.mMeshes[m]->mPrimitiveTypes & aiPrimitiveType_TRIANGLE))
        ++open_meshes;
    if (open_meshes != 0 && open_meshes == scene.mNumMeshes) {
      return ctx.error("its " + std::to_string(open_meshes) + (open_meshes == 1 ? " mesh holds" : " meshes hold") +
                       " only points or lines, and ossa cooks triangle meshes; there is no skeleton or animation "
                       "to cook either");
    }
    return ctx.error("holds no mesh, skeleton or animation to cook");
  }
  // Values the format cannot hold are named here, not found by the writer's own verification.
  if (Status st = check_scene_values(out); !st) return ctx.error(st.message());
  // Decomposition noise (1e-33 where 0 is meant) would cost the runtime subnormal arithmetic.
  flush_tiny_values(out);
  // One line per thing said: a texture two materials share, or a slot Assimp fills twice, would
  // otherwise say the same twice. The first occurrence keeps its place.
  std::set<std::string> seen;
  std::vector<std::string> unique;
  for (std::string& w : out.warnings)
    if (seen.insert(w).second) unique.push_back(std::move(w));
  out.warnings = std::move(unique);
  return out;
}

namespace {

/// Tangents only where a normal map will need them: CalcTangentSpace costs a pass over every
/// vertex, and most characters here have no normal map.
bool wants_tangents(const aiScene& scene) {
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    const aiMesh* mesh = scene.mMeshes[m];
    if (!mesh || mesh->mTangents || !mesh->mNormals || !mesh->mTextureCoords[0]) continue;
    if (mesh->mMaterialIndex >= scene.mNumMaterials) continue;
    const aiMaterial* mat = scene.mMaterials[mesh->mMaterialIndex];
    if (mat &&
        (mat->GetTextureCount(aiTextureType_NORMALS) > 0 || mat->GetTextureCount(aiTextureType_NORMAL_CAMERA) > 0)) {
      return true;
    }
  }
  return false;
}

/// Every length in the scene times `s`: node translations, position keys, vertex positions and the
/// translations of bone offset matrices. For a uniform s this is the change of basis S·M·S⁻¹ of
/// every transform (a uniform scale commutes with rotations and scales), so globals, skinning and
/// keys stay consistent and only the unit changes. Normals and directions are untouched.
void scale_lengths(aiScene& scene, double s) {
  const auto scale_translation = [s](aiMatrix4x4& m) {
    m.a4 = static_cast<ai_real>(m.a4 * s);
    m.b4 = static_cast<ai_real>(m.b4 * s);
    m.c4 = static_cast<ai_real>(m.c4 * s);
  };
  std::vector<aiNode*> stack;
  if (scene.mRootNode) stack.push_back(scene.mRootNode);
  while (!stack.empty()) {  // iterative: hierarchies may be deep
    aiNode* n = stack.back();
    stack.pop_back();
    scale_translation(n->mTransformation);
    for (unsigned c = 0; c < n->mNumChildren; ++c)
      if (n->mChildren[c]) stack.push_back(n->mChildren[c]);
  }
  for (unsigned a = 0; a < scene.mNumAnimations; ++a) {
    const aiAnimation* anim = scene.mAnimations[a];
    for (unsigned c = 0; anim && c < anim->mNumChannels; ++c) {
      aiNodeAnim* ch = anim->mChannels[c];
      for (unsigned k = 0; ch && k < ch->mNumPositionKeys; ++k) ch->mPositionKeys[k].mValue *= static_cast<ai_real>(s);
    }
  }
  for (unsigned m = 0; m < scene.mNumMeshes; ++m) {
    aiMesh* mesh = scene.mMeshes[m];
    if (!mesh) continue;
    for (unsigned v = 0; mesh->mVertices && v < mesh->mNumVertices; ++v) mesh->mVertices[v] *= static_cast<ai_real>(s);
    for (unsigned b = 0; b < mesh->mNumBones; ++b)
      if (mesh->mBones[b]) scale_translation(mesh->mBones[b]->mOffsetMatrix);
  }
}

/// The unit the file's lengths are in: the override, else what convert_scene would find (with its
/// warnings: "BVH states no length unit").
float source_metres_per_unit(const aiScene& scene, const std::string& path, const ImportOptions& options,
                             std::vector<std::string>* warnings) {
  if (options.metres_per_unit > 0.0f) return options.metres_per_unit;
  Context ctx;
  ctx.scene = &scene;
  ctx.path = path;
  ctx.format = format_of(path);
  ctx.options = &options;
  ctx.warnings = warnings;
  return metres_per_unit(ctx);
}

Result<SourceScene> read_and_convert(const std::string& path, const ImportOptions& options) {
  Assimp::Importer importer;
  auto* io = new LoggedIOSystem(path);  // every file the importer reads enters the cook key
  importer.SetIOHandler(io);            // (the importer owns it)
  importer.SetPropertyBool(AI_CONFIG_IMPORT_FBX_PRESERVE_PIVOTS, false);
  importer.SetPropertyBool(AI_CONFIG_FBX_CONVERT_TO_M, false);  // keep source units
  importer.SetPropertyInteger(AI_CONFIG_PP_SBP_REMOVE, 0);      // drop lines ourselves, with a warning
  // Collada's <up_axis> is applied by Assimp unless --up-axis overrides it (import_axes.cpp).
  importer.SetPropertyBool(AI_CONFIG_IMPORT_COLLADA_IGNORE_UP_DIRECTION, !assimp_applies_up_axis(path, options));
  // By its absolute path: every path an importer builds from it is then absolute, and a path a
  // scene names as it is (a LightWave scene's objects) resolves against the source's folder in
  // the IO system, not against the working directory (import_io.h).
  std::error_code ec;
  const std::filesystem::path absolute = std::filesystem::absolute(path, ec);
  const aiScene* scene = importer.ReadFile(ec ? path : absolute.lexically_normal().string(), assimp_import_flags());
  if (!io->refused().empty()) return Error{path + ": " + io->refused()};
  if (!scene) {
    // A file whose extension no Assimp reader claims was sniffed by content; a failure there is
    // Assimp's guess at a format the file never was ("FBX-Tokenize ... unexpected double-quote" for
    // a README), so say what the file is not. A known extension keeps Assimp's own message.
    const std::string ext = std::filesystem::path(path).extension().string();
    if (ext.empty() || !importer.IsExtensionSupported(ext))
      return Error{path + ": not a model file ossa-cook can read (FBX, glTF, GLB, DAE, BVH, OBJ, ...)"};
    return Error{path + ": " + importer.GetErrorString()};
  }
  // Y-up from here on: the importer's own scene, ours to edit.
  turn_to_y_up(*const_cast<aiScene*>(scene), source_up(*scene, path, options));
  if (wants_tangents(*scene)) {
    scene = importer.ApplyPostProcessing(aiProcess_CalcTangentSpace);
    if (!scene) return Error{path + ": " + importer.GetErrorString()};
  }
  // Against a rig in other units (an FBX clip in centimetres onto a glTF rig in metres, the
  // everyday Mixamo case), the file is converted into the rig's units before anything is folded:
  // otherwise it would play 100x too large.
  const float reference_unit = options.reference ? options.reference->metres_per_unit : 0.0f;
  std::vector<std::string> unit_warnings;
  const float file_unit = source_metres_per_unit(*scene, path, options, &unit_warnings);
  if (reference_unit > 0.0f && file_unit > 0.0f && std::abs(file_unit / reference_unit - 1.0f) > 1e-6f) {
    const double ratio = static_cast<double>(file_unit) / static_cast<double>(reference_unit);
    scale_lengths(*const_cast<aiScene*>(scene), ratio);  // the importer's own scene, ours to edit
    ImportOptions converted = options;
    converted.metres_per_unit = reference_unit;
    auto out = convert_scene(*scene, path, format_of(path), converted);
    if (out) {
      char text[200];
      std::snprintf(text, sizeof text,
                    "converted from the file's unit (%g m) to the reference rig's (%g m): lengths x %g",
                    static_cast<double>(file_unit), static_cast<double>(reference_unit), ratio);
      out->warnings.insert(out->warnings.begin(), text);
      out->warnings.insert(out->warnings.begin(), unit_warnings.begin(), unit_warnings.end());
    }
    return out;
  }
  return convert_scene(*scene, path, format_of(path), options);
}

}  // namespace
}  // namespace detail

unsigned assimp_import_flags() {
  return aiProcess_Triangulate | aiProcess_SortByPType | aiProcess_ValidateDataStructure;
}

Result<SourceScene> import_scene(const std::string& path, const ImportOptions& options) {
  try {
    return detail::read_and_convert(path, options);
  } catch (const std::exception& e) {
    return Error{path + ": " + e.what()};
  } catch (...) {
    return Error{path + ": unknown error while importing"};
  }
}

}  // namespace ossa::cook
