// import_clips_gltf.cpp — the glTF samplers Assimp 5.2.5 mishandles, and a clip's frame rate.
//
// Assimp hands STEP and CUBICSPLINE keys over as if they were LINEAR (STEP values as plain keys,
// CUBICSPLINE reduced to the value of each [in-tangent, value, out-tangent] triple) and clamps
// negative morph weights. For a glTF source the samplers are read from the file itself
// (gltf_samplers.h), mapped onto the node graph by walking both trees together, and each such
// channel's node keys are replaced by the source curve evaluated at every frame of the clip's grid
// and at its own key times (import_clips.cpp then treats them like any other keys). The grid's rate
// is chosen here too: the slowest rate whose grid holds every source key.
#include <algorithm>
#include <cmath>
#include <iterator>
#include <optional>
#include <set>
#include <string>
#include <utility>
#include <vector>

#include <assimp/scene.h>

#include "cooker/import/clips_internal.h"

namespace ossa::cook::detail {
namespace {

/// The slowest grid that STEP and CUBICSPLINE channels are resampled on. One frame at 60 Hz is one
/// display frame: a STEP becomes a 16.7 ms ramp at worst (none when its key lies on the grid, see
/// resampling_rate), and a spline's chord error between frames is h²/8 · |p''| with h = 1/60 s.
constexpr double kMinResampleRate = 60.0;
/// Frame rates exporters key at, tried when the clip's own estimate does not hold every key.
constexpr double kCommonRates[] = {24.0, 25.0, 30.0, 48.0, 50.0, 60.0, 100.0, 120.0};

/// True when every key time (seconds) lies on a grid of `rate` frames per second, to a
/// thousandth of a frame plus what float key times can hold.
bool keys_on_grid(const std::vector<double>& times, double rate) {
  for (double t : times) {
    const double frame = t * rate;
    const double slack = 1e-3 + 4.0 * std::abs(frame) * 1.2e-7;  // float times: ~2^-23 relative
    if (std::abs(frame - std::round(frame)) > slack) return false;
  }
  return true;
}

}  // namespace

/// Every key time of a clip, in seconds.
std::vector<double> key_times(const std::vector<NodeKeys>& keys, double tps) {
  std::vector<double> times;
  for (const NodeKeys& k : keys) {
    for (const auto* list : {&k.tt, &k.rt, &k.st}) {
      for (double t : *list) times.push_back(t / tps);
    }
  }
  return times;
}

/// The grid rate for a clip with resampled channels: the smallest multiple of the rate its keys
/// were made at (the clip's own estimate, else a common frame rate holding every key) that is at
/// least kMinResampleRate, so every source key, and so every STEP jump, falls on a frame; when no
/// rate holds them all, max(estimate, kMinResampleRate). Lowered (keeping a multiple where there is
/// one) when the clip would need more than kMaxFrames frames, never below the estimate.
float resampling_rate(const std::vector<NodeKeys>& keys, double tps, float estimated, float duration) {
  const std::vector<double> times = key_times(keys, tps);
  double base = 0.0;
  if (estimated > 0.0f && keys_on_grid(times, estimated)) base = estimated;
  for (size_t i = 0; base == 0.0 && i < std::size(kCommonRates); ++i) {
    if (keys_on_grid(times, kCommonRates[i])) base = kCommonRates[i];
  }
  double rate =
      base > 0.0 ? base * std::ceil(kMinResampleRate / base - 1e-9) : std::max<double>(estimated, kMinResampleRate);
  const double fit = duration > 0.0f ? static_cast<double>(kMaxFrames - 1) / duration : rate;
  if (rate > fit) {
    const double lowered = base > 0.0 && fit >= base ? base * std::floor(fit / base) : fit;
    rate = std::max<double>(lowered, estimated);
  }
  const double whole = std::round(rate);  // 2.4f * 25 is 60.000004: say 60
  if (std::abs(rate - whole) < 1e-5 * rate) rate = whole;
  return static_cast<float>(rate);
}

/// The clip's frame rate: the slowest rate whose grid holds every source key, so that cooking on
/// that grid (cooker/model/clip_grid.h) loses no key. The most common key spacing is only a first guess:
/// Pab's jog keys most channels every 1/15 s but some every 1/30 s, and a BVH's "Frame Time:
/// 0.0083333" is not exactly 120 Hz. Candidates, slowest first among: the estimate rounded to a
/// whole rate, the estimate as measured, their multiples up to 8x, and the common exporter rates
/// and their doubles. When none holds every key (irregular keys), the estimate is kept and the
/// keys are resampled at the faster of the estimate and the file's own frame rate; *off_grid says
/// so. FBX and BVH state a frame rate (Assimp's ticks per second: 30 for Pab, 1 / Frame Time for a
/// BVH); glTF's 1000 ticks per second is a time unit, not a rate, so only rates up to 240 count.
/// Pab's FBX clips are such a case: Assimp merges each curve's own key times, which lie on no grid,
/// and the file's 30 fps is what ozz-animation samples them at too. 0 when there is no estimate
/// (fewer than two keys).
float clip_sample_rate(const std::vector<double>& times, float estimated, double tps, bool* off_grid) {
  *off_grid = false;
  if (!(estimated > 0.0f)) return 0.0f;
  const double raw = estimated;
  const double whole = std::round(raw);
  const double file_rate = tps > 1.0 && tps <= 240.0 ? tps : 0.0;
  std::vector<double> candidates;
  if (file_rate > 0.0) candidates.push_back(file_rate);
  for (int k = 1; k <= 8; ++k) {
    if (whole > 0.0) candidates.push_back(whole * k);
    candidates.push_back(raw * k);
  }
  for (double r : kCommonRates) {
    candidates.push_back(r);
    candidates.push_back(2.0 * r);
  }
  std::stable_sort(candidates.begin(), candidates.end());
  // No cap from the 65,536 frames one clip can address: a longer clip is cooked in parts
  // (clip_split.h), never resampled off its keys' grid to fit.
  for (double r : candidates) {
    if (r + 1e-9 < raw * 0.999) continue;  // never coarser than the keys' own spacing
    // A whole rate within a thousandth wins over the measured 23.99997 it was estimated as.
    const double rounded = std::round(r);
    if (rounded > 0.0 && std::abs(rounded - r) < 1e-3 * r && keys_on_grid(times, rounded))
      return static_cast<float>(rounded);
    if (keys_on_grid(times, r)) return static_cast<float>(r);
  }
  *off_grid = true;
  return static_cast<float>(std::max(std::abs(raw - whole) < 1e-3 * raw ? whole : raw, file_rate));
}

namespace {

const char* path_name(gltf::TargetPath p) {
  switch (p) {
    case gltf::TargetPath::Translation: return "translation";
    case gltf::TargetPath::Rotation: return "rotation";
    case gltf::TargetPath::Scale: return "scale";
    default: return "other";
  }
}

/// glTF node -> graph node (-1 when unmatched). Assimp 5.2.5 builds its tree from the imported
/// scene (gltf::Animations::scene_roots): the single root node is the aiScene root, several roots
/// hang in order under a node it adds ("ROOT"), children keep the file's order, and each node is
/// named as gltf::assimp_node_name says. Walking both trees together and accepting a pair only when
/// name and child count agree matches nodes by position, which names alone cannot (glTF names
/// need not be unique), and matches nothing where Assimp's tree differs from the file.
std::vector<int> match_gltf_nodes(const gltf::Animations& file, const NodeGraph& graph) {
  std::vector<int> node_of(file.nodes.size(), -1);
  std::vector<std::vector<int>> children(graph.nodes.size());
  for (size_t n = 1; n < graph.nodes.size(); ++n) {
    // Depth-first order gives a node's children increasing indices in their source order.
    if (graph.nodes[n].parent >= 0) children[graph.nodes[n].parent].push_back(static_cast<int>(n));
  }
  std::vector<std::pair<int, int>> pending;  // (glTF node, graph node)
  if (graph.nodes.empty()) return node_of;
  if (file.scene_roots.size() == 1) {
    pending.emplace_back(file.scene_roots[0], 0);
  } else if (children[0].size() == file.scene_roots.size()) {
    for (size_t i = 0; i < file.scene_roots.size(); ++i) {
      pending.emplace_back(file.scene_roots[i], children[0][i]);
    }
  }
  std::vector<bool> used(graph.nodes.size(), false);
  while (!pending.empty()) {
    const auto [n, g] = pending.back();
    pending.pop_back();
    if (n < 0 || used[g]) continue;
    const gltf::Node& node = file.nodes[static_cast<size_t>(n)];
    if (graph.nodes[g].name != gltf::assimp_node_name(file, n) || children[g].size() != node.children.size()) {
      continue;
    }
    used[g] = true;
    // A node listed twice (not a tree, against the spec) has two aiNodes: keep the first.
    if (node_of[static_cast<size_t>(n)] < 0) node_of[static_cast<size_t>(n)] = g;
    for (size_t c = 0; c < node.children.size(); ++c) {
      pending.emplace_back(node.children[c], children[g][c]);
    }
  }
  return node_of;
}

/// Which channels of one glTF animation to resample. Only channels that move a joint (a node on
/// some joint's chain), that step or curve in a way Assimp's linear keys do not already give, and
/// whose keys could be read.
GltfClip plan_gltf_clip(const gltf::Animations& file, const gltf::Animation& anim, const std::vector<int>& node_of,
                        const NodeGraph& graph, const std::vector<bool>& on_chain) {
  GltfClip out;
  // (node, path): a second channel on the same target is ignored.
  std::set<std::pair<int, int>> seen;
  for (const gltf::Channel& ch : anim.channels) {
    if (ch.node < 0 || ch.sampler < 0 || ch.path == gltf::TargetPath::Other) continue;
    const gltf::Sampler& s = anim.samplers[static_cast<size_t>(ch.sampler)];
    if (ch.path == gltf::TargetPath::Weights) {
      const int mesh = file.nodes[static_cast<size_t>(ch.node)].mesh;
      if (!s.error.empty()) {
        std::string note = "'";  // appended: "'" + std::string&& trips GCC 12's false -Wrestrict at -O3
        note += gltf::assimp_node_name(file, ch.node);
        note += "' weights dropped (" + s.error + ")";
        out.kept.push_back(std::move(note));
      } else if (mesh >= 0 && !s.times.empty()) {
        out.weights.emplace_back(&s, &file.meshes[static_cast<size_t>(mesh)].names);
      }
      continue;
    }
    if (s.interpolation == gltf::Interpolation::Linear && s.error.empty()) continue;
    if (!seen.insert({ch.node, static_cast<int>(ch.path)}).second) continue;
    const std::string name = gltf::assimp_node_name(file, ch.node);
    const std::string what = "'" + name + "' " + path_name(ch.path);
    const int g = node_of[static_cast<size_t>(ch.node)];
    if (g < 0) {
      // A node of another scene is not imported at all (the rig stage names it); otherwise
      // Assimp's tree differs from the file's here and the keys cannot be placed with certainty.
      if (graph.by_name.count(name)) {
        out.kept.push_back(what + " (Assimp's node tree differs from the file's)");
      }
      continue;
    }
    if (!on_chain[static_cast<size_t>(g)]) continue;
    if (!s.error.empty()) {
      out.kept.push_back(what + " (" + s.error + ")");
      continue;
    }
    if (s.width != (ch.path == gltf::TargetPath::Rotation ? 4 : 3)) {
      out.kept.push_back(what + " (the sampler's output has " + std::to_string(s.width) + " components)");
      continue;
    }
    if (graph.resolve(name) != g) {
      // Channels are bound to nodes by name (collect_keys): with a repeated name Assimp's keys may
      // sit on another node, so replacing this node's keys could move the wrong one.
      out.kept.push_back(what + " (the node's name is not unique)");
      continue;
    }
    if (gltf::is_linear_equivalent(s)) continue;
    out.fixes.push_back({g, ch.path, &s});
  }
  return out;
}

}  // namespace

/// Reads the glTF file behind the scene and plans every clip; nullopt (with a warning when the
/// file has STEP or CUBICSPLINE samplers or cannot be read) when nothing is to be resampled.
std::optional<GltfSamplers> read_gltf_samplers(const Context& ctx, const NodeGraph& graph, const Rig& rig) {
  Result<gltf::Animations> file = gltf::read_gltf_animations(ctx.path);
  const std::string fallback = ": STEP and CUBICSPLINE samplers, if any, are interpolated linearly";
  if (!file) {
    ctx.warn("glTF samplers not read (" + file.error().message + ")" + fallback);
    return std::nullopt;
  }
  bool any_weights = false;
  for (const gltf::Animation& anim : file->animations)
    for (const gltf::Channel& ch : anim.channels) any_weights = any_weights || ch.path == gltf::TargetPath::Weights;
  if (!file->any_nonlinear && !any_weights) return std::nullopt;
  const aiScene& scene = *ctx.scene;
  if (file->animations.size() != scene.mNumAnimations) {
    ctx.warn("the file has " + std::to_string(file->animations.size()) + " animations, Assimp " +
             std::to_string(scene.mNumAnimations) + fallback);
    return std::nullopt;
  }
  GltfSamplers out;
  out.file = std::move(*file);
  std::vector<bool> on_chain(graph.nodes.size(), false);
  for (const auto& chain : rig.chain) {
    for (int c : chain) on_chain[static_cast<size_t>(c)] = true;
  }
  const std::vector<int> node_of = match_gltf_nodes(out.file, graph);
  out.clips.resize(scene.mNumAnimations);
  for (unsigned a = 0; a < scene.mNumAnimations; ++a) {
    const gltf::Animation& anim = out.file.animations[a];
    if (!scene.mAnimations[a]) continue;
    if (anim.name != scene.mAnimations[a]->mName.C_Str()) {
      // Assimp keeps the file's order and names; if not, the animations cannot be paired.
      out.clips[a].kept.push_back("all (the file's animation " + std::to_string(a) + " is named '" + anim.name + "')");
      continue;
    }
    out.clips[a] = plan_gltf_clip(out.file, anim, node_of, graph, on_chain);
  }
  return out;
}

/// Replaces one channel of a node's keys with the sampler evaluated at every frame of the grid and
/// at its own key times, all inside [0, duration]; times in ticks.
void resample_gltf_channel(const GltfFix& fix, const FrameGrid& grid, float duration, double tps, NodeKeys* keys) {
  const gltf::Sampler& s = *fix.sampler;
  // A ten-thousandth of a frame: far below any real spacing, far above float rounding of a time.
  const double snap = 1e-4 / grid.sample_rate;
  const double end = static_cast<double>(duration) + snap;
  std::vector<double> times;
  for (uint32_t f = 0; f < grid.frame_count && grid.time(f) <= end; ++f) {
    times.push_back(grid.time(f));
  }
  for (float t : s.times) {
    if (t >= 0.0f && t <= duration) times.push_back(t);
  }
  std::sort(times.begin(), times.end());
  std::vector<double> unique;
  for (double t : times) {
    if (unique.empty() || t - unique.back() > snap) unique.push_back(t);  // keeps the frame's time
  }
  std::vector<double>* out_times = fix.path == gltf::TargetPath::Translation ? &keys->tt
                                   : fix.path == gltf::TargetPath::Rotation  ? &keys->rt
                                                                             : &keys->st;
  out_times->clear();
  std::vector<glm::dvec3>* out_vec = fix.path == gltf::TargetPath::Translation ? &keys->tv : &keys->sv;
  if (fix.path == gltf::TargetPath::Rotation) {
    keys->rv.clear();
  } else {
    out_vec->clear();
  }
  for (double t : unique) {
    double v[4] = {0.0, 0.0, 0.0, 0.0};
    gltf::evaluate(s, t, snap, v);
    if (fix.path == gltf::TargetPath::Rotation) {
      const glm::dquat q(v[3], v[0], v[1], v[2]);  // glTF stores (x, y, z, w)
      const double len = glm::length(q);
      if (!(len > 0.5)) {
        continue;  // a spline through zero: no rotation to give, the neighbours hold
      }
      keys->rv.push_back(q / len);
    } else {
      out_vec->push_back(glm::dvec3(v[0], v[1], v[2]));
    }
    out_times->push_back(t * tps);
  }
}

/// Adds `track` unless a track of that name exists (several meshes of one head, each animated by
/// its own node, usually carry the same curve); counts the differing duplicates.
void add_morph_track(SourceMorphTrack track, std::vector<SourceMorphTrack>* tracks, size_t* conflicts) {
  for (const SourceMorphTrack& t : *tracks) {
    if (t.name != track.name) continue;
    if (t.times != track.times || t.weights != track.weights) ++*conflicts;
    return;
  }
  tracks->push_back(std::move(track));
}

/// The glTF weight channels of one clip as morph tracks: LINEAR keys as stored; STEP and
/// CUBICSPLINE evaluated at every frame of the grid and at their own key times.
void gltf_morph_tracks(const GltfClip& gltf_clip, const FrameGrid& grid, float duration,
                       std::vector<SourceMorphTrack>* tracks, size_t* conflicts) {
  const double snap = 1e-4 / grid.sample_rate;
  for (const auto& [sampler, names] : gltf_clip.weights) {
    const gltf::Sampler& s = *sampler;
    std::vector<double> times;
    if (s.interpolation == gltf::Interpolation::Linear) {
      times.assign(s.times.begin(), s.times.end());
    } else {
      for (uint32_t f = 0; f < grid.frame_count && grid.time(f) <= duration + snap; ++f) times.push_back(grid.time(f));
      for (float t : s.times)
        if (t >= 0.0f && t <= duration) times.push_back(t);
      std::sort(times.begin(), times.end());
      std::vector<double> unique;
      for (double t : times)
        if (unique.empty() || t - unique.back() > snap) unique.push_back(t);
      times = std::move(unique);
    }
    std::vector<double> value(static_cast<size_t>(s.width));
    std::vector<SourceMorphTrack> per_target(names->size());
    for (size_t i = 0; i < names->size(); ++i) per_target[i].name = (*names)[i];
    for (double t : times) {
      gltf::evaluate(s, t, snap, value.data());
      for (size_t i = 0; i < names->size() && i < value.size(); ++i) {
        per_target[i].times.push_back(static_cast<float>(t));
        per_target[i].weights.push_back(static_cast<float>(value[i]));
      }
    }
    for (SourceMorphTrack& track : per_target)
      if (!track.times.empty()) add_morph_track(std::move(track), tracks, conflicts);
  }
}

}  // namespace ossa::cook::detail
