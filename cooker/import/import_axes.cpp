// import_axes.cpp — every source comes out Y-up: the up axis the file states (FBX's UpAxis and
// UpAxisSign, as Assimp passes them on as metadata), or its format's fixed convention (Valve SMD is
// Z-up), or --up-axis over both, is turned onto +Y before the scene is converted.
//
// The turn is one rotation premultiplied onto the root node (and onto the keys of a root node that
// is animated, as a BVH's is): every node's global transform, and so every joint, mesh and clip,
// turns with it, while vertices stay in their node's space and bone offsets (mesh node relative to
// bone) are unchanged, so skins stay bound. That is also how Assimp applies Collada's <up_axis>
// itself, which is why Collada is left to Assimp unless --up-axis overrides it (the importer is
// then told to ignore the file's statement). Only the up axis is turned, never front or handedness:
// a file that states Y-up is left exactly as it was read, so no Y-up source changes its bytes.
#include <algorithm>
#include <cctype>
#include <filesystem>

#include <assimp/quaternion.h>
#include <assimp/scene.h>

#include "cooker/import/import_internal.h"

namespace ossa::cook::detail {
namespace {

std::string lower_extension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  return ext;
}

bool metadata_int(const aiMetadata* meta, const char* key, int* out) {
  int32_t value = 0;
  if (!meta || !meta->Get(key, value)) return false;
  *out = value;
  return true;
}

/// The rotation that takes `axis` (0 x, 1 y, 2 z) with `sign` onto +Y, about the axis that keeps
/// the other two in the ground plane (Z-up: (x, y, z) -> (x, z, -y), Assimp's own for Collada).
aiMatrix4x4 to_y_up(int axis, int sign) {
  if (axis == 2)
    return sign > 0 ? aiMatrix4x4(1, 0, 0, 0, 0, 0, 1, 0, 0, -1, 0, 0, 0, 0, 0, 1)
                    : aiMatrix4x4(1, 0, 0, 0, 0, 0, -1, 0, 0, 1, 0, 0, 0, 0, 0, 1);
  if (axis == 0)
    return sign > 0 ? aiMatrix4x4(0, -1, 0, 0, 1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1)
                    : aiMatrix4x4(0, 1, 0, 0, -1, 0, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1);
  return sign > 0 ? aiMatrix4x4() : aiMatrix4x4(1, 0, 0, 0, 0, -1, 0, 0, 0, 0, -1, 0, 0, 0, 0, 1);
}

}  // namespace

bool assimp_applies_up_axis(const std::string& path, const ImportOptions& options) {
  return lower_extension(path) == ".dae" && options.up_axis < 0;
}

SourceUp source_up(const aiScene& scene, const std::string& path, const ImportOptions& options) {
  if (options.up_axis >= 0 && options.up_axis <= 2) return {options.up_axis, 1, "--up-axis"};
  const std::string ext = lower_extension(path);
  if (ext == ".smd" || ext == ".vta") return {2, 1, "Valve SMD convention"};
  if (ext == ".dae") return {1, 1, "Collada <up_axis>, applied by Assimp"};
  int axis = 1, sign = 1;
  if (metadata_int(scene.mMetaData, "UpAxis", &axis) && axis >= 0 && axis <= 2) {
    if (!metadata_int(scene.mMetaData, "UpAxisSign", &sign) || (sign != 1 && sign != -1)) sign = 1;
    return {axis, sign, "the file's UpAxis"};
  }
  return {1, 1, "Y-up"};
}

void turn_to_y_up(aiScene& scene, const SourceUp& up) {
  if ((up.axis == 1 && up.sign > 0) || scene.mRootNode == nullptr) return;
  const aiMatrix4x4 turn = to_y_up(up.axis, up.sign);
  aiNode& root = *scene.mRootNode;
  root.mTransformation = turn * root.mTransformation;
  // A root node with keys of its own (a BVH's hips) would lose the turn to them: turn its keys too.
  const aiMatrix3x3 turn3(turn);
  const aiQuaternion turn_q(turn3);
  for (unsigned a = 0; a < scene.mNumAnimations; ++a) {
    const aiAnimation* anim = scene.mAnimations[a];
    for (unsigned c = 0; anim && c < anim->mNumChannels; ++c) {
      aiNodeAnim* ch = anim->mChannels[c];
      if (ch == nullptr || ch->mNodeName != root.mName) continue;
      for (unsigned k = 0; k < ch->mNumPositionKeys; ++k)
        ch->mPositionKeys[k].mValue = turn3 * ch->mPositionKeys[k].mValue;
      for (unsigned k = 0; k < ch->mNumRotationKeys; ++k)
        ch->mRotationKeys[k].mValue = turn_q * ch->mRotationKeys[k].mValue;
    }
  }
}

}  // namespace ossa::cook::detail
