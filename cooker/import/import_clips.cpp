// import_clips.cpp — Assimp animations -> per-joint T/R/S keys in seconds, one clip per aiAnimation.
//
// A joint's local transform is the product of the nodes in its chain (import_rig.cpp): usually
// just the joint's node, but also the `$AssimpFbx$` helpers above it, the nodes above the root, or
// in clip-only cooking the nodes the reference lacks. Keys are therefore produced two ways:
//   - copied: only the joint's own node is animated and the static part above it is identity or a
//     similarity (uniform scale, rotation, translation), which maps T, R and S keys one by one.
//     Source keys and their times survive exactly, which the compression stage's error bound and
//     round-trip tests rely on. This is every asset in the test set.
//   - resampled: otherwise the chain's product is evaluated (linear / slerp between each channel's
//     source keys, as Assimp's own evaluator does) at the union of the chain's key times and
//     decomposed. Between those times the product of interpolations is not the interpolation of the
//     product, so this is exact at the keys and approximate in between; the keys are the source's.
// Then times become seconds, strictly increasing and inside [0, duration], rotations unit and on
// the previous key's hemisphere.
//
// glTF STEP and CUBICSPLINE samplers: Assimp 5.2.5 hands their keys over as if they were LINEAR
// (STEP values as plain keys, CUBICSPLINE reduced to the value of each [in-tangent, value,
// out-tangent] triple), so both would be interpolated linearly. For a glTF source the samplers
// are read from the file itself (gltf_samplers.h) and each such channel's node keys are replaced,
// before anything above runs, by the source curve evaluated at every frame of the clip's grid and
// at its own key times. Folding into chains, the copy/resample choice and the final conversion
// then treat them like any other keys, and the compressor, which samples the grid, sees exactly
// the source's curve at every frame: a STEP holds until the frame at (or after) the next key time,
// a spline is the spline. Between frames the runtime interpolates linearly, so the grid rate
// decides how close that comes to the source; see resampling_rate() for the choice. That half is
// import_clips_gltf.cpp.
#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>
#include <iterator>
#include <map>
#include <optional>
#include <set>

#include <assimp/scene.h>

#include "cooker/import/clip_split.h"
#include "cooker/import/clips_internal.h"

