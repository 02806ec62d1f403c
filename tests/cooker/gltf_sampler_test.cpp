// gltf_sampler_test.cpp — glTF STEP / LINEAR / CUBICSPLINE samplers are honoured by the importer.
//
// Assimp 5.2.5 hands STEP and CUBICSPLINE keys over as if they were LINEAR; the importer reads the
// samplers from the file itself (cooker/import/gltf_samplers.h) and resamples those channels on the clip's
// frame grid (cooker/import/import_clips.cpp). These tests check the SourceScene the importer returns:
//   - interpolation_test.gltf (Khronos sample, ../shared/assets; skipped with a notice when
//   absent):
//     every grid frame of each STEP / CUBICSPLINE channel equals the glTF sampler evaluated here,
//     independently, from the file's key data copied into this test; LINEAR channels keep their
//     source keys exactly;
//   - Fox.glb (LINEAR only) keeps its keys, compared with the GLB's accessors read by a small
//     reader in this test;
//   - hand-made files: unnamed and repeated node names, external buffers with a percent-encoded
//     name, a GLB container, and accessors Assimp reads but the importer rejects (warning, Assimp's
//     keys kept), plus unit checks of the reader on malformed input: errors, never a crash.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/quaternion.hpp>
#include <nlohmann/json.hpp>

#include "cooker/model/clip_grid.h"
#include "cooker/import/gltf_samplers.h"
#include "cooker/import/import_scene.h"
#include "test_files.h"

namespace fs = std::filesystem;
using ossa::cook::SourceClip;
using ossa::cook::SourceScene;
using ossa::cook::SourceTrack;
using Json = nlohmann::json;

