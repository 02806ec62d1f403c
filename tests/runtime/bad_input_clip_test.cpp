// bad_input_clip_test.cpp — the bad-input suite (bad_input_test.cpp) on the clip, root motion and
// cooked texture invariants of ossa/loader/validate.h: each case starts from the valid synthetic
// file and breaks exactly one, and must be rejected with a message naming the file and what is wrong.
#include <gtest/gtest.h>

#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <string>
#include <vector>

#include <flatbuffers/flatbuffers.h>

#include "bad_input.h"
#include <ossa/format/clip_codec.h>
#include <ossa/format/hash.h>
#include <ossa/loader/asset.h>
#include <ossa/loader/texture.h>
#include "test_files.h"

namespace ossa::test {
namespace {

// ---------------------------------------------------------------------------------------------
// Clip invariants

// The default clip (test_files.h): 31 frames at 30/s; constants spine translation, head
// rotation; animated spine rotation (16 bits, frames 0 15 30), arm translation (12 bits, 0 30),
// arm scale (raw floats, 0 8 23 30), packed in that order: 144 + 72 bits, then the raw keys from
// bit 216 (byte 27) to bit 600, then 8 padding bytes.

TEST(Clip, SampleRateInvalid) {
  for (float rate : {0.0f, -30.0f, kNaN, kInf}) {
    SyntheticSpec spec;
    spec.clips[0].sample_rate = rate;
    spec.clips[0].duration = 1.0f;
    EXPECT_TRUE(rejects(spec, with(kClip, {"sample rate"}))) << rate;
  }
}

TEST(Clip, FrameCountInvalid) {
  for (uint32_t frames : {0u, 65537u, 0xFFFFFFFFu}) {
    SyntheticSpec spec;
    spec.clips[0].frame_count = frames;
    spec.clips[0].duration = 1.0f;
    EXPECT_TRUE(rejects(spec, with(kClip, {"frame count"}))) << frames;
  }
}

TEST(Clip, DurationDoesNotMatchFrames) {
  for (float d : {2.0f, 1.001f, -1.0f, kNaN, kInf}) {
    SyntheticSpec spec;
    spec.clips[0].duration = d;  // 31 frames at 30/s: 1 s
    EXPECT_TRUE(rejects(spec, with(kClip, {"duration"}))) << d;
  }
  SyntheticSpec single;
  single.clips[0].frame_count = 1;
  single.clips[0].animated.clear();
  single.clips[0].duration = 0.5f;  // one frame lasts 0 s
  EXPECT_TRUE(rejects(single, with(kClip, {"duration"})));
}

TEST(Clip, ConstantsNotSortedOrRepeated) {
  SyntheticSpec spec;
  std::swap(spec.clips[0].constants[0], spec.clips[0].constants[1]);
  EXPECT_TRUE(rejects(spec, with(kClip, {"sorted"})));
  spec.clips[0].constants = {{1, fb::Channel::Translation, fb::Quat(0, 1, 0, 0)},
                             {1, fb::Channel::Translation, fb::Quat(0, 2, 0, 0)}};
  EXPECT_TRUE(rejects(spec, with(kClip, {"sorted", "at most once"})));
}

TEST(Clip, AnimatedNotSortedOrRepeated) {
  SyntheticSpec spec;
  std::swap(spec.clips[0].animated[1], spec.clips[0].animated[2]);  // arm scale before arm translation
  EXPECT_TRUE(rejects(spec, with(kClip, {"sorted"})));
  SyntheticSpec repeated;
  repeated.clips[0].animated[2].channel = fb::Channel::Translation;
  EXPECT_TRUE(rejects(repeated, with(kClip, {"sorted", "at most once"})));
}

TEST(Clip, ChannelJointPastJointCount) {
  SyntheticSpec constant;
  constant.clips[0].constants[1].joint = 4;  // joint_count 4
  EXPECT_TRUE(rejects(constant, with(kClip, {"joint count"})));
  SyntheticSpec animated;
  animated.clips[0].animated[1].joint = 4;
  animated.clips[0].animated[2].joint = 4;
  EXPECT_TRUE(rejects(animated, with(kClip, {"joint count"})));
}

TEST(Clip, ChannelEnumUnknown) {
  SyntheticSpec constant;
  constant.clips[0].constants[1].channel = static_cast<fb::Channel>(3);
  EXPECT_TRUE(rejects(constant, with(kClip, {"unknown channel"})));
  SyntheticSpec animated;
  animated.clips[0].animated[2].channel = static_cast<fb::Channel>(200);
  EXPECT_TRUE(rejects(animated, with(kClip, {"unknown channel"})));
}

TEST(Clip, ChannelBothConstantAndAnimated) {
  SyntheticSpec spec;
  // spine rotation is animated; also make it constant (constants stay sorted).
  spec.clips[0].constants.insert(spec.clips[0].constants.begin() + 1, {1, fb::Channel::Rotation, fb::Quat(0, 0, 0, 1)});
  EXPECT_TRUE(rejects(spec, with(kClip, {"also constant"})));
}

TEST(Clip, AnimatedWithFewerThanTwoKeys) {
  for (uint32_t n : {0u, 1u}) {
    SyntheticSpec spec;
    spec.clips[0].animated[1].key_count = n;
    EXPECT_TRUE(rejects(spec, with(kClip, {"at least 2"}))) << n;
  }
}

TEST(Clip, KeysPastKeyFrames) {
  SyntheticSpec spec;
  spec.clips[0].animated[2].first_key = 6;  // 9 key frames; 6 + 4 > 9
  EXPECT_TRUE(rejects(spec, with(kClip, {"key frames"})));
  // first_key + key_count wraps in 32 bits: the check must not.
  SyntheticSpec wraps;
  wraps.clips[0].animated[1].first_key = 0xFFFFFFFFu;
  EXPECT_TRUE(rejects(wraps, with(kClip, {"key frames"})));
  SyntheticSpec huge;
  huge.clips[0].animated[1].key_count = 0xFFFFFFF0u;
  EXPECT_TRUE(rejects(huge, with(kClip, {"keys, more than the clip's 31 frames"})));
}

TEST(Clip, KeyFramesNotIncreasing) {
  SyntheticSpec spec;
  spec.clips[0].animated[0].frames = {0, 20, 10};
  EXPECT_TRUE(rejects(spec, with(kClip, {"strictly increase"})));
  spec.clips[0].animated[0].frames = {0, 30, 30};
  EXPECT_TRUE(rejects(spec, with(kClip, {"strictly increase"})));
}

TEST(Clip, FirstKeyNotAtFrameZero) {
  SyntheticSpec spec;
  spec.clips[0].animated[0].frames = {1, 15, 30};
  EXPECT_TRUE(rejects(spec, with(kClip, {"first key"}, {"frame 0", "must be 0"})));
}

TEST(Clip, LastKeyNotAtLastFrame) {
  SyntheticSpec spec;
  spec.clips[0].animated[0].frames = {0, 15, 29};
  EXPECT_TRUE(rejects(spec, with(kClip, {"last key"})));
  SyntheticSpec past;
  past.clips[0].animated[0].frames = {0, 15, 31};
  EXPECT_TRUE(rejects(past, with(kClip, {"last key"})));
}

TEST(Clip, BitsInvalid) {
  for (uint8_t bits : {0, 20, 31, 33, 255}) {
    SyntheticSpec spec;
    spec.clips[0].animated[1].bits = bits;
    EXPECT_TRUE(rejects(spec, with(kClip, {"bits"}))) << int(bits);
  }
  // Per component (format v12): one bad width among good ones, and raw floats mixed with
  // quantized components (a raw key is three floats or nothing).
  for (const std::array<uint8_t, 3> widths :
       {std::array<uint8_t, 3>{12, 0, 12}, std::array<uint8_t, 3>{12, 12, 20}, std::array<uint8_t, 3>{32, 12, 12},
        std::array<uint8_t, 3>{12, 32, 32}, std::array<uint8_t, 3>{32, 32, 19}}) {
    SyntheticSpec spec;
    spec.clips[0].animated[1].widths = widths;
    EXPECT_TRUE(rejects(spec, with(kClip, {"bits for its components"})))
        << int(widths[0]) << " " << int(widths[1]) << " " << int(widths[2]);
  }
}

TEST(Clip, DroppedComponentInvalid) {
  SyntheticSpec rotation;
  rotation.clips[0].animated[0].dropped = 4;  // x, y, z, w are 0..3
  EXPECT_TRUE(rejects(rotation, with(kClip, {"dropped"})));
  // Other channels ignore the field.
  SyntheticSpec translation;
  translation.clips[0].animated[1].dropped = 3;
  EXPECT_TRUE(accepts(make_valid_file(translation)));
  for (uint8_t d = 0; d < 4; ++d) {
    SyntheticSpec valid;
    valid.clips[0].animated[0].dropped = d;
    EXPECT_TRUE(accepts(make_valid_file(valid))) << int(d);
  }
}

TEST(Clip, RawKeysNotByteAligned) {
  SyntheticSpec spec;
  spec.clips[0].animated[2].bit_offset = 217;
  EXPECT_TRUE(rejects(spec, with(kClip, {"byte boundary"})));
}

TEST(Clip, KeyBitsPastKeyValues) {
  SyntheticSpec spec;
  spec.clips[0].animated[0].bit_offset = 1000;
  EXPECT_TRUE(rejects(spec, with(kClip, {"key value bits"})));
  // Keys that end inside the padding: the decoder's 64-bit reads would leave the vector.
  SyntheticSpec short_padding;
  short_padding.clips[0].key_value_padding = 4;
  EXPECT_TRUE(rejects(short_padding, with(kClip, {"key value bits"})));
  // bit_offset + 3 * bits * key_count overflows 32 bits: the check must not.
  SyntheticSpec wraps;
  wraps.clips[0].animated[0].bit_offset = 0xFFFFFFF0u;
  EXPECT_TRUE(rejects(wraps, with(kClip, {"key value bits"})));
}

TEST(Clip, KeyValuesShorterThanPadding) {
  SyntheticSpec spec;
  spec.clips[0].key_values = std::vector<uint8_t>(4, 0);
  EXPECT_TRUE(rejects(spec, with(kClip, {"padding"})));
  SyntheticSpec missing;
  missing.clips[0].key_values = std::vector<uint8_t>();
  EXPECT_TRUE(rejects(missing, with(kClip, {"padding"})));
}

TEST(Clip, RangeNotFiniteOrNegative) {
  const std::pair<fb::Vec3, fb::Vec3> ranges[] = {
      {fb::Vec3(kNaN, 0, 0), fb::Vec3(1, 1, 1)},
      {fb::Vec3(0, 0, 0), fb::Vec3(1, kInf, 1)},
      {fb::Vec3(0, 0, 0), fb::Vec3(1, 1, -0.5f)},
      {fb::Vec3(3e38f, 0, 0), fb::Vec3(3e38f, 0, 0)},  // top overflows
  };
  for (const auto& [lo, extent] : ranges) {
    SyntheticSpec spec;
    spec.clips[0].animated[1].range_min = lo;
    spec.clips[0].animated[1].range_extent = extent;
    EXPECT_TRUE(rejects(spec, with(kClip, {"range"}))) << lo.x() << " " << extent.y();
  }
}

TEST(Clip, RotationRangeOutsideUnit) {
  SyntheticSpec spec;
  spec.clips[0].animated[0].range_min = fb::Vec3(-3, 0, 0);
  EXPECT_TRUE(rejects(spec, with(kClip, {"rotation"}, {"[-1, 1]"})));
  SyntheticSpec raw;
  raw.clips[0].animated[0].bits = 32;
  raw.clips[0].animated[0].values[1] = {0, 1.5f, 0};
  EXPECT_TRUE(rejects(raw, with(kClip, {"rotation"}, {"[-1, 1]"})));
}

TEST(Clip, RawKeyNotFinite) {
  for (float v : {kNaN, kInf, -kInf}) {
    SyntheticSpec spec;
    spec.clips[0].animated[2].values[3][1] = v;
    EXPECT_TRUE(rejects(spec, with(kClip, {"raw key"}, {"finite"}))) << v;
  }
}

TEST(Clip, ConstantNotFinite) {
  SyntheticSpec translation;
  translation.clips[0].constants[0].value = fb::Quat(kInf, 1, 0, 0);
  EXPECT_TRUE(rejects(translation, with(kClip, {"finite"})));
  SyntheticSpec rotation;
  rotation.clips[0].constants[1].value = fb::Quat(0, kNaN, 0, 1);
  EXPECT_TRUE(rejects(rotation, with(kClip, {"finite"}, {"quaternion"})));
  // w is unused for translation and scale constants: garbage there is harmless.
  SyntheticSpec unused_w;
  unused_w.clips[0].constants[0].value = fb::Quat(0, 1, 0, kNaN);
  EXPECT_TRUE(accepts(make_valid_file(unused_w)));
}

TEST(Clip, RotationConstantOutOfRange) {
  // A rotation constant stores three components of a unit quaternion: each must lie in [-1, 1]
  // (then the rebuilt quaternion is normalizable; huge ones would overflow its norm).
  for (const fb::Vec3& v : {fb::Vec3(2, 0, 0), fb::Vec3(0, -1.5f, 0), fb::Vec3(3e38f, 3e38f, 0)}) {
    SyntheticSpec spec;
    spec.clips[0].constants[1].stored = v;
    EXPECT_TRUE(rejects(spec, with(kClip, {"quaternion"}))) << v.x() << " " << v.y();
  }
  SyntheticSpec dropped;
  dropped.clips[0].constants[1].dropped = 4;
  EXPECT_TRUE(rejects(dropped, with(kClip, {"dropped component 4"})));
  // All three zero is the identity's w rebuilt: valid, and sampled as the identity.
  SyntheticSpec zero;
  zero.clips[0].constants[1].stored = fb::Vec3(0, 0, 0);
  EXPECT_TRUE(accepts(make_valid_file(zero)));
}

TEST(Clip, EveryFrameChannelWithKeyFrames) {
  // A channel with a key on every frame stores no key frames: its first_key must be 0.
  SyntheticSpec spec;
  test::SyntheticAnimated& a = spec.clips[0].animated[0];
  a.frames.clear();
  a.values.clear();
  for (uint16_t f = 0; f < spec.clips[0].frame_count; ++f) {
    a.frames.push_back(f);
    a.values.push_back({0.01f * f, 0.0f, 1.0f});
  }
  EXPECT_TRUE(accepts(make_valid_file(spec)));
  a.first_key = 1;
  EXPECT_TRUE(rejects(spec, with(kClip, {"first_key must be 0"})));
}

/// The default clip with one animated channel, the arm's translation keyed at every frame in 4
/// bits per component and segmented with 8-bit data offsets (format v14), its key values written
/// here bit by bit: 31 keys are two segments, headers of 15 + 8 + 12 bits (widths, where the keys
/// start, minima); segment 0 has component 0 at minimum `min0` in `width0` bits (every field 0)
/// and its keys start at bit 70 + `skew`; segment 1 holds still (widths 0).
SyntheticSpec segmented_spec(uint32_t min0, uint32_t width0, uint32_t skew) {
  SyntheticSpec spec;
  test::SyntheticAnimated a = spec.clips[0].animated[1];
  a.frames.clear();
  a.values.clear();
  for (uint16_t f = 0; f < spec.clips[0].frame_count; ++f) {
    a.frames.push_back(f);
    a.values.push_back({0.01f * f, 0.0f, 1.0f});
  }
  a.bits = 4;
  a.segment_offset_bits = 8;
  a.bit_offset = 0;
  spec.clips[0].animated = {a};
  BitWriter w;
  const uint32_t headers = 2 * (8 + 12 + 15);
  w.write(width0, 5), w.write(0, 5), w.write(0, 5);
  w.write(headers + skew, 8);
  w.write(min0, 4), w.write(0, 4), w.write(0, 4);
  w.write(0, 15);
  w.write(headers + 16 * width0, 8);
  w.write(0, 12);
  for (uint32_t k = 0; k < 16; ++k) w.write(0, width0);  // segment 0's keys
  spec.clips[0].key_values = w.finish();
  return spec;
}

TEST(Clip, SegmentedKeysInvalid) {
  EXPECT_TRUE(accepts(make_valid_file(segmented_spec(3, 2, 0))));
  EXPECT_TRUE(accepts(make_valid_file(segmented_spec(12, 2, 0)))) << "12 + 3 is the largest 4-bit code";
  EXPECT_TRUE(rejects(segmented_spec(14, 2, 0), with(kClip, {"segment 0's component 0", "4-bit codes"})));
  EXPECT_TRUE(rejects(segmented_spec(0, 5, 0), with(kClip, {"segment 0's component 0 (minimum 0, 5 bits)"})));
  EXPECT_TRUE(rejects(segmented_spec(0, 2, 1), with(kClip, {"segment 0's keys start at bit 71"})));
  // Segment 0 has 32 bits of keys, the first written: its keys cannot also start where segment 1's do.
  SyntheticSpec late = segmented_spec(0, 2, 0);
  (*late.clips[0].key_values)[6] ^= 0x08;  // segment 1's offset (bits 50..57): its bit 1 flipped
  EXPECT_TRUE(rejects(late, with(kClip, {"segment 1's keys start"})));
  // Headers past the key values, and layouts that cannot be segmented.
  SyntheticSpec past = segmented_spec(0, 2, 0);
  past.clips[0].animated[0].bit_offset = 200;
  EXPECT_TRUE(rejects(past, with(kClip, {"segment headers need key value bits"})));
  SyntheticSpec wide = segmented_spec(0, 2, 0);
  wide.clips[0].animated[0].segment_offset_bits = 33;
  EXPECT_TRUE(rejects(wide, with(kClip, {"segment_offset_bits 33"})));
  SyntheticSpec sparse;  // the spine rotation keeps frames 0 15 30
  sparse.clips[0].animated[0].segment_offset_bits = 8;
  EXPECT_TRUE(rejects(sparse, with(kClip, {"segment_offset_bits 8", "a key on every frame"})));
  SyntheticSpec raw = segmented_spec(0, 2, 0);  // raw floats carry no codes to segment
  raw.clips[0].animated[0].bits = 32;
  raw.clips[0].key_values.reset();
  raw.clips[0].animated[0].segment_offset_bits = 0;
  ASSERT_TRUE(accepts(make_valid_file(raw)));
  raw.clips[0].animated[0].segment_offset_bits = 8;
  EXPECT_TRUE(rejects(raw, with(kClip, {"segment_offset_bits 8", "quantized keys"})));
}

SyntheticRootMotion valid_root_motion(uint32_t frames) {
  SyntheticRootMotion rm;
  rm.translations.assign(frames, fb::Vec3(0, 0, 0));
  rm.yaws.assign(frames, 0.0f);
  return rm;
}

TEST(Clip, RootMotionLengthMismatch) {
  SyntheticSpec spec;
  spec.clips[0].root_motion = valid_root_motion(30);  // 31 frames
  EXPECT_TRUE(rejects(spec, with(kClip, {"root motion"})));
  spec.clips[0].root_motion = valid_root_motion(31);
  spec.clips[0].root_motion->yaws.push_back(0.0f);
  EXPECT_TRUE(rejects(spec, with(kClip, {"root motion"})));
}

TEST(Clip, RootMotionNotFinite) {
  SyntheticSpec spec;
  spec.clips[0].root_motion = valid_root_motion(31);
  spec.clips[0].root_motion->translations[7] = fb::Vec3(0, kNaN, 0);
  EXPECT_TRUE(rejects(spec, with(kClip, {"root motion"}, {"finite"})));
  spec.clips[0].root_motion = valid_root_motion(31);
  spec.clips[0].root_motion->yaws[30] = kInf;
  EXPECT_TRUE(rejects(spec, with(kClip, {"root motion"}, {"finite"})));
}

TEST(Clip, RootMotionUpAxisInvalid) {
  SyntheticSpec spec;
  spec.clips[0].root_motion = valid_root_motion(31);
  spec.clips[0].root_motion->up_axis = 3;
  EXPECT_TRUE(rejects(spec, with(kClip, {"up axis"})));
}

TEST(Clip, JointCountDiffersFromItsSkeleton) {
  SyntheticSpec spec;
  spec.clips[0].joint_count = 5;  // bound by hash to the file's 4-joint skeleton
  EXPECT_TRUE(rejects(spec, with(kClip, {"joint"})));
}

TEST(Clip, BindingToAnotherRigRejected) {
  SyntheticSpec spec;
  spec.clips[0].skeleton_hash = 0xBADBADBADull;
  const Result<Asset> asset = Asset::from_bytes(make_valid_file(spec), "other-rig.ossa");
  ASSERT_TRUE(asset.ok()) << asset.error().message;  // a clip may belong to another rig
  const Status status = check_clip_binding(asset->clip(0), asset->skeleton(), "other-rig.ossa");
  EXPECT_FALSE(status.ok());
  EXPECT_TRUE(explains(status.message(), "other-rig.ossa", {{"walk"}, {"hash", "skeleton", "rig"}}));
}

// ---------------------------------------------------------------------------------------------
// Cooked textures (format v7): the chain's bytes must be exactly what its encoding and size give.

const Keywords kTexture = {{"skin", "material 0"}, {"texture 2", "Specular"}};

TEST(Texture, ChainBytesMustMatch) {
  SyntheticSpec spec;
  spec.materials[0].textures[2].data->push_back(0);  // one byte past the chain
  EXPECT_TRUE(rejects(spec, with(kTexture, {"40 bytes", "41"})));
  spec.materials[0].textures[2].data->resize(32);  // the last level missing
  EXPECT_TRUE(rejects(spec, with(kTexture, {"40 bytes", "32"})));
}

TEST(Texture, MipCountWithinTheFullChain) {
  SyntheticSpec spec;
  spec.materials[0].textures[2].mip_count = 5;  // 8 x 4 has 4 levels
  EXPECT_TRUE(rejects(spec, with(kTexture, {"mip levels"})));
  spec.materials[0].textures[2].mip_count = 0;
  EXPECT_TRUE(rejects(spec, with(kTexture, {"mip levels"})));
}

TEST(Texture, SizeWithinLimits) {
  SyntheticSpec spec;
  spec.materials[0].textures[2].width = 0;
  EXPECT_TRUE(rejects(spec, with(kTexture, {"texels"})));
  spec.materials[0].textures[2].width = 8;
  spec.materials[0].textures[2].height = 1u << 20;  // a huge claim over 40 bytes
  EXPECT_TRUE(rejects(spec, with(kTexture, {"texels"})));
}

TEST(Texture, UnknownEncodingAndSourceWithLevels) {
  SyntheticSpec spec;
  spec.materials[0].textures[2].encoding = static_cast<fb::TextureEncoding>(42);
  EXPECT_TRUE(rejects(spec, with(kTexture, {"encoding"})));
  SyntheticSpec source;
  source.materials[0].textures[0].mip_count = 3;  // PNG bytes do not have levels
  EXPECT_TRUE(rejects(source, {{"skin", "material 0"}, {"texture 0", "Diffuse"}, {"mip levels"}}));
}

// A PBR source's fields (format v11): the emissive colour finite, metallic and roughness in [0, 1].
TEST(Material, PbrFieldsOutOfRangeRejected) {
  SyntheticSpec spec;
  spec.materials[0].emissive = fb::Vec3(1.0f, 0.5f, 0.0f);
  spec.materials[0].pbr = fb::PbrFactors(0.25f, 0.75f);
  EXPECT_TRUE(accepts(make_valid_file(spec)));
  spec.materials[0].emissive = fb::Vec3(1.0f, std::numeric_limits<float>::quiet_NaN(), 0.0f);
  EXPECT_TRUE(rejects(spec, {{"skin", "material 0"}, {"emissive"}, {"finite"}}));
  spec.materials[0].emissive.reset();
  for (const fb::PbrFactors bad : {fb::PbrFactors(1.5f, 0.5f), fb::PbrFactors(0.5f, -0.1f),
                                   fb::PbrFactors(std::numeric_limits<float>::quiet_NaN(), 0.5f)}) {
    spec.materials[0].pbr = bad;
    EXPECT_TRUE(rejects(spec, {{"skin", "material 0"}, {"metallic"}, {"roughness"}}));
  }
}

TEST(Texture, EveryEncodingsChainAccepted) {
  // Each encoding at an odd size: level sizes round up to whole blocks (or texels for RGBA8).
  for (const auto e : {fb::TextureEncoding::Rgba8, fb::TextureEncoding::Bc1, fb::TextureEncoding::Bc3,
                       fb::TextureEncoding::Bc4, fb::TextureEncoding::Bc5}) {
    SyntheticSpec spec;
    SyntheticTexture& t = spec.materials[0].textures[2];
    t.encoding = e;
    t.width = 13;
    t.height = 5;
    t.mip_count = static_cast<uint8_t>(texture_full_mip_count(13, 5));
    t.data = std::vector<uint8_t>(static_cast<size_t>(texture_chain_bytes(e, 13, 5, t.mip_count)), 0x5a);
    EXPECT_TRUE(accepts(make_valid_file(spec))) << fb::EnumNameTextureEncoding(e);
    t.data->pop_back();
    EXPECT_TRUE(rejects(spec, with(kTexture, {"bytes"}))) << fb::EnumNameTextureEncoding(e);
  }
}

}  // namespace
}  // namespace ossa::test
