// sample_decode.h — the sampler's key decoding (anim/sample_keys.cpp), internal to runtime/anim.
//
// ossa/format/clip_codec.h defines how a channel's keys are stored; this is the same decoding
// specialized for the hot path: each animated channel gathered into one flat record (Track) when
// a sampling cache is made, keys read from it with the same bits as decode_key. Plain keys are one
// read each; a segmented channel's keys (format v14) first need their segment's header, which a
// per-cache cursor keeps unpacked, so forward playback reads a header once per 16 keys and a seek
// one per pair. The decoders are templates on the layout: sample_keys.cpp decodes a run's plain and
// segmented channels in separate loops, each compiled without the other's branch. On x86-64 the
// three components of a key are dequantized in one SSE register (one division instead of three),
// each lane performing the scalar code's IEEE operations in its order. Every helper of the hot
// path is OSSA_INLINE, so each of sample_keys.cpp's two compiled copies gets its own.
#pragma once
#include <cstdint>
#include <cstring>
#include <limits>

#if defined(__SSE2__)
#include <immintrin.h>
#endif

#include <ossa/format/clip_codec.h>
#include "internal/vector_clones.h"

namespace ossa::sample_detail {

/// How to decode one animated channel and where its values go, gathered from the FlatBuffer at
/// cache creation so the hot path reads one flat record.
struct Track {
  uint64_t bit_offset = 0;
  uint32_t key_bits = 0;         // bits per key: the three widths summed (96: raw floats)
  bool raw = false;              // raw floats
  uint8_t shift[3] = {0, 0, 0};  // each component's bit position in a key
  uint32_t mask[3] = {0, 0, 0};  // 2^width - 1
  float qmax[4] = {1, 1, 1, 1};  // the same as floats, 4 wide for one SSE load
  float lo[4] = {0, 0, 0, 0};    // 4 wide (the 4th unused) for one SSE load; never -0 (dequantize's lo + 0)
  float extent[4] = {0, 0, 0, 0};
  bool rotation = false;
  uint32_t offset[4] = {0, 0, 0, 0};  // where components go in k0 / k1 (offset[3]: a rotation's rebuilt one)
  uint32_t weight_index = 0;          // kind * stride + joint, into start / inv_length
  uint32_t offset_bits = 0;           // segment_offset_bits: 0 plain keys, else segmented
  uint32_t header_bits = 0;           // segmented: one segment header's bits
  KeyWidths widths;                   // the channel's (clip_codec.h's key_codes)
};

/// The segment a segmented track last decoded from, its header unpacked (per cache: tracks may be
/// a prototype's): keys of the same segment then decode as plain keys do, one read each, so
/// forward playback reads a header once per 16 keys and a seek's pair one header.
struct SegmentCursor {
  uint32_t segment = std::numeric_limits<uint32_t>::max();
  uint32_t key_bits = 0;           // the segment's three widths summed
  uint64_t data = 0;               // bit position of its first key in the stream
  uint32_t min[4] = {0, 0, 0, 0};  // 4 wide (the 4th 0) for one SSE load
  uint32_t mask[3] = {0, 0, 0};
  uint32_t shift[3] = {0, 0, 0};
};

/// Where keys are decoded from: the clip's stream, and the segment cursors of `tracks`
/// (cursors[i] for tracks[i]; empty when no track is segmented).
struct KeySource {
  const uint8_t* stream;
  const Track* tracks;
  SegmentCursor* cursors;
};

/// The 64 bits from bit `bit` of the stream, of which the low 57 are the stream's: a key (3 x 19
/// bits at most, validate_clip.cpp) or two that fit, with the bits after them left in, which
/// the per-component masks drop (read_bits's own mask is 7 instructions of a seek's ~110 per key).
inline uint64_t key_word(const uint8_t* stream, uint64_t bit) {
  uint64_t word;
  std::memcpy(&word, stream + (bit >> 3), 8);  // little-endian host assumed (as FlatBuffers does)
  return word >> (bit & 7u);
}

/// Unpacks header `segment` of a segmented track into c: clip_codec.h's read_segment, specialized
/// to the track's precomputed widths (the minima and widths in one read when they fit in 57 bits).
inline void load_segment(const Track& t, const uint8_t* stream, uint32_t segment, SegmentCursor& c) {
  const uint64_t at = t.bit_offset + uint64_t{t.header_bits} * segment;
  c.segment = segment;
  // Widths and data position in one read (15 + at most 32 bits), the minima in a second, beside it.
  const uint64_t widths = read_bits(stream, at, 3 * kSegmentWidthBits + t.offset_bits);
  c.data = t.bit_offset + (widths >> (3 * kSegmentWidthBits));
  const uint64_t mins = key_word(stream, at + 3 * kSegmentWidthBits + t.offset_bits);
  const auto w0 = static_cast<uint32_t>(widths) & 31u, w1 = static_cast<uint32_t>(widths >> 5) & 31u,
             w2 = static_cast<uint32_t>(widths >> 10) & 31u;
  const uint32_t m0 = static_cast<uint32_t>(mins) & t.mask[0];
  const uint32_t m1 = static_cast<uint32_t>(mins >> t.shift[1]) & t.mask[1];
  const uint32_t m2 = static_cast<uint32_t>(mins >> t.shift[2]) & t.mask[2];
#if defined(__SSE2__)
  // One 16-byte store: the decode reads the minima back as one 16-byte load, which three 4-byte
  // stores could not forward to (a store-forwarding stall on every header load).
  _mm_storeu_si128(reinterpret_cast<__m128i*>(c.min),
                   _mm_setr_epi32(static_cast<int>(m0), static_cast<int>(m1), static_cast<int>(m2), 0));
#else
  c.min[0] = m0, c.min[1] = m1, c.min[2] = m2;
#endif
  c.mask[0] = quant_max(w0), c.mask[1] = quant_max(w1), c.mask[2] = quant_max(w2);
  c.shift[0] = 0, c.shift[1] = w0, c.shift[2] = w0 + w1;
  c.key_bits = w0 + w1 + w2;
}

/// The three codes of key `key` of a segmented track, through its cursor. O(1).
OSSA_INLINE void segment_codes(const Track& t, const KeySource& src, uint32_t key, uint32_t q[3]) {
  SegmentCursor& c = src.cursors[&t - src.tracks];
  if (c.segment != key / kSegmentKeys) load_segment(t, src.stream, key / kSegmentKeys, c);
  const uint64_t packed = key_word(src.stream, c.data + uint64_t{c.key_bits} * (key % kSegmentKeys));
  for (uint32_t i = 0; i < 3; ++i) q[i] = c.min[i] + (static_cast<uint32_t>(packed >> c.shift[i]) & c.mask[i]);
}

// Key decodes: ossa/format/clip_codec.h's decode_key and rotation_from_stored, specialized to the
// precomputed record, with the same bits: on x86-64 the three components are dequantized in one
// SSE register (one division instead of three), each lane performing the scalar code's IEEE
// operations (lo + extent * (q / qmax)) in its order.
#if defined(__SSE2__)
/// Key `key` of a quantized track as (x, y, z, 0): its three stored components, dequantized.
template <bool kSegments>
OSSA_INLINE __m128 dequantized(const Track& t, const KeySource& src, uint32_t key) {
  // q < 2^19 fits a signed 32-bit lane, so the signed conversion is exact.
  __m128i q;
  if (kSegments) {
    uint32_t c[3];
    segment_codes(t, src, key, c);
    q = _mm_setr_epi32(static_cast<int>(c[0]), static_cast<int>(c[1]), static_cast<int>(c[2]), 0);
  } else {
    const uint64_t packed = key_word(src.stream, t.bit_offset + uint64_t{t.key_bits} * key);
    const auto q0 = static_cast<int>(static_cast<uint32_t>(packed) & t.mask[0]);
    const auto q1 = static_cast<int>(static_cast<uint32_t>(packed >> t.shift[1]) & t.mask[1]);
    const auto q2 = static_cast<int>(static_cast<uint32_t>(packed >> t.shift[2]) & t.mask[2]);
    q = _mm_setr_epi32(q0, q1, q2, 0);
  }
  const __m128 f = _mm_div_ps(_mm_cvtepi32_ps(q), _mm_loadu_ps(t.qmax));
  return _mm_add_ps(_mm_loadu_ps(t.lo), _mm_mul_ps(_mm_loadu_ps(t.extent), f));
}

/// Key `key` of any track as (x, y, z, 0): its three stored components. A raw key is read as 16
/// bytes (validation keeps 8 padding bytes after the last key, so the read stays inside the stream)
/// and the bytes after it are cleared, so no arithmetic on lane 3 can raise a floating-point flag;
/// + 0 turns a -0 into +0, as decode_key does.
template <bool kSegments>
OSSA_INLINE __m128 stored(const Track& t, const KeySource& src, uint32_t key) {
  if (t.raw)
    return _mm_add_ps(
        _mm_and_ps(_mm_loadu_ps(reinterpret_cast<const float*>(src.stream + (t.bit_offset >> 3) + 12ull * key)),
                   _mm_castsi128_ps(_mm_setr_epi32(-1, -1, -1, 0))),
        _mm_setzero_ps());
  return dequantized<kSegments>(t, src, key);
}

/// Writes the three stored components where the record says they go (through memory: a 16-byte
/// store forwards to the 4-byte loads, cheaper than shuffling each lane out).
OSSA_INLINE void put(const Track& t, __m128 v, float* keys) {
  float x[4];
  _mm_storeu_ps(x, v);
  keys[t.offset[0]] = x[0];
  keys[t.offset[1]] = x[1];
  keys[t.offset[2]] = x[2];
}

/// Decodes key `key` of a track into the k0 or k1 array.
template <bool kSegments>
OSSA_INLINE void decode(const Track& t, const KeySource& src, uint32_t key, float* keys) {
  float v[4];
  _mm_storeu_ps(v, stored<kSegments>(t, src, key));
  keys[t.offset[0]] = v[0];
  keys[t.offset[1]] = v[1];
  keys[t.offset[2]] = v[2];
  if (t.rotation) keys[t.offset[3]] = rotation_w(v);
}

/// rotation_w of two stored keys at once (lanes 0 and 1): its operations, lane for lane, in its
/// order, with one square root for both.
OSSA_INLINE __m128 rotation_w2(__m128 a, __m128 b) {
  const __m128 xy = _mm_unpacklo_ps(a, b);  // xa xb ya yb
  const __m128 z = _mm_unpackhi_ps(a, b);   // za zb 0 0
  const __m128 sq = _mm_mul_ps(xy, xy);
  const __m128 w2 = _mm_sub_ps(_mm_sub_ps(_mm_sub_ps(_mm_set1_ps(1.0f), sq), _mm_movehl_ps(sq, sq)), _mm_mul_ps(z, z));
  // w2 <= 0 gives 0, as rotation_w's test does; clamping first keeps a negative (or another lane's
  // unused value) out of the square root, which would raise invalid-operation.
  return _mm_sqrt_ps(_mm_max_ps(w2, _mm_setzero_ps()));
}

/// The codes of one key of a segment, `packed` its bits, as (q0, q1, q2, 0).
OSSA_INLINE __m128i cursor_codes(const SegmentCursor& c, uint64_t packed) {
  const auto q0 = static_cast<int>(static_cast<uint32_t>(packed) & c.mask[0]);
  const auto q1 = static_cast<int>(static_cast<uint32_t>(packed >> c.shift[1]) & c.mask[1]);
  const auto q2 = static_cast<int>(static_cast<uint32_t>(packed >> c.shift[2]) & c.mask[2]);
  return _mm_add_epi32(_mm_setr_epi32(q0, q1, q2, 0), _mm_loadu_si128(reinterpret_cast<const __m128i*>(c.min)));
}

/// Codes as floats dequantized the way dequantized() does.
OSSA_INLINE __m128 dequantize_codes(const Track& t, __m128i q) {
  const __m128 f = _mm_div_ps(_mm_cvtepi32_ps(q), _mm_loadu_ps(t.qmax));
  return _mm_add_ps(_mm_loadu_ps(t.lo), _mm_mul_ps(_mm_loadu_ps(t.extent), f));
}

/// Keys `key` and `key + 1` of a segmented track: one header for both unless `key` ends its
/// segment, and one read for both when they fit 57 bits (the cursor is left on key + 1's segment).
OSSA_INLINE void segment_pair(const Track& t, const KeySource& src, uint32_t key, __m128& a, __m128& b) {
  SegmentCursor& c = src.cursors[&t - src.tracks];
  const uint32_t segment = key / kSegmentKeys, i = key % kSegmentKeys;
  if (c.segment != segment) load_segment(t, src.stream, segment, c);
  const uint64_t at = c.data + uint64_t{c.key_bits} * i;
  if (i + 1 < kSegmentKeys) {
    if (2 * c.key_bits <= 57) {
      const uint64_t both = key_word(src.stream, at);
      a = dequantize_codes(t, cursor_codes(c, both));
      b = dequantize_codes(t, cursor_codes(c, both >> c.key_bits));
    } else {
      a = dequantize_codes(t, cursor_codes(c, key_word(src.stream, at)));
      b = dequantize_codes(t, cursor_codes(c, key_word(src.stream, at + c.key_bits)));
    }
    return;
  }
  a = dequantize_codes(t, cursor_codes(c, key_word(src.stream, at)));
  load_segment(t, src.stream, segment + 1, c);
  b = dequantize_codes(t, cursor_codes(c, key_word(src.stream, c.data)));
}

/// Keys `key` and `key + 1` of a track into k0 and k1 (a seek).
template <bool kSegments>
OSSA_INLINE void decode_pair(const Track& t, const KeySource& src, uint32_t key, float* k0, float* k1) {
  __m128 a, b;
  if (kSegments) {
    segment_pair(t, src, key, a, b);
  } else {
    a = stored<kSegments>(t, src, key);
    b = stored<kSegments>(t, src, key + 1);
  }
  put(t, a, k0);
  put(t, b, k1);
  if (!t.rotation) return;
  float w[4];
  _mm_storeu_ps(w, rotation_w2(a, b));
  k0[t.offset[3]] = w[0];
  k1[t.offset[3]] = w[1];
}

/// Key `key` of two tracks into `keys` (forward playback). Always inlined, as decode is: sample_keys.cpp
/// calls them from several per-track loops, and GCC would otherwise call them once per track.
template <bool kSegments>
OSSA_INLINE void decode_two(const Track& ta, const Track& tb, const KeySource& src, uint32_t key, float* keys) {
  const __m128 a = stored<kSegments>(ta, src, key), b = stored<kSegments>(tb, src, key);
  put(ta, a, keys);
  put(tb, b, keys);
  if (!(ta.rotation || tb.rotation)) return;
  float w[4];
  _mm_storeu_ps(w, rotation_w2(a, b));
  if (ta.rotation) keys[ta.offset[3]] = w[0];
  if (tb.rotation) keys[tb.offset[3]] = w[1];
}
#else
template <bool kSegments>
inline void decode(const Track& t, const KeySource& src, uint32_t key, float* keys) {
  float v[3];
  if (t.raw) {
    std::memcpy(v, src.stream + (t.bit_offset >> 3) + 12ull * key, 12);
    for (float& x : v) x += 0.0f;  // -0 reads as +0 (decode_key)
  } else {
    uint32_t q[3];
    if (kSegments) segment_codes(t, src, key, q);
    else key_codes(src.stream, t.bit_offset, t.widths, 0, key, q);
    for (uint32_t c = 0; c < 3; ++c) v[c] = t.lo[c] + t.extent[c] * (static_cast<float>(q[c]) / t.qmax[c]);
  }
  keys[t.offset[0]] = v[0];
  keys[t.offset[1]] = v[1];
  keys[t.offset[2]] = v[2];
  if (t.rotation) keys[t.offset[3]] = rotation_w(v);
}

template <bool kSegments>
OSSA_INLINE void decode_pair(const Track& t, const KeySource& src, uint32_t key, float* k0, float* k1) {
  decode<kSegments>(t, src, key, k0);
  decode<kSegments>(t, src, key + 1, k1);
}

template <bool kSegments>
inline void decode_two(const Track& ta, const Track& tb, const KeySource& src, uint32_t key, float* keys) {
  decode<kSegments>(ta, src, key, keys);
  decode<kSegments>(tb, src, key, keys);
}
#endif

}  // namespace ossa::sample_detail