namespace {

// ---------------------------------------------------------------------------------------------
// Reference evaluation, written from the glTF 2.0 specification (Appendix C), independent of the
// cooker's.

enum class Mode { Linear, Step, Cubic };
enum class Path { T, R, S };

/// One channel of a glTF file as data: times, and per key either one value or (in, value, out).
struct RefChannel {
  const char* clip;
  const char* node;
  Path path;
  Mode mode;
  std::vector<float> times;
  std::vector<glm::dvec4> values;  // per element; vec3 channels leave w = 0; rotations (x,y,z,w)
};

glm::dvec4 ref_value(const RefChannel& c, size_t k) { return c.values[c.mode == Mode::Cubic ? 3 * k + 1 : k]; }

glm::dvec4 normalize_if_rotation(const RefChannel& c, glm::dvec4 v) {
  return c.path == Path::R ? v / glm::length(v) : v;
}

/// The sampler's value at time t. A key time counts as reached when t is within 1e-6 s of it:
/// the frame grid's float times and the file's float key times are compared, not real numbers.
glm::dvec4 ref_evaluate(const RefChannel& c, double t) {
  const size_t n = c.times.size();
  size_t k = 0;
  while (k + 1 < n && static_cast<double>(c.times[k + 1]) <= t + 1e-6) ++k;
  if (t <= c.times[0] || k + 1 == n || c.mode == Mode::Step) {
    return normalize_if_rotation(c, ref_value(c, k));
  }
  const double t0 = c.times[k], t1 = c.times[k + 1], d = t1 - t0, u = (t - t0) / d;
  if (c.mode == Mode::Linear) {
    if (c.path == Path::R) {
      glm::dvec4 a = ref_value(c, k), b = ref_value(c, k + 1);
      if (glm::dot(a, b) < 0) b = -b;
      const double angle = std::acos(std::min(1.0, glm::dot(a, b)));
      if (angle < 1e-9) return a;
      return (std::sin((1 - u) * angle) * a + std::sin(u * angle) * b) / std::sin(angle);
    }
    return (1 - u) * ref_value(c, k) + u * ref_value(c, k + 1);
  }
  const glm::dvec4 vk = c.values[3 * k + 1], bk = c.values[3 * k + 2];
  const glm::dvec4 vk1 = c.values[3 * (k + 1) + 1], ak1 = c.values[3 * (k + 1)];
  const double u2 = u * u, u3 = u2 * u;
  const glm::dvec4 p =
      (2 * u3 - 3 * u2 + 1) * vk + (u3 - 2 * u2 + u) * d * bk + (-2 * u3 + 3 * u2) * vk1 + (u3 - u2) * d * ak1;
  return normalize_if_rotation(c, p);
}

/// The same keys' values at t interpolated linearly (what Assimp's keys alone would give).
glm::dvec4 ref_linear(const RefChannel& c, double t) {
  RefChannel lin = c;
  lin.mode = Mode::Linear;
  lin.values.clear();
  for (size_t k = 0; k < c.times.size(); ++k) lin.values.push_back(ref_value(c, k));
  return ref_evaluate(lin, t);
}

// The animated channels of interpolation_test.gltf, copied from the file (its .bin, decoded with
// Python's struct module). Note the file's quirk: the animation named "Linear Scale" uses a
// CUBICSPLINE sampler (with zero tangents), and it is tested as what the file says.
const std::vector<float> kScaleTimes = {0.0416666679084301f, 0.4166666567325592f, 0.875f, 1.25f, 1.6666666269302368f};
const std::vector<float> kRotationTimes = {0.0f, 0.4166666567325592f, 0.875f, 1.25f, 1.7083333730697632f};
const std::vector<float> kStepTranslationTimes = {0.0f, 0.4583333432674408f, 0.8333333134651184f, 1.2916666269302368f,
                                                  1.7083333730697632f};
const std::vector<float> kTranslationTimes = {0.0f, 0.4166666567325592f, 0.8333333134651184f, 1.25f,
                                              1.6666666269302368f};

glm::dvec4 v3(double x, double y, double z) { return {x, y, z, 0.0}; }
glm::dvec4 q4(double x, double y, double z, double w) { return {x, y, z, w}; }

std::vector<glm::dvec4> zero_tangents(const std::vector<glm::dvec4>& values) {
  std::vector<glm::dvec4> out;
  for (const glm::dvec4& v : values) {
    out.push_back(glm::dvec4(0.0));
    out.push_back(v);
    out.push_back(glm::dvec4(0.0));
  }
  return out;
}

const std::vector<glm::dvec4> kScaleValues = {v3(1, 1, 1), v3(0.5, 0.5, 0.5), v3(1, 1, 1), v3(0.5, 0.5, 0.5),
                                              v3(1, 1, 1)};
const std::vector<glm::dvec4> kRotationValues = {q4(0, 0, -0.0, 1.0), q4(0, 0, -0.3826834559440613, 0.9238795638084412),
                                                 q4(0, 0, -0.7071068286895752, 0.7071068286895752),
                                                 q4(0, 0, -0.9238795042037964, 0.38268348574638367),
                                                 q4(0, 0, -1.0, -4.371138828673793e-08)};

std::vector<RefChannel> interpolation_test_channels() {
  const double cx = 3.3051798343658447, lx = -3.2975807189941406;
  return {
      {"Step Scale", "Cube", Path::S, Mode::Step, kScaleTimes, kScaleValues},
      {"Linear Scale", "Cube.001", Path::S, Mode::Cubic, kScaleTimes, zero_tangents(kScaleValues)},
      {"CubicSpline Scale", "Cube.002", Path::S, Mode::Cubic, kScaleTimes, zero_tangents(kScaleValues)},
      {"Step Rotation", "Cube.003", Path::R, Mode::Step, kRotationTimes, kRotationValues},
      {"CubicSpline Rotation",
       "Cube.004",
       Path::R,
       Mode::Cubic,
       kRotationTimes,
       {q4(0, 0, -0.0, 1.0), q4(0, 0, -0.0, 1.0), q4(0, 0, -0.0, 1.0),
        q4(0, 0, -0.04789090156555176, 0.9988526701927185), q4(0, 0, -0.3826834559440613, 0.9238795638084412),
        q4(0, 0, -0.04789090156555176, 0.9988526701927185), q4(0, 0, -0.035464316606521606, 0.9993709921836853),
        q4(0, 0, -0.7071068286895752, 0.7071068286895752), q4(0, 0, -0.035464316606521606, 0.9993709921836853),
        q4(0, 0, -0.050318874418735504, 0.9987332224845886), q4(0, 0, -0.9238795042037964, 0.38268348574638367),
        q4(0, 0, -0.050318874418735504, 0.9987332224845886), q4(0, 0, -0.0, 1.0),
        q4(0, 0, -1.0, -4.371138828673793e-08), q4(0, 0, -0.0, 1.0)}},
      {"Linear Rotation", "Cube.005", Path::R, Mode::Linear, kRotationTimes, kRotationValues},
      {"Step Translation",
       "Cube.006",
       Path::T,
       Mode::Step,
       kStepTranslationTimes,
       {v3(0, 6.665226459503174, 0), v3(0, 10, 0), v3(0, 6, 0), v3(0, 10, 0), v3(0, 6, 0)}},
      {"CubicSpline Translation", "Cube.008", Path::T, Mode::Cubic, kTranslationTimes,
       zero_tangents({v3(cx, 6.640117168426514, 0), v3(cx, 10, 0), v3(cx, 6, 0), v3(cx, 10, 0), v3(cx, 6, 0)})},
      {"Linear Translation",
       "Cube.009",
       Path::T,
       Mode::Linear,
       kTranslationTimes,
       {v3(lx, 6.621014595031738, 0), v3(lx, 10, 0), v3(lx, 6, 0), v3(lx, 10, 0), v3(lx, 6, 0)}},
  };
}

// ---------------------------------------------------------------------------------------------
// Reading the imported scene

const SourceClip* find_clip(const SourceScene& scene, const std::string& name) {
  for (const SourceClip& c : scene.clips) {
    if (c.name == name) return &c;
  }
  return nullptr;
}

const SourceTrack* find_track(const SourceScene& scene, const SourceClip& clip, const std::string& joint) {
  for (const SourceTrack& t : clip.tracks) {
    if (t.joint < scene.skeleton.joints.size() && scene.skeleton.joints[t.joint].name == joint) {
      return &t;
    }
  }
  return nullptr;
}

/// One channel of a track as times + vec4 values (rotations x, y, z, w).
struct TrackChannel {
  std::vector<float> times;
  std::vector<glm::dvec4> values;
};

TrackChannel channel_of(const SourceTrack& t, Path p) {
  TrackChannel c;
  if (p == Path::T) {
    c.times = t.translation_times;
    for (const glm::vec3& v : t.translations) c.values.push_back(v3(v.x, v.y, v.z));
  } else if (p == Path::S) {
    c.times = t.scale_times;
    for (const glm::vec3& v : t.scales) c.values.push_back(v3(v.x, v.y, v.z));
  } else {
    c.times = t.rotation_times;
    for (const glm::quat& q : t.rotations) c.values.push_back(q4(q.x, q.y, q.z, q.w));
  }
  return c;
}

/// Index of the key at time t (within 1e-6 s), or -1: the importer is to key every frame.
int key_at(const TrackChannel& c, double t) {
  for (size_t i = 0; i < c.times.size(); ++i) {
    if (std::abs(static_cast<double>(c.times[i]) - t) <= 1e-6) return static_cast<int>(i);
  }
  return -1;
}

/// Largest component difference; rotations compared up to sign (q and -q are one rotation).
double difference(const glm::dvec4& a, const glm::dvec4& b, Path p) {
  auto max_abs = [](glm::dvec4 v) { return std::max({std::abs(v.x), std::abs(v.y), std::abs(v.z), std::abs(v.w)}); };
  const double d = max_abs(a - b);
  return p == Path::R ? std::min(d, max_abs(a + b)) : d;
}

std::optional<SourceScene> import_shared(const std::string& relative) {
  const fs::path path = ossa::test::shared_assets() / relative;
  if (!fs::exists(path)) return std::nullopt;
  ossa::Result<SourceScene> scene = ossa::cook::import_scene(path.string());
  EXPECT_TRUE(scene.ok()) << (scene.ok() ? "" : scene.error().message);
  if (!scene.ok()) return std::nullopt;
  return std::move(*scene);
}

bool mentions(const std::vector<std::string>& lines, const std::string& what) {
  return std::any_of(lines.begin(), lines.end(),
                     [&](const std::string& l) { return l.find(what) != std::string::npos; });
}

std::string all_lines(const std::vector<std::string>& lines) {
  std::string out;
  for (const std::string& l : lines) out += "  " + l + "\n";
  return out;
}

// ---------------------------------------------------------------------------------------------
// interpolation_test.gltf

class InterpolationTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (fs::exists(ossa::test::shared_assets() / "Khronos_embedded/interpolation_test.gltf")) {
      scene_ = new std::optional<SourceScene>(import_shared("Khronos_embedded/interpolation_test.gltf"));
    }
  }
  static void TearDownTestSuite() {
    delete scene_;
    scene_ = nullptr;
  }
  void SetUp() override {
    if (!scene_) GTEST_SKIP() << "notice: " << ossa::test::shared_assets() << " is absent";
    ASSERT_TRUE(scene_->has_value());
  }
  const SourceScene& scene() const { return **scene_; }

  /// Every frame of the clip's grid: the track's key there equals the reference sampler.
  void expect_frames_match(const RefChannel& ref) const {
    SCOPED_TRACE(std::string(ref.clip) + " / " + ref.node);
    const SourceClip* clip = find_clip(scene(), ref.clip);
    ASSERT_NE(clip, nullptr);
    const SourceTrack* track = find_track(scene(), *clip, ref.node);
    ASSERT_NE(track, nullptr);
    const TrackChannel ch = channel_of(*track, ref.path);
    const ossa::cook::FrameGrid grid = ossa::cook::frame_grid(*clip);
    for (uint32_t f = 0; f < grid.frame_count; ++f) {
      const double t = grid.time(f);
      if (t > clip->duration + 1e-6) break;  // the grid may end half a frame past the clip
      const int k = key_at(ch, t);
      ASSERT_GE(k, 0) << "no key at frame " << f << " (t = " << t << ")";
      const glm::dvec4 want = ref_evaluate(ref, t);
      EXPECT_LE(difference(ch.values[static_cast<size_t>(k)], want, ref.path), 1e-5)
          << "frame " << f << " t = " << t << ": got (" << ch.values[k].x << ", " << ch.values[k].y << ", "
          << ch.values[k].z << ", " << ch.values[k].w << "), want (" << want.x << ", " << want.y << ", " << want.z
          << ", " << want.w << ")";
    }
  }

  static std::optional<SourceScene>* scene_;
};