namespace ossa::cook::detail {
namespace {

bool finite3(const aiVector3D& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

template <class Key, class Value, class Convert>
void take_keys(const Key* keys, unsigned count, std::vector<double>* times, std::vector<Value>* values, Convert convert,
               size_t* dropped) {
  std::vector<std::pair<double, Value>> pairs;
  pairs.reserve(count);
  for (unsigned i = 0; keys && i < count; ++i) {
    bool ok = std::isfinite(keys[i].mTime);
    Value v{};
    if (ok) ok = convert(keys[i].mValue, &v);
    if (ok) {
      pairs.emplace_back(keys[i].mTime, v);
    } else {
      ++*dropped;
    }
  }
  std::stable_sort(pairs.begin(), pairs.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
  for (const auto& [t, v] : pairs) {
    times->push_back(t);
    values->push_back(v);
  }
}

NodeKeys extract_keys(const aiNodeAnim& ch, size_t* dropped) {
  NodeKeys k;
  auto vec = [](const aiVector3D& a, glm::dvec3* out) {
    if (!finite3(a)) return false;
    *out = glm::dvec3(a.x, a.y, a.z);
    return true;
  };
  auto quat = [](const aiQuaternion& a, glm::dquat* out) {
    const glm::dquat q(a.w, a.x, a.y, a.z);
    const double len = glm::length(q);
    if (!std::isfinite(len) || len < 1e-12) return false;
    *out = q / len;
    return true;
  };
  take_keys(ch.mPositionKeys, ch.mNumPositionKeys, &k.tt, &k.tv, vec, dropped);
  take_keys(ch.mRotationKeys, ch.mNumRotationKeys, &k.rt, &k.rv, quat, dropped);
  take_keys(ch.mScalingKeys, ch.mNumScalingKeys, &k.st, &k.sv, vec, dropped);
  return k;
}

/// Index of the segment [i-1, i] holding t, and the blend factor; clamps outside the keys.
size_t segment(const std::vector<double>& times, double t, double* f) {
  const size_t i = static_cast<size_t>(std::upper_bound(times.begin(), times.end(), t) - times.begin());
  if (i == 0) {
    *f = 0.0;
    return 1;  // caller reads [0] when f == 0
  }
  if (i == times.size()) {
    *f = 1.0;
    return times.size() - 1;
  }
  *f = (t - times[i - 1]) / (times[i] - times[i - 1]);
  return i;
}

glm::dvec3 sample(const std::vector<double>& times, const std::vector<glm::dvec3>& values, double t) {
  if (times.size() == 1) return values[0];
  double f = 0.0;
  const size_t i = segment(times, t, &f);
  if (f <= 0.0) return values[i - 1];
  return glm::mix(values[i - 1], values[i], f);
}

glm::dquat sample(const std::vector<double>& times, const std::vector<glm::dquat>& values, double t) {
  if (times.size() == 1) return values[0];
  double f = 0.0;
  const size_t i = segment(times, t, &f);
  if (f <= 0.0) return values[i - 1];
  glm::dquat b = values[i];
  if (glm::dot(values[i - 1], b) < 0.0) b = -b;  // shortest arc
  return glm::normalize(glm::slerp(values[i - 1], b, f));
}

/// The node's local transform at tick t: keyed components from its keys, others from its static
/// transform.
glm::dmat4 local_at(const Node& node, const NodeKeys* keys, double t) {
  if (!keys) return node.local;
  Trs trs = decompose(node.local);
  if (!keys->tt.empty()) trs.t = sample(keys->tt, keys->tv, t);
  if (!keys->rt.empty()) trs.r = sample(keys->rt, keys->rv, t);
  if (!keys->st.empty()) trs.s = sample(keys->st, keys->sv, t);
  return compose(trs);
}

/// A track in ticks and double precision, before the final conversion.
struct RawTrack {
  std::vector<double> tt, rt, st;
  std::vector<glm::dvec3> tv, sv;
  std::vector<glm::dquat> rv;
};

/// Uniform-scale rotation+translation with positive determinant: maps keys one by one.
bool as_similarity(const glm::dmat4& f, Trs* out) {
  const glm::dmat3 a(f);
  const double s = glm::length(a[0]);
  if (!(s > 0.0) || glm::determinant(a) <= 0.0) return false;
  constexpr double kTolerance = 1e-6;  // relative; far below what float keys can tell apart
  for (int c = 0; c < 3; ++c) {
    if (std::abs(glm::length(a[c]) - s) > kTolerance * s) return false;
    for (int d = c + 1; d < 3; ++d) {
      if (std::abs(glm::dot(a[c], a[d])) > kTolerance * s * s) return false;
    }
  }
  out->t = glm::dvec3(f[3]);
  out->r = glm::normalize(glm::quat_cast(a / s));
  out->s = glm::dvec3(s);
  return true;
}

RawTrack copy_keys(const NodeKeys& k, const glm::dmat4& prefix) {
  RawTrack raw{k.tt, k.rt, k.st, k.tv, k.sv, k.rv};
  if (relative_difference(prefix, glm::dmat4(1.0)) == 0.0) return raw;
  Trs f;
  as_similarity(prefix, &f);  // checked by the caller
  for (auto& v : raw.tv) v = f.t + f.s.x * (f.r * v);
  for (auto& q : raw.rv) q = glm::normalize(f.r * q);
  for (auto& v : raw.sv) v = f.s.x * v;
  return raw;
}

RawTrack resample_chain(const NodeGraph& graph, const glm::dmat4& prefix, const std::vector<int>& chain,
                        const std::vector<const NodeKeys*>& keys_of) {
  std::vector<double> times;
  bool before_zero = false;
  for (size_t i = 0; i < chain.size(); ++i) {
    if (!keys_of[i]) continue;
    for (const auto* list : {&keys_of[i]->tt, &keys_of[i]->rt, &keys_of[i]->st}) {
      for (double t : *list) {
        if (t < 0.0) {
          before_zero = true;
        } else {
          times.push_back(t);
        }
      }
    }
  }
  if (before_zero) times.push_back(0.0);  // the clip starts at 0: its value there, not earlier
  std::sort(times.begin(), times.end());
  times.erase(std::unique(times.begin(), times.end()), times.end());
  RawTrack raw;
  for (double t : times) {
    glm::dmat4 m = prefix;
    for (size_t i = 0; i < chain.size(); ++i) m = m * local_at(graph.nodes[chain[i]], keys_of[i], t);
    const Trs trs = decompose(m);
    raw.tt.push_back(t);
    raw.tv.push_back(trs.t);
    raw.rt.push_back(t);
    raw.rv.push_back(trs.r);
    raw.st.push_back(t);
    raw.sv.push_back(trs.s);
  }
  return raw;
}

bool has_negative_time(const NodeKeys& k) {
  for (const auto* list : {&k.tt, &k.rt, &k.st}) {
    if (!list->empty() && list->front() < 0.0) return true;
  }
  return false;
}

RawTrack joint_keys(const NodeGraph& graph, const glm::dmat4& rig_prefix, const std::vector<int>& chain,
                    const std::vector<const NodeKeys*>& keys_of) {
  size_t animated = 0;
  for (const auto* k : keys_of) animated += k ? 1 : 0;
  const NodeKeys* last = keys_of.back();
  if (animated == 1 && last && !has_negative_time(*last)) {
    glm::dmat4 prefix = rig_prefix;
    for (size_t i = 0; i + 1 < chain.size(); ++i) prefix = prefix * graph.nodes[chain[i]].local;
    Trs unused;
    if (relative_difference(prefix, glm::dmat4(1.0)) == 0.0 || as_similarity(prefix, &unused)) {
      return copy_keys(*last, prefix);
    }
  }
  return resample_chain(graph, rig_prefix, chain, keys_of);
}

/// Seconds, strictly increasing in float, inside [0, duration]. Returns keys dropped as duplicates.
template <class In, class Out, class Convert>
size_t finish_channel(const std::vector<double>& ticks, const std::vector<In>& values, double tps, float duration,
                      std::vector<float>* times, std::vector<Out>* out, Convert convert) {
  size_t duplicates = 0;
  for (size_t i = 0; i < ticks.size(); ++i) {
    const float t = std::clamp(static_cast<float>(ticks[i] / tps), 0.0f, duration);
    if (!times->empty() && t <= times->back()) {
      ++duplicates;  // same time twice: keep the first, as a linear sampler would reach it first
      continue;
    }
    times->push_back(t);
    out->push_back(convert(values[i]));
  }
  return duplicates;
}

SourceTrack finish_track(const RawTrack& raw, uint16_t joint, double tps, float duration, size_t* duplicates) {
  SourceTrack track;
  track.joint = joint;
  auto vec = [](const glm::dvec3& v) { return glm::vec3(v); };
  auto quat = [](const glm::dquat& q) { return glm::normalize(glm::quat(q)); };
  *duplicates += finish_channel(raw.tt, raw.tv, tps, duration, &track.translation_times, &track.translations, vec);
  *duplicates += finish_channel(raw.rt, raw.rv, tps, duration, &track.rotation_times, &track.rotations, quat);
  *duplicates += finish_channel(raw.st, raw.sv, tps, duration, &track.scale_times, &track.scales, vec);
  for (size_t i = 1; i < track.rotations.size(); ++i) {
    if (glm::dot(track.rotations[i - 1], track.rotations[i]) < 0.0f) {
      track.rotations[i] = -track.rotations[i];
    }
  }
  return track;
}

/// Keys per second from the most common spacing between keys; 0 when no channel has two keys.
float estimate_sample_rate(const std::vector<NodeKeys>& keys, double tps) {
  std::map<long long, std::pair<size_t, double>> buckets;  // spacing in 0.1 µs -> (count, sum)
  for (const NodeKeys& k : keys) {
    for (const auto* list : {&k.tt, &k.rt, &k.st}) {
      for (size_t i = 1; i < list->size(); ++i) {
        const double d = ((*list)[i] - (*list)[i - 1]) / tps;
        if (!(d > 0.0)) continue;
        auto& b = buckets[std::llround(d * 1e7)];
        ++b.first;
        b.second += d;
      }
    }
  }
  const std::pair<size_t, double>* best = nullptr;
  for (const auto& [spacing, b] : buckets) {
    if (!best || b.first > best->first) best = &b;  // ties: the smaller spacing, seen first
  }
  if (!best) return 0.0f;
  return static_cast<float>(static_cast<double>(best->first) / best->second);
}

/// Assimp's morph channels (FBX blend shape animation; glTF's come from the file instead). Each
/// aiMeshMorphAnim names a mesh (or the node holding it); its keys list, per time, the targets
/// keyed then and their weights. Keys are merged across targets there, so each target's own keys
/// are collected (a target absent from a key has no key at that time) and interpolated alone.
void assimp_morph_tracks(const aiScene& scene, const aiAnimation& anim, double tps,
                         std::vector<SourceMorphTrack>* tracks, size_t* conflicts) {
  for (unsigned c = 0; c < anim.mNumMorphMeshChannels; ++c) {
    const aiMeshMorphAnim* ch = anim.mMorphMeshChannels[c];
    if (!ch) continue;
    const aiMesh* mesh = nullptr;
    // Assimp 5.2.5's FBX importer names the channel "<mesh>*<scene mesh index>".
    const std::string name = ch->mName.C_Str();
    const size_t star = name.rfind('*');
    if (star != std::string::npos && star + 1 < name.size() &&
        name.find_first_not_of("0123456789", star + 1) == std::string::npos && name.size() - star <= 10) {
      const unsigned long index = std::stoul(name.substr(star + 1));
      if (index < scene.mNumMeshes && scene.mMeshes[index] && scene.mMeshes[index]->mNumAnimMeshes &&
          std::string(scene.mMeshes[index]->mName.C_Str()) == name.substr(0, star))
        mesh = scene.mMeshes[index];
    }
    for (unsigned m = 0; m < scene.mNumMeshes && !mesh; ++m)
      if (scene.mMeshes[m] && scene.mMeshes[m]->mNumAnimMeshes && scene.mMeshes[m]->mName == ch->mName)
        mesh = scene.mMeshes[m];
    if (!mesh && scene.mRootNode) {
      if (const aiNode* node = scene.mRootNode->FindNode(ch->mName))
        for (unsigned i = 0; i < node->mNumMeshes && !mesh; ++i)
          if (node->mMeshes[i] < scene.mNumMeshes && scene.mMeshes[node->mMeshes[i]]->mNumAnimMeshes)
            mesh = scene.mMeshes[node->mMeshes[i]];
    }
    if (!mesh) continue;
    std::map<unsigned, SourceMorphTrack> per_target;
    for (unsigned k = 0; k < ch->mNumKeys; ++k) {
      const aiMeshMorphKey& key = ch->mKeys[k];
      const double t = key.mTime / tps;
      if (!std::isfinite(t) || !key.mValues || !key.mWeights) continue;
      for (unsigned i = 0; i < key.mNumValuesAndWeights; ++i) {
        const unsigned target = key.mValues[i];
        if (target >= mesh->mNumAnimMeshes || !std::isfinite(key.mWeights[i])) continue;
        SourceMorphTrack& track = per_target[target];
        if (!track.times.empty() && !(static_cast<float>(t) > track.times.back())) continue;
        track.times.push_back(static_cast<float>(t));
        track.weights.push_back(static_cast<float>(key.mWeights[i]));
      }
    }
    for (auto& [target, track] : per_target) {
      const aiAnimMesh* am = mesh->mAnimMeshes[target];
      track.name = am && am->mName.length ? am->mName.C_Str() : "target" + std::to_string(target);
      add_morph_track(std::move(track), tracks, conflicts);
    }
  }
}

double ticks_per_second(const Context& ctx, const aiAnimation& anim) {
  const double tps = anim.mTicksPerSecond;
  if (std::isfinite(tps) && tps > 0.0) return tps;
  // What Assimp's importers mean by 0: glTF keys are in milliseconds (Assimp's glTF2 importer
  // writes 1000 itself); FBX, Collada and the rest follow Assimp's documented default of 25.
  const double fallback = ctx.format == SourceFormat::Gltf ? 1000.0 : 25.0;
  ctx.warn("clip '" + std::string(anim.mName.C_Str()) + "' has no ticks per second, " +
           std::to_string(static_cast<int>(fallback)) + " assumed");
  return fallback;
}

std::string clip_name(const aiAnimation& anim, unsigned index, std::set<std::string>* used) {
  std::string base = anim.mName.length ? anim.mName.C_Str() : "clip" + std::to_string(index);
  std::string name = base;
  for (int n = 2; !used->insert(name).second; ++n) name = base + " (" + std::to_string(n) + ")";
  return name;
}

/// Whether a clip name says nothing about the motion: what exporters and importers invent when the
/// artist named nothing. Mixamo's "mixamo.com", 3ds Max / Maya / MotionBuilder takes ("Take 001",
/// "Unreal Take"), Blender's default "Action" (after an optional "Armature|" prefix), Assimp's own
/// "Anim_0" / "Anim_0_Armature" for unnamed glTF animations and BVH's "Motion", this cooker's
/// "clip0", and, for Collada, the name of a node in the file (Assimp names an unnamed animation
/// after the first node it moves: "Hips", "Camera01").
bool generic_clip_name(const std::string& name, const NodeGraph& graph) {
  if (name.empty() || graph.by_name.count(name)) return true;
  std::string n = name.substr(name.rfind('|') == std::string::npos ? 0 : name.rfind('|') + 1);
  for (char& c : n) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (graph.by_name.count(n)) return true;
  // A generic word, then an optional separator and number: "take 001", "take_1", "action.001".
  static const char* const kWords[] = {"mixamo.com", "take",           "unreal take", "default take", "default",
                                       "action",     "armatureaction", "animation",   "anim",         "clip",
                                       "motion",     "scene",          "animstack",   "base layer",   "globalshape"};
  for (const char* word : kWords) {
    const std::string w(word);
    if (n.compare(0, w.size(), w) != 0) continue;
    size_t i = w.size();
    if (i < n.size() && (n[i] == ' ' || n[i] == '_' || n[i] == '.' || n[i] == '-')) ++i;
    size_t digits = i;
    while (digits < n.size() && std::isdigit(static_cast<unsigned char>(n[digits]))) ++digits;
    if (digits == n.size() && (digits > i || i == w.size())) return true;
    // Assimp's glTF names: "anim_<index>_<node>".
    if (w == "anim" && digits > i && digits < n.size() && n[digits] == '_') return true;
  }
  return false;
}

/// Clips to name in the per-file warnings (one line each, however many clips a file has).
struct ClipSummary {
  std::vector<std::string> morphs, empty;
};

std::string join(const std::vector<std::string>& names) {
  std::string out;
  for (size_t i = 0; i < names.size(); ++i) out += (i ? ", " : "") + names[i];
  return out;
}

/// Every channel's keys, indexed by node; a node animated twice in one clip keeps its first.
struct ClipKeys {
  std::vector<NodeKeys> keys;
  std::vector<int> node_keys;  // per node: index into keys, or -1
  double end_ticks = 0.0;      // the later of the stated duration and the last key
  size_t non_finite = 0, twice = 0;
};

ClipKeys collect_keys(const NodeGraph& graph, const aiAnimation& anim) {
  ClipKeys out;
  out.node_keys.assign(graph.nodes.size(), -1);
  out.end_ticks = std::isfinite(anim.mDuration) ? std::max(0.0, anim.mDuration) : 0.0;
  const std::vector<int> nodes = channel_nodes(graph, anim);
  for (unsigned c = 0; c < anim.mNumChannels; ++c) {
    const aiNodeAnim* ch = anim.mChannels[c];
    if (!ch) continue;
    const int n = nodes[c];
    if (n < 0) continue;  // warned once per file by the rig stage
    if (out.node_keys[n] >= 0) {
      ++out.twice;
      continue;
    }
    NodeKeys k = extract_keys(*ch, &out.non_finite);
    if (!k.any()) continue;
    for (const auto* list : {&k.tt, &k.rt, &k.st}) {
      if (!list->empty()) out.end_ticks = std::max(out.end_ticks, list->back());
    }
    out.node_keys[n] = static_cast<int>(out.keys.size());
    out.keys.push_back(std::move(k));
  }
  return out;
}

/// A joint held at its node pose (Rig::rest) for the whole clip: one key per channel at time 0.
SourceTrack rest_track(const Rig& rig, uint16_t joint) {
  const Trs& r = rig.rest[joint];
  SourceTrack t;
  t.joint = joint;
  t.translation_times = {0.0f};
  t.translations = {glm::vec3(r.t)};
  t.rotation_times = {0.0f};
  t.rotations = {glm::normalize(glm::quat(r.r))};
  t.scale_times = {0.0f};
  t.scales = {glm::vec3(r.s)};
  return t;
}

/// One track per joint whose chain carries keys, in joint order (and, where the bind pose is the
/// skins' and not the node pose, one per other joint holding the node pose).
std::vector<SourceTrack> joint_tracks(const NodeGraph& graph, const Rig& rig, const ClipKeys& keys, double tps,
                                      float duration, size_t* duplicates) {
  std::vector<SourceTrack> tracks;
  for (size_t j = 0; j < rig.chain.size(); ++j) {
    const auto& chain = rig.chain[j];
    std::vector<const NodeKeys*> keys_of(chain.size(), nullptr);
    bool animated = false;
    for (size_t i = 0; i < chain.size(); ++i) {
      if (keys.node_keys[chain[i]] >= 0) {
        keys_of[i] = &keys.keys[keys.node_keys[chain[i]]];
        animated = true;
      }
    }
    if (!animated) {
      if (!rig.rest.empty()) tracks.push_back(rest_track(rig, static_cast<uint16_t>(j)));
      continue;
    }
    const RawTrack raw = joint_keys(graph, rig.prefix[j], chain, keys_of);
    tracks.push_back(finish_track(raw, static_cast<uint16_t>(j), tps, duration, duplicates));
    if (!rig.rest.empty()) {  // channels the clip does not key stay at the node pose too
      const SourceTrack rest = rest_track(rig, static_cast<uint16_t>(j));
      SourceTrack& t = tracks.back();
      if (t.translations.empty()) t.translation_times = rest.translation_times, t.translations = rest.translations;
      if (t.rotations.empty()) t.rotation_times = rest.rotation_times, t.rotations = rest.rotations;
      if (t.scales.empty()) t.scale_times = rest.scale_times, t.scales = rest.scales;
    }
  }
  return tracks;
}

SourceClip import_clip(const Context& ctx, const NodeGraph& graph, const Rig& rig, const aiAnimation& anim,
                       unsigned index, const GltfClip* gltf_clip, std::set<std::string>* names, ClipSummary* summary) {
  SourceClip clip;
  clip.name = clip_name(anim, index, names);
  if (clip.name != std::string(anim.mName.C_Str()) && anim.mName.length) {
    ctx.warn("clip name '" + std::string(anim.mName.C_Str()) + "' is used twice, renamed '" + clip.name + "'");
  }
  const double tps = ticks_per_second(ctx, anim);
  ClipKeys keys = collect_keys(graph, anim);
  clip.duration = static_cast<float>(keys.end_ticks / tps);
  size_t conflicts = 0;
  if (!gltf_clip && ctx.format != SourceFormat::Gltf) {
    assimp_morph_tracks(*ctx.scene, anim, tps, &clip.morph_weights, &conflicts);
    for (const SourceMorphTrack& t : clip.morph_weights) clip.duration = std::max(clip.duration, t.times.back());
  }
  const std::string label = "clip '" + clip.name + "': ";
  bool off_grid = false;
  clip.sample_rate = clip_sample_rate(key_times(keys.keys, tps), estimate_sample_rate(keys.keys, tps), tps, &off_grid);
  if (off_grid) {
    ctx.warn(label + "keys are not on any uniform frame grid; resampled at " + std::to_string(clip.sample_rate) +
             " frames per second");
  }
  // Weight keys past the joints' last key lengthen the clip.
  if (gltf_clip)
    for (const auto& w : gltf_clip->weights) clip.duration = std::max(clip.duration, w.first->times.back());
  if (gltf_clip && !gltf_clip->fixes.empty()) {
    // The rate first (from the source's own key times), then the keys on that grid.
    clip.sample_rate = resampling_rate(keys.keys, tps, clip.sample_rate, clip.duration);
    const FrameGrid grid = frame_grid(clip);
    for (const GltfFix& fix : gltf_clip->fixes) {
      const int k = keys.node_keys[static_cast<size_t>(fix.node)];
      if (k < 0) continue;  // Assimp gave the node no channel: nothing is animated there to fix
      resample_gltf_channel(fix, grid, clip.duration, tps, &keys.keys[static_cast<size_t>(k)]);
    }
  }
  if (gltf_clip && !gltf_clip->kept.empty()) {
    ctx.warn(label + "glTF STEP / CUBICSPLINE channels kept as Assimp's linear keys: " + join(gltf_clip->kept));
  }
  size_t duplicates = 0;
  clip.tracks = joint_tracks(graph, rig, keys, tps, clip.duration, &duplicates);
  if (keys.non_finite) ctx.warn(label + std::to_string(keys.non_finite) + " non-finite keys dropped");
  if (keys.twice) {
    ctx.warn(label + std::to_string(keys.twice) + " nodes have two channels, the second is dropped");
  }
  if (duplicates) {
    ctx.warn(label + std::to_string(duplicates) + " keys at a time already keyed are dropped");
  }
  if (gltf_clip) gltf_morph_tracks(*gltf_clip, frame_grid(clip), clip.duration, &clip.morph_weights, &conflicts);
  std::sort(clip.morph_weights.begin(), clip.morph_weights.end(),
            [](const SourceMorphTrack& a, const SourceMorphTrack& b) { return a.name < b.name; });
  if (conflicts) {
    ctx.warn(label + std::to_string(conflicts) +
             " morph weight curves differ from another curve for a target of the same name; the first is kept");
  }
  if (anim.mNumMeshChannels || (anim.mNumMorphMeshChannels && clip.morph_weights.empty()))
    summary->morphs.push_back(clip.name);
  if (clip.tracks.empty() && clip.morph_weights.empty()) summary->empty.push_back(clip.name);
  return clip;
}

}  // namespace

std::vector<SourceClip> import_clips(const Context& ctx, const NodeGraph& graph, const Rig& rig) {
  std::vector<SourceClip> clips;
  const aiScene& scene = *ctx.scene;
  // Without joints only morph weights can be animated (a blend-shape face with no skeleton): such
  // clips are kept with no joint tracks, the others dropped below.
  const bool no_joints = rig.skeleton.joints.empty();
  std::optional<GltfSamplers> gltf_samplers;
  if (ctx.format == SourceFormat::Gltf && scene.mNumAnimations) {
    gltf_samplers = read_gltf_samplers(ctx, graph, rig);
  }
  std::set<std::string> names;
  ClipSummary summary;
  for (unsigned a = 0; a < scene.mNumAnimations; ++a) {
    if (!scene.mAnimations[a]) continue;
    const GltfClip* gltf_clip = gltf_samplers ? &gltf_samplers->clips[a] : nullptr;
    clips.push_back(import_clip(ctx, graph, rig, *scene.mAnimations[a], a, gltf_clip, &names, &summary));
  }
  if (no_joints) {
    const size_t before = clips.size();
    clips.erase(std::remove_if(clips.begin(), clips.end(), [](const SourceClip& c) { return c.morph_weights.empty(); }),
                clips.end());
    summary.empty.clear();  // said here instead
    if (clips.size() < before)
      ctx.warn(std::to_string(before - clips.size()) +
               " animations are dropped: they animate nothing that is a joint or a morph target");
  }
  // A file's single clip is its motion: with a generic source name it takes the file's stem, so a
  // library of Mixamo exports is not a library of clips all named "mixamo.com". The source name is
  // kept (SourceClip::source_name) so sidecars, settings and graph files may still use it.
  if (clips.size() == 1 && generic_clip_name(clips[0].name, graph)) {
    const std::string stem = std::filesystem::path(ctx.path).stem().string();
    if (!stem.empty() && stem != clips[0].name) {
      ctx.warn("clip '" + clips[0].name + "' is named '" + stem + "' after the file (its source name is generic)");
      clips[0].source_name = clips[0].name;
      clips[0].name = stem;
    }
  }
  // A clip longer than the 65,536 frames one clip can address is cooked as consecutive parts
  // (clip_split.h) rather than refused or resampled coarser.
  std::vector<SourceClip> fitted;
  for (SourceClip& clip : clips) {
    const std::string split = split_long_clip(std::move(clip), &fitted);
    if (!split.empty()) ctx.warn(split);
  }
  clips = std::move(fitted);
  if (!summary.morphs.empty()) {
    ctx.warn("mesh channels, and morph channels for targets no mesh holds, are dropped from clips: " +
             join(summary.morphs));
  }
  if (!summary.empty.empty()) ctx.warn("clips that animate no joint: " + join(summary.empty));
  return clips;
}

}  // namespace ossa::cook::detail
