// clip_compress_channel.cpp — steps 4 and 5 of the clip compressor for one channel (the design is
// in clip_compress.cpp's header): the channel error metric, classification (bind / constant /
// animated), key reduction, quantisation with the decoder-aware rotation encoding, and decoding a
// plan back exactly as the runtime decodes it.
//
// Why it is a file of its own: it sees one channel's samples only (the reference, the target and
// a lever), never the skeleton or the clip; the whole-clip order, compensation, packing and
// verification stay in clip_compress.cpp, and what the two share is clip_compress_internal.h.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <span>
#include <vector>

#include "cooker/clip/clip_compress_internal.h"
#include <ossa/format/clip_codec.h>

namespace ossa::cook::compress_detail {
namespace {

constexpr uint32_t kKeyFrameBits = 16;

// ---------------------------------------------------------------------------------------------
// Channel error and interpolation (the runtime's arithmetic)

/// A bound of the model-space displacement `decoded` causes where `reference` was intended.
double channel_error(const Metric& m, const glm::vec4& reference, const glm::vec4& decoded) {
  if (m.channel == kTranslation) {
    return glm::length(glm::dvec3(reference) - glm::dvec3(decoded)) * m.lever;
  }
  if (m.channel == kRotation) {
    const glm::dvec4 r = glm::normalize(glm::dvec4(reference));
    glm::dvec4 d = glm::normalize(glm::dvec4(decoded));
    if (glm::dot(r, d) < 0.0) d = -d;
    const double chord = glm::length(r - d);                                              // = 2 sin(angle / 4)
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

}  // namespace

// ---------------------------------------------------------------------------------------------
// 4-5. One channel: classification, keys and bits

bool all_equal(const glm::vec4* v, uint32_t n, const glm::vec4& value) {
  for (uint32_t f = 0; f < n; ++f)
    if (v[f] != value) return false;
  return true;
}

namespace {

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

}  // namespace

/// Greedy key removal on per-frame candidate key values (KeyFit::decoded): from each kept key, the
/// furthest next key whose interpolation keeps every frame between them, and the points between
/// frames (KeyFit::positions: the target at every position of kErrorSubdivisions per frame, as
/// between_frames makes it), within tolerance, for every channel of `fits` at once. The points
/// between frames matter where a channel turns fast: nlerp over a long span does not pass where two
/// nlerps over its halves do (two keys 72 degrees apart put the quarter point 2 degrees from the
/// midpoint of the first 36).
std::vector<uint16_t> reduce_keys(std::span<const KeyFit> fits, uint32_t n) {
  constexpr uint32_t kSub = kErrorSubdivisions;
  auto valid_one = [&](const KeyFit& fit, uint32_t a, uint32_t b) {
    const float inv_length = 1.0f / static_cast<float>(b - a);
    for (uint32_t p = a * kSub + 1; p < b * kSub; ++p) {
      const float x = static_cast<float>(p / kSub) + static_cast<float>(p % kSub) / static_cast<float>(kSub);
      const float alpha = (x - static_cast<float>(a)) * inv_length;
      const glm::vec4 v = interpolate_keys(fit.metric.channel, fit.decoded[a], fit.decoded[b], alpha);
      if (channel_error(fit.metric, fit.positions[p], v) > fit.tolerance) return false;
    }
    return true;
  };
  auto valid = [&](uint32_t a, uint32_t b) {
    for (const KeyFit& fit : fits)
      if (!valid_one(fit, a, b)) return false;
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

std::vector<glm::vec4> target_positions(uint32_t channel, const glm::vec4* target, uint32_t n) {
  std::vector<glm::vec4> positions((n - 1) * kErrorSubdivisions + 1);
  for (uint32_t p = 0; p < positions.size(); ++p) {
    const uint32_t f = p / kErrorSubdivisions, k = p % kErrorSubdivisions;
    positions[p] = k == 0 ? target[f]
                          : interpolate_keys(channel, target[f], target[f + 1],
                                             static_cast<float>(k) / static_cast<float>(kErrorSubdivisions));
  }
  return positions;
}

namespace {

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

glm::vec4 decode_code(uint32_t channel, uint32_t dropped, const KeyWidths& bits, const float lo[3],
                      const float extent[3], const Code& code) {
  float xyz[3];
  for (int c = 0; c < 3; ++c) {
    if (bits.raw()) std::memcpy(&xyz[c], &code[c], 4);
    else xyz[c] = dequantize(code[c], lo[c], extent[c], bits.c[c]);
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
  const KeyWidths raw = KeyWidths::uniform(kRawFloatBits);
  Code best = {float_bits(stored.x), float_bits(stored.y), float_bits(stored.z)};
  double best_error = channel_error(angle, ref, decode_code(kRotation, dropped, raw, zero, zero, best));
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
          const double e = channel_error(angle, ref, decode_code(kRotation, dropped, raw, zero, zero, code));
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
Code encode_quantized(const Metric& m, const glm::vec4& ref, const glm::vec4& stored, uint32_t dropped,
                      const KeyWidths& bits, const float lo[3], const float extent[3], double budget) {
  Code best;
  for (int c = 0; c < 3; ++c) best[c] = quantize(stored[c], lo[c], extent[c], bits.c[c]);
  if (m.channel != kRotation) return best;
  double best_error = channel_error(m, ref, decode_code(kRotation, dropped, bits, lo, extent, best));
  if (best_error <= budget) return best;
  const Code nearest = best;
  const int64_t qmax[3] = {quant_max(bits.c[0]), quant_max(bits.c[1]), quant_max(bits.c[2])};
  for (int adj = 0; adj < 3; ++adj) {
    float xyz[3];
    for (int c = 0; c < 3; ++c) xyz[c] = dequantize(nearest[c], lo[c], extent[c], bits.c[c]);
    const auto center =
        static_cast<int64_t>(quantize(solve_component(xyz, adj, stored.w), lo[adj], extent[adj], bits.c[adj]));
    const int a = (adj + 1) % 3, b = (adj + 2) % 3;
    for (int64_t d = -2; d <= 2; ++d) {
      for (int64_t da = -1; da <= 1; ++da) {
        for (int64_t db = -1; db <= 1; ++db) {
          Code code = nearest;
          const int64_t qa = static_cast<int64_t>(nearest[a]) + da, qb = static_cast<int64_t>(nearest[b]) + db;
          const int64_t qc = center + d;
          if (qa < 0 || qa > qmax[a] || qb < 0 || qb > qmax[b] || qc < 0 || qc > qmax[adj]) continue;
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
  plan.widths = KeyWidths::uniform(kRawFloatBits);
  plan.dropped = channel == kRotation ? choose_dropped(ref, n) : 0;
  plan.codes = raw_codes(channel, plan.dropped, ref, n);
  plan.frames.resize(n);
  for (uint32_t f = 0; f < n; ++f) plan.frames[f] = static_cast<uint16_t>(f);
  return plan;
}

}  // namespace

KeyWidths key_widths(uint32_t bits, const float extent[3]) {
  if (bits == kRawFloatBits) return KeyWidths::uniform(kRawFloatBits);
  const auto range = [&](int c) { return static_cast<double>(extent[c]); };
  const double step = std::max({range(0), range(1), range(2)}) / quant_max(bits);
  KeyWidths w;
  for (int c = 0; c < 3; ++c) {
    uint32_t b = 1;
    while (b < bits && range(c) / quant_max(b) > step) ++b;
    w.c[c] = b;
  }
  return w;
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

namespace {

/// `target`'s frames in the stored form of `plan.dropped`, and their range written to `plan`
/// (range_min, range_extent per stored component). O(n).
std::vector<glm::vec4> stored_with_range(uint32_t channel, const glm::vec4* target, uint32_t n, ChannelPlan& plan) {
  std::vector<glm::vec4> stored(n);
  glm::vec4 lo(std::numeric_limits<float>::max()), hi(-std::numeric_limits<float>::max());
  for (uint32_t f = 0; f < n; ++f) {
    stored[f] = stored_form(channel, plan.dropped, target[f]);
    lo = glm::min(lo, stored[f]);
    hi = glm::max(hi, stored[f]);
  }
  for (int c = 0; c < 3; ++c) {
    plan.range_min[c] = lo[c];
    plan.range_extent[c] = hi[c] - lo[c];
  }
  return stored;
}

}  // namespace

/// Step 5: keys and bits of an animated channel fitted to `target` (per frame) within tolerance.
ChannelPlan encode_animated(const Metric& m, const glm::vec4* target, uint32_t n, double tolerance) {
  ChannelPlan plan;
  plan.kind = Kind::Animated;
  plan.dropped = m.channel == kRotation ? choose_dropped(target, n) : 0;
  const std::vector<glm::vec4> stored = stored_with_range(m.channel, target, n, plan);

  // Raw floats: the fallback, and (its key count) the floor no bit count can go below.
  std::vector<glm::vec4> dec(n);
  plan.bits = kRawFloatBits;
  plan.widths = KeyWidths::uniform(kRawFloatBits);
  plan.codes = raw_codes(m.channel, plan.dropped, target, n);
  for (uint32_t f = 0; f < n; ++f) {
    dec[f] = decode_code(m.channel, plan.dropped, plan.widths, plan.range_min, plan.range_extent, plan.codes[f]);
  }
  // Keys at every frame share one run of key_frames with every other such channel (pack), so
  // their frames cost nothing; a reduced set pays kKeyFrameBits per key.
  std::vector<uint16_t> all_frames(n);
  for (uint32_t f = 0; f < n; ++f) all_frames[f] = static_cast<uint16_t>(f);
  uint64_t best_cost = std::numeric_limits<uint64_t>::max();
  auto consider = [&](uint32_t bits, const KeyWidths& widths, std::vector<uint16_t> frames) {
    const uint64_t all_cost = n * widths.total();
    const uint64_t reduced_cost = frames.size() * (widths.total() + kKeyFrameBits);
    if (std::min(all_cost, reduced_cost) >= best_cost) return false;
    best_cost = std::min(all_cost, reduced_cost);
    plan.bits = bits;
    plan.widths = widths;
    plan.frames = all_cost <= reduced_cost ? all_frames : std::move(frames);
    return true;
  };
  // The target at every position between frames too, as the runtime would play it keyed at every
  // frame (what verification measures against).
  const std::vector<glm::vec4> positions = target_positions(m.channel, target, n);
  auto reduce = [&] {
    const KeyFit fit{m, positions.data(), dec.data(), tolerance};
    return reduce_keys(std::span<const KeyFit>(&fit, 1), n);
  };
  std::vector<uint16_t> raw_frames = reduce();
  const size_t floor_keys = raw_frames.size();
  consider(kRawFloatBits, plan.widths, std::move(raw_frames));

  // Widths grow with bits, so the first bit count whose cheapest possible cost cannot beat the
  // best found ends the search.
  std::vector<Code> codes(n);
  for (uint32_t bits = 1; bits <= kMaxQuantBits; ++bits) {
    const KeyWidths widths = key_widths(bits, plan.range_extent);
    const uint64_t lowest = std::min<uint64_t>(n * widths.total(), floor_keys * (widths.total() + kKeyFrameBits));
    if (lowest >= best_cost) break;
    bool holds = true;
    for (uint32_t f = 0; f < n && holds; ++f) {
      codes[f] =
          encode_quantized(m, target[f], stored[f], plan.dropped, widths, plan.range_min, plan.range_extent, tolerance);
      dec[f] = decode_code(m.channel, plan.dropped, widths, plan.range_min, plan.range_extent, codes[f]);
      holds = channel_error(m, target[f], dec[f]) <= tolerance;
    }
    if (holds && consider(bits, widths, reduce())) plan.codes = codes;
  }
  return plan;
}

ChannelPlan refit_animated(const Metric& m, const glm::vec4* target, uint32_t n, double tolerance, uint32_t bits,
                           std::vector<uint16_t> frames) {
  ChannelPlan plan;
  plan.kind = Kind::Animated;
  plan.bits = bits;
  plan.frames = std::move(frames);
  plan.dropped = m.channel == kRotation ? choose_dropped(target, n) : 0;
  if (bits == kRawFloatBits) {
    plan.widths = KeyWidths::uniform(kRawFloatBits);
    plan.codes = raw_codes(m.channel, plan.dropped, target, n);
    return plan;
  }
  const std::vector<glm::vec4> stored = stored_with_range(m.channel, target, n, plan);
  plan.widths = key_widths(bits, plan.range_extent);
  plan.codes.resize(n);
  for (uint32_t f = 0; f < n; ++f)
    plan.codes[f] = encode_quantized(m, target[f], stored[f], plan.dropped, plan.widths, plan.range_min,
                                     plan.range_extent, tolerance);
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
      decode_code(channel, plan.dropped, plan.widths, plan.range_min, plan.range_extent, plan.codes[plan.frames[0]]);
  out[0] = prev;
  for (size_t k = 1; k < plan.frames.size(); ++k) {
    const glm::vec4 next =
        decode_code(channel, plan.dropped, plan.widths, plan.range_min, plan.range_extent, plan.codes[plan.frames[k]]);
    const uint32_t f0 = plan.frames[k - 1], f1 = plan.frames[k];
    const float inv_length = 1.0f / static_cast<float>(f1 - f0);
    for (uint32_t f = f0; f <= f1; ++f)
      out[f] = interpolate_keys(channel, prev, next, static_cast<float>(f - f0) * inv_length);
    prev = next;
  }
}

std::vector<glm::vec4> decode_codes(const ChannelPlan& plan, uint32_t channel, uint32_t n) {
  std::vector<glm::vec4> out(n);
  for (uint32_t f = 0; f < n; ++f)
    out[f] = decode_code(channel, plan.dropped, plan.widths, plan.range_min, plan.range_extent, plan.codes[f]);
  return out;
}

}  // namespace ossa::cook::compress_detail