std::optional<SourceScene>* InterpolationTest::scene_ = nullptr;

RefChannel channel_named(const char* clip) {
  for (const RefChannel& c : interpolation_test_channels()) {
    if (std::string(c.clip) == clip) return c;
  }
  ADD_FAILURE() << "no reference channel " << clip;
  return interpolation_test_channels().front();
}

TEST_F(InterpolationTest, ResampledClipsUseAKeyAlignedGridOfAtLeast60Hz) {
  // The keys sit on Blender's 24 fps grid (those of "CubicSpline Translation" even on a 2.4 Hz
  // one): the importer takes the smallest multiple of at least 60 Hz, 72 Hz (or 60 Hz), so every
  // source key, and every STEP jump, lands exactly on a frame.
  for (const RefChannel& c : interpolation_test_channels()) {
    if (c.mode == Mode::Linear) continue;
    const SourceClip* clip = find_clip(scene(), c.clip);
    ASSERT_NE(clip, nullptr) << c.clip;
    EXPECT_TRUE(clip->sample_rate == 72.0f || clip->sample_rate == 60.0f) << c.clip << ": " << clip->sample_rate;
    for (float t : c.times) {
      const double frame = static_cast<double>(t) * clip->sample_rate;
      EXPECT_NEAR(frame, std::round(frame), 1e-4) << c.clip << ": key at " << t << " s is off the grid";
    }
  }
}

TEST_F(InterpolationTest, StepHoldsEachValueUntilTheNextKeyTime) {
  for (const char* name : {"Step Scale", "Step Rotation", "Step Translation"}) {
    const RefChannel ref = channel_named(name);
    expect_frames_match(ref);
    // The jump: the frame at a key time has the new value, the frame before the old one.
    const SourceClip* clip = find_clip(scene(), name);
    ASSERT_NE(clip, nullptr);
    const TrackChannel ch = channel_of(*find_track(scene(), *clip, ref.node), ref.path);
    const ossa::cook::FrameGrid grid = ossa::cook::frame_grid(*clip);
    for (size_t k = 1; k < ref.times.size(); ++k) {
      const double frame = std::round(ref.times[k] * grid.sample_rate);
      ASSERT_NEAR(grid.time(static_cast<uint32_t>(frame)), ref.times[k], 1e-6)
          << name << ": key " << k << " is off the grid";
      const int at = key_at(ch, grid.time(static_cast<uint32_t>(frame)));
      const int before = key_at(ch, grid.time(static_cast<uint32_t>(frame) - 1));
      ASSERT_GE(at, 0);
      ASSERT_GE(before, 0);
      EXPECT_LE(difference(ch.values[at], normalize_if_rotation(ref, ref_value(ref, k)), ref.path), 1e-5)
          << name << ": the frame at key " << k;
      EXPECT_LE(difference(ch.values[before], normalize_if_rotation(ref, ref_value(ref, k - 1)), ref.path), 1e-5)
          << name << ": the frame before key " << k;
    }
  }
}

