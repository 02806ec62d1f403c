// clips_internal.h — what import_clips.cpp (Assimp's keys, chains, the clip) and
// import_clips_gltf.cpp (glTF samplers Assimp mishandles, a clip's frame rate) share. Nothing
// outside those two files includes it.
#pragma once
#include <cstddef>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include "cooker/import/gltf_samplers.h"
#include "cooker/import/import_internal.h"
#include "cooker/model/clip_grid.h"

namespace ossa::cook::detail {

/// One node's keys, sorted by time, non-finite ones removed. Times in ticks.
struct NodeKeys {
  std::vector<double> tt, rt, st;
  std::vector<glm::dvec3> tv, sv;
  std::vector<glm::dquat> rv;
  bool any() const { return !tt.empty() || !rt.empty() || !st.empty(); }
};

/// One channel whose node keys are replaced by its glTF sampler.
struct GltfFix {
  int node = -1;  // graph node
  gltf::TargetPath path = gltf::TargetPath::Other;
  const gltf::Sampler* sampler = nullptr;
};

/// Per aiAnimation: the channels to resample, and those kept as Assimp's linear keys, with why.
struct GltfClip {
  std::vector<GltfFix> fixes;
  std::vector<std::string> kept;
  /// Morph weight channels, read from the file (Assimp 5.2.5 clamps negative weights and drops
  /// CUBICSPLINE tangents), each with the target names of the mesh its node holds.
  std::vector<std::pair<const gltf::Sampler*, const std::vector<std::string>*>> weights;
};

/// The file's samplers mapped onto the node graph, one GltfClip per aiAnimation.
struct GltfSamplers {
  gltf::Animations file;
  std::vector<GltfClip> clips;
};

/// Every key time of a clip, in seconds.
std::vector<double> key_times(const std::vector<NodeKeys>& keys, double tps);

/// The grid rate for a clip with resampled channels (see the definition for the rule).
float resampling_rate(const std::vector<NodeKeys>& keys, double tps, float estimated, float duration);

/// The clip's frame rate: the slowest rate whose grid holds every source key; *off_grid when none does.
float clip_sample_rate(const std::vector<double>& times, float estimated, double tps, bool* off_grid);

/// Reads the glTF file behind the scene and plans every clip; nullopt when nothing is to be resampled.
std::optional<GltfSamplers> read_gltf_samplers(const Context& ctx, const NodeGraph& graph, const Rig& rig);

/// Replaces one channel of a node's keys with the sampler evaluated on the grid and at its own keys.
void resample_gltf_channel(const GltfFix& fix, const FrameGrid& grid, float duration, double tps, NodeKeys* keys);

/// Adds `track` unless a track of that name exists; counts the differing duplicates.
void add_morph_track(SourceMorphTrack track, std::vector<SourceMorphTrack>* tracks, size_t* conflicts);

/// The glTF weight channels of one clip as morph tracks.
void gltf_morph_tracks(const GltfClip& gltf_clip, const FrameGrid& grid, float duration,
                       std::vector<SourceMorphTrack>* tracks, size_t* conflicts);

}  // namespace ossa::cook::detail
