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
#include <algorithm>
#include <cmath>
#include <map>
#include <set>

#include <assimp/scene.h>

#include "cooker/import_internal.h"

namespace ossa::cook::detail {
namespace {

/// One node's keys, sorted by time, non-finite ones removed. Times in ticks.
struct NodeKeys {
  std::vector<double> tt, rt, st;
  std::vector<glm::dvec3> tv, sv;
  std::vector<glm::dquat> rv;
  bool any() const { return !tt.empty() || !rt.empty() || !st.empty(); }
};

bool finite3(const aiVector3D& v) {
  return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z);
}

template <class Key, class Value, class Convert>
void take_keys(const Key* keys, unsigned count, std::vector<double>* times, std::vector<Value>* values,
               Convert convert, size_t* dropped) {
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
  std::stable_sort(pairs.begin(), pairs.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
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

RawTrack resample_chain(const NodeGraph& graph, const glm::dmat4& prefix,
                        const std::vector<int>& chain, const std::vector<const NodeKeys*>& keys_of) {
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

RawTrack joint_keys(const NodeGraph& graph, const glm::dmat4& rig_prefix,
                    const std::vector<int>& chain, const std::vector<const NodeKeys*>& keys_of) {
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
size_t finish_channel(const std::vector<double>& ticks, const std::vector<In>& values, double tps,
                      float duration, std::vector<float>* times, std::vector<Out>* out,
                      Convert convert) {
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

SourceTrack finish_track(const RawTrack& raw, uint16_t joint, double tps, float duration,
                         size_t* duplicates) {
  SourceTrack track;
  track.joint = joint;
  auto vec = [](const glm::dvec3& v) { return glm::vec3(v); };
  auto quat = [](const glm::dquat& q) { return glm::normalize(glm::quat(q)); };
  *duplicates += finish_channel(raw.tt, raw.tv, tps, duration, &track.translation_times,
                                &track.translations, vec);
  *duplicates += finish_channel(raw.rt, raw.rv, tps, duration, &track.rotation_times,
                                &track.rotations, quat);
  *duplicates += finish_channel(raw.st, raw.sv, tps, duration, &track.scale_times, &track.scales,
                                vec);
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
  double rate = static_cast<double>(best->first) / best->second;
  const double whole = std::round(rate);
  if (whole > 0.0 && std::abs(rate - whole) < 1e-3 * rate) rate = whole;
  return static_cast<float>(rate);
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
  for (unsigned c = 0; c < anim.mNumChannels; ++c) {
    const aiNodeAnim* ch = anim.mChannels[c];
    if (!ch) continue;
    const int n = graph.resolve(ch->mNodeName.C_Str());
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

/// One track per joint whose chain carries keys, in joint order.
std::vector<SourceTrack> joint_tracks(const NodeGraph& graph, const Rig& rig, const ClipKeys& keys,
                                      double tps, float duration, size_t* duplicates) {
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
    if (!animated) continue;
    const RawTrack raw = joint_keys(graph, rig.prefix[j], chain, keys_of);
    tracks.push_back(finish_track(raw, static_cast<uint16_t>(j), tps, duration, duplicates));
  }
  return tracks;
}

SourceClip import_clip(const Context& ctx, const NodeGraph& graph, const Rig& rig,
                       const aiAnimation& anim, unsigned index, std::set<std::string>* names,
                       ClipSummary* summary) {
  SourceClip clip;
  clip.name = clip_name(anim, index, names);
  if (clip.name != std::string(anim.mName.C_Str()) && anim.mName.length) {
    ctx.warn("clip name '" + std::string(anim.mName.C_Str()) + "' is used twice, renamed '" +
             clip.name + "'");
  }
  const double tps = ticks_per_second(ctx, anim);
  const ClipKeys keys = collect_keys(graph, anim);
  clip.duration = static_cast<float>(keys.end_ticks / tps);
  clip.sample_rate = estimate_sample_rate(keys.keys, tps);
  size_t duplicates = 0;
  clip.tracks = joint_tracks(graph, rig, keys, tps, clip.duration, &duplicates);
  const std::string label = "clip '" + clip.name + "': ";
  if (keys.non_finite) ctx.warn(label + std::to_string(keys.non_finite) + " non-finite keys dropped");
  if (keys.twice) {
    ctx.warn(label + std::to_string(keys.twice) + " nodes have two channels, the second is dropped");
  }
  if (duplicates) {
    ctx.warn(label + std::to_string(duplicates) + " keys at a time already keyed are dropped");
  }
  if (anim.mNumMeshChannels || anim.mNumMorphMeshChannels) summary->morphs.push_back(clip.name);
  if (clip.tracks.empty()) summary->empty.push_back(clip.name);
  return clip;
}

}  // namespace

std::vector<SourceClip> import_clips(const Context& ctx, const NodeGraph& graph, const Rig& rig) {
  std::vector<SourceClip> clips;
  const aiScene& scene = *ctx.scene;
  if (scene.mNumAnimations && rig.skeleton.joints.empty()) {
    ctx.warn(std::to_string(scene.mNumAnimations) +
             " animations are dropped: they animate nothing that is a joint");
    return clips;
  }
  std::set<std::string> names;
  ClipSummary summary;
  for (unsigned a = 0; a < scene.mNumAnimations; ++a) {
    if (!scene.mAnimations[a]) continue;
    clips.push_back(import_clip(ctx, graph, rig, *scene.mAnimations[a], a, &names, &summary));
  }
  if (!summary.morphs.empty()) {
    ctx.warn("mesh and morph-target channels are not supported, dropped from clips: " +
             join(summary.morphs));
  }
  if (!summary.empty.empty()) ctx.warn("clips that animate no joint: " + join(summary.empty));
  return clips;
}

}  // namespace ossa::cook::detail
