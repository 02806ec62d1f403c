// sample_test.cpp — the clip sampler (ossa/anim/sample.h) against an independent reference.
//
// The reference here decodes keys with ossa/format/clip_codec.h and interpolates them the slow, obvious
// way (linear search for the key pair, double precision, lerp / nlerp with the shortest-arc sign
// fix / slerp), so the tests hold the cached SoA sampler to what the format says a clip means:
//   - at frame times sampling reproduces the decoded keys; between keys it is their interpolation;
//   - the cache is invisible: cached sampling equals a fresh cache for forward (60 Hz), reverse
//     (negative rate through advance_time) and random-seek sequences;
//   - loop and clamp modes, loop-boundary continuity, rotations across hemispheres, slerp;
//   - a clip is refused by a skeleton it was not cooked for.
// Synthetic v2 clips (test_files.h) pin the exact cases; Pab's cooked walk (tests/fixtures/Pab,
// cooked by ossa-cook against its skeleton, as bench/bench_fixture.cpp does) checks real data.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <memory>
#include <map>
#include <optional>
#include <random>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>

#include <ossa/format/clip_codec.h>
#include <ossa/loader/asset.h>
#include <ossa/anim/pose.h>
#include <ossa/anim/sample.h>
#include <ossa/anim/vector_isa.h>
#include "test_files.h"

#if defined(__SSE2__)
#include <xmmintrin.h>
#endif

namespace ossa {
namespace {

namespace fs = std::filesystem;
using test::SyntheticSpec;

// ---- the reference sampler -----------------------------------------------------------------

/// One joint's channel values as doubles: T xyz, R xyzw, S xyz (pose component order).
struct RefJoint {
  double v[kPoseComponents];
};

/// Decoded key k of an animated channel, rotation w restored.
std::array<double, 4> decoded_key(const ClipView& clip, const fb::AnimatedChannel& a, uint32_t k) {
  const float lo[3] = {a.range_min().x(), a.range_min().y(), a.range_min().z()};
  const float ex[3] = {a.range_extent().x(), a.range_extent().y(), a.range_extent().z()};
  float v[3];
  decode_key(clip.key_values().data(), a.bit_offset(), widths_of(a), a.segment_offset_bits(), lo, ex, k, v);
  if (a.channel() != fb::Channel::Rotation) return {v[0], v[1], v[2], 0.0};
  // The dropped component, rebuilt by the format's own float expression (the cooker tunes the
  // stored values to it, so a double-precision rebuild would disagree near half turns).
  const double rebuilt = rotation_w(v);
  std::array<double, 4> q{};
  for (uint32_t c = 0, i = 0; c < 4; ++c) q[c] = c == a.dropped() ? rebuilt : v[i++];
  return q;
}

uint32_t first_component(fb::Channel c) {
  return c == fb::Channel::Translation ? kTx : c == fb::Channel::Rotation ? kRx : kSx;
}

enum class RefRotation { Nlerp, Slerp };

/// The pose at frame position `frame` (already wrapped or clamped), computed the obvious way.
std::vector<RefJoint> reference_pose(const ClipView& clip, const SkeletonView& skeleton, double frame,
                                     RefRotation rotation = RefRotation::Nlerp) {
  std::vector<RefJoint> out(skeleton.joint_count());
  for (size_t j = 0; j < out.size(); ++j) {
    const auto& t = skeleton.bind_translations()[j];
    const auto& r = skeleton.bind_rotations()[j];
    const auto& s = skeleton.bind_scales()[j];
    out[j] = RefJoint{{t.x(), t.y(), t.z(), r.x(), r.y(), r.z(), r.w(), s.x(), s.y(), s.z()}};
  }
  for (const fb::ConstantChannel& c : clip.constants()) {
    const uint32_t base = first_component(c.channel());
    float q[4];
    constant_value(c, q);
    for (uint32_t i = 0; i < (c.channel() == fb::Channel::Rotation ? 4u : 3u); ++i) out[c.joint()].v[base + i] = q[i];
  }
  for (const fb::AnimatedChannel& a : clip.animated()) {
    const auto frames = [&](uint32_t k) {
      return key_frame(clip.key_frames().data(), a.first_key(), a.key_count(), clip.frame_count(), k);
    };
    uint32_t k = 0;
    while (k + 2 < a.key_count() && frames(k + 1) <= frame) ++k;
    const double f0 = frames(k), f1 = frames(k + 1);
    const double w = std::clamp((frame - f0) / (f1 - f0), 0.0, 1.0);
    const auto ka = decoded_key(clip, a, k), kb0 = decoded_key(clip, a, k + 1);
    auto kb = kb0;
    const uint32_t base = first_component(a.channel());
    if (a.channel() != fb::Channel::Rotation) {
      for (int i = 0; i < 3; ++i) out[a.joint()].v[base + i] = ka[i] * (1 - w) + kb[i] * w;
      continue;
    }
    const double dot = ka[0] * kb[0] + ka[1] * kb[1] + ka[2] * kb[2] + ka[3] * kb[3];
    if (dot < 0)
      for (double& x : kb) x = -x;
    double r[4];
    if (rotation == RefRotation::Slerp && std::fabs(dot) < 0.9995) {
      const double theta = std::acos(std::fabs(dot));
      const double wa = std::sin((1 - w) * theta) / std::sin(theta), wb = std::sin(w * theta) / std::sin(theta);
      for (int i = 0; i < 4; ++i) r[i] = ka[i] * wa + kb[i] * wb;
    } else {
      for (int i = 0; i < 4; ++i) r[i] = ka[i] * (1 - w) + kb[i] * w;
    }
    const double n = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2] + r[3] * r[3]);
    for (int i = 0; i < 4; ++i) out[a.joint()].v[base + i] = r[i] / n;
  }
  // Normalize fixed rotations too (the sampler does, at cache creation).
  for (RefJoint& j : out) {
    const double n = std::sqrt(j.v[kRx] * j.v[kRx] + j.v[kRy] * j.v[kRy] + j.v[kRz] * j.v[kRz] + j.v[kRw] * j.v[kRw]);
    for (uint32_t i = kRx; i <= kRw; ++i) j.v[i] /= n;
  }
  return out;
}

/// Largest difference between a sampled pose and the reference; rotations compared up to sign.
double max_difference(ConstPoseSpan pose, const std::vector<RefJoint>& ref) {
  double worst = 0.0;
  for (uint32_t j = 0; j < ref.size(); ++j) {
    for (PoseComponent c : {kTx, kTy, kTz, kSx, kSy, kSz}) worst = std::max(worst, std::fabs(pose[c][j] - ref[j].v[c]));
    double same = 0.0, flipped = 0.0;
    for (uint32_t c = kRx; c <= kRw; ++c) {
      const double p = pose[static_cast<PoseComponent>(c)][j];
      same = std::max(same, std::fabs(p - ref[j].v[c]));
      flipped = std::max(flipped, std::fabs(p + ref[j].v[c]));
    }
    worst = std::max(worst, std::min(same, flipped));
  }
  return worst;
}

/// Bitwise equality of the joints' lanes of two poses.
bool same_bits(ConstPoseSpan a, ConstPoseSpan b) {
  for (uint32_t c = 0; c < kPoseComponents; ++c)
    if (std::memcmp(a[static_cast<PoseComponent>(c)], b[static_cast<PoseComponent>(c)],
                    a.joint_count * sizeof(float)) != 0)
      return false;
  return true;
}

double wrapped_frame(const ClipView& clip, double t, bool loop) {
  const double d = clip.duration();
  if (loop) {
    t = d > 0 ? t - std::floor(t / d) * d : 0.0;
    if (t >= d) t = 0.0;
  } else {
    t = std::clamp(t, 0.0, d);
  }
  return std::min(t * clip.sample_rate(), static_cast<double>(clip.frame_count() - 1));
}

// ---- fixtures ------------------------------------------------------------------------------

struct Loaded {
  Asset asset;
  ClipView clip() const { return asset.clip(0); }
  SkeletonView skeleton() const { return asset.skeleton(); }
};