TEST_F(InterpolationTest, CubicSplineFollowsTheHermiteCurveNotALine) {
  for (const char* name : {"CubicSpline Scale", "Linear Scale", "CubicSpline Rotation", "CubicSpline Translation"}) {
    const RefChannel ref = channel_named(name);
    expect_frames_match(ref);
    // The curve must differ from the straight line between the keys somewhere on the grid.
    const SourceClip* clip = find_clip(scene(), name);
    ASSERT_NE(clip, nullptr);
    const TrackChannel ch = channel_of(*find_track(scene(), *clip, ref.node), ref.path);
    const ossa::cook::FrameGrid grid = ossa::cook::frame_grid(*clip);
    double most = 0.0;
    for (uint32_t f = 0; f < grid.frame_count && grid.time(f) <= clip->duration; ++f) {
      const int k = key_at(ch, grid.time(f));
      ASSERT_GE(k, 0);
      most = std::max(most, difference(ch.values[k], ref_linear(ref, grid.time(f)), ref.path));
    }
    // Smoothstep segments (zero tangents) leave the line by up to 0.096 of the jump (0.5 here).
    EXPECT_GT(most, ref.path == Path::R ? 1e-3 : 0.04) << name << " came out linear";
  }
  // Where tangents are not zero (the rotation's first segment), even the midpoint moves off the
  // line: with zero tangents a Hermite segment is a smoothstep, whose midpoint is the line's.
  const RefChannel rot = channel_named("CubicSpline Rotation");
  const double mid = 0.5 * (rot.times[0] + rot.times[1]);  // 5/24 s: frame 15 at 72 Hz
  const SourceClip* clip = find_clip(scene(), rot.clip);
  ASSERT_NE(clip, nullptr);
  const TrackChannel ch = channel_of(*find_track(scene(), *clip, rot.node), Path::R);
  const int k = key_at(ch, mid);
  ASSERT_GE(k, 0) << "no key at the midpoint of the first segment";
  EXPECT_LE(difference(ch.values[k], ref_evaluate(rot, mid), Path::R), 1e-5);
  EXPECT_GT(difference(ch.values[k], ref_linear(rot, mid), Path::R), 1e-3);
}

TEST_F(InterpolationTest, LinearChannelsKeepTheirSourceKeys) {
  for (const char* name : {"Linear Rotation", "Linear Translation"}) {
    const RefChannel ref = channel_named(name);
    const SourceClip* clip = find_clip(scene(), name);
    ASSERT_NE(clip, nullptr);
    EXPECT_LT(clip->sample_rate, 60.0f) << name << ": a LINEAR-only clip keeps its own rate";
    const TrackChannel ch = channel_of(*find_track(scene(), *clip, ref.node), ref.path);
    ASSERT_EQ(ch.times.size(), ref.times.size()) << name;
    for (size_t k = 0; k < ref.times.size(); ++k) {
      EXPECT_NEAR(ch.times[k], ref.times[k], 1e-6) << name << " key " << k;
      EXPECT_LE(difference(ch.values[k], normalize_if_rotation(ref, ref_value(ref, k)), ref.path), 1e-6)
          << name << " key " << k;
    }
  }
  EXPECT_FALSE(mentions(scene().warnings, "glTF")) << all_lines(scene().warnings);
}

// ---------------------------------------------------------------------------------------------
// Fox.glb: LINEAR only, keys as the file has them.

/// A small GLB reader for the test's own comparisons: float accessors, tightly packed or strided.
struct TestGlb {
  Json json;
  std::vector<uint8_t> bin;
};

std::optional<TestGlb> read_glb(const fs::path& path) {
  const auto bytes = ossa::test::read_file(path);
  if (!bytes || bytes->size() < 20) return std::nullopt;
  auto u32 = [&](size_t at) {
    uint32_t v;
    std::memcpy(&v, bytes->data() + at, 4);
    return v;
  };
  TestGlb out;
  size_t at = 12;
  while (at + 8 <= bytes->size()) {
    const uint32_t length = u32(at), type = u32(at + 4);
    if (at + 8 + length > bytes->size()) return std::nullopt;
    if (type == 0x4E4F534A) {
      out.json =
          Json::parse(bytes->begin() + static_cast<long>(at + 8), bytes->begin() + static_cast<long>(at + 8 + length));
    }
    if (type == 0x004E4942) {
      out.bin.assign(bytes->begin() + static_cast<long>(at + 8), bytes->begin() + static_cast<long>(at + 8 + length));
    }
    at += 8 + length;
  }
  return out;
}

std::vector<float> glb_floats(const TestGlb& g, size_t accessor) {
  const Json& a = g.json["accessors"][accessor];
  const Json& v = g.json["bufferViews"][a["bufferView"].get<size_t>()];
  const size_t n = a["type"] == "SCALAR" ? 1 : a["type"] == "VEC3" ? 3 : 4;
  const size_t stride = v.value("byteStride", n * 4);
  const size_t base = v.value("byteOffset", size_t{0}) + a.value("byteOffset", size_t{0});
  std::vector<float> out(a["count"].get<size_t>() * n);
  for (size_t e = 0; e < a["count"].get<size_t>(); ++e) {
    std::memcpy(&out[e * n], g.bin.data() + base + e * stride, n * 4);
  }
  return out;
}

