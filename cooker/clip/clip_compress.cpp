// clip_compress.cpp — SourceClip -> CompressedClip with a measured model-space error bound
// (clip_compress.h). The design, stage by stage:
//
// 1. Reference. Every channel of every joint is sampled on the clip's frame grid (clip_grid.h)
//    from its source keys: linear for translation and scale, slerp on the shortest arc for
//    rotation (what Assimp's own evaluator does), ends clamped; a grid time within 1/1000 of a
//    frame of a source key takes that key's value exactly, so a source keyed on the grid survives
//    bit for bit. Joints or channels without keys hold the skeleton's bind value. This pose at
//    every frame is what the cooked clip is measured against.
//
// 2. Levers. A channel's error moves points by different amounts depending on where it sits in
//    the hierarchy, so each joint gets bounds from the reference poses, maximised over frames:
//    translation error moves the joint and everything under it by at most |dt| * sigma(parent's
//    model-space linear part); rotation error of angle a (and relative scale error ds/s) moves a
//    point at offset v from the joint by at most 2 sin(a/2) * kappa(parent) * |v| (resp. ds/s *
//    kappa * |v|), where |v| reaches the furthest probe point of the joint's whole subtree and kappa
//    is the parent's condition number (1 without non-uniform scale); probe points sit `probe` from
//    their joint in model space (clip_error.h), whatever scale the armature carries. With error
//    compensation (step 4) a rotation's |v| stops at the origins of the descendants that
//    compensate it. These turn each channel's local error into a model-space displacement bound
//    ("channel error").
//
// 3. Tolerance allocation ("hierarchical tolerance", as ozz-animation's optimizer and ACL's
//    per-joint error do it). Errors of a chain of joints add up at its end, so a joint's channels
//    get tolerance / N^0.4, N the number of varying joints on the longest root-to-leaf path
//    through it. Far from the linear split the triangle inequality would need: independent
//    quantization and key-removal errors add up more like a random walk than in step, and step 6
//    tightens the chains where they do line up.
//
// 4. Classification, then error compensation. Each channel is classified against the source and
//    its budget: bind (every frame within budget of the skeleton's bind value: stored as nothing),
//    constant (within budget of one value: the per-component mid-range, or the normalized mean
//    rotation), else animated. Animated channels are then encoded parents first, each fitted to a
//    compensated target: the local values that put the joint where the source has it *given its
//    parent as decoded* (the parent's model-space rotation error folded into the rotation, its
//    position error into the translation; scale is not compensated). A parent's error is then
//    undone at the child's keys (at every frame for channels that keep every frame, which most do
//    at tight tolerances) instead of swinging the whole subtree, so a rotation's lever shrinks from
//    its subtree's reach to its children's bone lengths (Pab's hips: 122 cm to 10 cm, three bits
//    per component). Where a child drops keys, the parent's error it does not undo between them is
//    inside the child's own channel error, so the accounting stays closed.
//
// 5. Keys and bits per animated channel, chosen together. A rotation channel first picks the
//    component it drops (ossa/format/clip_codec.h): the one whose smallest magnitude over the channel's
//    frames is largest, so the rebuilt component stays away from 0 unless every component comes
//    near 0 somewhere (a leg swinging through a half turn drops x, not w), and each key is stored
//    with that component >= 0 (consecutive keys may then be on opposite hemispheres, which the
//    runtime's shortest-arc nlerp undoes). For each bit count b in 1..kMaxQuantBits (19) the
//    values at every frame are range-quantized per component, the component of widest range in b
//    bits and each other one in the fewest whose step is no coarser (key_widths: a knee's quiet
//    components take a few bits), the dropped component rebuilt from the other three exactly as
//    decoded; a b whose quantized frames alone break the budget is skipped; otherwise greedy key
//    removal runs on the quantized values: from each kept key, the furthest next key whose linear
//    interpolation (normalized lerp on the shortest arc for rotations: what the runtime does)
//    keeps every frame in between within budget, found by doubling then bisection (O(frames log
//    gap) checks, instead of O(frames^2) for Douglas-Peucker on long mocap clips). With W the
//    three widths summed, a reduced key set costs keys * (W + 16) bits (16 for its key frame);
//    keys at every frame cost frames * W, their key frames being one run shared by all such
//    channels. The cheapest (b, keys) wins; the search stops when no larger b can beat it. 32-bit
//    raw floats are the escape when no b holds the budget (a root translation over tens of metres
//    at a 0.03 mm budget, a root rotation through a full turn, which no dropped component avoids).
//    Rotation keys are chosen decoder-aware: rebuilding the dropped component d loses precision
//    where d is small (only in channels where every component comes near zero somewhere), because
//    1 - a^2 - b^2 - c^2 in float resolves d^2 only to ~6e-8; where rounding each component misses,
//    the encoder solves for one stored component (through the float arithmetic decoders use,
//    rotation_w) and searches the stored values around it for the key whose decoded rotation is
//    closest.
//
// 6. Verification. The clip is packed into the bytes the file will hold and decoded back exactly as
//    a runtime decodes it (decode_key, rotation_from_stored, lerp/nlerp in float), model space is
//    rebuilt at every frame and at three points between each pair of frames (clip_error.h: the
//    source there is its frames interpolated as a runtime interpolates them), and the probe error
//    measured for every joint. Where a joint exceeds the tolerance, every channel on its chain
//    (itself and its ancestors) gets its budget scaled by about tolerance / error and is
//    recompressed; at most kMaxTightening rounds, then the chains still over are cooked losslessly
//    (raw floats at every frame). The final measurement is what
//    the clip reports. A bound no float data can hold is reported as measured, never hidden (none
//    of the shared assets has one: every clip of them cooks within the default 0.1 mm).
//
// 7. Shared key lists (clip_compress_share.cpp). Channels whose lists can become one list within
//    each one's budget are grouped while that saves bytes (a list fewer counted as kRunBits), then
//    every channel is fitted again, parents first, to its compensated target given its parents as
//    now decoded (its list and bits kept), and the clip verified again; a joint over the bound takes
//    its chain out of sharing (kMaxShareRounds), and a clip that never holds keeps step 6's lists.
//
// Lossless mode (--no-clip-compression): a channel is bind or constant only when every frame is
// bit-equal to that value; every other channel keeps every frame as raw floats. Translations and
// scales are then bit-exact; rotations store their three kept components exactly (the quaternion
// taken with its dropped component >= 0) wherever that decodes to within 1e-6 of the source, and
// the decoder-aware choice above where it does not.
//
// Layout: constants and animated channels sorted by (joint, channel); each animated channel's keys
// are contiguous in key_values and its key frames contiguous in key_frames, in frame order, so
// forward playback reads both in memory order. A channel keyed at every frame (mocap, lossless
// cooks) stores no key frames; channels whose other lists are identical point at one shared run of
// key_frames (first_key), which saves two bytes per key for every list step 7 shares. A channel
// keyed at every frame is stored in segments of 16 keys where that takes fewer bits (format v14).
//
// Files: step 2 is in clip_compress_levers.cpp, steps 4-5 for one channel in
// clip_compress_channel.cpp, step 7's grouping in clip_compress_share.cpp, packing in
// clip_compress_pack.cpp, what they share in clip_compress_internal.h; this file runs the whole
// clip (classification order, compensation, verification, step 7's refit). Step 1 is
// clip_reference.h's.
#include "cooker/clip/clip_compress.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>