Loaded load(const SyntheticSpec& spec) {
  auto asset = Asset::from_bytes(make_valid_file(spec), "synthetic.ossa");
  EXPECT_TRUE(asset.ok()) << asset.error().message;
  return Loaded{std::move(*asset)};
}

SamplingCache cache_for(const ClipView& clip, const SkeletonView& skeleton) {
  auto cache = make_sampling_cache(clip, skeleton);
  EXPECT_TRUE(cache.ok()) << cache.error().message;
  return std::move(*cache);
}

/// Pab's skeleton and its walk, cooked by ossa-cook (the walk against the skeleton, default options)
/// into the committed fixtures (tests/fixtures/Pab); opened once per process.
struct Pab {
  Asset skeleton;
  Asset walk;
};

const Pab* pab() {
  static const std::unique_ptr<Pab> data = []() -> std::unique_ptr<Pab> {
    const fs::path dir = test::fixtures_dir() / "Pab";
    auto s = Asset::open((dir / "skeleton.ossa").string());
    auto w = Asset::open((dir / "walk.ossa").string());
    EXPECT_TRUE(s.ok()) << (s.ok() ? "" : s.error().message);
    EXPECT_TRUE(w.ok()) << (w.ok() ? "" : w.error().message);
    if (!s.ok() || !w.ok()) return nullptr;
    return std::unique_ptr<Pab>(new Pab{std::move(*s), std::move(*w)});
  }();
  return data.get();
}

#define REQUIRE_PAB()                                                            \
  const Pab* p = pab();                                                          \
  ASSERT_NE(p, nullptr) << "tests/fixtures/Pab could not be opened (see above)"; \
  const ClipView clip = p->walk.clip(0);                                         \
  const SkeletonView skeleton = p->skeleton.skeleton()

/// Samples `times` twice, once with each vector copy (vector_isa.h) and a cache of its own, and
/// counts the poses compared; fails at the first that differs in a bit.
int expect_copies_agree(const ClipView& clip, const SkeletonView& skeleton, const std::vector<float>& times,
                        const std::string& what) {
  const auto joints = static_cast<uint32_t>(skeleton.joint_count());
  SamplingCache ca = cache_for(clip, skeleton), cb = cache_for(clip, skeleton);
  Pose a(joints), b(joints);
  int checked = 0;
  for (const float t : times) {
    for (const RotationInterpolation r : {RotationInterpolation::Nlerp, RotationInterpolation::Slerp}) {
      const SampleOptions o{.loop = true, .rotation = r};
      EXPECT_TRUE(ossa::set_vector_isa(ossa::VectorIsa::Avx2));
      sample(clip, t, o, ca, a);
      EXPECT_TRUE(ossa::set_vector_isa(ossa::VectorIsa::Baseline));
      sample(clip, t, o, cb, b);
      ossa::set_vector_isa(ossa::best_vector_isa());
      EXPECT_TRUE(same_bits(a, b)) << what << " at t=" << t;
      if (!same_bits(a, b)) return checked;
      ++checked;
    }
  }
  return checked;
}

// ---- synthetic clips -----------------------------------------------------------------------

TEST(Sample, FrameTimesReproduceDecodedKeys) {
  const Loaded f = load({});
  const ClipView clip = f.clip();
  SamplingCache cache = cache_for(clip, f.skeleton());
  Pose pose(static_cast<uint32_t>(f.skeleton().joint_count()));
  for (const fb::AnimatedChannel& a : clip.animated()) {
    for (uint32_t k = 0; k < a.key_count(); ++k) {
      const uint32_t frame = key_frame(clip.key_frames().data(), a.first_key(), a.key_count(), clip.frame_count(), k);
      sample(clip, static_cast<float>(frame) / clip.sample_rate(), SampleOptions{.loop = false}, cache, pose);
      const auto key = decoded_key(clip, a, k);
      const uint32_t base = first_component(a.channel());
      const uint32_t n = a.channel() == fb::Channel::Rotation ? 4 : 3;
      double norm = 0.0;
      for (uint32_t i = 0; i < n; ++i) norm += key[i] * key[i];
      norm = a.channel() == fb::Channel::Rotation ? std::sqrt(norm) : 1.0;
      for (uint32_t i = 0; i < n; ++i)
        EXPECT_NEAR(pose.span()[static_cast<PoseComponent>(base + i)][a.joint()], key[i] / norm, 1e-6)
            << "joint " << a.joint() << " channel " << int(a.channel()) << " key " << k << " component " << i;
    }
  }
}

TEST(Sample, KeyFramesGiveTheFormatsDecodedTranslationsAndScalesBitForBit) {
  // At a key's frame a translation or scale is that key exactly (lerp weight 0), so the sampler's
  // decode must give clip_codec.h's decode_key bits, on every valid synthetic clip and Pab's clips.
  std::vector<test::SyntheticSpec> specs;
  for (const auto& [name, spec] : test::valid_variants())
    if (!spec.clips.empty() && spec.skeleton && !spec.clips[0].skeleton_hash) specs.push_back(spec);
  std::vector<Asset> assets;
  for (const test::SyntheticSpec& spec : specs) assets.push_back(load(spec).asset);
  std::vector<std::pair<ClipView, SkeletonView>> clips;
  for (const Asset& a : assets) clips.emplace_back(a.clip(0), a.skeleton());
  auto rig = Asset::open((test::fixtures_dir() / "Pab" / "skeleton.ossa").string());
  ASSERT_TRUE(rig.ok()) << rig.error().message;
  for (const char* name : {"walk", "jog", "run", "crossarms"}) {
    auto a = Asset::open((test::fixtures_dir() / "Pab" / (std::string(name) + ".ossa")).string());
    ASSERT_TRUE(a.ok()) << a.error().message;
    assets.push_back(std::move(*a));
  }
  for (size_t i = specs.size(); i < assets.size(); ++i) clips.emplace_back(assets[i].clip(0), rig->skeleton());
  size_t checked = 0;
  for (const auto& [clip, skeleton] : clips) {
    SamplingCache cache = cache_for(clip, skeleton);
    Pose pose(static_cast<uint32_t>(skeleton.joint_count()));
    for (const fb::AnimatedChannel& a : clip.animated()) {
      if (a.channel() == fb::Channel::Rotation) continue;
      const float lo[3] = {a.range_min().x(), a.range_min().y(), a.range_min().z()};
      const float ex[3] = {a.range_extent().x(), a.range_extent().y(), a.range_extent().z()};
      for (uint32_t k = 0; k < a.key_count(); ++k) {
        const uint32_t frame = key_frame(clip.key_frames().data(), a.first_key(), a.key_count(), clip.frame_count(), k);
        sample(clip, static_cast<float>(frame) / clip.sample_rate(), SampleOptions{.loop = false}, cache, pose);
        float v[3];
        decode_key(clip.key_values().data(), a.bit_offset(), widths_of(a), a.segment_offset_bits(), lo, ex, k, v);
        for (uint32_t c = 0; c < 3; ++c) {
          const float got = pose.span()[static_cast<PoseComponent>(first_component(a.channel()) + c)][a.joint()];
          ASSERT_EQ(std::memcmp(&got, &v[c], sizeof got), 0)
              << clip.name() << " joint " << a.joint() << " key " << k << " component " << c;
          ++checked;
        }
      }
    }
  }
  EXPECT_GT(checked, 1000u);
}

TEST(Sample, AbsentAndConstantChannelsHoldTheirValues) {
  const Loaded f = load({});
  SamplingCache cache = cache_for(f.clip(), f.skeleton());
  Pose pose(4);
  sample(f.clip(), 0.4f, {}, cache, pose);
  // root: nothing in the clip: bind pose (identity at the origin).
  const Transform root = get_transform(pose, 0);
  EXPECT_EQ(root.translation, glm::vec3(0.0f));
  EXPECT_EQ(root.scale, glm::vec3(1.0f));
  // spine translation: constant (0, 1, 0); head rotation: constant 30 degrees about z.
  EXPECT_EQ(get_transform(pose, 1).translation, glm::vec3(0, 1, 0));
  const glm::quat head = get_transform(pose, 2).rotation;
  EXPECT_NEAR(head.z, 0.25881905f, 1e-6f);
  EXPECT_NEAR(head.w, 0.96592583f, 1e-6f);
  // arm rotation: absent: the bind rotation (90 degrees about z).
  EXPECT_NEAR(get_transform(pose, 3).rotation.z, 0.70710678f, 1e-6f);
}