TEST(FoxGlb, LinearKeysAreImportedAsTheFileHasThem) {
  const fs::path path = ossa::test::shared_assets() / "Fox/Fox.glb";
  if (!fs::exists(path)) GTEST_SKIP() << "notice: " << path << " is absent";
  const std::optional<SourceScene> scene = import_shared("Fox/Fox.glb");
  ASSERT_TRUE(scene.has_value());
  const std::optional<TestGlb> glb = read_glb(path);
  ASSERT_TRUE(glb.has_value());
  EXPECT_FALSE(mentions(scene->warnings, "glTF")) << all_lines(scene->warnings);
  const Json& animations = glb->json["animations"];
  ASSERT_EQ(scene->clips.size(), animations.size());
  size_t compared = 0;
  for (size_t a = 0; a < animations.size(); ++a) {
    const SourceClip& clip = scene->clips[a];
    EXPECT_EQ(clip.name, animations[a]["name"].get<std::string>());
    // The clip's rate is one whose frame grid holds every key the file has (the importer's rule:
    // no source key is lost to resampling); Fox keys at 24 fps, Run at times only 120 fps holds.
    EXPECT_GE(clip.sample_rate, 24.0f) << clip.name;
    for (const Json& ch : animations[a]["channels"]) {
      const Json& sampler = animations[a]["samplers"][ch["sampler"].get<size_t>()];
      for (float t : glb_floats(*glb, sampler["input"].get<size_t>())) {
        const double frame = double(t) * clip.sample_rate;
        EXPECT_NEAR(frame, std::round(frame), 2e-3) << clip.name << ": key at " << t << " s is off the frame grid";
      }
      ASSERT_EQ(sampler.value("interpolation", std::string("LINEAR")), "LINEAR");
      const std::string node = glb->json["nodes"][ch["target"]["node"].get<size_t>()]["name"];
      const std::string p = ch["target"]["path"];
      const Path path_kind = p == "translation" ? Path::T : p == "rotation" ? Path::R : Path::S;
      const SourceTrack* track = find_track(*scene, clip, node);
      ASSERT_NE(track, nullptr) << clip.name << " " << node;
      const TrackChannel got = channel_of(*track, path_kind);
      const std::vector<float> times = glb_floats(*glb, sampler["input"].get<size_t>());
      const std::vector<float> values = glb_floats(*glb, sampler["output"].get<size_t>());
      ASSERT_EQ(got.times.size(), times.size()) << clip.name << " " << node << " " << p;
      const bool root = scene->skeleton.joints[track->joint].parent < 0;  // its keys fold in nodes above
      const size_t w = path_kind == Path::R ? 4 : 3;
      for (size_t k = 0; k < times.size(); ++k) {
        EXPECT_NEAR(got.times[k], times[k], 1e-6);
        if (root) continue;
        const glm::dvec4 want = w == 4 ? q4(values[4 * k], values[4 * k + 1], values[4 * k + 2], values[4 * k + 3])
                                       : v3(values[3 * k], values[3 * k + 1], values[3 * k + 2]);
        EXPECT_LE(difference(got.values[k], path_kind == Path::R ? want / glm::length(want) : want, path_kind), 1e-5)
            << clip.name << " " << node << " " << p << " key " << k;
        ++compared;
      }
    }
  }
  EXPECT_GT(compared, 100u);
}

// ---------------------------------------------------------------------------------------------
// Hand-made files

std::vector<uint8_t> float_bytes(const std::vector<float>& v) {
  std::vector<uint8_t> out(v.size() * 4);
  std::memcpy(out.data(), v.data(), out.size());
  return out;
}

std::string base64(const std::vector<uint8_t>& bytes) {
  static const char* alphabet = "ABCDEFGHIJKLMNOPQRSTUVWXYZabcdefghijklmnopqrstuvwxyz0123456789+/";
  std::string out;
  for (size_t i = 0; i < bytes.size(); i += 3) {
    const uint32_t b = static_cast<uint32_t>(bytes[i]) << 16 | (i + 1 < bytes.size() ? bytes[i + 1] << 8 : 0) |
                       (i + 2 < bytes.size() ? bytes[i + 2] : 0);
    out += alphabet[b >> 18 & 63];
    out += alphabet[b >> 12 & 63];
    out += i + 1 < bytes.size() ? alphabet[b >> 6 & 63] : '=';
    out += i + 2 < bytes.size() ? alphabet[b & 63] : '=';
  }
  return out;
}

/// GLB container: header, JSON chunk (space-padded), BIN chunk (zero-padded).
std::vector<uint8_t> make_glb(const Json& json, std::vector<uint8_t> bin) {
  std::string text = json.dump();
  while (text.size() % 4) text += ' ';
  while (bin.size() % 4) bin.push_back(0);
  std::vector<uint8_t> out;
  auto put = [&](uint32_t v) {
    for (int i = 0; i < 4; ++i) out.push_back(static_cast<uint8_t>(v >> (8 * i)));
  };
  put(0x46546C67);
  put(2);
  put(static_cast<uint32_t>(12 + 8 + text.size() + 8 + bin.size()));
  put(static_cast<uint32_t>(text.size()));
  put(0x4E4F534A);
  out.insert(out.end(), text.begin(), text.end());
  put(static_cast<uint32_t>(bin.size()));
  put(0x004E4942);
  out.insert(out.end(), bin.begin(), bin.end());
  return out;
}

// Keys shared by the hand-made files: times 0, 0.5, 1; STEP values; a cubic's (in, value, out).
const std::vector<float> kTimes = {0.0f, 0.5f, 1.0f};
const std::vector<float> kStepValues = {0, 0, 0, 1, 2, 3, 4, 5, 6};
const std::vector<float> kCubicValues = {0,  0, 0, 0, 0, 0, 2, 0, 0,   // key 0: out-tangent (2, 0, 0)
                                         0,  0, 0, 1, 1, 1, 0, 0, 0,   // key 1: value (1, 1, 1)
                                         -4, 0, 0, 2, 0, 2, 0, 0, 0};  // key 2: in-tangent (-4, 0, 0)

/// Buffer: times (12 bytes) | STEP values (36) | cubic values (108) | 16 bytes of padding, so an
/// accessor that overreads its view by a few bytes still stays inside the buffer for Assimp.
std::vector<uint8_t> hand_made_buffer() {
  std::vector<uint8_t> b = float_bytes(kTimes);
  for (const auto* v : {&kStepValues, &kCubicValues}) {
    const std::vector<uint8_t> bytes = float_bytes(*v);
    b.insert(b.end(), bytes.begin(), bytes.end());
  }
  b.resize(b.size() + 16, 0);
  return b;
}

