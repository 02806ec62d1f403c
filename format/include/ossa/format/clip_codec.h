// clip_codec.h — the key encoding of compressed clips (format/ossa.fbs, AnimatedChannel), one
// definition for the cooker that packs keys and the runtime that unpacks them.
//
// Keys are three components of 1..19 bits each (a width per component: KeyWidths), packed
// LSB-first into a byte stream, each component range-reduced to its channel's [min, min + extent].
// A width per component rather than one per channel: a rotation that turns mostly about one axis
// (a knee, an elbow) spans a wide range in one stored component and almost none in the others,
// which then need a few bits for the same step instead of all of them. Rotations drop one component
// per channel (stored with that component >= 0): like ACL's drop-w format, range reduction then
// buys 3-5 bits per component over smallest-three's fixed range and no per-key selector bits are
// needed; unlike always dropping w, choosing the component that stays largest over the channel
// keeps the rebuilt component precise near half turns. Widths of 32 store raw floats: the escape
// for channels no quantization can hold within tolerance (and for lossless cooks).
//
// A channel keyed at every frame may be segmented (AnimatedChannel.segment_offset_bits > 0): its
// keys go in segments of kSegmentKeys, each with its own minimum code and width per component, so
// a long clip pays for the range each 16-frame stretch covers rather than the whole clip's (ACL's
// segments; on CMU mocap ~20% fewer key bits, headers included). The codes are the channel's own
// (a lossless re-packing of the plain layout), so range, dequantization and error are unchanged.
// Layout at bit_offset: the segments' headers, then their keys. Header s is segment_header_bits
// long, at bit_offset + s * that: the three widths (kSegmentWidthBits each, 0..bits[c]), the bit
// position of its first key relative to bit_offset (segment_offset_bits bits), the three minimum
// codes (bits[c] bits each); key i of the segment follows at that position + i * (the three
// widths summed), component c decoding to minimum + field. Random access stays O(1): a header
// read, then the key. Widths and position come first so that one 64-bit read gives the key's
// address, and the minima's read runs beside the key's.
//
// Decoding reads 64 bits at a time: the stream must be followed by at least 8 readable bytes
// (kKeyValuePadding), which the writer appends and the loader checks.
#pragma once
#include <cmath>
#include <cstdint>
#include <cstring>
#include <vector>