TEST(Sample, BetweenKeysMatchesInterpolationOfDecodedKeys) {
  for (const auto& [name, spec] : test::valid_variants()) {
    if (spec.clips.empty() || !spec.skeleton || spec.clips[0].skeleton_hash) continue;
    const Loaded f = load(spec);
    const ClipView clip = f.clip();
    SamplingCache cache = cache_for(clip, f.skeleton());
    Pose pose(static_cast<uint32_t>(f.skeleton().joint_count()));
    std::mt19937 rng(7);
    std::uniform_real_distribution<float> time(-0.5f, 2.5f);
    for (int i = 0; i < 200; ++i) {
      const float t = time(rng);
      for (bool loop : {true, false}) {
        sample(clip, t, SampleOptions{.loop = loop}, cache, pose);
        const auto ref = reference_pose(clip, f.skeleton(), wrapped_frame(clip, t, loop));
        ASSERT_LT(max_difference(pose, ref), 2e-6) << name << " t=" << t << " loop=" << loop;
      }
    }
  }
}

/// A clip of one joint rotating about x from 170 to 190 degrees: stored with w >= 0 (w dropped),
/// its second key lies in the opposite hemisphere of the first, and only the sign fix keeps the
/// blend on the 20-degree arc through 180 degrees.
SyntheticSpec hemisphere_spec(uint8_t bits) {
  SyntheticSpec spec;
  test::SyntheticClip& c = spec.clips[0];
  c.constants.clear();
  c.animated.clear();
  const double a0 = glm::radians(170.0) / 2, a1 = glm::radians(190.0) / 2;
  // 190 degrees has w = cos(95) < 0: stored negated.
  test::SyntheticAnimated r;
  r.joint = 1;
  r.channel = fb::Channel::Rotation;
  r.bits = bits;
  r.frames = {0, 30};
  r.values = {{static_cast<float>(std::sin(a0)), 0, 0}, {static_cast<float>(-std::sin(a1)), 0, 0}};
  c.animated.push_back(r);
  return spec;
}

TEST(Sample, SeeksFindTheKeyPairInALongClipWithSparseAndDenseRuns) {
  // 200 frames, so a sparse run's seek index has 4 blocks of 64 frames (every frame below samples
  // the bitmaps' word edges): keys on 8-frame starts and just past them, a 42-frame gap, a run that
  // ends its keys early, a dense run (a key on every frame), one that misses a single frame and a
  // raw-float one. Every frame, every half frame, each 8-frame block's edges,
  // and random times, sampled in an order that jumps back and forth through one cache, must give
  // the pose of the key pair found by a plain walk over the keys (reference_pose).
  test::SyntheticSpec spec;
  test::SyntheticClip& c = spec.clips[0];
  c.frame_count = 200;
  c.constants.clear();
  const auto channel = [](uint16_t joint, fb::Channel ch, uint8_t bits, std::vector<uint16_t> frames) {
    test::SyntheticAnimated a;
    a.joint = joint;
    a.channel = ch;
    a.bits = bits;
    for (size_t k = 0; k < frames.size(); ++k) {
      const float x = 0.3f * std::sin(0.7f * static_cast<float>(k)) + 0.01f * static_cast<float>(frames[k]);
      a.values.push_back(ch == fb::Channel::Rotation ? std::array<float, 3>{0.0f, 0.5f * std::sin(x), 0.0f}
                                                     : std::array<float, 3>{x, 1.0f - x, 0.5f * x});
    }
    a.frames = std::move(frames);
    return a;
  };
  std::vector<uint16_t> every(200);
  for (uint16_t k = 0; k < 200; ++k) every[k] = k;
  std::vector<uint16_t> almost_every = every;  // sparse, yet 7 keys past some block starts
  almost_every.erase(almost_every.begin() + 100);
  c.animated = {channel(0, fb::Channel::Translation, 10, {0, 2, 4, 6, 8, 10, 12, 14, 16, 18, 20, 22, 24, 199}),
                channel(1, fb::Channel::Rotation, 14, every),
                channel(2, fb::Channel::Rotation, 12, {0, 5, 31, 100, 120, 121, 122, 199}),
                channel(2, fb::Channel::Scale, 16, almost_every),
                channel(3, fb::Channel::Translation, 16, {0, 1, 7, 8, 9, 15, 16, 17, 32, 33, 47, 48, 90, 91, 150, 199}),
                channel(3, fb::Channel::Scale, 32, {0, 64, 65, 199})};
  const Loaded f = load(spec);
  const ClipView clip = f.clip();
  SamplingCache cache = cache_for(clip, f.skeleton());
  Pose pose(static_cast<uint32_t>(f.skeleton().joint_count()));
  std::vector<double> frames;
  for (int k = 0; k < 200; ++k) frames.insert(frames.end(), {double(k), k + 0.5, k + 0.99});
  for (int b = 8; b < 200; b += 8) frames.insert(frames.end(), {b - 0.01, double(b), b + 0.01});
  std::mt19937 rng(17);
  std::uniform_real_distribution<double> u(0.0, 199.0);
  for (int i = 0; i < 400; ++i) frames.push_back(u(rng));
  std::shuffle(frames.begin(), frames.end(), rng);
  const size_t half = frames.size() / 2;
  frames.insert(frames.end(), frames.begin(), frames.begin() + static_cast<std::ptrdiff_t>(half));
  std::sort(frames.begin() + static_cast<std::ptrdiff_t>(half), frames.end());  // forward playback too
  // Steps that skip a key and land on the next one (a run then holds only its pair's first key),
  // then a jump inside that pair's long gap, which must decode the second key.
  frames.insert(frames.end(), {63.5, 65.0, 100.0, 119.5, 121.0, 121.5, 63.5, 65.0, 64.5, 30.0, 31.0, 80.0});
  for (const double frame : frames) {
    const float t = static_cast<float>(frame / clip.sample_rate());
    sample(clip, t, SampleOptions{.loop = false}, cache, pose);
    const auto ref = reference_pose(clip, f.skeleton(), wrapped_frame(clip, t, false));
    ASSERT_LT(max_difference(pose, ref), 2e-6) << "frame " << frame;
  }
  // A cache made with a prototype reads the prototype's seek indexes: the same bits.
  auto prototype = make_sampling_cache(clip, f.skeleton());
  ASSERT_TRUE(prototype.ok()) << prototype.error().message;
  auto shared = make_sampling_cache(clip, f.skeleton(), &*prototype);
  ASSERT_TRUE(shared.ok()) << shared.error().message;
  SamplingCache own = cache_for(clip, f.skeleton());
  Pose other(static_cast<uint32_t>(f.skeleton().joint_count()));
  for (const double frame : frames) {
    const float t = static_cast<float>(frame / clip.sample_rate());
    sample(clip, t, SampleOptions{.loop = false}, *shared, pose);
    sample(clip, t, SampleOptions{.loop = false}, own, other);
    ASSERT_TRUE(same_bits(pose, other)) << "frame " << frame;
  }
}