#include "cooker/clip/clip_compress_internal.h"
#include "cooker/clip/clip_error.h"
#include "cooker/clip/clip_reference.h"
#include <ossa/format/clip_codec.h>
#include <ossa/format/ossa_generated.h>

namespace ossa::cook {
namespace {

using namespace compress_detail;  // the stages in clip_compress_levers.cpp and clip_compress_channel.cpp

constexpr uint32_t kMaxTightening = 8;
// Rounds of step 7 (sharing key lists) before the clip keeps its own lists.
constexpr uint32_t kMaxShareRounds = 4;
// Joint-frames up to which model-space transforms are cached (two arrays of 96-byte Affines:
// ~100 MB at the limit; the CMU clip, 38 joints x 4511 frames, takes 33 MB).
constexpr uint64_t kModelCacheLimit = 1u << 19;
// Budget split down a chain of N varying joints: tolerance / N^kChainExponent. 1 would be the
// triangle inequality's split (no tightening ever needed, ~10-20% larger on the Pab clips);
// 0.25-0.5 measured smallest over the Pab, Fox, CesiumMan and CMU clips (within 3% of each other);
// with the per-channel dropped component, 0.3 is 1.5-3% smaller than 0.4 on every shared asset
// (Pab walk/jog/run/atlas, CMU, the rest together), at the same cook time.
constexpr double kChainExponent = 0.3;

// ---------------------------------------------------------------------------------------------
// Error compensation (step 4 of the header)

/// Model space of every joint at every frame, for the reference and for the clip as planned so
/// far (parents first). Kept in memory when they fit kModelCacheLimit joint-frames; otherwise each
/// is recomputed down its chain on demand (same values, O(depth) each).
class Models {
 public:
  Models(const SourceSkeleton& skeleton, const ClipSamples& ref, const ClipSamples& planned)
      : skeleton_(skeleton), ref_(ref), planned_(planned), frames_(ref.frame_count) {
    const uint64_t count = static_cast<uint64_t>(ref.joint_count) * frames_;
    if (count > kModelCacheLimit) return;
    ref_model_.resize(count);
    planned_model_.resize(count);
    std::vector<Affine> at_frame(ref.joint_count);
    for (uint32_t f = 0; f < frames_; ++f) {
      model_at_frame(skeleton, ref, f, at_frame);
      for (uint32_t j = 0; j < ref.joint_count; ++j) ref_model_[j * frames_ + f] = at_frame[j];
    }
  }
  bool cached() const { return !ref_model_.empty(); }

