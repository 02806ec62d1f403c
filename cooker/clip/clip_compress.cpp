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
//    values at every frame are range-quantized per component (the dropped component rebuilt from
//    the other three exactly as decoded); a b whose quantized frames alone break the
//    budget is skipped; otherwise greedy key removal runs on the quantized values: from each kept
//    key, the furthest next key whose linear interpolation (normalized lerp on the shortest arc for
//    rotations: what the runtime does) keeps every frame in between within budget, found by
//    doubling then bisection (O(frames log gap) checks, instead of O(frames^2) for Douglas-Peucker
//    on long mocap clips). A reduced key set costs keys * (3b + 16) bits (16 for its key frame);
//    keys at every frame cost frames * 3b, their key frames being one run shared by all such
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
// Lossless mode (--no-clip-compression): a channel is bind or constant only when every frame is
// bit-equal to that value; every other channel keeps every frame as raw floats. Translations and
// scales are then bit-exact; rotations store their three kept components exactly (the quaternion
// taken with its dropped component >= 0) wherever that decodes to within 1e-6 of the source, and
// the decoder-aware choice above where it does not.
//
// Layout: constants and animated channels sorted by (joint, channel); each animated channel's keys
// are contiguous in key_values and its key frames contiguous in key_frames, in frame order, so
// forward playback reads both in memory order. Channels whose key frames are identical point at one
// shared run of key_frames (first_key), which the format allows and which saves two bytes per key
// for every channel keyed at every frame (mocap, lossless cooks).
#include "cooker/clip/clip_compress.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <limits>
#include <map>

#include "cooker/clip/clip_error.h"
#include "cooker/clip/clip_reference.h"
#include <ossa/format/clip_codec.h>
#include <ossa/format/ossa_generated.h>

