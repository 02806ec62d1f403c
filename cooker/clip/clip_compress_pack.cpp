// clip_compress_pack.cpp — the clip compressor's packing (the design is in clip_compress.cpp's
// header): channel plans to the bytes a file holds, as ossa/format/clip_codec.h defines them.
//
// Why it is a file of its own: packing runs once per verification round and is the one place
// that chooses a channel's layout. A channel keyed at every frame is segmented (16 keys per
// segment, each with its own minimum code and width per component) when that saves a sixth of its
// plain keys' bits or more (segmenting_pays): the codes are the same, so the choice changes bytes
// and seek time, never values. Long mocap gains most (CMU 01_03: ~16% fewer bytes); a short
// clip's single segment rarely pays for its header.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <map>
#include <string>
#include <vector>

#include "cooker/clip/clip_compress_internal.h"
#include <ossa/format/clip_codec.h>
#include <ossa/format/ossa_generated.h>

namespace ossa::cook::compress_detail {
namespace {

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

/// A segmented layout of an every-frame channel: per segment, each component's minimum code and
/// width; the data offsets' width; the channel's bits in all (headers and keys). offset_bits 0:
/// none fits.
struct Segments {
  uint32_t offset_bits = 0;
  std::vector<std::array<uint32_t, 3>> min, width;
  uint64_t bits = 0;
};

/// Bits needed to hold v (0 for 0).
uint32_t bit_width(uint64_t v) {
  uint32_t w = 0;
  while (w < 64 && (v >> w) != 0) ++w;
  return w;
}

/// The segments of plan p's codes over `frames` keys: each component's minimum and the fewest bits
/// that reach its maximum, the minimum lowered where those bits would pass the channel's largest
/// code (the loader checks min + 2^w - 1 stays inside). O(frames).
Segments plan_segments(const ChannelPlan& p, uint32_t frames) {
  Segments s;
  const uint32_t count = segment_count(frames);
  s.min.resize(count);
  s.width.resize(count);
  uint64_t data = 0, before_last = 0;
  for (uint32_t g = 0; g < count; ++g) {
    const uint32_t first = g * kSegmentKeys, n = std::min(kSegmentKeys, frames - first);
    uint64_t key_bits = 0;
    for (uint32_t c = 0; c < 3; ++c) {
      uint32_t lo = std::numeric_limits<uint32_t>::max(), hi = 0;
      for (uint32_t f = first; f < first + n; ++f) {
        lo = std::min(lo, p.codes[f][c]);
        hi = std::max(hi, p.codes[f][c]);
      }
      const uint32_t w = bit_width(hi - lo);
      s.width[g][c] = w;
      s.min[g][c] = std::min(lo, quant_max(p.widths.c[c]) - quant_max(w));
      key_bits += w;
    }
    if (g + 1 == count) before_last = data;
    data += key_bits * n;
  }
  for (uint32_t o = 1; o <= kMaxSegmentOffsetBits; ++o) {
    const uint64_t headers = segment_header_bits(p.widths, o) * count;
    if (bit_width(headers + before_last) <= o) {
      s.offset_bits = o;
      s.bits = headers + data;
      break;
    }
  }
  return s;
}

/// Whether a channel is segmented: when its segments take at most 5/6 of its plain keys' bits.
/// A seek into a segmented channel decodes a header before its keys (CMU 01_03, Zen 5: random
/// access ~1.6x the plain keys' time with every channel segmented), so the small savings are left
/// plain: at 5/6 CMU 01_03 keeps ~85% of the bytes segmenting saves and seeks ~0.9x ACL's time.
bool segmenting_pays(uint64_t segmented_bits, uint64_t plain_bits) { return segmented_bits * 6 <= plain_bits * 5; }

/// Writes plan p's keys in the segmented layout `s` (clip_codec.h: headers, then keys).
void write_segments(const ChannelPlan& p, const Segments& s, uint32_t frames, KeyWriter& writer) {
  const auto count = static_cast<uint32_t>(s.min.size());
  uint64_t data = segment_header_bits(p.widths, s.offset_bits) * count;
  for (uint32_t g = 0; g < count; ++g) {
    for (uint32_t c = 0; c < 3; ++c) writer.write(s.width[g][c], kSegmentWidthBits);
    writer.write(static_cast<uint32_t>(data), s.offset_bits);
    for (uint32_t c = 0; c < 3; ++c) writer.write(s.min[g][c], p.widths.c[c]);
    const uint32_t n = std::min(kSegmentKeys, frames - g * kSegmentKeys);
    data += (uint64_t{s.width[g][0]} + s.width[g][1] + s.width[g][2]) * n;
  }
  for (uint32_t f = 0; f < frames; ++f) {
    const uint32_t g = f / kSegmentKeys;
    for (uint32_t c = 0; c < 3; ++c) writer.write(p.codes[f][c] - s.min[g][c], s.width[g][c]);
  }
}

}  // namespace

Status pack(const std::vector<ChannelPlan>& plans, uint32_t joints, uint32_t frames, CompressedClip& out) {
  out.constants.clear();
  out.animated.clear();
  out.key_frames.clear();
  KeyWriter writer;
  // Identical key frame lists share one run, found through an ordered map (deterministic).
  std::map<std::vector<uint16_t>, uint32_t> shared_frames;
  for (uint32_t j = 0; j < joints; ++j) {
    for (uint32_t ch = 0; ch < kChannelsPerJoint; ++ch) {
      const ChannelPlan& p = plans[j * 3 + ch];
      if (p.kind == Kind::Bind) continue;
      if (p.kind == Kind::Constant) {
        CompressedConstant c;
        c.joint = static_cast<uint16_t>(j);
        c.channel = static_cast<uint8_t>(ch);
        for (int i = 0; i < 4; ++i) c.value[i] = p.constant[i];
        if (ch != kRotation) {
          c.value[3] = 0.0f;
        } else {  // stored as three components: the value is what a reader rebuilds
          c.dropped = static_cast<uint8_t>(largest_component(c.value));
          float stored[3];
          rotation_to_stored(c.value, c.dropped, stored);
          rotation_from_stored(stored, c.dropped, c.value);
        }
        out.constants.push_back(c);
        continue;
      }
      CompressedAnimated a;
      a.joint = static_cast<uint16_t>(j);
      a.channel = static_cast<uint8_t>(ch);
      a.bits = p.widths;
      a.dropped = static_cast<uint8_t>(ch == kRotation ? p.dropped : 0);  // 0 for other channels
      a.key_count = static_cast<uint32_t>(p.frames.size());
      if (!keyed_every_frame(a.key_count, frames)) {  // an every-frame channel stores no frames
        const auto [it, inserted] = shared_frames.emplace(p.frames, static_cast<uint32_t>(out.key_frames.size()));
        if (inserted) out.key_frames.insert(out.key_frames.end(), p.frames.begin(), p.frames.end());
        a.first_key = it->second;
      }
      if (p.widths.raw()) writer.align_byte();
      if (writer.bit_size() > std::numeric_limits<uint32_t>::max()) {
        return Error{"clip '" + out.name + "': compressed keys exceed 4 Gbit"};
      }
      a.bit_offset = static_cast<uint32_t>(writer.bit_size());
      for (int c = 0; c < 3; ++c) {
        a.range_min[c] = p.widths.raw() ? 0.0f : p.range_min[c];
        a.range_extent[c] = p.widths.raw() ? 0.0f : p.range_extent[c];
      }
      const Segments seg =
          keyed_every_frame(a.key_count, frames) && !p.widths.raw() ? plan_segments(p, frames) : Segments{};
      if (seg.offset_bits != 0 && segmenting_pays(seg.bits, p.widths.total() * a.key_count)) {
        a.segment_offset_bits = static_cast<uint8_t>(seg.offset_bits);
        write_segments(p, seg, a.key_count, writer);
      } else {
        for (const uint16_t f : p.frames)
          for (int c = 0; c < 3; ++c) writer.write(p.codes[f][c], p.widths.c[c]);
      }
      out.animated.push_back(a);
    }
  }
  if (writer.bit_size() > std::numeric_limits<uint32_t>::max()) {
    return Error{"clip '" + out.name + "': compressed keys exceed 4 Gbit"};
  }
  out.key_values = writer.finish();
  out.cooked_bytes = static_cast<uint32_t>(out.constants.size() * sizeof(fb::ConstantChannel) +
                                           out.animated.size() * sizeof(fb::AnimatedChannel) +
                                           out.key_frames.size() * sizeof(uint16_t) + out.key_values.size());
  return {};
}

}  // namespace ossa::cook::compress_detail