TEST(Sample, AKeysOwnFrameGivesTheSameBitsWhateverTheNextKeyHolds) {
  // At a key's own frame the sampler may decode only the pair's first key (sample_keys.cpp, settle):
  // the second key's weight is 0 there, and no key decodes to -0 (clip_codec.h), so the pose may
  // not depend on the second key. Keys holding -0 (raw floats; a quantized channel whose range
  // minimum and extent are -0) beside keys of either sign, sampled at their frames after a jump
  // (first keys only), a step forward onto the key and a step back inside the pair after it (whole
  // pairs), must give the same bits, nlerp and slerp, with +0 where a key holds -0. At weight 0
  // slerp is nlerp (both the normalized first key), which is what keeps it off the second key.
  test::SyntheticSpec spec;
  test::SyntheticClip& c = spec.clips[0];
  c.frame_count = 8;
  c.constants.clear();
  const float z = -0.0f;
  test::SyntheticAnimated raw_t;
  raw_t.joint = 0;
  raw_t.channel = fb::Channel::Translation;
  raw_t.bits = 32;
  raw_t.values = {{z, z, 0.5f}, {1.0f, -1.0f, 0.5f},  {z, 2.0f, z}, {-1.0f, 1.0f, 1.0f},
                  {z, z, z},    {2.0f, -2.0f, 0.25f}, {z, 0.0f, z}, {-3.0f, 3.0f, -1.0f}};
  test::SyntheticAnimated raw_r;
  raw_r.joint = 1;
  raw_r.channel = fb::Channel::Rotation;
  raw_r.bits = 32;
  raw_r.values = {{z, 0.0f, 0.6f}, {0.3f, -0.2f, 0.1f}, {z, z, z},        {-0.4f, 0.5f, -0.3f},
                  {z, 0.2f, z},    {0.1f, 0.1f, -0.6f}, {0.0f, z, -0.1f}, {-0.5f, -0.5f, 0.5f}};
  test::SyntheticAnimated flat;  // quantized; every code decodes to min + extent * q / max = -0 + -0
  flat.joint = 2;
  flat.channel = fb::Channel::Translation;
  flat.bits = 8;
  flat.values.assign(8, {0.0f, 1.0f, 0.0f});
  flat.range_min = fb::Vec3(z, 1.0f, z);
  flat.range_extent = fb::Vec3(z, 0.0f, z);
  for (test::SyntheticAnimated* a : {&raw_t, &raw_r, &flat}) a->frames = {0, 1, 2, 3, 4, 5, 6, 7};
  c.animated = {raw_t, raw_r, flat};
  const Loaded f = load(spec);
  const ClipView clip = f.clip();
  const auto joints = static_cast<uint32_t>(f.skeleton().joint_count());
  std::map<int, Pose> nlerped;
  for (const RotationInterpolation mode : {RotationInterpolation::Nlerp, RotationInterpolation::Slerp}) {
    const SampleOptions o{.loop = false, .rotation = mode};
    for (const int key : {0, 2, 4, 6}) {
      // How each cache comes to the key's frame: the frames sampled before it.
      const std::vector<std::vector<double>> ways = {{},    {key - 0.5}, {key + 0.5}, {key + 0.25, key + 0.75},
                                                     {7.0}, {key + 3.0}, {key - 3.0}};
      std::optional<Pose> first;
      for (const auto& before : ways) {
        SamplingCache cache = cache_for(clip, f.skeleton());
        Pose pose(joints);
        for (const double frame : before)
          if (frame >= 0.0 && frame <= 7.0) sample(clip, static_cast<float>(frame / 30.0), o, cache, pose);
        sample(clip, static_cast<float>(key / 30.0), o, cache, pose);
        EXPECT_FALSE(std::signbit(pose.span()[kTx][0])) << "key " << key << ": raw -0 reads as +0";
        EXPECT_FALSE(std::signbit(pose.span()[kTx][2])) << "key " << key << ": -0 + -0 decodes as +0";
        if (!first) first = std::move(pose);
        else ASSERT_TRUE(same_bits(*first, pose)) << "key " << key << " after " << before.size() << " samples";
      }
      if (mode == RotationInterpolation::Nlerp) nlerped.emplace(key, std::move(*first));
      else EXPECT_TRUE(same_bits(nlerped.at(key), *first)) << "key " << key << ": slerp at weight 0 is nlerp";
    }
  }
}

TEST(Sample, SegmentedKeysSampleAsTheirPlainKeysBitForBit) {
  // Format v14: a channel keyed at every frame may store its codes in segments of 16 keys, each
  // with its own minimum and width per component. The same codes segmented or plain must sample to
  // the same bits at every time, forward and by seeks: here 200 frames (13 segments, the last of 8
  // keys), components that move slowly, jump once (a segment spanning the channel's whole range),
  // or hold still for a segment (width 0), in rotation, translation and scale channels of
  // different widths, with data offsets of 14 bits (the fewest that hold them all) and 32, and
  // with one channel segmented beside plain ones (the sampler decodes those in a loop of its own).
  const auto spec_of = [](std::array<uint8_t, 3> offset_bits) {
    test::SyntheticSpec spec;
    test::SyntheticClip& c = spec.clips[0];
    c.frame_count = 200;
    c.constants.clear();
    const auto channel = [&](uint16_t joint, fb::Channel ch, std::array<uint8_t, 3> widths, float phase) {
      test::SyntheticAnimated a;
      a.joint = joint;
      a.channel = ch;
      a.widths = widths;
      a.segment_offset_bits = offset_bits[joint];
      for (uint16_t f = 0; f < 200; ++f) {
        const float x = 0.3f * std::sin(0.05f * static_cast<float>(f) + phase) + (f >= 120 ? 0.4f : 0.0f);
        const float still = f >= 32 && f < 48 ? 0.25f : 0.1f * std::cos(0.11f * static_cast<float>(f));
        a.frames.push_back(f);
        a.values.push_back(ch == fb::Channel::Rotation ? std::array<float, 3>{0.5f * x, still, 0.1f}
                                                       : std::array<float, 3>{x, still, 1.0f + 0.5f * x});
      }
      return a;
    };
    c.animated = {channel(0, fb::Channel::Translation, {10, 6, 3}, 0.0f),
                  channel(1, fb::Channel::Rotation, {14, 12, 1}, 1.0f),
                  channel(2, fb::Channel::Scale, {19, 19, 19}, 2.0f)};
    return spec;
  };
  const Loaded plain = load(spec_of({0, 0, 0}));
  const std::vector<uint8_t> plain_bytes = make_valid_file(spec_of({0, 0, 0}));
  using Layout = std::array<uint8_t, 3>;
  for (const Layout offset_bits : {Layout{14, 14, 14}, Layout{32, 32, 32}, Layout{0, 14, 0}, Layout{32, 0, 14}}) {
    const test::SyntheticSpec spec = spec_of(offset_bits);
    EXPECT_LT(make_valid_file(spec).size(), plain_bytes.size()) << "segments take fewer bits here";
    const Loaded segmented = load(spec);
    SamplingCache a = cache_for(plain.clip(), plain.skeleton());
    SamplingCache b = cache_for(segmented.clip(), segmented.skeleton());
    Pose pa(static_cast<uint32_t>(plain.skeleton().joint_count()));
    Pose pb(static_cast<uint32_t>(segmented.skeleton().joint_count()));
    std::vector<double> frames;
    for (int k = 0; k < 200; ++k) frames.insert(frames.end(), {double(k), k + 0.25, k + 0.75});
    std::mt19937 rng(23);
    std::uniform_real_distribution<double> u(0.0, 199.0);
    for (int i = 0; i < 300; ++i) frames.push_back(u(rng));
    std::shuffle(frames.begin() + 600, frames.end(), rng);  // forward playback first, then seeks
    for (const double frame : frames) {
      const float t = static_cast<float>(frame / plain.clip().sample_rate());
      sample(plain.clip(), t, SampleOptions{.loop = false}, a, pa);
      sample(segmented.clip(), t, SampleOptions{.loop = false}, b, pb);
      ASSERT_TRUE(same_bits(pa, pb)) << "offset bits " << int{offset_bits[0]} << " " << int{offset_bits[1]} << " "
                                     << int{offset_bits[2]} << ", frame " << frame;
    }
    if (ossa::best_vector_isa() == ossa::VectorIsa::Avx2) {  // both key decodes (vector_isa.h) agree
      std::vector<float> times;
      for (const double frame : frames) times.push_back(static_cast<float>(frame / plain.clip().sample_rate()));
      EXPECT_EQ(expect_copies_agree(segmented.clip(), segmented.skeleton(), times, "segmented"),
                static_cast<int>(2 * times.size()));
    }
  }
}