  Affine reference(int joint, uint32_t frame) {
    return cached() ? ref_model_[static_cast<size_t>(joint) * frames_ + frame] : walk(ref_, joint, frame);
  }
  Affine planned(int joint, uint32_t frame) {
    return cached() ? planned_model_[static_cast<size_t>(joint) * frames_ + frame] : walk(planned_, joint, frame);
  }
  /// Call once a joint's channels are all planned (its parent's already are).
  void joint_planned(uint32_t joint) {
    if (!cached()) return;
    const int parent = skeleton_.joints[joint].parent;
    for (uint32_t f = 0; f < frames_; ++f) {
      const Affine local = affine_from_trs(planned_.channel(joint, kTranslation)[f],
                                           planned_.channel(joint, kRotation)[f], planned_.channel(joint, kScale)[f]);
      Affine& m = planned_model_[static_cast<size_t>(joint) * frames_ + f];
      if (parent < 0) {
        m = local;
      } else {
        const Affine& p = planned_model_[static_cast<size_t>(parent) * frames_ + f];
        m.linear = p.linear * local.linear;
        m.origin = p.linear * local.origin + p.origin;
      }
    }
  }

 private:
  Affine walk(const ClipSamples& samples, int joint, uint32_t frame) {
    chain_.clear();
    for (int a = joint; a >= 0; a = skeleton_.joints[static_cast<size_t>(a)].parent) chain_.push_back(a);
    Affine m;
    for (size_t i = chain_.size(); i-- > 0;) {
      const auto j = static_cast<uint32_t>(chain_[i]);
      const Affine local = affine_from_trs(samples.channel(j, kTranslation)[frame],
                                           samples.channel(j, kRotation)[frame], samples.channel(j, kScale)[frame]);
      m.origin = m.linear * local.origin + m.origin;
      m.linear = m.linear * local.linear;
    }
    return m;
  }

