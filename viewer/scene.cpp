// scene.cpp — see scene.h.
#include "viewer/scene.h"

#include <filesystem>
#include <utility>

#include <ossa/anim/morph.h>

#include "viewer/cook_job.h"

namespace ossa::view {
namespace {

/// The character's morph channels, each mesh's target -> channel table and the default weights.
void bind_character_morphs(Scene& scene, const Asset& character) {
  for (size_t m = 0; m < character.mesh_count(); ++m) collect_morph_channels(character.mesh(m), scene.morph_channels);
  scene.morph_defaults.assign(scene.morph_channels.size(), 0.0f);
  for (size_t m = 0; m < character.mesh_count(); ++m) {
    const MeshView mesh = character.mesh(m);
    std::vector<int32_t> targets(mesh.morph_target_count(), -1);
    (void)bind_morph_targets(mesh, scene.morph_channels, targets);
    scene.morph_targets.push_back(std::move(targets));
  }
  // In reverse, so that the first mesh's default wins (default_morph_weights: "the first of the
  // mesh's targets bound to channel c"; across meshes the first mesh).
  for (size_t m = character.mesh_count(); m-- > 0;)
    (void)default_morph_weights(character.mesh(m), scene.morph_targets[m], scene.morph_defaults);
}

/// Appends `asset`'s clips to the scene after checking each binds to the character's skeleton.
Status add_clips(Scene& scene, Asset asset, const std::string& path, bool is_character) {
  const SkeletonView skeleton = scene.assets.empty() ? asset.skeleton() : scene.skeleton();
  std::vector<SceneClip> added;
  if (is_character) bind_character_morphs(scene, asset);
  for (size_t c = 0; c < asset.clip_count(); ++c) {
    const ClipView clip = asset.clip(c);
    // Without joints (a blend-shape face), a clip of weights alone plays on the meshes' targets.
    const bool weights_only = skeleton.empty() && clip.joint_count() == 0 && clip.morph_track_count() > 0;
    if (Status s = weights_only ? Status{} : check_clip_binding(clip, skeleton, path); !s) {
      return Error{s.message() + (is_character ? "" : " (clips added to a character must be cooked for its skeleton)")};
    }
    SceneClip entry{clip, scene.assets.size(), std::string(clip.name()), {}};
    if (!is_character) entry.label += " (" + std::filesystem::path(path).filename().string() + ")";
    entry.morph_tracks.assign(clip.morph_track_count(), -1);
    (void)bind_morph_tracks(clip, scene.morph_channels, entry.morph_tracks);
    added.push_back(std::move(entry));
  }
  if (!is_character && added.empty()) return Error{path + ": no clips to add"};
  scene.assets.push_back(std::move(asset));
  scene.paths.push_back(path);
  scene.clips.insert(scene.clips.end(), added.begin(), added.end());
  return {};
}

}  // namespace

// Files are read into memory, not mapped (OpenMode::kRead): the viewer is the tool artists leave
// open while they re-cook, and a mapped file rewritten in place would end it with SIGBUS.
Result<Scene> load_scene(std::span<const std::string> paths) {
  if (paths.empty()) return Error{"no .ossa file given"};
  std::vector<Asset> opened;
  size_t character = paths.size();
  for (size_t i = 0; i < paths.size(); ++i) {
    Result<Asset> a = Asset::open(paths[i], OpenMode::kRead);
    if (!a && is_cook_source(paths[i]) && std::filesystem::is_regular_file(paths[i]))
      return Error{a.error().message + "; it is a source model, which the viewer shows once cooked: ossa-cook '" +
                   paths[i] + "' -o cooked, then ossa-view cooked/" + std::filesystem::path(paths[i]).stem().string() +
                   ".ossa (or, in the window, --cook-and-open '" + paths[i] + "' cooks and opens it)"};
    if (!a) return a.error();
    if (character == paths.size() && a->mesh_count() > 0) character = i;
    opened.push_back(std::move(*a));
  }
  // No body among them: a file with a skeleton of its own (mocap, a rig) is shown as its bones.
  for (size_t i = 0; character == paths.size() && i < opened.size(); ++i)
    if (!opened[i].skeleton().empty() && opened[i].skeleton().joint_count() > 0) character = i;
  if (character == paths.size()) {
    return Error{paths.size() == 1 ? paths[0] +
                                         ": has no mesh or skeleton to show (a clip-only file needs its "
                                         "character: ossa-view CHARACTER.ossa " +
                                         paths[0] + ")"
                                   : paths[0] + " and the other files given: none has a mesh or skeleton to show"};
  }
  Scene scene;
  if (Status s = add_clips(scene, std::move(opened[character]), paths[character], true); !s) return s.error();
  for (size_t i = 0; i < paths.size(); ++i) {
    if (i == character) continue;
    if (Status s = add_clips(scene, std::move(opened[i]), paths[i], false); !s) return s.error();
  }
  return scene;
}

Status add_clip_file(Scene& scene, const std::string& path) {
  Result<Asset> a = Asset::open(path, OpenMode::kRead);
  if (!a) return a.error();
  return add_clips(scene, std::move(*a), path, false);
}

Result<bool> file_has_mesh(const std::string& path) {
  Result<Asset> a = Asset::open(path, OpenMode::kRead);
  if (!a) return a.error();
  return a->mesh_count() > 0;
}

bool shows_bones_only(const Scene& scene) { return !scene.assets.empty() && scene.character().mesh_count() == 0; }

int find_morph_channel(const Scene& scene, std::string_view name) {
  for (size_t c = 0; c < scene.morph_channels.size(); ++c)
    if (scene.morph_channels[c] == name) return static_cast<int>(c);
  return -1;
}

int find_clip(const Scene& scene, std::string_view name) {
  for (size_t i = 0; i < scene.clips.size(); ++i) {
    if (scene.clips[i].clip.name() == name || scene.clips[i].label == name) return static_cast<int>(i);
  }
  return -1;
}

SceneCounts count(const Scene& scene) {
  SceneCounts c;
  const Asset& a = scene.character();
  c.meshes = a.mesh_count();
  c.joints = scene.joint_count();
  for (size_t m = 0; m < a.mesh_count(); ++m) {
    c.vertices += a.mesh(m).vertex_count();
    c.triangles += a.mesh(m).index_count() / 3;
  }
  return c;
}

}  // namespace ossa::view