/// Nodes: 0 "rig" -> {1 unnamed, 2 "A", 3 "A" -> {4 unnamed}}. STEP translation on node 1,
/// CUBICSPLINE translation on node 4, STEP scale on node 3 (a repeated name: kept, with a warning).
Json hand_made_json(const Json& buffer) {
  return Json{
      {"asset", {{"version", "2.0"}}},
      {"buffers", Json::array({buffer})},
      {"bufferViews", Json::array({{{"buffer", 0}, {"byteOffset", 0}, {"byteLength", 12}},
                                   {{"buffer", 0}, {"byteOffset", 12}, {"byteLength", 36}},
                                   {{"buffer", 0}, {"byteOffset", 48}, {"byteLength", 108}}})},
      {"accessors", Json::array({{{"bufferView", 0},
                                  {"componentType", 5126},
                                  {"count", 3},
                                  {"type", "SCALAR"},
                                  {"min", Json::array({0.0})},
                                  {"max", Json::array({1.0})}},
                                 {{"bufferView", 1}, {"componentType", 5126}, {"count", 3}, {"type", "VEC3"}},
                                 {{"bufferView", 2}, {"componentType", 5126}, {"count", 9}, {"type", "VEC3"}}})},
      {"nodes", Json::array({{{"name", "rig"}, {"children", {1, 2, 3}}},
                             Json::object(),
                             {{"name", "A"}},
                             {{"name", "A"}, {"children", Json::array({4})}},
                             Json::object()})},
      {"scenes", Json::array({Json{{"nodes", Json::array({0})}}})},
      {"scene", 0},
      {"animations",
       Json::array({{{"name", "move"},
                     {"samplers", Json::array({{{"input", 0}, {"output", 1}, {"interpolation", "STEP"}},
                                               {{"input", 0}, {"output", 2}, {"interpolation", "CUBICSPLINE"}}})},
                     {"channels", Json::array({{{"sampler", 0}, {"target", {{"node", 1}, {"path", "translation"}}}},
                                               {{"sampler", 1}, {"target", {{"node", 4}, {"path", "translation"}}}},
                                               {{"sampler", 0}, {"target", {{"node", 3}, {"path", "scale"}}}}})}}})},
  };
}

RefChannel hand_made_step() {
  return {"move", "nodes[1]", Path::T, Mode::Step, kTimes, {v3(0, 0, 0), v3(1, 2, 3), v3(4, 5, 6)}};
}

RefChannel hand_made_cubic() {
  std::vector<glm::dvec4> v;
  for (size_t i = 0; i < kCubicValues.size(); i += 3) {
    v.push_back(v3(kCubicValues[i], kCubicValues[i + 1], kCubicValues[i + 2]));
  }
  return {"move", "nodes[4]", Path::T, Mode::Cubic, kTimes, v};
}

/// Every grid frame of the channel equals the reference.
void expect_channel(const SourceScene& scene, const RefChannel& ref) {
  SCOPED_TRACE(ref.node);
  ASSERT_EQ(scene.clips.size(), 1u);
  const SourceClip& clip = scene.clips[0];
  const SourceTrack* track = find_track(scene, clip, ref.node);
  ASSERT_NE(track, nullptr) << "no track for joint " << ref.node;
  const TrackChannel ch = channel_of(*track, ref.path);
  const ossa::cook::FrameGrid grid = ossa::cook::frame_grid(clip);
  EXPECT_FLOAT_EQ(grid.sample_rate, 60.0f);  // keys on a 2 Hz grid: its multiple of at least 60 Hz
  for (uint32_t f = 0; f < grid.frame_count; ++f) {
    const int k = key_at(ch, grid.time(f));
    ASSERT_GE(k, 0) << "frame " << f;
    EXPECT_LE(difference(ch.values[k], ref_evaluate(ref, grid.time(f)), ref.path), 1e-5) << "frame " << f;
  }
}

class HandMadeFiles : public ::testing::Test {
 protected:
  void SetUp() override { dir_ = ossa::test::make_temp_dir("gltf-sampler"); }
  fs::path dir_;
};

TEST_F(HandMadeFiles, UnnamedNodesAndExternalBuffer) {
  // Assimp 5.2.5 opens a buffer URI as written, without percent-decoding it, so the file must
  // have the encoded name for Assimp to import it; the sampler reader finds it too.
  ASSERT_TRUE(ossa::test::write_file(dir_ / "keys%20data.bin", hand_made_buffer()));
  const Json json = hand_made_json({{"byteLength", hand_made_buffer().size()}, {"uri", "keys%20data.bin"}});
  ASSERT_TRUE(ossa::test::write_file(dir_ / "rig.gltf", json.dump()));
  ossa::Result<SourceScene> scene = ossa::cook::import_scene((dir_ / "rig.gltf").string());
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  expect_channel(*scene, hand_made_step());
  expect_channel(*scene, hand_made_cubic());
  // The repeated name "A": Assimp's channel is bound by name, so its keys stay as they were, said.
  EXPECT_TRUE(mentions(scene->warnings, "'A' scale (the node's name is not unique)")) << all_lines(scene->warnings);
}

TEST_F(HandMadeFiles, GlbWithEmbeddedBinaryChunk) {
  const Json json = hand_made_json({{"byteLength", hand_made_buffer().size()}});
  ASSERT_TRUE(ossa::test::write_file(dir_ / "rig.glb", make_glb(json, hand_made_buffer())));
  ossa::Result<SourceScene> scene = ossa::cook::import_scene((dir_ / "rig.glb").string());
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  expect_channel(*scene, hand_made_step());
  expect_channel(*scene, hand_made_cubic());
}

TEST_F(HandMadeFiles, AnAccessorPastItsViewKeepsAssimpKeysWithAWarning) {
  // Assimp 5.2.5 checks an accessor against its view's length without the accessor's offset, so
  // it reads this one (4 bytes past the view, still inside the buffer); the importer refuses it,
  // says so, and keeps Assimp's keys for that channel alone.
  Json json = hand_made_json({{"byteLength", hand_made_buffer().size()},
                              {"uri", "data:application/octet-stream;base64," + base64(hand_made_buffer())}});
  json["accessors"][1]["byteOffset"] = 4;
  ASSERT_TRUE(ossa::test::write_file(dir_ / "rig.gltf", json.dump()));
  ossa::Result<SourceScene> scene = ossa::cook::import_scene((dir_ / "rig.gltf").string());
  ASSERT_TRUE(scene.ok()) << scene.error().message;
  EXPECT_TRUE(mentions(scene->warnings, "'nodes[1]' translation (accessor 1")) << all_lines(scene->warnings);
  expect_channel(*scene, hand_made_cubic());  // the other channel is still resampled
  const SourceTrack* track = find_track(*scene, scene->clips[0], "nodes[1]");
  ASSERT_NE(track, nullptr);
  EXPECT_EQ(track->translation_times.size(), 3u) << "Assimp's three keys, as they were";
}

// ---------------------------------------------------------------------------------------------
// The reader on malformed input, and the evaluator.

ossa::Result<ossa::cook::gltf::Animations> parse(const std::string& text) {
  return ossa::cook::gltf::parse_gltf_animations(std::vector<uint8_t>(text.begin(), text.end()), "", "test.gltf");
}