TEST(Sample, RotationKeysInOppositeHemispheresTakeTheShortArc) {
  for (uint8_t bits : {uint8_t{16}, uint8_t{32}}) {
    for (RotationInterpolation mode : {RotationInterpolation::Nlerp, RotationInterpolation::Slerp}) {
      const Loaded f = load(hemisphere_spec(bits));
      SamplingCache cache = cache_for(f.clip(), f.skeleton());
      Pose pose(4);
      sample(f.clip(), 0.5f, SampleOptions{.loop = false, .rotation = mode}, cache, pose);
      const glm::quat q = get_transform(pose, 1).rotation;
      // Half way is 180 degrees about x: (x, y, z, w) = (+-1, 0, 0, 0).
      EXPECT_NEAR(std::fabs(q.x), 1.0f, 1e-4f) << int(bits);
      EXPECT_NEAR(q.w, 0.0f, 1e-3f) << int(bits);
      // A quarter of the way: 175 degrees.
      sample(f.clip(), 0.25f, SampleOptions{.loop = false, .rotation = mode}, cache, pose);
      const glm::quat r = get_transform(pose, 1).rotation;
      EXPECT_NEAR(std::fabs(r.w), std::cos(glm::radians(175.0f) / 2), 2e-3f) << int(bits);
    }
  }
}

TEST(Sample, SlerpHasConstantAngularVelocity) {
  // 0 -> 160 degrees about y in 30 frames: nlerp and slerp differ visibly at a quarter.
  SyntheticSpec spec;
  test::SyntheticClip& c = spec.clips[0];
  c.animated[0].frames = {0, 30};
  c.animated[0].values = {{0, 0, 0}, {0, static_cast<float>(std::sin(glm::radians(80.0))), 0}};
  const Loaded f = load(spec);
  SamplingCache cache = cache_for(f.clip(), f.skeleton());
  Pose pose(4);
  for (float t : {0.0f, 0.25f, 0.5f, 0.8f, 1.0f}) {
    sample(f.clip(), t, SampleOptions{.loop = false, .rotation = RotationInterpolation::Slerp}, cache, pose);
    const glm::quat q = get_transform(pose, 1).rotation;
    const float angle = glm::degrees(2.0f * std::atan2(std::fabs(q.y), std::fabs(q.w)));
    EXPECT_NEAR(angle, 160.0f * t, 0.05f) << t;
    const auto ref = reference_pose(f.clip(), f.skeleton(), t * 30.0, RefRotation::Slerp);
    EXPECT_LT(max_difference(pose, ref), 2e-6) << t;
  }
  sample(f.clip(), 0.25f, SampleOptions{.loop = false, .rotation = RotationInterpolation::Nlerp}, cache, pose);
  const glm::quat n = get_transform(pose, 1).rotation;
  EXPECT_GT(std::fabs(glm::degrees(2.0f * std::atan2(std::fabs(n.y), std::fabs(n.w))) - 40.0f), 1.0f)
      << "nlerp and slerp should differ on a 160-degree key pair";
}

TEST(Sample, AtAKeysFrameSlerpAndNlerpGiveTheSameBits) {
  // Three joints rotating 50-170 degrees between keys about changing axes, each with keys of its
  // own: slerp takes its own branch between them. At a joint's key frame the key itself is the
  // answer, whichever interpolation is asked for, so switching modes never moves a keyed pose
  // (and the slerp reads nothing of a second key the sampler may not have decoded there).
  const auto unit_xyz = [](double degrees, glm::dvec3 axis) {
    const glm::dvec3 a = glm::normalize(axis) * std::sin(glm::radians(degrees) / 2);
    return std::array<float, 3>{static_cast<float>(a.x), static_cast<float>(a.y), static_cast<float>(a.z)};
  };
  SyntheticSpec spec;
  std::vector<test::SyntheticAnimated>& tracks = spec.clips[0].animated;
  tracks[0].frames = {0, 7, 15, 22, 30};
  tracks[0].values = {unit_xyz(0, {0, 1, 0}), unit_xyz(110, {0.3, 1, 0.2}), unit_xyz(60, {1, 0.2, 0}),
                      unit_xyz(170, {0.1, 0.4, 1}), unit_xyz(50, {0.6, 0.6, 0.2})};
  test::SyntheticAnimated more = tracks[0];
  more.joint = 0;
  more.frames = {0, 4, 11, 19, 26, 30};
  more.values = {unit_xyz(20, {1, 0, 0}),  unit_xyz(150, {0.2, 0.1, 1}), unit_xyz(70, {0, 1, 0.5}),
                 unit_xyz(160, {1, 1, 0}), unit_xyz(90, {0.2, 1, 0.9}),  unit_xyz(10, {0, 0, 1})};
  tracks.insert(tracks.begin(), more);  // sorted by (joint, channel)
  more.joint = 3;
  more.bits = 32;
  more.frames = {0, 10, 20, 30};
  more.values = {unit_xyz(130, {0.5, 1, 0}), unit_xyz(40, {1, 0.3, 0.3}), unit_xyz(175, {0, 0.2, 1}),
                 unit_xyz(80, {0.7, 0, 0.7})};
  tracks.insert(tracks.begin() + 3, more);  // between joint 3's translation and scale
  const std::map<int, std::vector<int>> keys = {
      {1, {0, 7, 15, 22, 30}}, {0, {0, 4, 11, 19, 26, 30}}, {3, {0, 10, 20, 30}}};
  const Loaded f = load(spec);
  const SampleOptions n_opt{.loop = false, .rotation = RotationInterpolation::Nlerp};
  const SampleOptions s_opt{.loop = false, .rotation = RotationInterpolation::Slerp};
  const auto rotation = [](const Pose& p, int j) { return get_transform(p, static_cast<uint16_t>(j)).rotation; };
  const auto same = [](glm::quat a, glm::quat b) { return std::memcmp(&a, &b, sizeof a) == 0; };
  // Every frame played forward, then each joint's key frames alone (jumps past whole key pairs),
  // and each frame from a fresh cache (a seek).
  std::vector<std::vector<int>> orders(1);
  for (int frame = 0; frame <= 30; ++frame) orders[0].push_back(frame);
  for (const auto& [joint, frames] : keys) orders.push_back(frames);
  int checked = 0, differing = 0;
  for (const std::vector<int>& order : orders) {
    SamplingCache by_nlerp = cache_for(f.clip(), f.skeleton()), by_slerp = cache_for(f.clip(), f.skeleton());
    Pose nlerp(4), slerp(4), sought(4);
    for (const int frame : order) {
      const float t = static_cast<float>(frame) / 30.0f;
      sample(f.clip(), t, n_opt, by_nlerp, nlerp);
      sample(f.clip(), t, s_opt, by_slerp, slerp);
      SamplingCache fresh = cache_for(f.clip(), f.skeleton());
      sample(f.clip(), t, s_opt, fresh, sought);
      for (const auto& [joint, frames] : keys) {
        if (std::find(frames.begin(), frames.end(), frame) != frames.end()) {
          EXPECT_TRUE(same(rotation(nlerp, joint), rotation(slerp, joint))) << "joint " << joint << " frame " << frame;
          EXPECT_TRUE(same(rotation(nlerp, joint), rotation(sought, joint)))
              << "joint " << joint << " frame " << frame << " after a seek";
          ++checked;
        } else if (!same(rotation(nlerp, joint), rotation(slerp, joint))) {
          ++differing;
        }
      }
    }
  }
  EXPECT_EQ(checked, 15 + 9 + 10 + 8);  // forward; then the key frames of joints 1, 0 and 3 (0 and 30: all three)
  EXPECT_GT(differing, 50) << "slerp should differ from nlerp between these keys";
}

