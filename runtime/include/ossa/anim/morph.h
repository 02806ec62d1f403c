// morph.h — morph targets (blend shapes): weights sampled from clips, blended like poses, and
// applied to a mesh's vertices on the CPU.
//
// Weights live in one float array per character, indexed by *channel*: a name the host chose to
// drive (usually every distinct target name over the character's meshes, collect_morph_channels).
// Binding by name, once at load, is what lets a face clip cooked from another file drive this
// character's targets, lets several meshes (a head split by material) share one "smile", and keeps
// the per-frame work to indexed loads: sample_morph_weights writes channels, blend_morph_weights
// crossfades two channel arrays the way blend poses crossfade joints, and apply_morphs reads them.
//
// apply_morphs is the reference the GPU path is tested against: a sparse accumulate over each
// active target's listed vertices (the cooker stored only the vertices a target moves), in the
// mesh's own vertex order, allocation-free. It adds to positions the caller decoded (and normals,
// tangents when given); skinning then runs on the morphed vertices, as glTF specifies.
//
// Every function validates its spans and returns false (writing nothing) when one is too small.
#pragma once
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include <glm/glm.hpp>

#include <ossa/loader/asset.h>

namespace ossa {

/// Appends to `channels` the names of the mesh's targets not already there, in the mesh's order.
/// Load time (allocates). O(targets * channels).
void collect_morph_channels(const MeshView& mesh, std::vector<std::string_view>& channels);

/// target_channel[t] = index in `channels` of the mesh's target t, or -1. Load time. O(targets *
/// channels). target_channel.size() must be >= mesh.morph_target_count().
bool bind_morph_targets(const MeshView& mesh, std::span<const std::string_view> channels,
                        std::span<int32_t> target_channel);

/// track_channel[k] = index in `channels` of the clip's weight track k, or -1 (a track for a target
/// this character lacks is ignored). Load time. track_channel.size() must be >= morph_track_count().
bool bind_morph_tracks(const ClipView& clip, std::span<const std::string_view> channels,
                       std::span<int32_t> track_channel);

/// weights[c] = the default weight of the first of the mesh's targets bound to channel c. Call it
/// for each mesh, then let clips overwrite what they drive. O(targets).
bool default_morph_weights(const MeshView& mesh, std::span<const int32_t> target_channel, std::span<float> weights);

/// One weight track's value at `time` seconds (clamped to the clip), linear between keys. O(log keys).
float sample_morph_track(const ClipView& clip, const fb::MorphTrack& track, float time);

/// weights[track_channel[k]] = clip's track k at `time`, for every bound track; channels no track
/// drives keep their values. O(tracks * log keys), no allocation.
bool sample_morph_weights(const ClipView& clip, float time, std::span<const int32_t> track_channel,
                          std::span<float> weights);

/// out[c] = a[c] + (b[c] - a[c]) * t: a crossfade or blend-space step, as for poses. out may alias
/// a or b. O(channels).
bool blend_morph_weights(std::span<const float> a, std::span<const float> b, float t, std::span<float> out);

/// Adds, for each of the mesh's targets t with a weight w = weights[target_channel[t]] that is not
/// 0, w times its deltas to positions[v] (normals[v], tangents[v] when those spans are not empty)
/// of each vertex v it lists. Spans hold one element per mesh vertex, in the mesh's vertex order.
/// Normals and tangents are not renormalized (skinning, or the caller, normalizes). Cost: O(listed
/// vertices of the active targets); no allocation.
bool apply_morphs(const MeshView& mesh, std::span<const int32_t> target_channel, std::span<const float> weights,
                  std::span<glm::vec3> positions, std::span<glm::vec3> normals = {},
                  std::span<glm::vec3> tangents = {});

}  // namespace ossa