ossa::Result<ossa::cook::gltf::Animations> parse(const Json& json) { return parse(json.dump()); }

Json data_uri_json() {
  return hand_made_json({{"byteLength", hand_made_buffer().size()},
                         {"uri", "data:application/octet-stream;base64," + base64(hand_made_buffer())}});
}

TEST(GltfReader, ReadsStepAndCubicKeysFromADataUri) {
  const auto file = parse(data_uri_json());
  ASSERT_TRUE(file.ok()) << file.error().message;
  ASSERT_EQ(file->animations.size(), 1u);
  const auto& samplers = file->animations[0].samplers;
  ASSERT_EQ(samplers.size(), 2u);
  EXPECT_TRUE(file->any_nonlinear);
  EXPECT_EQ(samplers[0].error, "");
  EXPECT_EQ(samplers[0].interpolation, ossa::cook::gltf::Interpolation::Step);
  EXPECT_EQ(samplers[0].times, kTimes);
  EXPECT_EQ(samplers[0].values, kStepValues);
  EXPECT_EQ(samplers[1].values, kCubicValues);
  EXPECT_EQ(samplers[1].width, 3);
  EXPECT_EQ(ossa::cook::gltf::assimp_node_name(*file, 1), "nodes[1]");
  EXPECT_EQ(ossa::cook::gltf::assimp_node_name(*file, 2), "A");
  EXPECT_EQ(file->scene_roots, std::vector<int>{0});
}

TEST(GltfReader, MalformedFilesAreErrorsNotCrashes) {
  for (const char* text : {"", "{", "not json", "[1, 2]", "{\"animations\": 3}"}) {
    const auto file = parse(std::string(text));
    if (file.ok()) {
      EXPECT_TRUE(file->animations.empty()) << text;  // valid JSON without animations: nothing to read
    } else {
      EXPECT_EQ(file.error().message.rfind("test.gltf: ", 0), 0u) << file.error().message;
    }
  }
  EXPECT_FALSE(parse(std::string("{")).ok());
  // GLB: a chunk longer than the file; a header alone.
  std::vector<uint8_t> glb = make_glb(data_uri_json(), {});
  glb[12] = 0xff;
  glb[13] = 0xff;
  const auto bad = ossa::cook::gltf::parse_gltf_animations(glb, "", "x.glb");
  ASSERT_FALSE(bad.ok());
  EXPECT_NE(bad.error().message.find("chunk"), std::string::npos) << bad.error().message;
  EXPECT_FALSE(ossa::cook::gltf::parse_gltf_animations({0x67, 0x6C, 0x54, 0x46}, "", "x.glb").ok());
  // Types the reader does not expect where it expects objects, arrays, indices.
  Json weird = data_uri_json();
  weird["animations"][0]["channels"][0]["target"] = "node 1";
  weird["animations"][0]["samplers"][1]["input"] = -1;
  weird["accessors"][1]["count"] = "3";
  weird["nodes"][0]["children"] = {1, 99, "x"};
  const auto w = parse(weird);
  ASSERT_TRUE(w.ok()) << w.error().message;
  EXPECT_NE(w->animations[0].samplers[0].error, "");
  EXPECT_NE(w->animations[0].samplers[1].error, "");
  EXPECT_EQ(w->nodes[0].children, (std::vector<int>{1, -1, -1}));
}

std::string sampler_error(const Json& json, size_t sampler = 0) {
  const auto file = parse(json);
  if (!file.ok()) return "file: " + file.error().message;
  return file->animations[0].samplers[sampler].error;
}

TEST(GltfReader, BadAccessorsAreReportedPerSampler) {
  Json j = data_uri_json();
  j["accessors"][1]["count"] = 4;  // past its view
  EXPECT_NE(sampler_error(j).find("reads past the end of bufferView 1"), std::string::npos) << sampler_error(j);

  j = data_uri_json();
  j["accessors"][1]["count"] = 1000000000000;  // offsets must not overflow
  EXPECT_NE(sampler_error(j).find("reads past"), std::string::npos) << sampler_error(j);

  j = data_uri_json();
  j["bufferViews"][1]["byteLength"] = 100000;  // past its buffer
  EXPECT_NE(sampler_error(j).find("outside buffer 0"), std::string::npos) << sampler_error(j);

  j = data_uri_json();
  j["animations"][0]["samplers"][1]["output"] = 1;  // CUBICSPLINE with one element per key
  EXPECT_NE(sampler_error(j, 1).find("9 expected for 3 keys"), std::string::npos) << sampler_error(j, 1);

  j = data_uri_json();
  j["animations"][0]["samplers"][0]["input"] = 1;  // times must be SCALAR
  EXPECT_NE(sampler_error(j).find("components, 1 expected"), std::string::npos) << sampler_error(j);

  j = data_uri_json();
  j["buffers"][0]["uri"] = "data:application/octet-stream;base64,@@@@";
  EXPECT_NE(sampler_error(j).find("invalid base64"), std::string::npos) << sampler_error(j);

  j = data_uri_json();
  j["buffers"][0]["uri"] = "missing.bin";
  EXPECT_NE(sampler_error(j).find("cannot be read"), std::string::npos) << sampler_error(j);

  j = data_uri_json();
  j["buffers"][0]["uri"] = "https://example.com/keys.bin";
  EXPECT_NE(sampler_error(j).find("cannot read"), std::string::npos) << sampler_error(j);

  j = data_uri_json();
  j["accessors"][0]["byteOffset"] = 4;  // 4 + 3 * 4 bytes from a 12-byte view
  EXPECT_NE(sampler_error(j).find("reads past"), std::string::npos) << sampler_error(j);
  j["bufferViews"][0]["byteLength"] = 16;  // times 0.5, 1, then the first STEP value (0)
  EXPECT_NE(sampler_error(j).find("strictly increasing"), std::string::npos) << sampler_error(j);
}