namespace ossa::cook {
namespace {

constexpr uint32_t kMaxTightening = 8;
// Joint-frames up to which model-space transforms are cached (two arrays of 96-byte Affines:
// ~100 MB at the limit; the CMU clip, 38 joints x 4511 frames, takes 33 MB).
constexpr uint64_t kModelCacheLimit = 1u << 19;
// Budget split down a chain of N varying joints: tolerance / N^kChainExponent. 1 would be the
// triangle inequality's split (no tightening ever needed, ~10-20% larger on the Pab clips);
// 0.25-0.5 measured smallest over the Pab, Fox, CesiumMan and CMU clips (within 3% of each other);
// with the per-channel dropped component, 0.3 is 1.5-3% smaller than 0.4 on every shared asset
// (Pab walk/jog/run/atlas, CMU, the rest together), at the same cook time.
constexpr double kChainExponent = 0.3;
constexpr uint32_t kKeyFrameBits = 16;

enum class Kind : uint8_t { Bind, Constant, Animated };

// ---------------------------------------------------------------------------------------------
// 2. Levers: model-space displacement per unit of local error

/// An upper bound of the largest singular value: sqrt of the largest absolute row sum of A^T A
/// (Gershgorin), exact for a rotation times a uniform scale.
double sigma_max(const glm::dmat3& a) {
  const glm::dmat3 ata = glm::transpose(a) * a;
  double worst = 0.0;
  for (int r = 0; r < 3; ++r) worst = std::max(worst, std::abs(ata[0][r]) + std::abs(ata[1][r]) + std::abs(ata[2][r]));
  return std::sqrt(worst);
}

/// sigma_max(a) * sigma_max(a^-1): how much a non-uniform parent can stretch a local error. 1 for
/// a singular parent (a zero scale flattens everything under it; verification still measures it).
double condition(const glm::dmat3& a) {
  const double det = glm::determinant(a);
  if (!(std::abs(det) > 1e-30)) return 1.0;
  return std::max(1.0, sigma_max(a) * sigma_max(glm::inverse(a)));
}

/// Per joint: which of its channels are fitted to compensate their parent's decoded error.
constexpr uint8_t kCompensatesRotation = 1, kCompensatesTranslation = 2;

struct Lever {
  double translation = 0.0;  // model displacement per unit of local translation error
  double rotation = 0.0;     // ... per unit of 2 sin(angle / 2), or of relative scale error
  double compensated = 0.0;  // rotation, when the joints in `compensates` absorb it (step 4)
};

/// Levers from the reference poses, maximised over frames. A rotation error of joint j moves its
/// own probe points and its descendants; a descendant k below j whose rotation is compensated
/// (compensates[k]: its keys are fitted to undo its parent's decoded error) stops the swing: k and
/// everything under it then only shift with k's origin, by |o_k - o_j| per unit of error (nothing
/// when k's translation compensates too). `compensated` is j's lever under that assumption,
/// `rotation` the lever without any compensation. O(frames * joints * depth).
std::vector<Lever> compute_levers(const SourceSkeleton& skeleton, const ClipSamples& ref, double probe,
                                  const std::vector<uint8_t>& compensates) {
  const uint32_t joints = ref.joint_count;
  std::vector<Lever> levers(joints);
  std::vector<Affine> model(joints);
  std::vector<double> sigma(joints), reach(joints), reach_compensated(joints);
  for (uint32_t f = 0; f < ref.frame_count; ++f) {
    model_at_frame(skeleton, ref, f, model);
    for (uint32_t j = 0; j < joints; ++j) {
      sigma[j] = sigma_max(model[j].linear);
      reach[j] = reach_compensated[j] = probe;  // probe points sit `probe` from the joint in model space
    }
    // Every joint's probe points, pushed up to each ancestor: O(joints * depth). Walking up from
    // d, `stop` is the compensating joint closest below the current ancestor.
    for (uint32_t d = 0; d < joints; ++d) {
      const double own = probe;
      int stop = (compensates[d] & kCompensatesRotation) ? static_cast<int>(d) : -1;
      for (int a = skeleton.joints[d].parent; a >= 0; a = skeleton.joints[static_cast<size_t>(a)].parent) {
        const auto ai = static_cast<size_t>(a);
        const double full = glm::length(model[d].origin - model[ai].origin) + own;
        reach[ai] = std::max(reach[ai], full);
        double shift = full;
        if (stop >= 0) {
          const auto si = static_cast<size_t>(stop);
          shift = (compensates[si] & kCompensatesTranslation) ? 0.0 : glm::length(model[si].origin - model[ai].origin);
        }
        reach_compensated[ai] = std::max(reach_compensated[ai], shift);
        if (compensates[ai] & kCompensatesRotation) stop = a;
      }
    }
    for (uint32_t j = 0; j < joints; ++j) {
      const int p = skeleton.joints[j].parent;
      const double sp = p < 0 ? 1.0 : sigma[static_cast<size_t>(p)];
      const double kp = p < 0 ? 1.0 : condition(model[static_cast<size_t>(p)].linear);
      levers[j].translation = std::max(levers[j].translation, sp);
      levers[j].rotation = std::max(levers[j].rotation, kp * reach[j]);
      levers[j].compensated = std::max(levers[j].compensated, kp * reach_compensated[j]);
    }
  }
  return levers;
}

// ---------------------------------------------------------------------------------------------
// Channel error and interpolation (the runtime's arithmetic)

struct Metric {
  uint32_t channel = kTranslation;
  double lever = 1.0;
};

/// A bound of the model-space displacement `decoded` causes where `reference` was intended.
double channel_error(const Metric& m, const glm::vec4& reference, const glm::vec4& decoded) {
  if (m.channel == kTranslation) {
    return glm::length(glm::dvec3(reference) - glm::dvec3(decoded)) * m.lever;
  }
  if (m.channel == kRotation) {
    const glm::dvec4 r = glm::normalize(glm::dvec4(reference));
    glm::dvec4 d = glm::normalize(glm::dvec4(decoded));
    if (glm::dot(r, d) < 0.0) d = -d;
    const double chord = glm::length(r - d);  // = 2 sin(angle / 4)
    return 2.0 * chord * std::sqrt(std::max(0.0, 1.0 - 0.25 * chord * chord)) * m.lever;  // 2 sin(angle / 2)
  }
  double worst = 0.0;
  for (int c = 0; c < 3; ++c) {
    const double s = std::abs(static_cast<double>(reference[c]));
    const double ds = std::abs(static_cast<double>(reference[c]) - static_cast<double>(decoded[c]));
    if (ds > 0.0) worst = std::max(worst, s > 0.0 ? ds / s : std::numeric_limits<double>::infinity());
  }
  return worst * m.lever;
}

// ---------------------------------------------------------------------------------------------
// 4-5. One channel: classification, keys and bits

/// One key as stored: three quantized components, or three raw float bit patterns (bits == 32).
using Code = std::array<uint32_t, 3>;

struct ChannelPlan {
  Kind kind = Kind::Bind;
  glm::vec4 constant{0.0f};
  uint32_t bits = 0;                 // animated: 1..kMaxQuantBits or 32
  uint32_t dropped = 0;              // animated rotation: the component not stored (0..3)
  std::vector<uint16_t> frames;      // animated: kept key frames
  std::vector<Code> codes;           // animated: every frame's key as it would be stored
  float range_min[3] = {0, 0, 0}, range_extent[3] = {0, 0, 0};
};

bool all_equal(const glm::vec4* v, uint32_t n, const glm::vec4& value) {
  for (uint32_t f = 0; f < n; ++f)
    if (v[f] != value) return false;
  return true;
}

double max_error_against(const Metric& m, const glm::vec4* ref, uint32_t n, const glm::vec4& value) {
  double worst = 0.0;
  for (uint32_t f = 0; f < n; ++f) worst = std::max(worst, channel_error(m, ref[f], value));
  return worst;
}

glm::vec4 central_value(uint32_t channel, const glm::vec4* ref, uint32_t n) {
  if (channel == kRotation) {
    glm::dvec4 sum(0.0);
    for (uint32_t f = 0; f < n; ++f) {
      const glm::dvec4 q(ref[f]);
      sum += glm::dot(q, glm::dvec4(ref[0])) < 0.0 ? -q : q;
    }
    return glm::vec4(glm::normalize(sum));
  }
  glm::vec4 lo = ref[0], hi = ref[0];
  for (uint32_t f = 1; f < n; ++f) {
    lo = glm::min(lo, ref[f]);
    hi = glm::max(hi, ref[f]);
  }
  return glm::vec4((glm::dvec4(lo) + glm::dvec4(hi)) * 0.5);
}

/// Greedy key removal on per-frame candidate key values `dec`: from each kept key, the furthest
/// next key whose interpolation keeps every frame between them, and the points between frames
/// (`ref_positions`: the reference at every position of kErrorSubdivisions per frame, as
/// between_frames makes it), within tolerance. The points between frames matter where a channel
/// turns fast: nlerp over a long span does not pass where two nlerps over its halves do (two
/// keys 72 degrees apart put the quarter point 2 degrees from the midpoint of the first 36).
std::vector<uint16_t> reduce_keys(const Metric& m, const glm::vec4* ref_positions, const glm::vec4* dec, uint32_t n,
                                  double tolerance) {
  constexpr uint32_t kSub = kErrorSubdivisions;
  auto valid = [&](uint32_t a, uint32_t b) {
    const float inv_length = 1.0f / static_cast<float>(b - a);
    for (uint32_t p = a * kSub + 1; p < b * kSub; ++p) {
      const float x = static_cast<float>(p / kSub) + static_cast<float>(p % kSub) / static_cast<float>(kSub);
      const glm::vec4 v = interpolate_keys(m.channel, dec[a], dec[b], (x - static_cast<float>(a)) * inv_length);
      if (channel_error(m, ref_positions[p], v) > tolerance) return false;
    }
    return true;
  };
  std::vector<uint16_t> keys{0};
  const uint32_t last = n - 1;
  uint32_t a = 0;
  while (a < last) {
    uint32_t good = a + 1, bad = 0;  // bad == 0: no failing end found yet
    for (uint32_t step = 2; bad == 0; step *= 2) {
      const uint32_t b = std::min(last, a + step);
      if (b == good) break;
      if (valid(a, b)) {
        good = b;
        if (b == last) break;
      } else {
        bad = b;
      }
    }
    while (bad != 0 && bad - good > 1) {
      const uint32_t mid = good + (bad - good) / 2;
      if (valid(a, mid)) good = mid;
      else bad = mid;
    }
    keys.push_back(static_cast<uint16_t>(good));
    a = good;
  }
  return keys;
}

/// The component a rotation channel drops: the one whose smallest magnitude over the channel's
/// frames is largest (sign-independent, so the same on any hemisphere choice). Rebuilding it
/// (sqrt(1 - a^2 - b^2 - c^2)) then stays precise unless every component comes near 0 somewhere in
/// the channel (a turn about one axis that reaches both 0 and 180 degrees), where always dropping
/// w fails for any channel passing a half turn; and since the dropped component keeps its sign
/// along a hemisphere-consistent channel, the per-key flip to >= 0 keeps the three stored
/// components continuous (small ranges). Ties keep the later index (w, the historical choice).
uint32_t choose_dropped(const glm::vec4* q, uint32_t n) {
  uint32_t best = 3;
  float best_min = -1.0f;
  for (uint32_t c = 4; c-- > 0;) {
    float lo = std::numeric_limits<float>::infinity();
    for (uint32_t f = 0; f < n; ++f) lo = std::min(lo, std::abs(q[f][static_cast<int>(c)]));
    if (lo > best_min) {
      best_min = lo;
      best = c;
    }
  }
  return best;
}

/// The stored form of a frame value: for rotations, the three stored components (x, y, z, w order
/// without `dropped`, the quaternion taken with its dropped component >= 0) in [0..2] and the
/// dropped component (>= 0) in [3], the value the decoder is to rebuild. Other channels as they are.
glm::vec4 stored_form(uint32_t channel, uint32_t dropped, glm::vec4 v) {
  if (channel != kRotation) return v;
  const float xyzw[4] = {v.x, v.y, v.z, v.w};
  float stored[3];
  rotation_to_stored(xyzw, dropped, stored);
  return glm::vec4(stored[0], stored[1], stored[2], std::abs(xyzw[dropped]));
}

uint32_t float_bits(float f) {
  uint32_t u;
  std::memcpy(&u, &f, 4);
  return u;
}

glm::vec4 decode_code(uint32_t channel, uint32_t dropped, uint32_t bits, const float lo[3], const float extent[3],
                      const Code& code) {
  float xyz[3];
  for (int c = 0; c < 3; ++c) {
    if (bits == kRawFloatBits) std::memcpy(&xyz[c], &code[c], 4);
    else xyz[c] = dequantize(code[c], lo[c], extent[c], bits);
  }
  return key_sample(channel, dropped, xyz);
}

/// 1 - a^2 - b^2 - c^2 over the three stored components as decoders compute it (format/
/// clip_codec.h's rotation_w, same expression and order, in float), whichever component is dropped.
float decoded_w2(const float xyz[3]) { return 1.0f - xyz[0] * xyz[0] - xyz[1] * xyz[1] - xyz[2] * xyz[2]; }

/// The value of stored component `adj` that, with the other two as they are, makes the dropped
/// component a decoder rebuilds closest to target_w (sign kept from xyz[adj]): solved in double,
/// then corrected twice for the rounding the float evaluation adds.
float solve_component(const float xyz_in[3], int adj, double target_w) {
  float xyz[3] = {xyz_in[0], xyz_in[1], xyz_in[2]};
  double others = 0.0;
  for (int c = 0; c < 3; ++c)
    if (c != adj) others += static_cast<double>(xyz[c]) * static_cast<double>(xyz[c]);
  double v2 = std::max(0.0, 1.0 - target_w * target_w - others);
  const float sign = xyz[adj] < 0.0f ? -1.0f : 1.0f;
  for (int iteration = 0; iteration < 2; ++iteration) {
    xyz[adj] = sign * static_cast<float>(std::sqrt(v2));
    v2 = std::max(0.0, v2 + static_cast<double>(decoded_w2(xyz)) - target_w * target_w);
  }
  return sign * static_cast<float>(std::sqrt(v2));
}

// Decoder-aware rotation keys (see the header, step 5). Only keys whose plain rounding misses pay
// for the search.

float nudge(float v, int ulps) {
  for (; ulps < 0; ++ulps) v = std::nextafter(v, -std::numeric_limits<float>::infinity());
  for (; ulps > 0; --ulps) v = std::nextafter(v, std::numeric_limits<float>::infinity());
  return v;
}

/// Raw floats: the three floats nearest the source rotation after the dropped component (stored.w
/// here, see stored_form) is rebuilt. Solving one component for it leaves its square on that
/// component's rounding grid (~6e-9 for a component of 0.2); nudging a second component by a few
/// ulps first shifts the grid, which gets it another order of magnitude closer.
Code encode_rotation_raw(const glm::vec4& ref, const glm::vec4& stored, uint32_t dropped, double good_enough) {
  constexpr int kSecondUlps = 8, kSolvedUlps = 2;
  const Metric angle{kRotation, 1.0};
  const float zero[3] = {0, 0, 0};
  Code best = {float_bits(stored.x), float_bits(stored.y), float_bits(stored.z)};
  double best_error = channel_error(angle, ref, decode_code(kRotation, dropped, kRawFloatBits, zero, zero, best));
  for (int adj = 0; adj < 3 && best_error > good_enough; ++adj) {
    for (int other = 0; other < 3; ++other) {
      if (other == adj) continue;
      for (int k = -kSecondUlps; k <= kSecondUlps; ++k) {
        float xyz[3] = {stored.x, stored.y, stored.z};
        xyz[other] = nudge(xyz[other], k);
        const float solved = solve_component(xyz, adj, stored.w);
        for (int d = -kSolvedUlps; d <= kSolvedUlps; ++d) {
          xyz[adj] = nudge(solved, d);
          const Code code = {float_bits(xyz[0]), float_bits(xyz[1]), float_bits(xyz[2])};
          const double e = channel_error(angle, ref, decode_code(kRotation, dropped, kRawFloatBits, zero, zero, code));
          if (e < best_error) {
            best_error = e;
            best = code;
          }
        }
      }
    }
  }
  return best;
}

/// Quantized: the nearest lattice point, or when that misses `budget`, the best lattice point
/// around the one that solves for each component in turn.
Code encode_quantized(const Metric& m, const glm::vec4& ref, const glm::vec4& stored, uint32_t dropped, uint32_t bits,
                      const float lo[3], const float extent[3], double budget) {
  Code best;
  for (int c = 0; c < 3; ++c) best[c] = quantize(stored[c], lo[c], extent[c], bits);
  if (m.channel != kRotation) return best;
  double best_error = channel_error(m, ref, decode_code(kRotation, dropped, bits, lo, extent, best));
  if (best_error <= budget) return best;
  const Code nearest = best;
  const auto qmax = static_cast<int64_t>(quant_max(bits));
  for (int adj = 0; adj < 3; ++adj) {
    float xyz[3];
    for (int c = 0; c < 3; ++c) xyz[c] = dequantize(nearest[c], lo[c], extent[c], bits);
    const auto center = static_cast<int64_t>(quantize(solve_component(xyz, adj, stored.w),
                                                      lo[adj], extent[adj], bits));
    const int a = (adj + 1) % 3, b = (adj + 2) % 3;
    for (int64_t d = -2; d <= 2; ++d) {
      for (int64_t da = -1; da <= 1; ++da) {
        for (int64_t db = -1; db <= 1; ++db) {
          Code code = nearest;
          const int64_t qa = static_cast<int64_t>(nearest[a]) + da, qb = static_cast<int64_t>(nearest[b]) + db;
          const int64_t qc = center + d;
          if (qa < 0 || qa > qmax || qb < 0 || qb > qmax || qc < 0 || qc > qmax) continue;
          code[a] = static_cast<uint32_t>(qa);
          code[b] = static_cast<uint32_t>(qb);
          code[adj] = static_cast<uint32_t>(qc);
          const double e = channel_error(m, ref, decode_code(kRotation, dropped, bits, lo, extent, code));
          if (e < best_error) {
            best_error = e;
            best = code;
          }
        }
      }
    }
  }
  return best;
}

/// Raw float keys of a channel (rotations made decoder-exact).
std::vector<Code> raw_codes(uint32_t channel, uint32_t dropped, const glm::vec4* ref, uint32_t n) {
  // Well below any tolerance, above float noise: angle error (2 sin(a/2)) of a well-rounded key.
  constexpr double kGoodEnoughAngle = 1e-6;
  std::vector<Code> codes(n);
  for (uint32_t f = 0; f < n; ++f) {
    const glm::vec4 v = stored_form(channel, dropped, ref[f]);
    codes[f] = channel == kRotation ? encode_rotation_raw(ref[f], v, dropped, kGoodEnoughAngle)
                                    : Code{float_bits(v.x), float_bits(v.y), float_bits(v.z)};
  }
  return codes;
}

ChannelPlan animate_lossless(uint32_t channel, const glm::vec4* ref, uint32_t n) {
  ChannelPlan plan;
  plan.kind = Kind::Animated;
  plan.bits = kRawFloatBits;
  plan.dropped = channel == kRotation ? choose_dropped(ref, n) : 0;
  plan.codes = raw_codes(channel, plan.dropped, ref, n);
  plan.frames.resize(n);
  for (uint32_t f = 0; f < n; ++f) plan.frames[f] = static_cast<uint16_t>(f);
  return plan;
}

ChannelPlan plan_lossless(uint32_t channel, const glm::vec4* ref, uint32_t n, const glm::vec4& bind) {
  ChannelPlan plan;
  if (all_equal(ref, n, bind)) return plan;
  if (all_equal(ref, n, ref[0])) {
    plan.kind = Kind::Constant;
    plan.constant = ref[0];
    return plan;
  }
  return animate_lossless(channel, ref, n);
}

/// Step 4: bind or constant when the source (`ref`) allows it within `tolerance`; otherwise a plan
/// of kind Animated, still to be encoded.
ChannelPlan classify_channel(const Metric& m, const glm::vec4* ref, uint32_t n, const glm::vec4& bind,
                             double tolerance) {
  ChannelPlan plan;
  if (max_error_against(m, ref, n, bind) <= tolerance) return plan;  // bind
  if (all_equal(ref, n, ref[0]) || n < 2) {
    plan.kind = Kind::Constant;
    plan.constant = ref[0];
    return plan;
  }
  const glm::vec4 center = central_value(m.channel, ref, n);
  if (max_error_against(m, ref, n, center) <= tolerance) {
    plan.kind = Kind::Constant;
    plan.constant = center;
    return plan;
  }
  plan.kind = Kind::Animated;
  return plan;
}

/// Step 5: keys and bits of an animated channel fitted to `target` (per frame) within tolerance.
ChannelPlan encode_animated(const Metric& m, const glm::vec4* target, uint32_t n, double tolerance) {
  ChannelPlan plan;
  plan.kind = Kind::Animated;
  plan.dropped = m.channel == kRotation ? choose_dropped(target, n) : 0;
  std::vector<glm::vec4> stored(n);
  glm::vec4 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
  for (uint32_t f = 0; f < n; ++f) {
    stored[f] = stored_form(m.channel, plan.dropped, target[f]);
    lo = glm::min(lo, stored[f]);
    hi = glm::max(hi, stored[f]);
  }
  for (int c = 0; c < 3; ++c) {
    plan.range_min[c] = lo[c];
    plan.range_extent[c] = hi[c] - lo[c];
  }

  // Raw floats: the fallback, and (its key count) the floor no bit count can go below.
  std::vector<glm::vec4> dec(n);
  plan.bits = kRawFloatBits;
  plan.codes = raw_codes(m.channel, plan.dropped, target, n);
  for (uint32_t f = 0; f < n; ++f) {
    dec[f] = decode_code(m.channel, plan.dropped, kRawFloatBits, plan.range_min, plan.range_extent, plan.codes[f]);
  }
  // Keys at every frame share one run of key_frames with every other such channel (pack), so
  // their frames cost nothing; a reduced set pays kKeyFrameBits per key.
  std::vector<uint16_t> all_frames(n);
  for (uint32_t f = 0; f < n; ++f) all_frames[f] = static_cast<uint16_t>(f);
  uint64_t best_cost = std::numeric_limits<uint64_t>::max();
  auto consider = [&](uint32_t bits, std::vector<uint16_t> frames) {
    const uint64_t all_cost = n * 3ull * bits;
    const uint64_t reduced_cost = frames.size() * (3ull * bits + kKeyFrameBits);
    if (std::min(all_cost, reduced_cost) >= best_cost) return false;
    best_cost = std::min(all_cost, reduced_cost);
    plan.bits = bits;
    plan.frames = all_cost <= reduced_cost ? all_frames : std::move(frames);
    return true;
  };
  // The target at every position between frames too, as the runtime would play it keyed at every
  // frame (what verification measures against).
  std::vector<glm::vec4> target_positions((n - 1) * kErrorSubdivisions + 1);
  for (uint32_t p = 0; p < target_positions.size(); ++p) {
    const uint32_t f = p / kErrorSubdivisions, k = p % kErrorSubdivisions;
    target_positions[p] = k == 0 ? target[f]
                                 : interpolate_keys(m.channel, target[f], target[f + 1],
                                                    static_cast<float>(k) / static_cast<float>(kErrorSubdivisions));
  }
  std::vector<uint16_t> raw_frames = reduce_keys(m, target_positions.data(), dec.data(), n, tolerance);
  const size_t floor_keys = raw_frames.size();
  consider(kRawFloatBits, std::move(raw_frames));

  std::vector<Code> codes(n);
  for (uint32_t bits = 1; bits <= kMaxQuantBits; ++bits) {
    const uint64_t lowest = std::min<uint64_t>(n * 3ull * bits, floor_keys * (3ull * bits + kKeyFrameBits));
    if (lowest >= best_cost) break;
    bool holds = true;
    for (uint32_t f = 0; f < n && holds; ++f) {
      codes[f] = encode_quantized(m, target[f], stored[f], plan.dropped, bits, plan.range_min, plan.range_extent,
                                  tolerance);
      dec[f] = decode_code(m.channel, plan.dropped, bits, plan.range_min, plan.range_extent, codes[f]);
      holds = channel_error(m, target[f], dec[f]) <= tolerance;
    }
    if (holds && consider(bits, reduce_keys(m, target_positions.data(), dec.data(), n, tolerance))) plan.codes = codes;
  }
  return plan;
}

/// Every frame of a planned channel, decoded exactly as decode_clip decodes the packed bytes.
void decode_plan(const ChannelPlan& plan, uint32_t channel, uint32_t n, const glm::vec4& bind, glm::vec4* out) {
  if (plan.kind != Kind::Animated) {
    glm::vec4 v = plan.kind == Kind::Bind ? bind : plan.constant;
    if (channel != kRotation) v.w = 0.0f;
    std::fill_n(out, n, v);
    return;
  }
  glm::vec4 prev =
      decode_code(channel, plan.dropped, plan.bits, plan.range_min, plan.range_extent, plan.codes[plan.frames[0]]);
  out[0] = prev;
  for (size_t k = 1; k < plan.frames.size(); ++k) {
    const glm::vec4 next =
        decode_code(channel, plan.dropped, plan.bits, plan.range_min, plan.range_extent, plan.codes[plan.frames[k]]);
    const uint32_t f0 = plan.frames[k - 1], f1 = plan.frames[k];
    const float inv_length = 1.0f / static_cast<float>(f1 - f0);
    for (uint32_t f = f0; f <= f1; ++f) out[f] = interpolate_keys(channel, prev, next, static_cast<float>(f - f0) * inv_length);
    prev = next;
  }
}

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
      const glm::dquat q = rotation_of(inv * pr.linear) *
                           glm::dquat(static_cast<double>(src[f].w), static_cast<double>(src[f].x),
                                      static_cast<double>(src[f].y), static_cast<double>(src[f].z));
      const glm::dquat n = glm::normalize(q);
      out[f] = glm::vec4(static_cast<float>(n.x), static_cast<float>(n.y), static_cast<float>(n.z),
                         static_cast<float>(n.w));
    }
    if (!std::isfinite(out[f].x + out[f].y + out[f].z + out[f].w)) out[f] = src[f];
  }
}