TEST(Sample, ClampAndLoopModes) {
  const Loaded f = load({});
  const ClipView clip = f.clip();
  SamplingCache cache = cache_for(clip, f.skeleton());
  Pose a(4), b(4);
  const SampleOptions clamp{.loop = false};
  // Clamped: before the start is frame 0, past the end is the last frame.
  sample(clip, -3.0f, clamp, cache, a);
  sample(clip, 0.0f, clamp, cache, b);
  EXPECT_TRUE(same_bits(a, b));
  sample(clip, 7.5f, clamp, cache, a);
  sample(clip, clip.duration(), clamp, cache, b);
  EXPECT_TRUE(same_bits(a, b));
  EXPECT_LT(max_difference(a, reference_pose(clip, f.skeleton(), 30.0)), 1e-6);
  // Looping: t and t + k * duration are the same pose; duration itself wraps to 0.
  sample(clip, 0.3f, {}, cache, a);
  sample(clip, 2.3f, {}, cache, b);
  EXPECT_LT(max_difference(b, reference_pose(clip, f.skeleton(), wrapped_frame(clip, 2.3, true))), 2e-6);
  EXPECT_LT(max_difference(a, reference_pose(clip, f.skeleton(), 9.0)), 2e-6);
  sample(clip, -0.7f, {}, cache, a);
  EXPECT_LT(max_difference(a, reference_pose(clip, f.skeleton(), 9.0)), 2e-5);
  sample(clip, clip.duration(), {}, cache, a);
  sample(clip, 0.0f, {}, cache, b);
  EXPECT_TRUE(same_bits(a, b));
  // Not-a-number time plays frame 0 rather than poisoning the pose.
  sample(clip, std::numeric_limits<float>::quiet_NaN(), {}, cache, a);
  EXPECT_TRUE(same_bits(a, b));
}

TEST(Sample, SingleFrameClip) {
  SyntheticSpec spec;
  spec.clips[0].frame_count = 1;
  spec.clips[0].animated.clear();
  const Loaded f = load(spec);
  SamplingCache cache = cache_for(f.clip(), f.skeleton());
  Pose a(4), b(4);
  sample(f.clip(), 0.0f, {}, cache, a);
  for (float t : {-1.0f, 0.5f, 100.0f}) {
    for (bool loop : {true, false}) {
      sample(f.clip(), t, SampleOptions{.loop = loop}, cache, b);
      EXPECT_TRUE(same_bits(a, b)) << t;
    }
  }
}

TEST(Sample, RefusesAnotherSkeleton) {
  SyntheticSpec spec;
  spec.clips[0].skeleton_hash = 0xBADBADBADull;
  const Loaded f = load(spec);
  const auto cache = make_sampling_cache(f.clip(), f.skeleton());
  ASSERT_FALSE(cache.ok());
  EXPECT_NE(cache.error().message.find("walk"), std::string::npos) << cache.error().message;
  EXPECT_NE(cache.error().message.find("skeleton"), std::string::npos) << cache.error().message;
  // No skeleton at all.
  EXPECT_FALSE(make_sampling_cache(f.clip(), SkeletonView{}).ok());
  // The right hash on a clip claiming another joint count is refused too (a clip-only file).
  SyntheticSpec clip_only;
  clip_only.skeleton.reset();
  clip_only.meshes.clear();
  clip_only.clips[0].skeleton_hash = load({}).skeleton().hash();
  clip_only.clips[0].joint_count = 5;
  clip_only.clips[0].animated[1].joint = 4;
  clip_only.clips[0].animated[2].joint = 4;
  const Loaded other = load(clip_only);
  const Loaded rig = load({});
  EXPECT_FALSE(make_sampling_cache(other.clip(), rig.skeleton()).ok());
}

/// Plays `times` twice, through one persistent cache and through a fresh one per sample, and
/// requires bit-identical poses.
void expect_cache_invisible(const ClipView& clip, const SkeletonView& skeleton, const std::vector<float>& times,
                            const SampleOptions& options, const char* what) {
  SamplingCache cached = cache_for(clip, skeleton);
  const auto joints = static_cast<uint32_t>(skeleton.joint_count());
  Pose a(joints), b(joints);
  for (size_t i = 0; i < times.size(); ++i) {
    sample(clip, times[i], options, cached, a);
    SamplingCache fresh = cache_for(clip, skeleton);
    sample(clip, times[i], options, fresh, b);
    ASSERT_TRUE(same_bits(a, b)) << what << ": sample " << i << " at t=" << times[i];
  }
  // reset() forgets cursors without changing results.
  reset(cached);
  sample(clip, times.back(), options, cached, a);
  ASSERT_TRUE(same_bits(a, b)) << what << " after reset";
}

std::vector<float> playback(const ClipView& clip, float rate, int frames, bool loop, float start = 0.0f) {
  std::vector<float> times;
  float t = start;
  for (int i = 0; i < frames; ++i) {
    times.push_back(t);
    t = advance_time(t, 1.0f / 60.0f, rate, clip.duration(), loop);
  }
  return times;
}

std::vector<float> random_times(const ClipView& clip, int n, uint32_t seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-clip.duration(), 2.0f * clip.duration());
  std::vector<float> times;
  for (int i = 0; i < n; ++i) times.push_back(u(rng));
  return times;
}

/// Times that step back and forth by up to 5 frames, many of them near the sampler's seek
/// threshold (2 frames: a longer step decodes every channel's pair, a shorter one moves only the
/// runs that left their pair), so one cache goes through both paths in turn.
/// `whole`: from a key's frame, in steps of whole and half frames, so many samples land on keys'
/// own frames (where the sampler decodes a pair's first key only) reached in every way: by a jump,
/// a step forward or back, from the same pair.
std::vector<float> jumps(const ClipView& clip, int n, uint32_t seed, bool whole = false) {
  std::mt19937 rng(seed);
  const float steps[] = {0.4f, 1.0f, 1.99f, 2.0f, 2.01f, 2.5f, 3.0f, 5.0f};
  const float whole_steps[] = {0.5f, 1.0f, 1.5f, 2.0f, 2.0f, 3.0f, 4.0f, 7.0f};
  std::uniform_int_distribution<int> pick(0, 7), sign(0, 2);
  std::vector<float> times;
  const double frames = std::floor(0.37 * (clip.frame_count() - 1));
  float t = whole ? static_cast<float>(frames / clip.sample_rate()) : 0.37f * clip.duration();
  for (int i = 0; i < n; ++i) {
    times.push_back(t);
    const float step = (whole ? whole_steps : steps)[pick(rng)] * (sign(rng) == 0 ? -1.0f : 1.0f);
    t = advance_time(t, step / clip.sample_rate(), 1.0f, clip.duration(), true);
  }
  return times;
}

#if defined(__SSE2__)
TEST(Sample, RebuildingARotationRaisesNoInvalidOperation) {
  // Quantized rotation keys whose three stored components square to just over 1 (w2 < 0: the
  // rebuilt component is 0), next to a raw-float one: forward playback, seeks and loops must not
  // take a square root of a negative number or compute on bytes past a key, so a caller that
  // unmasks the invalid-operation exception (a debug build catching NaNs) is never trapped. The
  // sticky flag is what this checks (with FTZ / DAZ set first, which sample() then leaves as is).
  test::SyntheticSpec spec;
  test::SyntheticClip& c = spec.clips[0];
  c.frame_count = 40;
  c.constants.clear();
  test::SyntheticAnimated over;
  over.joint = 1;
  over.channel = fb::Channel::Rotation;
  over.bits = 19;
  test::SyntheticAnimated raw = over;
  raw.joint = 2;
  raw.bits = 32;
  for (uint16_t k = 0; k < 40; k += 3) {
    over.frames.push_back(k);
    over.values.push_back({0.57736f, 0.57736f, k % 2 ? 0.57737f : 0.57735f});
    raw.frames.push_back(k);
    raw.values.push_back({0.1f, 0.2f * static_cast<float>(k % 4), 0.3f});
  }
  over.frames.back() = raw.frames.back() = 39;
  test::SyntheticAnimated after = raw;  // quantized bits after the raw keys
  after.joint = 3;
  after.channel = fb::Channel::Translation;
  after.bits = 19;
  c.animated = {over, raw, after};
  const Loaded f = load(spec);
  const ClipView clip = f.clip();
  SamplingCache cache = cache_for(clip, f.skeleton());
  Pose pose(static_cast<uint32_t>(f.skeleton().joint_count()));
  const unsigned original = _mm_getcsr();
  std::vector<float> times = playback(clip, 1.0f, 200, true);
  const std::vector<float> seeks = random_times(clip, 200, 23);
  times.insert(times.end(), seeks.begin(), seeks.end());
  for (const float t : times) {
    _mm_setcsr((original & ~0x3fu) | 0x8040u);  // FTZ / DAZ already on: sample() then keeps the flags
    sample(clip, t, {}, cache, pose);
    const unsigned flags = _mm_getcsr() & 0x3fu;
    _mm_setcsr(original);
    ASSERT_EQ(flags & 0x1u, 0u) << "invalid operation at t=" << t;
  }
  EXPECT_EQ(get_transform(pose, 1).rotation.w, 0.0f);  // the keys' rebuilt component
}
#endif