TEST(GltfReader, NormalizedAndSparseOutputs) {
  // Rotation as normalized shorts: (0, 0, 32767, 0) and (0, 0, -32768, 0) -> z = 1 and -1
  // (clamped).
  std::vector<uint8_t> bin = float_bytes({0.0f, 1.0f});
  for (int16_t c :
       {int16_t{0}, int16_t{0}, int16_t{32767}, int16_t{0}, int16_t{0}, int16_t{0}, int16_t{-32768}, int16_t{0}}) {
    bin.push_back(static_cast<uint8_t>(c & 0xff));
    bin.push_back(static_cast<uint8_t>((c >> 8) & 0xff));
  }
  // Sparse: indices (uint8) {1}, value (0, 7, 0) over a zero accessor of 2 VEC3.
  bin.push_back(1);
  bin.resize(bin.size() + 3, 0);
  const std::vector<uint8_t> sparse_value = float_bytes({0.0f, 7.0f, 0.0f});
  bin.insert(bin.end(), sparse_value.begin(), sparse_value.end());
  Json j = Json::parse(R"({
    "buffers": [{"byteLength": 40}],
    "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 8},
                    {"buffer": 0, "byteOffset": 8, "byteLength": 16},
                    {"buffer": 0, "byteOffset": 24, "byteLength": 4},
                    {"buffer": 0, "byteOffset": 28, "byteLength": 12}],
    "accessors": [{"bufferView": 0, "componentType": 5126, "count": 2, "type": "SCALAR"},
                  {"bufferView": 1, "componentType": 5122, "normalized": true, "count": 2, "type": "VEC4"},
                  {"componentType": 5126, "count": 2, "type": "VEC3",
                   "sparse": {"count": 1, "indices": {"bufferView": 2, "componentType": 5121},
                              "values": {"bufferView": 3}}}],
    "nodes": [{}],
    "animations": [{"samplers": [{"input": 0, "output": 1, "interpolation": "STEP"},
                                 {"input": 0, "output": 2, "interpolation": "STEP"}],
                    "channels": [{"sampler": 0, "target": {"node": 0, "path": "rotation"}}]}]
  })");
  ASSERT_EQ(bin.size(), 40u);
  j["buffers"][0]["uri"] = "data:application/gltf-buffer;base64," + base64(bin);
  const auto file = parse(j);
  ASSERT_TRUE(file.ok()) << file.error().message;
  const auto& s = file->animations[0].samplers;
  EXPECT_EQ(s[0].error, "");
  EXPECT_EQ(s[0].values, (std::vector<float>{0, 0, 1, 0, 0, 0, -1, 0}));
  EXPECT_EQ(s[1].error, "");
  EXPECT_EQ(s[1].values, (std::vector<float>{0, 0, 0, 0, 7, 0}));
}

TEST(GltfReader, ExternalBufferUrisArePercentDecoded) {
  const fs::path dir = ossa::test::make_temp_dir("gltf-uri");
  ASSERT_TRUE(ossa::test::write_file(dir / "keys data.bin", hand_made_buffer()));
  const Json j = hand_made_json({{"byteLength", hand_made_buffer().size()}, {"uri", "keys%20data.bin"}});
  const std::string text = j.dump();
  const auto file = ossa::cook::gltf::parse_gltf_animations(std::vector<uint8_t>(text.begin(), text.end()),
                                                            dir.string(), "test.gltf");
  ASSERT_TRUE(file.ok()) << file.error().message;
  EXPECT_EQ(file->animations[0].samplers[0].error, "");
  EXPECT_EQ(file->animations[0].samplers[0].values, kStepValues);
}

TEST(GltfReader, LinearSamplersAreNotReadAtAll) {
  Json j = data_uri_json();
  for (Json& s : j["animations"][0]["samplers"]) s["interpolation"] = "LINEAR";
  j["buffers"][0]["uri"] = "missing.bin";  // would fail if read
  const auto file = parse(j);
  ASSERT_TRUE(file.ok());
  EXPECT_FALSE(file->any_nonlinear);
  EXPECT_EQ(file->animations[0].samplers[0].error, "");
  EXPECT_TRUE(file->animations[0].samplers[0].times.empty());
}

TEST(GltfEvaluate, StepSnapsToAKeyJustAheadAndCubicPassesThroughItsValues) {
  ossa::cook::gltf::Sampler s;
  s.interpolation = ossa::cook::gltf::Interpolation::Step;
  s.times = kTimes;
  s.values = kStepValues;
  s.width = 3;
  double v[4];
  ossa::cook::gltf::evaluate(s, 0.4999, 0.0, v);
  EXPECT_EQ(v[0], 0.0);
  ossa::cook::gltf::evaluate(s, 0.5 - 1e-9, 1e-7, v);  // a float hair before the key: reached
  EXPECT_EQ(v[0], 1.0);
  ossa::cook::gltf::evaluate(s, -1.0, 0.0, v);
  EXPECT_EQ(v[0], 0.0);
  ossa::cook::gltf::evaluate(s, 5.0, 0.0, v);
  EXPECT_EQ(v[0], 4.0);
  EXPECT_FALSE(ossa::cook::gltf::is_linear_equivalent(s));

  s.interpolation = ossa::cook::gltf::Interpolation::CubicSpline;
  s.values = kCubicValues;
  const RefChannel ref = hand_made_cubic();
  for (double t : {0.0, 0.1, 0.25, 0.5, 0.6, 0.99, 1.0}) {
    ossa::cook::gltf::evaluate(s, t, 0.0, v);
    const glm::dvec4 want = ref_evaluate(ref, t);
    EXPECT_NEAR(v[0], want.x, 1e-12) << t;
    EXPECT_NEAR(v[1], want.y, 1e-12) << t;
    EXPECT_NEAR(v[2], want.z, 1e-12) << t;
  }
  EXPECT_FALSE(ossa::cook::gltf::is_linear_equivalent(s));
  // Tangents equal to the chord slopes: a straight line, nothing to resample.
  s.values = {0, 0, 0, 0, 0, 0, 2, 0, 0, 2, 0, 0, 1, 0, 0, 2, 0, 0, 2, 0, 0, 2, 0, 0, 0, 0, 0};
  EXPECT_TRUE(ossa::cook::gltf::is_linear_equivalent(s));
}

}  // namespace