  const SourceSkeleton& skeleton_;
  const ClipSamples& ref_;
  const ClipSamples& planned_;
  uint32_t frames_;
  std::vector<Affine> ref_model_, planned_model_;
  std::vector<int> chain_;
};

/// Gram-Schmidt: the rotation nearest a near-rotation (uniformly scaled) matrix.
glm::dquat rotation_of(const glm::dmat3& a) {
  const glm::dvec3 x = glm::normalize(a[0]);
  const glm::dvec3 y = glm::normalize(a[1] - x * glm::dot(x, a[1]));
  return glm::normalize(glm::quat_cast(glm::dmat3(x, y, glm::cross(x, y))));
}

/// The local values of `joint`'s channel `ch` that put the joint where the reference has it, given
/// its parent as planned so far: the reference itself where the decoded parent is
/// exact (and for scale, which is not compensated).
void compensated_target(const SourceSkeleton& skeleton, const ClipSamples& ref, Models& models, uint32_t joint,
                        uint32_t ch, glm::vec4* out) {
  const glm::vec4* src = ref.channel(joint, ch);
  const int parent = skeleton.joints[joint].parent;
  if (parent < 0 || ch == kScale) {
    std::copy_n(src, ref.frame_count, out);
    return;
  }
  for (uint32_t f = 0; f < ref.frame_count; ++f) {
    const Affine pr = models.reference(parent, f);
    const Affine pd = models.planned(parent, f);
    // Nothing to undo, or nothing that can be undone (a parent scaled to zero somewhere).
    if ((pr.linear == pd.linear && pr.origin == pd.origin) || !(std::abs(glm::determinant(pd.linear)) > 1e-30) ||
        !(std::abs(glm::determinant(pr.linear)) > 1e-30)) {
      out[f] = src[f];
      continue;
    }
    const glm::dmat3 inv = glm::inverse(pd.linear);
    if (ch == kTranslation) {
      const glm::dvec3 origin = pr.linear * glm::dvec3(src[f]) + pr.origin;
      out[f] = glm::vec4(glm::vec3(inv * (origin - pd.origin)), 0.0f);
    } else {
      const glm::dquat q =
          rotation_of(inv * pr.linear) * glm::dquat(static_cast<double>(src[f].w), static_cast<double>(src[f].x),
                                                    static_cast<double>(src[f].y), static_cast<double>(src[f].z));
      const glm::dquat n = glm::normalize(q);
      out[f] =
          glm::vec4(static_cast<float>(n.x), static_cast<float>(n.y), static_cast<float>(n.z), static_cast<float>(n.w));
    }
    if (!std::isfinite(out[f].x + out[f].y + out[f].z + out[f].w)) out[f] = src[f];
  }
}

// ---------------------------------------------------------------------------------------------
// Packing and decoding (the runtime's reading of the bytes)

struct ClipLayout {
  std::vector<ChannelPlan> plans;  // [joint * 3 + channel]
};
}  // namespace

Result<CompressedClip> compress_clip(const SourceClip& clip, const SourceSkeleton& skeleton, float metres_per_unit,
                                     const ClipCompressionOptions& options) {
  CompressedClip out;
  out.name = clip.name;
  const std::string label = "clip '" + clip.name + "': ";
  if (!(std::isfinite(clip.duration) && clip.duration >= 0.0f)) return Error{label + "duration is not a finite time"};
  if (!(std::isfinite(clip.sample_rate) && clip.sample_rate >= 0.0f)) return Error{label + "sample rate is invalid"};
  const double frames_wanted = std::round(static_cast<double>(clip.duration) *
                                          (clip.sample_rate > 0.0f ? clip.sample_rate : kDefaultSampleRate)) +
                               1.0;
  if (frames_wanted > kMaxFrames) {
    char text[160];
    std::snprintf(text, sizeof text, "%.0f frames at %g frames/s, more than the %u a clip can address", frames_wanted,
                  static_cast<double>(clip.sample_rate > 0.0f ? clip.sample_rate : kDefaultSampleRate), kMaxFrames);
    return Error{label + text};
  }
  out.grid = frame_grid(clip);
  const auto joints = static_cast<uint32_t>(skeleton.joints.size());
  if (joints > std::numeric_limits<uint16_t>::max()) return Error{label + "more joints than a clip can address"};
  for (const SourceTrack& t : clip.tracks) {
    if (t.joint >= joints)
      return Error{label + "a track addresses joint " + std::to_string(t.joint) + " of " + std::to_string(joints)};
  }
  const uint32_t frames = out.grid.frame_count;
  const uint64_t raw = 10ull * sizeof(float) * joints * frames;
  out.raw_bytes = static_cast<uint32_t>(std::min<uint64_t>(raw, std::numeric_limits<uint32_t>::max()));
  out.has_root_motion = clip.has_root_motion;
  out.events = clip.events;
  out.root_motion = clip.root_motion;
  for (const SourceMorphTrack& track : clip.morph_weights)
    out.morph_weights.push_back(
        compress_morph_track(track, out.grid, options.enabled ? options.morph_weight_tolerance : 0.0f));
  std::sort(out.morph_weights.begin(), out.morph_weights.end(),
            [](const CompressedMorphTrack& a, const CompressedMorphTrack& b) { return a.name < b.name; });
  for (size_t k = 1; k < out.morph_weights.size(); ++k)
    if (out.morph_weights[k].name == out.morph_weights[k - 1].name)
      return Error{label + "two morph weight tracks drive '" + out.morph_weights[k].name + "'"};

  const double unit = std::isfinite(metres_per_unit) && metres_per_unit > 0.0f ? metres_per_unit : 1.0;
  const double probe = options.probe_metres / unit;
  const double tolerance = options.enabled ? options.tolerance_metres / unit : 0.0;
  out.probe_distance = static_cast<float>(probe);
  out.tolerance = static_cast<float>(tolerance);

  const ClipSamples ref = reference_samples(clip, skeleton, out.grid);
  ClipLayout layout;
  layout.plans.resize(static_cast<size_t>(joints) * kChannelsPerJoint);
  auto finish = [&](const ClipError& e) {
    out.max_error = static_cast<float>(e.max);
    out.mean_error = static_cast<float>(e.mean);
    out.worst_joint = e.worst_joint;
  };
  ClipSamples decoded;

  if (!options.enabled) {
    for (uint32_t j = 0; j < joints; ++j)
      for (uint32_t ch = 0; ch < kChannelsPerJoint; ++ch)
        layout.plans[j * 3 + ch] = plan_lossless(ch, ref.channel(j, ch), frames, bind_value(skeleton.joints[j], ch));
    if (Status st = pack(layout.plans, joints, frames, out); !st) return st.error();
    decode_clip(out, skeleton, decoded, kErrorSubdivisions);
    finish(measure_clip_error(skeleton, between_frames(ref), decoded, probe, nullptr, kErrorSubdivisions));
    return out;
  }

  // 3. Budgets: tolerance / N^kChainExponent, N the varying joints on the longest path through
  // the joint; every channel of the joint gets that share.
  std::vector<uint32_t> varying_channels(joints, 0), path(joints, 0), longest(joints, 0);
  std::vector<uint8_t> varying(joints, 0);
  for (uint32_t j = 0; j < joints; ++j) {
    for (uint32_t ch = 0; ch < kChannelsPerJoint; ++ch) {
      const glm::vec4* v = ref.channel(j, ch);
      if (!all_equal(v, frames, v[0])) {
        ++varying_channels[j];
        varying[j] |= ch == kRotation ? kCompensatesRotation : ch == kTranslation ? kCompensatesTranslation : 0;
      }
    }
    const int p = skeleton.joints[j].parent;
    path[j] = (varying_channels[j] > 0 ? 1u : 0u) + (p < 0 ? 0u : path[static_cast<size_t>(p)]);
    longest[j] = path[j];
  }
  for (uint32_t j = joints; j-- > 0;) {
    const int p = skeleton.joints[j].parent;
    if (p >= 0) longest[static_cast<size_t>(p)] = std::max(longest[static_cast<size_t>(p)], longest[j]);
  }
  std::vector<double> budget(static_cast<size_t>(joints) * kChannelsPerJoint);
  for (uint32_t j = 0; j < joints; ++j) {
    const double share = tolerance / std::pow(static_cast<double>(std::max(1u, longest[j])), kChainExponent);
    for (uint32_t ch = 0; ch < kChannelsPerJoint; ++ch) budget[j * 3 + ch] = share;
  }
  // Classification assumes every varying joint compensates (most animated ones will).
  const std::vector<Lever> class_levers = compute_levers(skeleton, ref, probe, varying);

  // 4-6. Classify, plan animated channels parents first against compensated targets, verify, and
  // tighten the chains that exceed the tolerance.
  const size_t channel_count = budget.size();
  std::vector<bool> lossless(channel_count, false);
  ClipSamples planned;  // every frame of every channel as planned so far (decoded)
  planned.resize(joints, frames);
  std::vector<glm::vec4> target(frames);
  // A channel whose target, budget and lever have not changed since its last encoding keeps it.
  struct Cached {
    std::vector<glm::vec4> target;
    double budget = -1.0, lever = -1.0;
  };
  std::vector<Cached> cache(channel_count);
  Models models(skeleton, ref, planned);
  // Verification measures every frame and the points between them (clip_error.h) against the
  // source played as a runtime plays it; its model space is computed once when it fits the cache.
  const ClipSamples ref_positions = between_frames(ref);
  std::vector<Affine> ref_position_models;
  if (static_cast<uint64_t>(joints) * ref_positions.frame_count <= kModelCacheLimit) {
    ref_position_models.resize(static_cast<size_t>(joints) * ref_positions.frame_count);
    std::vector<Affine> at(joints);
    for (uint32_t p = 0; p < ref_positions.frame_count; ++p) {
      model_at_frame(skeleton, ref_positions, p, at);
      for (uint32_t j = 0; j < joints; ++j)
        ref_position_models[static_cast<size_t>(j) * ref_positions.frame_count + p] = at[j];
    }
  }
  ClipError error;
  for (uint32_t round = 0;; ++round) {
    std::vector<uint8_t> compensates(joints, 0);
    for (uint32_t j = 0; j < joints; ++j) {
      for (uint32_t ch = 0; ch < kChannelsPerJoint; ++ch) {
        const size_t i = j * 3 + ch;
        const glm::vec4 bind = bind_value(skeleton.joints[j], ch);
        if (lossless[i]) {
          layout.plans[i] = plan_lossless(ch, ref.channel(j, ch), frames, bind);
          continue;
        }
        const Metric m{ch, ch == kTranslation ? class_levers[j].translation : class_levers[j].compensated};
        ChannelPlan classified = classify_channel(m, ref.channel(j, ch), frames, bind, budget[i]);
        if (classified.kind == Kind::Animated && ch == kRotation) compensates[j] |= kCompensatesRotation;
        if (classified.kind == Kind::Animated && ch == kTranslation) compensates[j] |= kCompensatesTranslation;
        if (classified.kind != Kind::Animated || layout.plans[i].kind != Kind::Animated) {
          layout.plans[i] = std::move(classified);
          cache[i].budget = -1.0;  // (re)encode when it turns animated
        }
      }
    }
    const std::vector<Lever> levers = compute_levers(skeleton, ref, probe, compensates);
    for (uint32_t j = 0; j < joints; ++j) {
      for (uint32_t ch = 0; ch < kChannelsPerJoint; ++ch) {
        const size_t i = j * 3 + ch;
        ChannelPlan& plan = layout.plans[i];
        if (plan.kind == Kind::Animated && !lossless[i]) {
          compensated_target(skeleton, ref, models, j, ch, target.data());
          const double lever = ch == kTranslation ? levers[j].translation
                               : ch == kRotation  ? levers[j].compensated
                                                  : levers[j].rotation;
          Cached& c = cache[i];
          if (c.budget != budget[i] || c.lever != lever || c.target != target) {
            plan = encode_animated(Metric{ch, lever}, target.data(), frames, budget[i]);
            c.target = target;
            c.budget = budget[i];
            c.lever = lever;
          }
        }
        decode_plan(plan, ch, frames, bind_value(skeleton.joints[j], ch), planned.channel(j, ch));
      }
      models.joint_planned(j);
    }
    if (Status st = pack(layout.plans, joints, frames, out); !st) return st.error();
    decode_clip(out, skeleton, decoded, kErrorSubdivisions);
    error = measure_clip_error(skeleton, ref_positions, decoded, probe,
                               ref_position_models.empty() ? nullptr : &ref_position_models, kErrorSubdivisions);
    if (error.max <= tolerance || round > kMaxTightening) break;

    // Each joint over the tolerance scales the budget of its whole chain; a channel on several
    // such chains takes the smallest factor. After kMaxTightening rounds the chains still over are
    // cooked losslessly (one more round to measure that).
    std::vector<double> factor(joints, 1.0);
    for (uint32_t d = 0; d < joints; ++d) {
      if (error.joint_max[d] <= tolerance) continue;
      const double f = std::clamp(0.9 * tolerance / error.joint_max[d], 0.25, 0.8);
      for (int a = static_cast<int>(d); a >= 0; a = skeleton.joints[static_cast<size_t>(a)].parent) {
        factor[static_cast<size_t>(a)] = std::min(factor[static_cast<size_t>(a)], f);
      }
    }
    for (uint32_t j = 0; j < joints; ++j) {
      if (factor[j] >= 1.0) continue;
      for (uint32_t ch = 0; ch < kChannelsPerJoint; ++ch) {
        const size_t i = j * 3 + ch;
        if (round == kMaxTightening) lossless[i] = true;
        budget[i] *= factor[j];
      }
    }
  }
  // 7. Shared key lists (clip_compress_share.cpp), kept when the clip still holds the bound; a
  // joint over it takes its chain (itself and its ancestors) out of sharing, for kMaxShareRounds.
  if (error.max <= tolerance) {
    std::vector<ShareInput> inputs(channel_count);
    for (size_t i = 0; i < channel_count; ++i) {
      if (layout.plans[i].kind != Kind::Animated || lossless[i] || cache[i].budget < 0.0) continue;
      inputs[i] = ShareInput{true, Metric{static_cast<uint32_t>(i % kChannelsPerJoint), cache[i].lever},
                             cache[i].budget, &cache[i].target};
    }
    const std::vector<ChannelPlan> own = layout.plans;
    bool kept = false;
    for (uint32_t round = 0; round < kMaxShareRounds && !kept; ++round) {
      layout.plans = own;
      const std::vector<bool> shared_list = share_key_lists(layout.plans, inputs, frames);
      if (std::find(shared_list.begin(), shared_list.end(), true) == shared_list.end()) break;  // own lists
      // Compensation again, parents first: each channel fitted to its target given its parents
      // with their shared lists, keeping its list when shared (its bits either way).
      for (uint32_t j = 0; j < joints; ++j) {
        for (uint32_t ch = 0; ch < kChannelsPerJoint; ++ch) {
          const size_t i = j * 3 + ch;
          ChannelPlan& plan = layout.plans[i];
          if (layout.plans[i].kind == Kind::Animated && !lossless[i] && cache[i].budget >= 0.0) {
            compensated_target(skeleton, ref, models, j, ch, target.data());
            const Metric m{ch, cache[i].lever};
            if (shared_list[i]) plan = refit_animated(m, target.data(), frames, budget[i], plan.bits, plan.frames);
            else if (target != cache[i].target) plan = encode_animated(m, target.data(), frames, budget[i]);
          }
          decode_plan(plan, ch, frames, bind_value(skeleton.joints[j], ch), planned.channel(j, ch));
        }
        models.joint_planned(j);
      }
      if (Status st = pack(layout.plans, joints, frames, out); !st) return st.error();
      decode_clip(out, skeleton, decoded, kErrorSubdivisions);
      const ClipError shared =
          measure_clip_error(skeleton, ref_positions, decoded, probe,
                             ref_position_models.empty() ? nullptr : &ref_position_models, kErrorSubdivisions);
      kept = shared.max <= tolerance;
      if (kept) {
        error = shared;
        break;
      }
      for (uint32_t d = 0; d < joints; ++d) {
        if (shared.joint_max[d] <= tolerance) continue;
        for (int a = static_cast<int>(d); a >= 0; a = skeleton.joints[static_cast<size_t>(a)].parent)
          for (uint32_t ch = 0; ch < kChannelsPerJoint; ++ch) inputs[static_cast<size_t>(a) * 3 + ch].share = false;
      }
    }
    if (!kept) {
      layout.plans = own;
      if (Status st = pack(layout.plans, joints, frames, out); !st) return st.error();
    }
  }
  finish(error);
  return out;
}

}  // namespace ossa::cook