TEST(Sample, CacheIsInvisibleOnSyntheticClips) {
  for (const auto& [name, spec] : test::valid_variants()) {
    if (spec.clips.empty() || !spec.skeleton || spec.clips[0].skeleton_hash) continue;
    const Loaded f = load(spec);
    for (bool loop : {true, false}) {
      const SampleOptions o{.loop = loop};
      expect_cache_invisible(f.clip(), f.skeleton(), playback(f.clip(), 1.0f, 200, loop), o, "forward");
      expect_cache_invisible(f.clip(), f.skeleton(), playback(f.clip(), -1.3f, 200, loop, 0.9f), o, "reverse");
      expect_cache_invisible(f.clip(), f.skeleton(), random_times(f.clip(), 200, 3), o, "seek");
      expect_cache_invisible(f.clip(), f.skeleton(), jumps(f.clip(), 200, 4), o, "steps and jumps");
      expect_cache_invisible(f.clip(), f.skeleton(), jumps(f.clip(), 200, 5, true), o, "keys' frames");
    }
  }
}

TEST(Sample, BothVectorCopiesGiveBitIdenticalPoses) {
  // Both passes of a sample are compiled for AVX2 and the baseline (vector_isa.h): the key decode
  // (seeks, steps, a key's own frame, segmented channels) and the interpolation. With no FMA in
  // either, a pose must not depend on which copy ran.
  if (ossa::best_vector_isa() != ossa::VectorIsa::Avx2) GTEST_SKIP() << "no AVX2 copy on this CPU or build";
  int checked = 0;
  for (const auto& [name, spec] : test::valid_variants()) {
    if (spec.clips.empty() || !spec.skeleton || spec.clips[0].skeleton_hash) continue;
    const Loaded f = load(spec);
    checked += expect_copies_agree(f.clip(), f.skeleton(), playback(f.clip(), 1.0f, 120, true), name + " forward");
    checked += expect_copies_agree(f.clip(), f.skeleton(), random_times(f.clip(), 60, 7), name + " seeks");
    checked += expect_copies_agree(f.clip(), f.skeleton(), jumps(f.clip(), 60, 8, true), name + " keys' frames");
  }
  auto rig = Asset::open((test::fixtures_dir() / "Pab" / "skeleton.ossa").string());
  ASSERT_TRUE(rig.ok()) << rig.error().message;
  for (const char* name : {"walk", "crossarms"}) {  // dense runs; sparse runs in a 259-frame clip
    auto a = Asset::open((test::fixtures_dir() / "Pab" / (std::string(name) + ".ossa")).string());
    ASSERT_TRUE(a.ok()) << a.error().message;
    const ClipView clip = a->clip(0);
    const std::string what = std::string("Pab ") + name;
    checked += expect_copies_agree(clip, rig->skeleton(), playback(clip, 1.0f, 120, true), what + " forward");
    checked += expect_copies_agree(clip, rig->skeleton(), random_times(clip, 120, 9), what + " seeks");
    checked += expect_copies_agree(clip, rig->skeleton(), jumps(clip, 120, 10), what + " steps and jumps");
  }
  EXPECT_GT(checked, 1000);
}

TEST(AdvanceTime, WrapsClampsAndCountsLoops) {
  int loops = 7;
  EXPECT_FLOAT_EQ(advance_time(0.5f, 0.25f, 1.0f, 1.0f, true, &loops), 0.75f);
  EXPECT_EQ(loops, 0);
  EXPECT_FLOAT_EQ(advance_time(0.9f, 0.2f, 1.0f, 1.0f, true, &loops), 0.1f);
  EXPECT_EQ(loops, 1);
  EXPECT_FLOAT_EQ(advance_time(0.1f, 0.2f, -1.0f, 1.0f, true, &loops), 0.9f);
  EXPECT_EQ(loops, -1);
  EXPECT_FLOAT_EQ(advance_time(0.5f, 1.0f, 2.5f, 1.0f, true, &loops), 0.0f);
  EXPECT_EQ(loops, 3);
  EXPECT_FLOAT_EQ(advance_time(0.9f, 0.2f, 1.0f, 1.0f, false, &loops), 1.0f);
  EXPECT_EQ(loops, 0);
  EXPECT_FLOAT_EQ(advance_time(0.1f, 0.2f, -1.0f, 1.0f, false, &loops), 0.0f);
  EXPECT_FLOAT_EQ(advance_time(0.3f, 0.1f, 1.0f, 0.0f, true, &loops), 0.0f);  // a one-frame clip
  EXPECT_FLOAT_EQ(advance_time(0.3f, std::numeric_limits<float>::infinity(), 1.0f, 1.0f, true), 0.0f);
  // A looping time never reaches the duration.
  for (float t = 0.0f; t < 1.0f; t += 0.01f) EXPECT_LT(advance_time(t, 1.0f / 60.0f, 1.0f, 1.0f, true), 1.0f);
}

// ---- Pab's cooked walk -------------------------------------------------------------------------

TEST(SamplePab, FrameTimesReproduceDecodedKeys) {
  REQUIRE_PAB();
  SamplingCache cache = cache_for(clip, skeleton);
  Pose pose(static_cast<uint32_t>(skeleton.joint_count()));
  for (uint32_t frame = 0; frame < clip.frame_count(); ++frame) {
    sample(clip, static_cast<float>(frame) / clip.sample_rate(), SampleOptions{.loop = false}, cache, pose);
    ASSERT_LT(max_difference(pose, reference_pose(clip, skeleton, frame)), 2e-6) << "frame " << frame;
  }
}

TEST(SamplePab, BetweenKeysMatchesInterpolationOfDecodedKeys) {
  REQUIRE_PAB();
  SamplingCache cache = cache_for(clip, skeleton);
  Pose pose(static_cast<uint32_t>(skeleton.joint_count()));
  for (float t : random_times(clip, 300, 11)) {
    sample(clip, t, {}, cache, pose);
    // Positions in centimetres: 2e-6 relative to values of order 100.
    ASSERT_LT(max_difference(pose, reference_pose(clip, skeleton, wrapped_frame(clip, t, true))), 2e-4) << t;
  }
}

TEST(SamplePab, LoopBoundaryIsContinuous) {
  REQUIRE_PAB();
  SamplingCache cache = cache_for(clip, skeleton);
  const auto joints = static_cast<uint32_t>(skeleton.joint_count());
  Pose end(joints), start(joints), step(joints);
  sample(clip, clip.duration() - 1e-4f, {}, cache, end);
  sample(clip, 0.0f, {}, cache, start);
  sample(clip, 1.0f / 60.0f, {}, cache, step);
  // The walk's last frame repeats its first, except where the character travels: the root's
  // translation (this cook keeps root motion in the root). Every other channel crosses the loop
  // moving a joint no more than a 60 Hz step inside the clip does.
  double across = 0.0, inside = 0.0;
  for (uint32_t j = 0; j < joints; ++j) {
    const Transform a = get_transform(end, j), b = get_transform(start, j), c = get_transform(step, j);
    EXPECT_GT(std::fabs(glm::dot(a.rotation, b.rotation)), 0.9995f) << "joint " << j;
    if (skeleton.parents()[j] < 0) continue;
    across = std::max<double>(across, glm::length(a.translation - b.translation));
    inside = std::max<double>(inside, glm::length(c.translation - b.translation));
  }
  EXPECT_LE(across, inside + 1e-3) << "translation jump across the loop: " << across << " vs a step: " << inside;
}

