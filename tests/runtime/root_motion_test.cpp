// root_motion_test.cpp — root motion from cook to host (cooker/clip/root_motion.h, ossa/anim/root_motion.h).
//
// Cook side: on a synthetic clip whose root runs 1.5 turns round a circle while turning with it
// (plus height bob, pitch/roll wobble, a constant tilt like a Z-up rig folded into Y-up, and a
// start away from the origin), extraction yields the expected yaw (unwrapped, no +-pi jumps) and
// ground path, and the in-place root composed with the extracted motion reproduces the original
// root model transform at every frame, for each up axis.
// Run-time side: deltas compose exactly (per-frame deltas over many loops = one delta over the
// whole time), reverse deltas are inverses, the translation is in the character's frame at
// `from`, and a host integrating deltas at 60 Hz reproduces the original root's world path across
// loops. Finally a real clip (Pab's walk) cooked with --root-motion walks forward while its root
// stays over frame 0's ground point.
#include <gtest/gtest.h>

#include <atomic>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <new>
#include <string>
#include <vector>

#include <glm/gtc/matrix_transform.hpp>
#include <glm/gtc/quaternion.hpp>

#include "cooker/model/clip_grid.h"
#include "cooker/clip/root_motion.h"
#include <ossa/loader/asset.h>
#include <ossa/anim/pose.h>
#include <ossa/anim/root_motion.h>
#include <ossa/anim/sample.h>
#include "test_files.h"
#include "allocation_counter.h"

namespace ossa {
namespace {

using cook::SourceClip;
using cook::SourceSkeleton;
using cook::SourceTrack;

constexpr double kPi = 3.14159265358979323846;

glm::dvec3 axis(int k) {
  glm::dvec3 v(0.0);
  v[k % 3] = 1.0;
  return v;
}

glm::dmat4 trs(const glm::dvec3& t, const glm::dquat& r, const glm::dvec3& s = glm::dvec3(1.0)) {
  return glm::translate(glm::dmat4(1.0), t) * glm::mat4_cast(r) * glm::scale(glm::dmat4(1.0), s);
}

double max_abs_difference(const glm::dmat4& a, const glm::dmat4& b) {
  double d = 0.0;
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r) d = std::max(d, std::abs(a[c][r] - b[c][r]));
  return d;
}

/// The host's view of a ground-plane motion: world position P, yaw Psi about up.
struct Placement {
  glm::dvec3 position{0.0};
  double yaw = 0.0;
};

/// What a host does each frame (the convention ossa/anim/root_motion.h documents), written with
/// glm so it does not share code with the implementation under test.
void apply(Placement& p, const RootMotionDelta& d, int up) {
  p.position += glm::angleAxis(p.yaw, axis(up)) * glm::dvec3(d.translation);
  p.yaw += d.yaw;
}

glm::dmat4 matrix(const Placement& p, int up) { return trs(p.position, glm::angleAxis(p.yaw, axis(up))); }

// ---------------------------------------------------------------------------------------------
// A synthetic root running round a circle.

struct Circle {
  int up = 1;
  float rate = 30.0f;
  uint32_t frames = 61;  // 2 s at 30 Hz
  double turns = 1.5;    // heading change over the clip: 3 pi, so unwrapping matters
  double radius = 2.0;
  glm::dvec3 start_offset{0.3, 0.0, -0.2};  // ground offset of the circle (up component ignored)
  double roll = 0.05;                       // roll amplitude: makes the swing twist-free only when 0
  bool tilt = true;                         // constant -90 degrees about the first ground axis

