// validate_clip.cpp — the loader's checks of a file's clips (validate.h lists them): channels,
// key frames and key bits, ranges, events, root motion and morph weight tracks. Part of the
// Validator (internal/validator.h) that validate.cpp runs.
//
// Why it is a file of its own: clips are the table family the sampler dereferences most (key
// ranges, bit offsets, padding), and their invariants are those of ossa/format/clip_codec.h, which
// only this file needs.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include <ossa/format/clip_codec.h>
#include "common/message.h"
#include "internal/validator.h"

namespace ossa::validate_detail {

// ---- clips ----
//
// Everything the sampler (runtime/anim/sample*.cpp) and root_motion.cpp dereference is proven here,
// before any of them runs: channel joints < joint_count, each animated channel keyed at every
// frame or its key range inside key_frames, and its bit range inside key_values minus the 8 padding bytes the decoder's
// 64-bit reads may touch, frames strictly increasing from 0 to frame_count - 1 (so a cursor or a
// binary search always finds a bracketing pair), ranges finite (so decoded values are), raw-float
// keys finite, rotations bounded (so normalizing never divides by zero or infinity).

namespace {

/// Where a segmented channel's keys end (a bit position of key_values), its headers read in
/// order: each segment's keys start where the previous segment's end (the first right after the
/// headers), and each width w and minimum m leave m + 2^w - 1 inside the channel's codes, so
/// every key decodes to a code the plain layout could hold. Empty, or what is wrong. O(segments).
std::string segments_end(const uint8_t* values, uint64_t value_bits, uint64_t offset, const KeyWidths& bits,
                         uint32_t offset_bits, uint32_t n, uint64_t& end) {
  const uint32_t segments = segment_count(n);
  const uint64_t headers = segment_header_bits(bits, offset_bits) * segments;
  if (offset + headers > value_bits)
    return format(": its %u segment headers need key value bits [%llu, %llu), the clip has %llu (before padding)",
                  segments, static_cast<unsigned long long>(offset), static_cast<unsigned long long>(offset + headers),
                  static_cast<unsigned long long>(value_bits));
  uint64_t data = headers;
  for (uint32_t s = 0; s < segments; ++s) {
    const SegmentHeader h = read_segment(values, offset, bits, offset_bits, s);
    if (h.data != data)
      return format(": segment %u's keys start at bit %llu of the channel, not %llu where the previous end", s,
                    static_cast<unsigned long long>(h.data), static_cast<unsigned long long>(data));
    for (uint32_t c = 0; c < 3; ++c)
      if (h.widths.c[c] > bits.c[c] || uint64_t{h.min[c]} + quant_max(h.widths.c[c]) > quant_max(bits.c[c]))
        return format(": segment %u's component %u (minimum %u, %u bits) leaves the channel's %u-bit codes", s, c,
                      h.min[c], h.widths.c[c], bits.c[c]);
    data += h.widths.total() * std::min(kSegmentKeys, n - s * kSegmentKeys);
  }
  end = offset + data;
  return {};
}

}  // namespace

/// "animated channel 3 (joint 5 'Hips' rotation)".
std::string Validator::channel_label(const char* kind, size_t index, size_t joint, unsigned channel,
                                     bool binds_here) const {
  const char* cn = channel <= static_cast<unsigned>(fb::Channel::MAX)
                       ? fb::EnumNameChannel(static_cast<fb::Channel>(channel))
                       : "unknown channel";
  return format("%s channel %zu (", kind, index) + (binds_here ? joint_label(joint) : format("joint %zu", joint)) +
         " " + cn + ")";
}

/// Sort key of a (joint, channel) pair.
uint32_t Validator::channel_key(uint16_t joint, fb::Channel channel) {
  return (static_cast<uint32_t>(joint) << 8) | static_cast<uint8_t>(channel);
}

Status Validator::check_clip(const fb::Clip& c, size_t clip_index) {
  const Where where{nullptr, "clip", clip_index, c.name()};
  const float rate = c.sample_rate();
  if (!std::isfinite(rate) || !(rate > 0.0f))
    return fail(where, format("sample rate %g must be a finite number > 0", rate));
  const uint32_t frame_count = c.frame_count();
  if (frame_count < 1 || frame_count > 65536)
    return fail(where, format("frame count %u must be in 1..65536 (frames are 16-bit)", frame_count));
  const float duration = c.duration();
  const double expected = static_cast<double>(frame_count - 1) / rate;
  if (!std::isfinite(duration) || std::fabs(duration - expected) > 1e-4 * expected + 1e-7)
    return fail(where, format("duration %g s does not match %u frames at %g frames/s (%g s)", duration, frame_count,
                              rate, expected));
  const size_t joint_count = c.joint_count();
  const bool binds_here = skeleton_ && c.skeleton_hash() == skeleton_->hash();
  if (binds_here && joint_count != joint_count_)
    return fail(where, format("addresses %s, but its skeleton (this file's, by hash) has %zu",
                              count_text(joint_count, "joint").c_str(), joint_count_));

  // Constant channels.
  const size_t constant_count = count_of(c.constants());
  if (!spend(static_cast<uint64_t>(constant_count) * sizeof(fb::ConstantChannel))) return over_budget(where);
  for (size_t k = 0; k < constant_count; ++k) {
    const fb::ConstantChannel& ch = *c.constants()->Get(static_cast<flatbuffers::uoffset_t>(k));
    const auto channel = static_cast<unsigned>(ch.channel());
    const auto cl = [&] { return channel_label("constant", k, ch.joint(), channel, binds_here); };
    if (channel > static_cast<unsigned>(fb::Channel::MAX))
      return fail(where, cl() + format(" has unknown channel %u", channel));
    if (ch.joint() >= joint_count)
      return fail(where, cl() + format(" addresses a joint past the clip's joint count %zu", joint_count));
    if (k > 0) {
      const fb::ConstantChannel& prev = *c.constants()->Get(static_cast<flatbuffers::uoffset_t>(k - 1));
      if (channel_key(ch.joint(), ch.channel()) <= channel_key(prev.joint(), prev.channel()))
        return fail(where, cl() + format(" is not after constant channel %zu: channels are sorted by (joint, "
                                         "channel), each at most once",
                                         k - 1));
    }
    if (ch.channel() == fb::Channel::Rotation) {
      // Three stored components in [-1, 1] rebuild a quaternion the sampler can normalize (all
      // zero rebuilds w = 1; otherwise the norm is that of a non-zero vector of unit-bounded values).
      if (ch.dropped() > 3)
        return fail(where, cl() + format(" has dropped component %u; must be 0..3 (x, y, z, w)", ch.dropped()));
      const fb::Vec3& v = ch.value();
      for (const float x : {v.x(), v.y(), v.z()})
        if (!(std::fabs(x) <= kRotationComponentLimit))
          return fail(where, cl() + format(": rotation value %s is not three finite quaternion components in [-1, 1]",
                                           vec3_text(v).c_str()));
    } else if (!bounded3(ch.value())) {
      return fail(where, cl() + ": value is not finite (or beyond 1e7)");
    }
  }

  // Animated channels.
  const size_t animated_count = count_of(c.animated());
  const size_t frame_total = count_of(c.key_frames());
  const size_t value_bytes = count_of(c.key_values());
  if (!spend(static_cast<uint64_t>(animated_count) * sizeof(fb::AnimatedChannel))) return over_budget(where);
  if (animated_count > 0 && value_bytes < kKeyValuePadding)
    return fail(where, format("key values are %zu bytes, less than the %u padding bytes decoders read past the "
                              "last key",
                              value_bytes, kKeyValuePadding));
  const uint64_t value_bits = value_bytes >= kKeyValuePadding ? 8ull * (value_bytes - kKeyValuePadding) : 0;
  const uint16_t* frames = c.key_frames() ? c.key_frames()->data() : nullptr;
  const uint8_t* values = c.key_values() ? c.key_values()->data() : nullptr;
  size_t next_constant = 0;  // merge walk: both lists are sorted, so disjointness is one pass
  for (size_t k = 0; k < animated_count; ++k) {
    const fb::AnimatedChannel& ch = *c.animated()->Get(static_cast<flatbuffers::uoffset_t>(k));
    const auto channel = static_cast<unsigned>(ch.channel());
    const auto cl = [&] { return channel_label("animated", k, ch.joint(), channel, binds_here); };
    if (channel > static_cast<unsigned>(fb::Channel::MAX))
      return fail(where, cl() + format(" has unknown channel %u", channel));
    if (ch.joint() >= joint_count)
      return fail(where, cl() + format(" addresses a joint past the clip's joint count %zu", joint_count));
    const uint32_t key = channel_key(ch.joint(), ch.channel());
    if (k > 0) {
      const fb::AnimatedChannel& prev = *c.animated()->Get(static_cast<flatbuffers::uoffset_t>(k - 1));
      if (key <= channel_key(prev.joint(), prev.channel()))
        return fail(where, cl() + format(" is not after animated channel %zu: channels are sorted by (joint, "
                                         "channel), each at most once",
                                         k - 1));
    }
    while (next_constant < constant_count) {
      const fb::ConstantChannel& cc = *c.constants()->Get(static_cast<flatbuffers::uoffset_t>(next_constant));
      const uint32_t ck = channel_key(cc.joint(), cc.channel());
      if (ck > key) break;
      if (ck == key) return fail(where, cl() + format(" is also constant channel %zu", next_constant));
      ++next_constant;
    }

    // Keys: a key on every frame (no key frames stored, first_key 0), or a range inside
    // key_frames, frames strictly increasing from 0 to the last frame.
    const uint32_t n = ch.key_count();
    if (n < 2) return fail(where, cl() + format(" has %u keys; an animated channel has at least 2", n));
    if (n > frame_count)
      return fail(where, cl() + format(" has %u keys, more than the clip's %u frames", n, frame_count));
    const uint64_t first = ch.first_key();
    if (keyed_every_frame(n, frame_count)) {
      if (first != 0)
        return fail(where, cl() + format(" has a key on every frame and first_key %llu; it stores no key frames, so "
                                         "first_key must be 0",
                                         static_cast<unsigned long long>(first)));
    } else {
      if (first + n > frame_total)
        return fail(where, cl() + format(" uses keys [%llu, %llu), past the %zu key frames",
                                         static_cast<unsigned long long>(first),
                                         static_cast<unsigned long long>(first + n), frame_total));
      if (!spend(static_cast<uint64_t>(n) * sizeof(uint16_t))) return over_budget(where);
      const uint16_t* f = frames + first;
      if (f[0] != 0) return fail(where, cl() + format(": first key is at frame %u, must be 0", f[0]));
      for (uint32_t i = 1; i < n; ++i)
        if (!(f[i] > f[i - 1]))
          return fail(where, cl() + format(": key %u at frame %u is not after key %u at frame %u (frames must "
                                           "strictly increase)",
                                           i, f[i], i - 1, f[i - 1]));
      if (f[n - 1] != frame_count - 1)
        return fail(where,
                    cl() + format(": last key is at frame %u, must be the last frame %u", f[n - 1], frame_count - 1));
    }

    // Bits: a width per component, each 1..19, or raw floats (all three 32); inside key_values,
    // minus the padding.
    const KeyWidths widths = widths_of(ch);
    const bool raw = widths.raw();
    bool widths_ok = true;
    for (const uint32_t w : widths.c)
      widths_ok = widths_ok && (raw ? w == kRawFloatBits : w >= 1 && w <= kMaxQuantBits);
    if (!widths_ok)
      return fail(where, cl() + format(" has %u, %u, %u bits for its components; each must be 1..%u, or all three 32",
                                       widths.c[0], widths.c[1], widths.c[2], kMaxQuantBits));
    // Rotations name the component they leave out (0..3). Other channels ignore the field (the
    // schema asks writers for 0 there, but nothing reads it, so a reader need not insist).
    const bool rotation = ch.channel() == fb::Channel::Rotation;
    if (rotation && ch.dropped() > 3)
      return fail(where, cl() + format(" has dropped component %u; must be 0..3 (x, y, z, w)", ch.dropped()));
    const uint64_t offset = ch.bit_offset();
    if (raw && offset % 8 != 0)
      return fail(where, cl() + format(": raw-float keys start at bit %llu, not on a byte boundary",
                                       static_cast<unsigned long long>(offset)));
    const uint32_t offset_bits = ch.segment_offset_bits();
    uint64_t end = offset + widths.total() * n;
    if (offset_bits != 0) {
      if (raw || offset_bits > kMaxSegmentOffsetBits || !keyed_every_frame(n, frame_count))
        return fail(where, cl() + format(" has segment_offset_bits %u; segments need 1..%u, quantized keys and a "
                                         "key on every frame",
                                         offset_bits, kMaxSegmentOffsetBits));
      if (!spend(uint64_t{segment_count(n)} * 16)) return over_budget(where);
      if (std::string why = segments_end(values, value_bits, offset, widths, offset_bits, n, end); !why.empty())
        return fail(where, cl() + why);
    }
    if (end > value_bits)
      return fail(where, cl() + format(" needs key value bits [%llu, %llu), the clip has %llu (before padding)",
                                       static_cast<unsigned long long>(offset), static_cast<unsigned long long>(end),
                                       static_cast<unsigned long long>(value_bits)));

    // Ranges: finite, extents >= 0, and the top of the range finite, so every decoded value
    // (lo + extent * q / max <= lo + extent) is.
    const fb::Vec3& lo = ch.range_min();
    const fb::Vec3& ex = ch.range_extent();
    const float los[3] = {lo.x(), lo.y(), lo.z()}, exs[3] = {ex.x(), ex.y(), ex.z()};
    if (!raw) {
      for (int i = 0; i < 3; ++i) {
        if (!bounded(los[i]) || !bounded(exs[i]) || !(exs[i] >= 0.0f) || !bounded(los[i] + exs[i]))
          return fail(where, cl() + format(": range min %s extent %s must be finite (within 1e7) with extents >= 0",
                                           vec3_text(lo).c_str(), vec3_text(ex).c_str()));
        if (rotation && (los[i] < -kRotationComponentLimit || los[i] + exs[i] > kRotationComponentLimit))
          return fail(where, cl() + format(": rotation range min %s extent %s leaves [-1, 1]", vec3_text(lo).c_str(),
                                           vec3_text(ex).c_str()));
      }
    } else {
      // Raw floats carry their own values: scan them (O(keys), once, at load).
      if (!spend(static_cast<uint64_t>(n) * 12)) return over_budget(where);
      const uint8_t* raw_keys = values + offset / 8;
      for (uint32_t i = 0; i < n; ++i) {
        float v[3];
        std::memcpy(v, raw_keys + 12ull * i, sizeof v);
        for (int j = 0; j < 3; ++j) {
          if (!bounded(v[j])) return fail(where, cl() + format(": raw key %u is not finite (or beyond 1e7)", i));
          if (rotation && std::fabs(v[j]) > kRotationComponentLimit)
            return fail(where, cl() + format(": raw rotation key %u component %g leaves [-1, 1]", i, v[j]));
        }
      }
    }
  }

  // Root motion: one sample per frame, finite.
  if (const fb::RootMotion* rm = c.root_motion()) {
    const size_t nt = rm->translations()->size(), ny = rm->yaws()->size();
    if (nt != frame_count || ny != frame_count)
      return fail(where,
                  format("root motion has %zu translations and %zu yaws, the clip has %u frames", nt, ny, frame_count));
    if (rm->up_axis() > 2) return fail(where, format("root motion up axis %u must be 0, 1 or 2", rm->up_axis()));
    if (!spend(static_cast<uint64_t>(frame_count) * 16)) return over_budget(where);
    for (size_t i = 0; i < nt; ++i) {
      const auto idx = static_cast<flatbuffers::uoffset_t>(i);
      if (!finite3(*rm->translations()->Get(idx)) || !std::isfinite(rm->yaws()->Get(idx)))
        return fail(where, format("root motion frame %zu is not finite", i));
    }
  }

  // Events: named, finite, inside the clip, sorted by time (the graph's event scan relies on it).
  if (const auto* events = c.events()) {
    if (!spend(static_cast<uint64_t>(events->size()) * 8)) return over_budget(where);
    float previous = 0.0f;
    for (flatbuffers::uoffset_t i = 0; i < events->size(); ++i) {
      const fb::ClipEvent& e = *events->Get(i);
      if (flatbuffers::GetStringView(e.name()).empty()) return fail(where, format("event %u has an empty name", i));
      const float t = e.time();
      if (!std::isfinite(t) || t < 0.0f || t > duration)
        return fail(where, format("event %u '%s' at %g s lies outside the clip [0, %g s]", i,
                                  detail::printable(flatbuffers::GetStringView(e.name())).c_str(), t, duration));
      if (t < previous)
        return fail(where, format("event %u at %g s comes before event %u's %g s: not sorted", i, t, i - 1, previous));
      previous = t;
    }
  }
  return check_morph_weights(c, where);
}

/// Weight tracks: sorted by name (so a binder can merge-walk them), keys as for animated channels
/// but a single key is a constant, values one per key, ranges bounded (see kMaxMorphWeight).
Status Validator::check_morph_weights(const fb::Clip& c, const Where& clip_where) {
  const auto* tracks = c.morph_weights();
  if (!tracks) return {};
  if (!spend(static_cast<uint64_t>(tracks->size()) * 48)) return over_budget(clip_where);
  std::string_view previous;
  for (flatbuffers::uoffset_t t = 0; t < tracks->size(); ++t) {
    const fb::MorphTrack& track = *tracks->Get(t);
    const std::string_view name = flatbuffers::GetStringView(track.name());
    const Where where{&clip_where, "morph weight track", t, track.name()};
    if (name.empty()) return fail(where, "has an empty name");
    if (t > 0 && !(name > previous))
      return fail(where, "is not after track " + std::to_string(t - 1) + " '" + detail::printable(previous) +
                             "': tracks are sorted by name, each name once");
    previous = name;
    const size_t n = track.key_frames()->size();
    if (n < 1) return fail(where, "has no keys");
    if (track.values()->size() != n)
      return fail(where, format("has %zu key frames but %u values", n, track.values()->size()));
    if (!spend(static_cast<uint64_t>(n) * 4)) return over_budget(where);
    const uint16_t* f = track.key_frames()->data();
    if (f[0] != 0) return fail(where, format("first key is at frame %u, must be 0", f[0]));
    for (size_t i = 1; i < n; ++i)
      if (!(f[i] > f[i - 1]))
        return fail(where, format("key %zu at frame %u is not after key %zu at frame %u (frames must strictly "
                                  "increase)",
                                  i, f[i], i - 1, f[i - 1]));
    if (n > 1 && f[n - 1] != c.frame_count() - 1)
      return fail(where, format("last key is at frame %u, must be the last frame %u", f[n - 1], c.frame_count() - 1));
    const float lo = track.range_min(), ex = track.range_extent();
    if (!std::isfinite(lo) || !std::isfinite(ex) || ex < 0.0f || std::fabs(lo) > kMaxMorphWeight ||
        std::fabs(lo + ex) > kMaxMorphWeight)
      return fail(where, format("weight range min %g extent %g must be finite within +-%g, extent >= 0", lo, ex,
                                kMaxMorphWeight));
    if (!std::isfinite(track.max_error()) || !(track.max_error() >= 0.0f))
      return fail(where, format("recorded error %g must be finite and >= 0", track.max_error()));
  }
  return {};
}

}  // namespace ossa::validate_detail
