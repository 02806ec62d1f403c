// morph_test.cpp — the runtime's morph weights and CPU morph (ossa/anim/morph.h) on the synthetic
// "morph" file (test_files.h): two targets on the 6-vertex grid, "smile" moving vertices 4 and 5
// up, "frown" moving 2, 3 and 4 with normal deltas, and a clip whose tracks ramp "smile" 0 -> 1 and
// hold "frown" at ~0.5. Expected values are computed here from the stored integers and steps, so
// the tests check arithmetic and binding, not numbers copied from the implementation.
#include <gtest/gtest.h>

#include <cmath>
#include <string_view>
#include <vector>

#include <ossa/anim/morph.h>
#include <ossa/loader/asset.h>

#include "allocation_counter.h"
#include "test_files.h"

namespace ossa::test {
namespace {

SyntheticSpec morph_spec() {
  for (auto& [name, spec] : valid_variants())
    if (name == "morph") return spec;
  ADD_FAILURE() << "no morph variant";
  return {};
}

Asset load_morph_file() {
  const std::vector<uint8_t> bytes = make_valid_file(morph_spec());
  auto a = Asset::from_bytes(bytes, "morph.ossa");
  if (!a.ok()) ADD_FAILURE() << a.error().message;
  return std::move(*a);
}

struct Loaded {
  Asset asset = load_morph_file();
};

TEST(Morph, ChannelsAreTheDistinctTargetNamesAndBindByName) {
  Loaded f;
  std::vector<std::string_view> channels = {"blink", "frown"};
  collect_morph_channels(f.asset.mesh(0), channels);
  ASSERT_EQ(channels.size(), 3u);
  EXPECT_EQ(channels[2], "smile");
  std::vector<int32_t> target_channel(2);
  ASSERT_TRUE(bind_morph_targets(f.asset.mesh(0), channels, target_channel));
  EXPECT_EQ(target_channel[0], 2);  // smile
  EXPECT_EQ(target_channel[1], 1);  // frown
  std::vector<int32_t> track_channel(2);
  const std::vector<std::string_view> only_smile = {"smile"};
  ASSERT_TRUE(bind_morph_tracks(f.asset.clip(0), only_smile, track_channel));
  EXPECT_EQ(track_channel[0], -1);  // "frown": this character has no such channel
  EXPECT_EQ(track_channel[1], 0);
  std::vector<int32_t> too_small(1);
  EXPECT_FALSE(bind_morph_targets(f.asset.mesh(0), channels, too_small));
  EXPECT_FALSE(bind_morph_tracks(f.asset.clip(0), channels, too_small));
}

TEST(Morph, DefaultsThenClipWeightsAtKeysAndBetween) {
  Loaded f;
  std::vector<std::string_view> channels;
  collect_morph_channels(f.asset.mesh(0), channels);  // smile, frown
  std::vector<int32_t> target_channel(2), track_channel(2);
  ASSERT_TRUE(bind_morph_targets(f.asset.mesh(0), channels, target_channel));
  ASSERT_TRUE(bind_morph_tracks(f.asset.clip(0), channels, track_channel));
  std::vector<float> w(2, -7.0f);
  ASSERT_TRUE(default_morph_weights(f.asset.mesh(0), target_channel, w));
  EXPECT_EQ(w[0], 0.0f);
  EXPECT_EQ(w[1], 0.25f);
  const ClipView clip = f.asset.clip(0);  // 31 frames at 30/s: 1 s
  for (float t : {0.0f, 0.25f, 0.5f, 1.0f, 2.0f, -1.0f}) {
    ASSERT_TRUE(sample_morph_weights(clip, t, track_channel, w));
    EXPECT_NEAR(w[0], std::clamp(t, 0.0f, 1.0f), 1e-5f) << t;  // smile: 0 at frame 0, 1 at frame 30
    EXPECT_NEAR(w[1], 32768.0f / 65535.0f, 1e-6f) << t;        // frown: one key, constant
  }
  std::vector<float> small(1);
  EXPECT_FALSE(sample_morph_weights(clip, 0.5f, track_channel, small));
}

TEST(Morph, ApplyAddsWeightedDeltasToListedVerticesOnly) {
  Loaded f;
  const MeshView mesh = f.asset.mesh(0);
  const std::vector<std::string_view> channels = {"smile", "frown"};
  std::vector<int32_t> target_channel(2);
  ASSERT_TRUE(bind_morph_targets(mesh, channels, target_channel));
  const size_t n = mesh.vertex_count();
  std::vector<glm::vec3> base(n), normals(n, glm::vec3(0, 0, 1));
  for (size_t v = 0; v < n; ++v) base[v] = glm::vec3(float(v), 10.0f * float(v), -float(v));
  std::vector<glm::vec3> p = base;
  const std::vector<float> weights = {0.5f, 2.0f};
  ASSERT_TRUE(apply_morphs(mesh, target_channel, weights, p, normals));
  // Expected from the spec's integers: smile (w 0.5, step 1e-4) lifts 4 by 0.05 and 5 by 0.1;
  // frown (w 2, step 1e-4) moves 2 by -0.1 in x, 3 by +0.1 in x, 4 by -0.06 in y.
  const std::vector<glm::vec3> expected_delta = {
      {0, 0, 0}, {0, 0, 0}, {-0.1f, 0, 0}, {0.1f, 0, 0}, {0, 0.05f - 0.06f, 0}, {0, 0.1f, 0}};
  for (size_t v = 0; v < n; ++v)
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(p[v][a] - base[v][a], expected_delta[v][a], 1e-5f) << v << " " << a;
  // Normals: frown's deltas (w 2, step 1e-3): +0.2 z on 2, -0.2 z on 3; smile has none.
  EXPECT_NEAR(normals[2].z, 1.2f, 1e-6f);
  EXPECT_NEAR(normals[3].z, 0.8f, 1e-6f);
  EXPECT_EQ(normals[4], glm::vec3(0, 0, 1));
  // Zero weights change nothing; a channel-less target is skipped.
  std::vector<glm::vec3> q = base;
  ASSERT_TRUE(apply_morphs(mesh, target_channel, std::vector<float>{0.0f, 0.0f}, q));
  EXPECT_EQ(q, base);
  const std::vector<int32_t> unbound = {-1, -1};
  ASSERT_TRUE(apply_morphs(mesh, unbound, weights, q));
  EXPECT_EQ(q, base);
}

TEST(Morph, ApplyRefusesShortSpansAndWritesNothing) {
  Loaded f;
  const MeshView mesh = f.asset.mesh(0);
  const std::vector<int32_t> target_channel = {0, 1};
  const size_t n = mesh.vertex_count();
  std::vector<glm::vec3> p(n - 1, glm::vec3(3.0f)), full(n, glm::vec3(3.0f)), short_normals(2);
  const std::vector<float> weights = {1.0f, 1.0f};
  EXPECT_FALSE(apply_morphs(mesh, target_channel, weights, p));
  EXPECT_FALSE(apply_morphs(mesh, target_channel, weights, full, short_normals));
  EXPECT_FALSE(apply_morphs(mesh, target_channel, std::vector<float>{1.0f}, full));  // channel 1 missing
  EXPECT_FALSE(apply_morphs(mesh, std::vector<int32_t>{0}, weights, full));          // 2 targets
  for (const glm::vec3& v : full) EXPECT_EQ(v, glm::vec3(3.0f));
}

TEST(Morph, BlendIsALerpAndChecksSizes) {
  const std::vector<float> a = {0.0f, 1.0f, -1.0f}, b = {1.0f, 1.0f, 1.0f};
  std::vector<float> out(3);
  ASSERT_TRUE(blend_morph_weights(a, b, 0.25f, out));
  EXPECT_FLOAT_EQ(out[0], 0.25f);
  EXPECT_FLOAT_EQ(out[1], 1.0f);
  EXPECT_FLOAT_EQ(out[2], -0.5f);
  EXPECT_FALSE(blend_morph_weights(a, std::vector<float>{1.0f}, 0.5f, out));
  std::vector<float> small(2);
  EXPECT_FALSE(blend_morph_weights(a, b, 0.5f, small));
}

TEST(Morph, PerFrameWorkDoesNotAllocate) {
  Loaded f;
  const MeshView mesh = f.asset.mesh(0);
  const ClipView clip = f.asset.clip(0);
  const std::vector<std::string_view> channels = {"smile", "frown"};
  std::vector<int32_t> target_channel(2), track_channel(2);
  ASSERT_TRUE(bind_morph_targets(mesh, channels, target_channel));
  ASSERT_TRUE(bind_morph_tracks(clip, channels, track_channel));
  std::vector<float> w(2), w2(2);
  std::vector<glm::vec3> p(mesh.vertex_count()), nrm(mesh.vertex_count());
  const size_t before = allocation_count();
  for (int i = 0; i < 100; ++i) {
    sample_morph_weights(clip, 0.01f * float(i), track_channel, w);
    blend_morph_weights(w, w2, 0.5f, w2);
    apply_morphs(mesh, target_channel, w2, p, nrm);
  }
  EXPECT_EQ(allocation_count(), before);
}

}  // namespace
}  // namespace ossa::test