  double duration() const { return double(frames - 1) / rate; }
  double omega() const { return 2.0 * kPi * turns / duration(); }
  /// Heading: turning with the circle, plus a wobble that is 0 at both ends.
  double heading(double t) const { return 0.4 + omega() * t + 0.15 * std::sin(4.0 * kPi * t / duration()); }
  glm::dvec3 position(double t) const {
    const glm::dvec3 i = axis(up + 1), j = axis(up + 2), u = axis(up);
    glm::dvec3 off = start_offset;
    off[up] = 0.0;
    const double phi = omega() * t;
    return off + radius * (std::sin(phi) * i + (std::cos(phi) - 1.0) * j) +
           (0.9 + 0.05 * std::sin(6.0 * kPi * t / duration())) * u;
  }
  glm::dquat rotation(double t) const {
    const glm::dvec3 i = axis(up + 1), j = axis(up + 2), u = axis(up);
    const double pitch = 0.1 * std::sin(6.0 * kPi * t / duration());
    const double r = roll * std::cos(2.0 * kPi * t / duration());
    glm::dquat q = glm::angleAxis(heading(t), u) * glm::angleAxis(pitch, i) * glm::angleAxis(r, j);
    if (tilt) q = q * glm::angleAxis(-0.5 * kPi, i);
    return glm::normalize(q);
  }
  glm::dvec3 scale(double t) const { return glm::dvec3(1.0 + 0.01 * std::sin(2.0 * kPi * t / duration())); }
  glm::dmat4 model(double t) const { return trs(position(t), rotation(t), scale(t)); }

  SourceSkeleton skeleton() const {
    SourceSkeleton s;
    s.joints.resize(2);
    s.joints[0].name = "root";
    s.joints[0].translation = glm::vec3(0.0f, 1.0f, 0.0f);
    s.joints[1].name = "spine";
    s.joints[1].parent = 0;
    s.joints[1].translation = glm::vec3(0.0f, 0.5f, 0.0f);
    return s;
  }

