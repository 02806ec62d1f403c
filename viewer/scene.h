// scene.h — what the viewer shows: one character file and the clips that can play on it.
//
// `ossa-view arnaud.ossa walk.ossa run.ossa`: the first file with a mesh is the character; every
// other file contributes its clips, which must be cooked for the character's skeleton (clip-only
// files carry no skeleton and bind by skeleton hash, ossa/loader/asset.h check_clip_binding). Assets
// are kept open for the scene's lifetime: clip views, mesh views and the sampling caches point
// into their bytes (an Asset's bytes do not move when the Asset does, so a vector of them is fine).
//
// Morph targets are bound by name once, here: the character's channels are every distinct target
// name over its meshes (ossa/anim/morph.h collect_morph_channels), each mesh's targets map to
// channels, and each clip's weight tracks map to channels as the clip is added (a face clip from
// another file drives the targets it names; tracks for targets the character lacks are ignored).
#pragma once
#include <cstddef>
#include <cstdint>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <ossa/format/result.h>
#include <ossa/loader/asset.h>

namespace ossa::view {

struct SceneClip {
  ClipView clip;
  size_t asset = 0;                   // index into Scene::assets
  std::string label;                  // "walk" or "walk (walk.ossa)" when it comes from another file
  std::vector<int32_t> morph_tracks;  // the clip's weight track k -> morph channel, or -1
};

struct Scene {
  std::vector<Asset> assets;  // [0] is the character
  std::vector<std::string> paths;
  std::vector<SceneClip> clips;
  // Morph targets of the character (empty when it has none).
  std::vector<std::string_view> morph_channels;     // names, into the character's bytes
  std::vector<std::vector<int32_t>> morph_targets;  // per character mesh: target -> channel
  std::vector<float> morph_defaults;                // per channel: the targets' default weights

  const Asset& character() const { return assets.front(); }
  SkeletonView skeleton() const { return assets.front().skeleton(); }
  size_t joint_count() const { return skeleton().joint_count(); }
};

/// Opens every path; the first with a mesh is the character, the others add their clips. Errors
/// name the file: unreadable or invalid (Asset::open's message), no file with a mesh, or a clip
/// cooked for another skeleton.
Result<Scene> load_scene(std::span<const std::string> paths);

/// Adds the clips of another file to a loaded scene (drag and drop, the panel's Open). Errors
/// name the file; the scene is unchanged then.
Status add_clip_file(Scene& scene, const std::string& path);

/// True when the file at `path` has a mesh (decides between "new character" and "more clips"
/// for dropped files). Errors as Asset::open.
Result<bool> file_has_mesh(const std::string& path);

/// True when the character has no mesh: a skeleton-only file (mocap, a rig) shown as its bones,
/// with the skeleton overlay always on.
bool shows_bones_only(const Scene& scene);

/// Index of the morph channel named `name`, or -1.
int find_morph_channel(const Scene& scene, std::string_view name);

/// Index of the clip named `name` (its name in the file, or its label), or -1.
int find_clip(const Scene& scene, std::string_view name);

/// Counts for the stats panel.
struct SceneCounts {
  size_t meshes = 0, vertices = 0, triangles = 0, joints = 0;
};
SceneCounts count(const Scene& scene);

}  // namespace ossa::view