namespace ossa {

inline constexpr uint32_t kKeyValuePadding = 8;
inline constexpr uint32_t kRawFloatBits = 32;
/// 3 * 19 = 57 bits: one unaligned 64-bit read holds a key at any bit position.
inline constexpr uint32_t kMaxQuantBits = 19;

/// Largest quantized value for a bit count in 1..kMaxQuantBits.
constexpr uint32_t quant_max(uint32_t bits) { return (1u << bits) - 1u; }

/// The widths of a key's three stored components (AnimatedChannel.bits): each 1..kMaxQuantBits,
/// or all three kRawFloatBits.
struct KeyWidths {
  uint32_t c[3] = {0, 0, 0};
  constexpr bool raw() const { return c[0] == kRawFloatBits; }
  /// Bits one key takes.
  constexpr uint64_t total() const { return uint64_t{c[0]} + c[1] + c[2]; }
  /// Bit position of component i within a key.
  constexpr uint32_t shift(uint32_t i) const { return i == 0 ? 0 : (i == 1 ? c[0] : c[0] + c[1]); }
  static KeyWidths uniform(uint32_t bits) { return KeyWidths{{bits, bits, bits}}; }
  bool operator==(const KeyWidths&) const = default;
};

/// The widths of a channel record (fb::AnimatedChannel or anything with its bits() array).
template <class Channel>
KeyWidths widths_of(const Channel& ch) {
  return KeyWidths{{ch.bits()->Get(0), ch.bits()->Get(1), ch.bits()->Get(2)}};
}

/// Quantizes v in [lo, lo + extent] to bits (1..kMaxQuantBits), rounding to nearest, clamped.
inline uint32_t quantize(float v, float lo, float extent, uint32_t bits) {
  if (!(extent > 0.0f)) return 0;
  float u = (v - lo) / extent;
  u = u < 0.0f ? 0.0f : (u > 1.0f ? 1.0f : u);
  return static_cast<uint32_t>(std::lround(u * static_cast<float>(quant_max(bits))));
}
/// The value of code q. Never -0 (see decode_key): lo + 0 turns a lo of -0 into +0, and a sum
/// whose first term is not -0 is not -0.
inline float dequantize(uint32_t q, float lo, float extent, uint32_t bits) {
  return (lo + 0.0f) + extent * (static_cast<float>(q) / static_cast<float>(quant_max(bits)));
}

/// Reads `count` (<= 57) bits at bit position `bit` of a padded stream.
inline uint64_t read_bits(const uint8_t* stream, uint64_t bit, uint32_t count) {
  uint64_t word;
  std::memcpy(&word, stream + (bit >> 3), 8);  // little-endian host assumed (as FlatBuffers does)
  return (word >> (bit & 7u)) & ((count >= 64 ? 0 : (1ull << count)) - 1ull);
}

inline constexpr uint32_t kSegmentKeys = 16;
inline constexpr uint32_t kSegmentWidthBits = 5;
/// Widest segment data offset (AnimatedChannel.segment_offset_bits: 1..this, 0 for plain keys).
inline constexpr uint32_t kMaxSegmentOffsetBits = 32;

/// Segments of a segmented channel of `key_count` keys.
constexpr uint32_t segment_count(uint32_t key_count) { return (key_count + kSegmentKeys - 1) / kSegmentKeys; }
/// Bits of one segment header of a channel of widths `bits` and data offsets of `offset_bits`.
constexpr uint64_t segment_header_bits(const KeyWidths& bits, uint32_t offset_bits) {
  return offset_bits + bits.total() + 3 * kSegmentWidthBits;
}

/// One segment's header: where its keys start (from the channel's bit_offset), each component's
/// minimum code and width (0..the channel's).
struct SegmentHeader {
  uint64_t data = 0;
  uint32_t min[3] = {0, 0, 0};
  KeyWidths widths;
};

/// Header of segment `segment` of a segmented channel. O(1): three reads.
inline SegmentHeader read_segment(const uint8_t* stream, uint64_t bit_offset, const KeyWidths& bits,
                                  uint32_t offset_bits, uint32_t segment) {
  SegmentHeader h;
  const uint64_t at = bit_offset + segment_header_bits(bits, offset_bits) * segment;
  const uint64_t widths = read_bits(stream, at, 3 * kSegmentWidthBits);
  h.data = read_bits(stream, at + 3 * kSegmentWidthBits, offset_bits);
  const uint64_t mins =
      read_bits(stream, at + 3 * kSegmentWidthBits + offset_bits, static_cast<uint32_t>(bits.total()));
  for (uint32_t c = 0; c < 3; ++c) {
    h.min[c] = static_cast<uint32_t>(mins >> bits.shift(c)) & quant_max(bits.c[c]);
    h.widths.c[c] = static_cast<uint32_t>(widths >> (kSegmentWidthBits * c)) & quant_max(kSegmentWidthBits);
  }
  return h;
}

/// The three codes of key `key` of a quantized channel, plain (offset_bits 0) or segmented. O(1).
inline void key_codes(const uint8_t* stream, uint64_t bit_offset, const KeyWidths& bits, uint32_t offset_bits,
                      uint32_t key, uint32_t q[3]) {
  if (offset_bits == 0) {
    const uint64_t packed = read_bits(stream, bit_offset + bits.total() * key, static_cast<uint32_t>(bits.total()));
    for (uint32_t c = 0; c < 3; ++c) q[c] = static_cast<uint32_t>(packed >> bits.shift(c)) & quant_max(bits.c[c]);
    return;
  }
  const SegmentHeader h = read_segment(stream, bit_offset, bits, offset_bits, key / kSegmentKeys);
  const uint64_t packed = read_bits(stream, bit_offset + h.data + h.widths.total() * (key % kSegmentKeys),
                                    static_cast<uint32_t>(h.widths.total()));
  for (uint32_t c = 0; c < 3; ++c)
    q[c] = h.min[c] + (static_cast<uint32_t>(packed >> h.widths.shift(c)) & quant_max(h.widths.c[c]));
}

/// Decodes key `key` of a channel: three floats (rotation: x, y, z with w >= 0 implied).
/// `offset_bits`: the channel's segment_offset_bits (0: plain keys). O(1), no branches but the
/// raw-float escape and the layout. No component decodes to -0 (a raw -0 reads as +0, as a
/// quantized zero does): a lerp or nlerp at weight 0 then gives the first key whatever the second
/// holds, so ossa::sample may leave the second undecoded at a key's own frame.
inline void decode_key(const uint8_t* stream, uint64_t bit_offset, const KeyWidths& bits, uint32_t offset_bits,
                       const float range_min[3], const float range_extent[3], uint32_t key, float out[3]) {
  if (bits.raw()) {
    std::memcpy(out, stream + ((bit_offset + 96ull * key) >> 3), 12);
    for (uint32_t c = 0; c < 3; ++c) out[c] += 0.0f;
    return;
  }
  uint32_t q[3];
  key_codes(stream, bit_offset, bits, offset_bits, key, q);
  for (uint32_t c = 0; c < 3; ++c) out[c] = dequantize(q[c], range_min[c], range_extent[c], bits.c[c]);
}

/// The dropped component of a unit quaternion from the three stored ones (it was >= 0). The
/// cooker tunes stored values to this exact float expression: keep it as written (no reordering,
/// no FMA contraction, no -ffast-math).
inline float rotation_w(const float xyz[3]) {
  const float w2 = 1.0f - xyz[0] * xyz[0] - xyz[1] * xyz[1] - xyz[2] * xyz[2];
  return w2 > 0.0f ? std::sqrt(w2) : 0.0f;
}

/// A rotation key as x, y, z, w from its three stored components and the dropped index (0..3).
inline void rotation_from_stored(const float stored[3], uint32_t dropped, float out[4]) {
  const float rebuilt = rotation_w(stored);
  uint32_t j = 0;
  for (uint32_t c = 0; c < 4; ++c) out[c] = c == dropped ? rebuilt : stored[j++];
}

/// The component a rotation constant leaves out: the first of largest magnitude, so the one rebuilt
/// (rotation_w) is the one least hurt by the square root's loss of precision near 0.
inline uint32_t largest_component(const float xyzw[4]) {
  uint32_t d = 0;
  for (uint32_t c = 1; c < 4; ++c)
    if (std::fabs(xyzw[c]) > std::fabs(xyzw[d])) d = c;
  return d;
}

/// The three components of x, y, z, w stored for a rotation with `dropped` left out (in order).
inline void rotation_to_stored(const float xyzw[4], uint32_t dropped, float stored[3]) {
  const float sign = xyzw[dropped] < 0.0f ? -1.0f : 1.0f;
  uint32_t j = 0;
  for (uint32_t c = 0; c < 4; ++c)
    if (c != dropped) stored[j++] = sign * xyzw[c];
}

/// Whether an animated channel of `key_count` keys in a clip of `frame_count` frames has a key on
/// every frame: then it stores no key frames (its key k is at frame k) and its first_key is 0.
constexpr bool keyed_every_frame(uint32_t key_count, uint32_t frame_count) { return key_count == frame_count; }

/// Frame of key `k` of an animated channel (first_key, key_count) of a clip of `frame_count`
/// frames whose key-frame vector is `key_frames`. O(1).
inline uint32_t key_frame(const uint16_t* key_frames, uint32_t first_key, uint32_t key_count, uint32_t frame_count,
                          uint32_t k) {
  return keyed_every_frame(key_count, frame_count) ? k : key_frames[first_key + k];
}

/// A constant channel's value (fb::ConstantChannel, or anything with channel(), dropped() and
/// value()) as x, y, z, w: w 0 for translation and scale; a rotation rebuilt from its three stored
/// components as rotation_from_stored does. O(1).
template <class Constant>
void constant_value(const Constant& c, float out[4]) {
  const float stored[3] = {c.value().x(), c.value().y(), c.value().z()};
  if (static_cast<uint32_t>(c.channel()) == 1u) {  // fb::Channel::Rotation
    rotation_from_stored(stored, c.dropped() & 3u, out);
  } else {
    out[0] = stored[0];
    out[1] = stored[1];
    out[2] = stored[2];
    out[3] = 0.0f;
  }
}

/// Appends bit fields LSB-first; finish() ends the stream with kKeyValuePadding zero bytes.
class BitWriter {
 public:
  uint64_t bit_size() const { return bits_; }
  /// Appends the low `count` bits of value; bits past its 64th are zeros. O(count).
  void write(uint64_t value, uint32_t count) {
    for (uint32_t i = 0; i < count; ++i, ++bits_) {
      if ((bits_ >> 3) >= bytes_.size()) bytes_.push_back(0);
      if (i < 64 && ((value >> i) & 1u)) bytes_[bits_ >> 3] |= static_cast<uint8_t>(1u << (bits_ & 7u));
    }
  }
  void write_float(float f) {
    uint32_t u;
    std::memcpy(&u, &f, 4);
    write(u, 32);
  }
  /// Aligns the next field to a byte boundary (raw-float channels start byte-aligned).
  void align_byte() {
    while (bits_ & 7u) write(0, 1);
  }
  std::vector<uint8_t> finish() {
    std::vector<uint8_t> out = bytes_;
    out.resize(out.size() + kKeyValuePadding, 0);
    return out;
  }

 private:
  std::vector<uint8_t> bytes_;
  uint64_t bits_ = 0;
};

}  // namespace ossa