// ---------------------------------------------------------------------------------------------
// Packing and decoding (the runtime's reading of the bytes)

struct ClipLayout {
  std::vector<ChannelPlan> plans;  // [joint * 3 + channel]
};

/// ossa/format/clip_codec.h's BitWriter, byte for byte (LSB-first fields, byte alignment, padding),
/// writing whole fields instead of single bits: packing runs once per verification round.
class KeyWriter {
 public:
  uint64_t bit_size() const { return bits_; }
  void write(uint32_t value, uint32_t count) {  // count <= 32
    const uint64_t v = (static_cast<uint64_t>(value) & ((1ull << count) - 1ull)) << (bits_ & 7u);
    const size_t first = static_cast<size_t>(bits_ >> 3);
    bits_ += count;
    bytes_.resize(static_cast<size_t>((bits_ + 7) >> 3), 0);
    for (size_t i = first; i < bytes_.size(); ++i) bytes_[i] |= static_cast<uint8_t>(v >> (8 * (i - first)));
  }
  void align_byte() { bits_ = (bits_ + 7) & ~7ull; }
  std::vector<uint8_t> finish() {
    std::vector<uint8_t> out = std::move(bytes_);
    out.resize(static_cast<size_t>((bits_ + 7) >> 3) + kKeyValuePadding, 0);
    return out;
  }