  /// Root keys at every grid frame (so the source value at a frame is exactly the key), and a
  /// spine track that extraction must leave alone.
  SourceClip clip() const {
    SourceClip c;
    c.name = "circle";
    c.sample_rate = rate;
    c.duration = static_cast<float>(duration());
    const cook::FrameGrid grid = cook::frame_grid(c);
    EXPECT_EQ(grid.frame_count, frames);
    SourceTrack root;
    root.joint = 0;
    glm::quat previous(1, 0, 0, 0);
    for (uint32_t f = 0; f < frames; ++f) {
      const float t = grid.time(f);
      glm::quat q(rotation(t));
      if (glm::dot(q, previous) < 0.0f) q = -q;
      previous = q;
      root.translation_times.push_back(t);
      root.translations.push_back(glm::vec3(position(t)));
      root.rotation_times.push_back(t);
      root.rotations.push_back(q);
      root.scale_times.push_back(t);
      root.scales.push_back(glm::vec3(scale(t)));
    }
    SourceTrack spine;
    spine.joint = 1;
    spine.rotation_times = {0.0f, c.duration};
    spine.rotations = {glm::quat(1, 0, 0, 0), glm::angleAxis(0.3f, glm::vec3(1, 0, 0))};
    c.tracks = {root, spine};
    return c;
  }
};

/// The root's model transform at grid frame f as the (rewritten) track holds it.
glm::dmat4 track_model(const SourceTrack& t, uint32_t f) {
  return trs(glm::dvec3(t.translations.at(f)), glm::dquat(t.rotations.at(f)), glm::dvec3(t.scales.at(f)));
}

/// W_f = T(translations[f]) Y(yaws[f]): the character motion extraction stored for frame f.
glm::dmat4 motion_matrix(const cook::SourceRootMotion& m, uint32_t f) {
  return trs(glm::dvec3(m.translations.at(f)), glm::angleAxis(double(m.yaws.at(f)), axis(m.up_axis)));
}

// ---------------------------------------------------------------------------------------------
// Cook side

TEST(ExtractRootMotion, InPlaceRootPlusMotionIsTheOriginalRoot) {
  for (int up = 0; up < 3; ++up) {
    for (bool tilt : {false, true}) {
      Circle circle;
      circle.up = up;
      circle.tilt = tilt;
      SCOPED_TRACE("up axis " + std::to_string(up) + (tilt ? ", tilted root" : ""));
      SourceClip clip = circle.clip();
      const SourceSkeleton skeleton = circle.skeleton();
      const SourceTrack spine_before = clip.tracks[1];
      ASSERT_TRUE(cook::extract_root_motion(clip, skeleton, static_cast<uint8_t>(up)));
      ASSERT_TRUE(clip.has_root_motion);
      const cook::SourceRootMotion& m = clip.root_motion;
      EXPECT_EQ(m.up_axis, up);
      ASSERT_EQ(m.translations.size(), circle.frames);
      ASSERT_EQ(m.yaws.size(), circle.frames);
      const SourceTrack& root = clip.tracks[0];
      ASSERT_EQ(root.translations.size(), circle.frames);
      ASSERT_EQ(root.rotations.size(), circle.frames);
      EXPECT_EQ(clip.tracks[1].rotations, spine_before.rotations);

      EXPECT_EQ(m.yaws[0], 0.0f);
      EXPECT_EQ(m.translations[0], glm::vec3(0.0f));
      const glm::dvec3 u = axis(up);
      const glm::dvec3 p0 = circle.position(0.0);
      const glm::dvec3 g0 = p0 - glm::dot(p0, u) * u;
      double worst = 0.0;
      for (uint32_t f = 0; f < circle.frames; ++f) {
        const double t = cook::frame_grid(clip).time(f);
        // Root motion lies in the ground plane; the in-place root keeps its height and frame 0's
        // ground position.
        EXPECT_EQ(m.translations[f][up], 0.0f);
        const glm::dvec3 in_place(root.translations[f]);
        EXPECT_NEAR(glm::length((in_place - glm::dot(in_place, u) * u) - g0), 0.0, 1e-6) << f;
        EXPECT_NEAR(glm::dot(in_place, u), glm::dot(circle.position(t), u), 1e-6) << f;
        if (f > 0) {
          EXPECT_LT(std::abs(m.yaws[f] - m.yaws[f - 1]), kPi / 4) << "yaw jumps at frame " << f;
        }
        // The reconstruction the runtime relies on.
        worst = std::max(worst, max_abs_difference(motion_matrix(m, f) * track_model(root, f), circle.model(t)));
      }
      EXPECT_LT(worst, 1e-4);
      // 1.5 turns, unwrapped: the last yaw is 3 pi (the wobble is 0 at the end), not -pi or pi.
      EXPECT_NEAR(m.yaws.back(), 3.0 * kPi, 1e-4);
    }
  }
}

TEST(ExtractRootMotion, YawIsTheTurnAboutUpAndTranslationTheGroundPath) {
  Circle circle;
  circle.roll = 0.0;  // swing purely about a ground axis: the twist is exactly the heading
  SourceClip clip = circle.clip();
  ASSERT_TRUE(cook::extract_root_motion(clip, circle.skeleton(), 1));
  const glm::dvec3 u(0, 1, 0);
  const glm::dvec3 p0 = circle.position(0.0);
  const glm::dvec3 g0 = p0 - glm::dot(p0, u) * u;
  for (uint32_t f = 0; f < circle.frames; ++f) {
    const double t = cook::frame_grid(clip).time(f);
    const double dpsi = circle.heading(t) - circle.heading(0.0);
    EXPECT_NEAR(clip.root_motion.yaws[f], dpsi, 1e-5) << f;
    // translations[f] = g_f - Y(dpsi) g_0 (the pivot is the model origin).
    const glm::dvec3 p = circle.position(t);
    const glm::dvec3 expected = (p - glm::dot(p, u) * u) - glm::angleAxis(dpsi, u) * g0;
    EXPECT_NEAR(glm::length(glm::dvec3(clip.root_motion.translations[f]) - expected), 0.0, 1e-5) << f;
  }
}

TEST(ExtractRootMotion, SamplesBetweenKeysAndUsesBindValuesForAbsentChannels) {
  // Root: two translation keys (lerp between them on the grid), no rotation keys (bind rotation:
  // a quarter turn about up).
  SourceSkeleton skeleton;
  skeleton.joints.resize(1);
  skeleton.joints[0].name = "root";
  skeleton.joints[0].rotation = glm::angleAxis(0.5f * float(kPi), glm::vec3(0, 1, 0));
  SourceClip clip;
  clip.name = "slide";
  clip.sample_rate = 10.0f;
  clip.duration = 1.0f;
  SourceTrack root;
  root.translation_times = {0.0f, 1.0f};
  root.translations = {{1, 2, 3}, {3, 2.5f, 7}};
  clip.tracks = {root};
  ASSERT_TRUE(cook::extract_root_motion(clip, skeleton, 1));
  ASSERT_EQ(clip.root_motion.translations.size(), 11u);
  for (uint32_t f = 0; f <= 10; ++f) {
    const float t = float(f) / 10.0f;
    EXPECT_NEAR(clip.root_motion.yaws[f], 0.0f, 1e-6f);
    EXPECT_NEAR(clip.root_motion.translations[f].x, 2.0f * t, 1e-6f);
    EXPECT_EQ(clip.root_motion.translations[f].y, 0.0f);
    EXPECT_NEAR(clip.root_motion.translations[f].z, 4.0f * t, 1e-6f);
    // In place: height keeps rising, ground stays at frame 0's; the bind rotation is kept.
    EXPECT_NEAR(clip.tracks[0].translations[f].x, 1.0f, 1e-6f);
    EXPECT_NEAR(clip.tracks[0].translations[f].y, 2.0f + 0.5f * t, 1e-6f);
    EXPECT_NEAR(clip.tracks[0].translations[f].z, 3.0f, 1e-6f);
    EXPECT_NEAR(std::abs(glm::dot(clip.tracks[0].rotations[f], skeleton.joints[0].rotation)), 1.0f, 1e-6f);
  }
}

TEST(ExtractRootMotion, ErrorsNameTheClipAndLeaveItUnchanged) {
  Circle circle;
  SourceClip clip = circle.clip();
  clip.tracks.erase(clip.tracks.begin());  // no root track
  const SourceClip before = clip;
  Status st = cook::extract_root_motion(clip, circle.skeleton(), 1);
  ASSERT_FALSE(st);
  EXPECT_NE(st.message().find("clip 'circle'"), std::string::npos) << st.message();
  EXPECT_NE(st.message().find("root"), std::string::npos) << st.message();
  EXPECT_FALSE(clip.has_root_motion);
  EXPECT_EQ(clip.tracks.size(), before.tracks.size());

  SourceClip clip2 = circle.clip();
  EXPECT_FALSE(cook::extract_root_motion(clip2, circle.skeleton(), 3));
  EXPECT_FALSE(clip2.has_root_motion);
  EXPECT_FALSE(cook::extract_root_motion(clip2, SourceSkeleton{}, 1));
  EXPECT_FALSE(clip2.has_root_motion);
}

// ---------------------------------------------------------------------------------------------
// Run-time side, on a synthetic file holding an extracted root-motion track

/// A valid file with one clip (no channels) carrying `motion`, through the real loader.
Result<Asset> file_with_motion(const cook::SourceRootMotion& motion, float rate) {
  test::SyntheticSpec spec;
  test::SyntheticClip clip;
  clip.name = "moving";
  clip.sample_rate = rate;
  clip.frame_count = static_cast<uint32_t>(motion.translations.size());
  clip.constants.clear();
  clip.animated.clear();
  test::SyntheticRootMotion rm;
  for (const glm::vec3& t : motion.translations) rm.translations.push_back(fb::Vec3(t.x, t.y, t.z));
  rm.yaws = motion.yaws;
  rm.up_axis = motion.up_axis;
  clip.root_motion = rm;
  spec.clips = {clip};
  return Asset::from_bytes(test::make_valid_file(spec), "root-motion.ossa");
}

cook::SourceRootMotion extracted(const Circle& circle) {
  SourceClip clip = circle.clip();
  EXPECT_TRUE(cook::extract_root_motion(clip, circle.skeleton(), static_cast<uint8_t>(circle.up)));
  return clip.root_motion;
}

TEST(RootMotionDelta, ZeroWithoutRootMotion) {
  test::SyntheticSpec spec;
  auto asset = Asset::from_bytes(test::make_valid_file(spec));
  ASSERT_TRUE(asset) << asset.error().message;
  const ClipView clip = asset->clip(0);
  EXPECT_FALSE(has_root_motion(clip));
  const RootMotionDelta d = root_motion_delta(clip, 0.1, 5.7);
  EXPECT_EQ(d.translation, glm::vec3(0.0f));
  EXPECT_EQ(d.yaw, 0.0f);
}

TEST(RootMotionDelta, MatchesTheStoredTrackWithinOneCycle) {
  Circle circle;
  const cook::SourceRootMotion m = extracted(circle);
  auto asset = file_with_motion(m, circle.rate);
  ASSERT_TRUE(asset) << asset.error().message;
  const ClipView clip = asset->clip(0);
  ASSERT_TRUE(has_root_motion(clip));
  // From 0 the character frame is the model frame of frame 0: the delta is W_f itself.
  for (uint32_t f = 0; f < circle.frames; f += 7) {
    const RootMotionDelta d = root_motion_delta(clip, 0.0, double(f) / circle.rate);
    EXPECT_NEAR(glm::length(d.translation - m.translations[f]), 0.0f, 1e-4f) << f;
    EXPECT_NEAR(d.yaw, m.yaws[f], 1e-5f) << f;
  }
  // Half-way between frames: linear interpolation of translation and (unwrapped) yaw.
  const double t = 10.5 / circle.rate;
  const RootMotionDelta d = root_motion_delta(clip, 0.0, t);
  EXPECT_NEAR(glm::length(d.translation - 0.5f * (m.translations[10] + m.translations[11])), 0.0f, 1e-4f);
  EXPECT_NEAR(d.yaw, 0.5f * (m.yaws[10] + m.yaws[11]), 1e-5f);
}

/// Composes deltas the way a host does and returns the placement reached from the origin.
Placement integrate(const ClipView& clip, double from, double to, double dt, int up) {
  Placement p;
  const long steps = std::lround((to - from) / dt);
  double t = from;
  for (long s = 1; s <= steps; ++s) {
    const double next = s == steps ? to : from + double(s) * dt;
    apply(p, root_motion_delta(clip, t, next), up);
    t = next;
  }
  return p;
}

TEST(RootMotionDelta, PerFrameDeltasOverManyLoopsEqualTheWholeDelta) {
  Circle circle;
  circle.frames = 47;  // 1.5333 s: 60 Hz steps straddle the loop points
  const cook::SourceRootMotion m = extracted(circle);
  auto asset = file_with_motion(m, circle.rate);
  ASSERT_TRUE(asset) << asset.error().message;
  const ClipView clip = asset->clip(0);
  const double duration = clip.duration();
  for (int loops : {1, 2, 5, 12}) {
    const double end = loops * duration;
    const Placement stepped = integrate(clip, 0.0, end, 1.0 / 60.0, 1);
    Placement whole;
    apply(whole, root_motion_delta(clip, 0.0, end), 1);
    // Independent expectation: the one-cycle motion applied `loops` times.
    Placement cycles;
    const RootMotionDelta cycle = root_motion_delta(clip, 0.0, duration);
    for (int i = 0; i < loops; ++i) apply(cycles, cycle, 1);
    double travelled = 0.0;  // path length, to scale the drift bound
    {
      Placement p;
      glm::dvec3 last(0.0);
      for (double t = 0.0; t < end; t += 1.0 / 60.0) {
        apply(p, root_motion_delta(clip, t, std::min(t + 1.0 / 60.0, end)), 1);
        travelled += glm::length(p.position - last);
        last = p.position;
      }
    }
    SCOPED_TRACE(std::to_string(loops) + " loops, path " + std::to_string(travelled));
    EXPECT_GT(travelled, 1.0);
    EXPECT_LT(glm::length(stepped.position - whole.position), 1e-4 * travelled);
    EXPECT_NEAR(stepped.yaw, whole.yaw, 1e-4);
    EXPECT_LT(glm::length(cycles.position - whole.position), 1e-4 * travelled);
    EXPECT_NEAR(cycles.yaw, whole.yaw, 1e-4);
    EXPECT_NEAR(whole.yaw, loops * double(m.yaws.back()), 1e-4 * loops);
  }
}

TEST(RootMotionDelta, ReverseIsTheInverse) {
  Circle circle;
  const cook::SourceRootMotion m = extracted(circle);
  auto asset = file_with_motion(m, circle.rate);
  ASSERT_TRUE(asset) << asset.error().message;
  const ClipView clip = asset->clip(0);
  const double pairs[][2] = {{0.0, 0.7}, {0.3, 1.9}, {1.7, 2.4}, {-0.5, 3.3}, {5.1, -7.9}, {1e4, 1e4 + 0.0166}};
  for (const auto& pr : pairs) {
    const RootMotionDelta forward = root_motion_delta(clip, pr[0], pr[1]);
    const RootMotionDelta backward = root_motion_delta(clip, pr[1], pr[0]);
    Placement p;
    apply(p, forward, 1);
    apply(p, backward, 1);
    EXPECT_LT(glm::length(p.position), 1e-4 * (1.0 + glm::length(glm::dvec3(forward.translation))))
        << pr[0] << " -> " << pr[1];
    EXPECT_NEAR(p.yaw, 0.0, 1e-5);
    EXPECT_NEAR(forward.yaw, -backward.yaw, 1e-5);
    // Playing backwards over the same span by small steps gives the same inverse.
    const Placement stepped = integrate(clip, pr[1], pr[0], pr[0] > pr[1] ? 1.0 / 60.0 : -1.0 / 60.0, 1);
    EXPECT_NEAR(stepped.yaw, backward.yaw, 1e-4);
    EXPECT_LT(glm::length(stepped.position - glm::dvec3(backward.translation)),
              1e-4 * (1.0 + glm::length(glm::dvec3(backward.translation))));
  }
  const RootMotionDelta none = root_motion_delta(clip, 1.234, 1.234);
  EXPECT_LT(glm::length(none.translation), 1e-6f);
  EXPECT_EQ(none.yaw, 0.0f);
}

// The delta's translation is in the character's frame at `from`: a clip that first turns a
// quarter turn in place, then walks along model +x (its forward after the turn, forward being +z
// at frame 0), reports the walk as straight ahead (+z), not as +x.
TEST(RootMotionDelta, TranslationIsInTheCharactersFrameAtFrom) {
  cook::SourceRootMotion m;
  m.up_axis = 1;
  for (int f = 0; f <= 20; ++f) {
    const float turn = std::min(f, 10) / 10.0f;      // frames 0..10: turn to +pi/2
    const float walk = std::max(f - 10, 0) / 10.0f;  // frames 10..20: 1.5 units along +x
    m.yaws.push_back(turn * 0.5f * float(kPi));
    m.translations.push_back({1.5f * walk, 0.0f, 0.0f});
  }
  auto asset = file_with_motion(m, 10.0f);
  ASSERT_TRUE(asset) << asset.error().message;
  const ClipView clip = asset->clip(0);
  const RootMotionDelta walk = root_motion_delta(clip, 1.0, 2.0);
  EXPECT_NEAR(walk.translation.x, 0.0f, 1e-5f);
  EXPECT_NEAR(walk.translation.z, 1.5f, 1e-5f);
  EXPECT_NEAR(walk.yaw, 0.0f, 1e-6f);
  const RootMotionDelta turn = root_motion_delta(clip, 0.0, 1.0);
  EXPECT_NEAR(glm::length(turn.translation), 0.0f, 1e-6f);
  EXPECT_NEAR(turn.yaw, 0.5f * float(kPi), 1e-6f);
  // A host facing world -x (yaw -pi/2 ... i.e. +z turned by -pi/2 is -x) walks along world -x.
  Placement host;
  host.yaw = -0.5 * kPi;
  apply(host, walk, 1);
  EXPECT_NEAR(host.position.x, -1.5, 1e-5);
  EXPECT_NEAR(host.position.z, 0.0, 1e-5);
  // Looping: the second cycle starts facing +x at (1.5, 0, 0) and turns to face -z, then walks
  // along its forward (-z), ending at (1.5, 0, -1.5) in the frame of time 0.
  Placement looped;
  apply(looped, root_motion_delta(clip, 0.0, 4.0), 1);
  EXPECT_NEAR(looped.position.x, 1.5, 1e-5);
  EXPECT_NEAR(looped.position.z, -1.5, 1e-5);
  EXPECT_NEAR(looped.yaw, kPi, 1e-5);
}

// The host convention end to end: integrating per-frame deltas at 60 Hz and drawing the in-place
// root under the host placement gives, at every frame of 2.5 loops, the original root looped as
// the source implies (each cycle starts where the previous one ended: C^k . M(tau), with C the
// ground motion from the first to the last frame measured on the source itself).
TEST(RootMotionDelta, HostIntegrationReproducesTheOriginalWorldPath) {
  for (int up = 0; up < 3; ++up) {
    Circle circle;
    circle.up = up;
    circle.roll = 0.0;  // so the heading (hence C) is known analytically from the source
    SCOPED_TRACE("up axis " + std::to_string(up));
    SourceClip clip = circle.clip();
    ASSERT_TRUE(cook::extract_root_motion(clip, circle.skeleton(), static_cast<uint8_t>(up)));
    auto asset = file_with_motion(clip.root_motion, circle.rate);
    ASSERT_TRUE(asset) << asset.error().message;
    const ClipView view = asset->clip(0);
    const SourceTrack& in_place = clip.tracks[0];

    const double duration = circle.duration();
    const glm::dvec3 u = axis(up);
    auto ground = [&](const glm::dvec3& p) { return p - glm::dot(p, u) * u; };
    const glm::dmat4 cycle = glm::translate(glm::dmat4(1.0), ground(circle.position(duration))) *
                             glm::mat4_cast(glm::angleAxis(circle.heading(duration) - circle.heading(0.0), u)) *
                             glm::translate(glm::dmat4(1.0), -ground(circle.position(0.0)));

    Placement host;
    double t = 0.0, worst = 0.0, farthest = 0.0;
    const int steps = int(std::lround(2.5 * duration * 60.0));
    for (int s = 1; s <= steps; ++s) {
      const double next = s / 60.0;
      apply(host, root_motion_delta(view, t, next), up);
      t = next;
      if (s % 2 != 0) continue;  // 30 Hz clip: every other 60 Hz step is on a frame
      const double loops = std::floor(t / duration + 1e-9);
      const uint32_t frame = static_cast<uint32_t>(std::lround((t - loops * duration) * circle.rate));
      glm::dmat4 expected = circle.model(double(frame) / circle.rate);
      for (int k = 0; k < int(loops); ++k) expected = cycle * expected;
      const glm::dmat4 drawn = matrix(host, up) * track_model(in_place, frame);
      worst = std::max(worst, max_abs_difference(drawn, expected));
      farthest = std::max(farthest, glm::length(host.position));
    }
    EXPECT_GT(farthest, 1.0);
    EXPECT_LT(worst, 1e-4 * (1.0 + farthest));
  }
}

TEST(RootMotionDelta, DoesNotAllocate) {
  Circle circle;
  auto asset = file_with_motion(extracted(circle), circle.rate);
  ASSERT_TRUE(asset) << asset.error().message;
  const ClipView clip = asset->clip(0);
  float checksum = 0.0f;
  const size_t before = ossa::test::allocation_count();
  for (int i = 0; i < 1000; ++i) checksum += root_motion_delta(clip, i / 60.0, (i + 1) / 60.0).yaw;
  EXPECT_EQ(ossa::test::allocation_count(), before);
  EXPECT_TRUE(std::isfinite(checksum));
}

// ---------------------------------------------------------------------------------------------
// A real clip: Pab's walk cooked with --root-motion against the Pab skeleton.

TEST(RootMotionCooked, PabWalkMovesForwardWithTheRootInPlace) {
  // Cooked by ossa-cook into the committed fixtures (tests/fixtures/cook_fixtures.cmake): the walk
  // against Pab's skeleton with --root-motion.
  const std::filesystem::path dir = test::fixtures_dir();
  auto rig_asset = Asset::open((dir / "Pab" / "skeleton.ossa").string());
  ASSERT_TRUE(rig_asset) << rig_asset.error().message;
  auto asset = Asset::open((dir / "root-motion" / "Pab" / "walk.ossa").string());
  ASSERT_TRUE(asset) << asset.error().message;
  ASSERT_EQ(asset->clip_count(), 1u);
  const ClipView clip = asset->clip(0);
  ASSERT_TRUE(has_root_motion(clip)) << "the writer did not serialize Clip.root_motion";
  const float metres = asset->file().metres_per_unit();
  const double duration = clip.duration();

  // One cycle moves the character forward, in the ground plane, without turning much.
  const RootMotionDelta cycle = root_motion_delta(clip, 0.0, duration);
  const double distance_m = glm::length(glm::dvec3(cycle.translation)) * metres;
  std::printf("Pab walk: %.3f s cycle, root motion %.3f m (%.1f units) per cycle, yaw %.4f rad\n", duration, distance_m,
              double(glm::length(cycle.translation)), double(cycle.yaw));
  EXPECT_GT(distance_m, 0.5);
  EXPECT_GT(cycle.translation.z, 0.99f * glm::length(cycle.translation));  // Pab faces +z
  EXPECT_EQ(cycle.translation.y, 0.0f);
  EXPECT_LT(std::abs(cycle.yaw), 0.2);

  // Sampled through the runtime, the cooked root stays over frame 0's ground point (to within the
  // compression tolerance plus a little), however far the clip walks.
  auto cache = make_sampling_cache(clip, rig_asset->skeleton());
  ASSERT_TRUE(cache) << cache.error().message;
  Pose pose(static_cast<uint32_t>(rig_asset->skeleton().joint_count()));
  SampleOptions sample_options;
  sample_options.loop = false;
  sample(clip, 0.0f, sample_options, *cache, pose);
  const glm::vec3 start = get_transform(pose, 0).translation;
  double drift = 0.0;
  const uint32_t frames = clip.frame_count();
  for (uint32_t f = 0; f < frames; ++f) {
    sample(clip, static_cast<float>(f) / clip.sample_rate(), sample_options, *cache, pose);
    const glm::vec3 p = get_transform(pose, 0).translation;
    drift = std::max(drift, double(glm::length(glm::vec2(p.x - start.x, p.z - start.z))));
  }
  std::printf("Pab walk: root ground drift from frame 0: %.4f mm\n", drift * metres * 1000.0);
  EXPECT_LT(drift * metres, 0.001);
}

}  // namespace
}  // namespace ossa