TEST(SamplePab, CacheIsInvisible) {
  REQUIRE_PAB();
  const SampleOptions loop{};
  expect_cache_invisible(clip, skeleton, playback(clip, 1.0f, 400, true), loop, "forward 60 Hz");
  expect_cache_invisible(clip, skeleton, playback(clip, -1.0f, 400, true, 0.3f), loop, "reverse");
  expect_cache_invisible(clip, skeleton, playback(clip, 0.37f, 400, false), SampleOptions{.loop = false},
                         "slow, clamped");
  // Many updates between keys (a montage's held section): pass 1 skips every run until one's pair ends.
  expect_cache_invisible(clip, skeleton, playback(clip, 0.05f, 400, true, 0.4f), loop, "very slow");
  expect_cache_invisible(clip, skeleton, playback(clip, -0.05f, 400, true, 0.4f), loop, "very slow, reverse");
  expect_cache_invisible(clip, skeleton, random_times(clip, 400, 5), loop, "random seeks");
  expect_cache_invisible(clip, skeleton, jumps(clip, 400, 8), loop, "steps and jumps");
  expect_cache_invisible(clip, skeleton, jumps(clip, 400, 10, true), loop, "keys' frames");
  expect_cache_invisible(clip, skeleton, random_times(clip, 100, 6),
                         SampleOptions{.loop = true, .rotation = RotationInterpolation::Slerp}, "slerp seeks");
}

TEST(SamplePab, CacheIsInvisibleOnEveryClipAtEveryRate) {
  // Every cooked Pab clip (their key runs differ: walk, jog, run, the mostly still crossarms) at
  // rates from a montage's hold (0.05: dozens of updates between keys, where pass 1 skips every
  // run) to fast, forward and reverse.
  REQUIRE_PAB();
  (void)clip;  // the walk is one of them
  for (const char* name : {"walk", "jog", "run", "crossarms"}) {
    auto a = Asset::open((test::fixtures_dir() / "Pab" / (std::string(name) + ".ossa")).string());
    ASSERT_TRUE(a.ok()) << a.error().message;
    for (size_t c = 0; c < a->clip_count(); ++c)
      for (float rate : {0.05f, -0.05f, 0.5f, 1.0f, 2.5f})
        for (bool looping : {true, false})
          expect_cache_invisible(a->clip(c), skeleton, playback(a->clip(c), rate, 300, looping, 0.2f),
                                 SampleOptions{.loop = looping}, name);
    for (size_t c = 0; c < a->clip_count(); ++c) {
      expect_cache_invisible(a->clip(c), skeleton, jumps(a->clip(c), 300, 9), SampleOptions{}, name);
      expect_cache_invisible(a->clip(c), skeleton, jumps(a->clip(c), 300, 11, true), SampleOptions{}, name);
    }
  }
}

TEST(SamplePab, JointFilterKeepsTheKeptJointsBitsAndDecodesNothingElse) {
  // A filtered cache (a masked slot's: Spine1's subtree, then the rest) samples every kept joint
  // bit for bit as the full cache does, at every rate; the joints it drops hold their bind pose
  // in a block it keeps a joint of (so it decoded none of their keys), and a block it keeps none
  // of is not written at all.
  REQUIRE_PAB();
  (void)clip;
  auto a = Asset::open((test::fixtures_dir() / "Pab" / "crossarms.ossa").string());
  ASSERT_TRUE(a.ok()) << a.error().message;
  const ClipView arms = a->clip(0);
  const auto joints = static_cast<uint32_t>(skeleton.joint_count());
  const int spine1 = skeleton.find_joint("Spine1");
  ASSERT_GE(spine1, 0);
  std::vector<uint8_t> upper(joints, 0), rest(joints, 0), none(joints, 0);
  for (uint32_t j = 0; j < joints; ++j) {
    for (int k = static_cast<int>(j); k >= 0; k = skeleton.parents()[static_cast<size_t>(k)])
      if (k == spine1) upper[j] = 1;
    rest[j] = upper[j] == 0;
  }
  // What a dropped joint holds (bind values, or the clip's constants): sampled with filters that
  // keep one joint per block (the first, or the second), each read where it drops the joint.
  Pose bind_pose(joints);
  for (uint32_t keep = 0; keep < 2; ++keep) {
    std::vector<uint8_t> one(joints, 0);
    for (uint32_t j = keep; j < joints; j += kPoseLanes) one[j] = 1;
    auto one_cache = make_sampling_cache(arms, skeleton, nullptr, one);
    ASSERT_TRUE(one_cache.ok());
    Pose single(joints);
    sample(arms, 1.0f, SampleOptions{}, *one_cache, single);
    for (uint32_t j = 0; j < joints; ++j)
      if ((j % kPoseLanes == 0) == (keep == 1))
        for (uint32_t k = 0; k < kPoseComponents; ++k)
          bind_pose.span()[PoseComponent(k)][j] = single.span()[PoseComponent(k)][j];
  }
  const ConstPoseSpan bind = bind_pose.span();
  {  // a filter keeping no joint writes nothing
    auto nothing = make_sampling_cache(arms, skeleton, nullptr, none);
    ASSERT_TRUE(nothing.ok());
    Pose untouched(joints);
    std::memcpy(untouched.span().base, bind.base, sizeof(float) * kPoseComponents * bind.stride);
    sample(arms, 1.0f, SampleOptions{}, *nothing, untouched);
    EXPECT_EQ(std::memcmp(untouched.span().base, bind.base, sizeof(float) * kPoseComponents * bind.stride), 0);
  }
  int dropped_animated = 0;
  for (const std::vector<uint8_t>* filter : {&upper, &rest}) {
    auto prototype = make_sampling_cache(arms, skeleton, nullptr, *filter);
    ASSERT_TRUE(prototype.ok()) << prototype.error().message;
    for (float rate : {0.05f, 1.0f, -2.5f}) {
      auto filtered = make_sampling_cache(arms, skeleton, &*prototype, *filter);
      SamplingCache full = cache_for(arms, skeleton);
      ASSERT_TRUE(filtered.ok()) << filtered.error().message;
      Pose got_pose(joints), want_pose(joints);
      const ConstPoseSpan got = got_pose.span(), want = want_pose.span();
      std::vector<uint8_t> block_kept(got_pose.span().stride / kPoseLanes, 0);
      for (uint32_t j = 0; j < joints; ++j) block_kept[j / kPoseLanes] |= (*filter)[j];
      ASSERT_NE(std::count(block_kept.begin(), block_kept.end(), 0), 0) << "some block has no kept joint";
      for (const float t : playback(arms, rate, 300, true, 0.2f)) {
        for (uint32_t k = 0; k < kPoseComponents; ++k)  // a value no sample writes
          std::fill_n(got_pose.span()[PoseComponent(k)], got_pose.span().stride, 7.25f);
        sample(arms, t, SampleOptions{}, *filtered, got_pose);
        sample(arms, t, SampleOptions{}, full, want_pose);
        for (uint32_t j = 0; j < joints; ++j) {
          const ConstPoseSpan expected = (*filter)[j] ? want : bind;
          for (uint32_t k = 0; k < kPoseComponents; ++k) {
            const auto c = PoseComponent(k);
            if (!block_kept[j / kPoseLanes]) {
              ASSERT_EQ(got[c][j], 7.25f) << "joint " << j << " of a block without a kept joint was written";
              continue;
            }
            ASSERT_EQ(std::memcmp(&got[c][j], &expected[c][j], sizeof(float)), 0)
                << "joint " << j << " component " << k << " at t=" << t << " rate " << rate;
            dropped_animated += !(*filter)[j] && std::memcmp(&got[c][j], &want[c][j], sizeof(float)) != 0;
          }
        }
      }
    }
  }
  EXPECT_GT(dropped_animated, 0) << "crossarms animates joints on both sides of the filter";
  const std::vector<uint8_t> wrong(joints + 1, 1);
  EXPECT_FALSE(make_sampling_cache(arms, skeleton, nullptr, wrong).ok());
}

TEST(SamplePab, RefusedByAnotherRig) {
  REQUIRE_PAB();
  const Loaded other = load({});
  EXPECT_FALSE(make_sampling_cache(clip, other.skeleton()).ok());
  EXPECT_TRUE(make_sampling_cache(clip, skeleton).ok());
}

}  // namespace
}  // namespace ossa