 private:
  std::vector<uint8_t> bytes_;
  uint64_t bits_ = 0;
};

Status pack(const ClipLayout& layout, uint32_t joints, uint32_t frames, CompressedClip& out) {
  out.constants.clear();
  out.animated.clear();
  out.key_frames.clear();
  KeyWriter writer;
  // Identical key frame lists share one run. Every-frame lists, the common case, are matched by
  // size alone; the rest through an ordered map (deterministic).
  std::map<std::vector<uint16_t>, uint32_t> shared_frames;
  int64_t every_frame_run = -1;
  for (uint32_t j = 0; j < joints; ++j) {
    for (uint32_t ch = 0; ch < kChannelsPerJoint; ++ch) {
      const ChannelPlan& p = layout.plans[j * 3 + ch];
      if (p.kind == Kind::Bind) continue;
      if (p.kind == Kind::Constant) {
        CompressedConstant c;
        c.joint = static_cast<uint16_t>(j);
        c.channel = static_cast<uint8_t>(ch);
        for (int i = 0; i < 4; ++i) c.value[i] = p.constant[i];
        if (ch != kRotation) c.value[3] = 0.0f;
        out.constants.push_back(c);
        continue;
      }
      CompressedAnimated a;
      a.joint = static_cast<uint16_t>(j);
      a.channel = static_cast<uint8_t>(ch);
      a.bits = static_cast<uint8_t>(p.bits);
      a.dropped = static_cast<uint8_t>(ch == kRotation ? p.dropped : 0);  // 0 for other channels
      a.key_count = static_cast<uint32_t>(p.frames.size());
      if (p.frames.size() == frames && every_frame_run >= 0) {
        a.first_key = static_cast<uint32_t>(every_frame_run);
      } else {
        const auto [it, inserted] = shared_frames.emplace(p.frames, static_cast<uint32_t>(out.key_frames.size()));
        if (inserted) out.key_frames.insert(out.key_frames.end(), p.frames.begin(), p.frames.end());
        a.first_key = it->second;
        if (p.frames.size() == frames) every_frame_run = it->second;
      }
      if (p.bits == kRawFloatBits) writer.align_byte();
      if (writer.bit_size() > std::numeric_limits<uint32_t>::max()) {
        return Error{"clip '" + out.name + "': compressed keys exceed 4 Gbit"};
      }
      a.bit_offset = static_cast<uint32_t>(writer.bit_size());
      for (int c = 0; c < 3; ++c) {
        a.range_min[c] = p.bits == kRawFloatBits ? 0.0f : p.range_min[c];
        a.range_extent[c] = p.bits == kRawFloatBits ? 0.0f : p.range_extent[c];
      }
      for (const uint16_t f : p.frames)
        for (int c = 0; c < 3; ++c) writer.write(p.codes[f][c], p.bits);
      out.animated.push_back(a);
    }
  }
  if (writer.bit_size() > std::numeric_limits<uint32_t>::max()) {
    return Error{"clip '" + out.name + "': compressed keys exceed 4 Gbit"};
  }
  out.key_values = writer.finish();
  out.cooked_bytes = static_cast<uint32_t>(
      out.constants.size() * sizeof(fb::ConstantChannel) + out.animated.size() * sizeof(fb::AnimatedChannel) +
      out.key_frames.size() * sizeof(uint16_t) + out.key_values.size());
  return {};
}

}  // namespace

Result<CompressedClip> compress_clip(const SourceClip& clip, const SourceSkeleton& skeleton, float metres_per_unit,
                                     const ClipCompressionOptions& options) {
  CompressedClip out;
  out.name = clip.name;
  const std::string label = "clip '" + clip.name + "': ";
  if (!(std::isfinite(clip.duration) && clip.duration >= 0.0f)) return Error{label + "duration is not a finite time"};
  if (!(std::isfinite(clip.sample_rate) && clip.sample_rate >= 0.0f)) return Error{label + "sample rate is invalid"};
  const double frames_wanted = std::round(static_cast<double>(clip.duration) *
                                          (clip.sample_rate > 0.0f ? clip.sample_rate : kDefaultSampleRate)) + 1.0;
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
    if (t.joint >= joints) return Error{label + "a track addresses joint " + std::to_string(t.joint) + " of " +
                                        std::to_string(joints)};
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
    if (Status st = pack(layout, joints, frames, out); !st) return st.error();
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
      for (uint32_t j = 0; j < joints; ++j) ref_position_models[static_cast<size_t>(j) * ref_positions.frame_count + p] = at[j];
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
    if (Status st = pack(layout, joints, frames, out); !st) return st.error();
    decode_clip(out, skeleton, decoded, kErrorSubdivisions);
    error = measure_clip_error(skeleton, ref_positions, decoded, probe, ref_position_models.empty() ? nullptr : &ref_position_models,
                               kErrorSubdivisions);
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
  finish(error);
  return out;
}

}  // namespace ossa::cook
