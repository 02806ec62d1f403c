// viewer_unit_test.cpp — the viewer's parts that need no display: the command line, camera
// framing, bind-pose bounds, how files become a scene (which files are the character, which
// add clips, which are refused), and morph targets (channels bound by name, the weights each
// frame, the GPU's vertex-major entry lists, the CPU morph against skin_cpu).
#include <gtest/gtest.h>

#include <cmath>
#include <filesystem>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/matrix_transform.hpp>

#include <ossa/anim/pose.h>
#include <ossa/anim/pose_ops.h>
#include <ossa/skinning/skinning.h>
#include "test_files.h"
#include "viewer/bounds.h"
#include "viewer/camera.h"
#include "viewer/gl.h"
#include "viewer/graph_driver.h"
#include "viewer/animation.h"
#include "viewer/graph_keys.h"
#include "viewer/morphs.h"
#include "viewer/options.h"
#include "viewer/scene.h"
#include "viewer_unit_common.h"

namespace fs = std::filesystem;
using namespace ossa;
using namespace ossa::view;

namespace {

fs::path cooked(const char* rel) { return test::viewer_unit_cooked(rel); }

ParsedOptions parse(std::vector<const char*> args) {
  args.insert(args.begin(), "ossa-view");
  return parse_options(static_cast<int>(args.size()), args.data());
}

TEST(ViewerOptions, SizeParsesWidthByHeight) {
  EXPECT_EQ(parse_size("640x480"), std::make_pair(640, 480));
  EXPECT_FALSE(parse_size("640"));
  EXPECT_FALSE(parse_size("640x"));
  EXPECT_FALSE(parse_size("0x10"));
  EXPECT_FALSE(parse_size("10x99999"));
  EXPECT_FALSE(parse_size("64x48px"));
}

TEST(ViewerOptions, ScreenshotMeansHeadlessOneFrame) {
  const ParsedOptions p = parse({"a.ossa", "b.ossa", "--screenshot", "out.png", "--size", "320x200", "--time", "1.5"});
  ASSERT_TRUE(p.options);
  EXPECT_TRUE(p.options->headless());
  EXPECT_EQ(p.options->frames, 1);
  EXPECT_EQ(p.options->files, (std::vector<std::string>{"a.ossa", "b.ossa"}));
  EXPECT_EQ(p.options->width, 320);
  EXPECT_EQ(p.options->height, 200);
  EXPECT_FLOAT_EQ(p.options->time, 1.5f);

  const ParsedOptions window = parse({"a.ossa", "--window-frames", "3", "--screenshot", "w.png"});
  ASSERT_TRUE(window.options);
  EXPECT_FALSE(window.options->headless());
  EXPECT_FALSE(parse({"a.ossa"}).options->headless());
}

TEST(ViewerOptions, GraphValuesTakeOneArgumentEach) {
  const ParsedOptions p =
      parse({"--graph", "pab", "--set", "speed=3", "--set", "strike_pose", "pab.ossa", "walk.ossa"});
  ASSERT_TRUE(p.options);
  EXPECT_EQ(p.options->graph, "pab");
  EXPECT_EQ(p.options->set, (std::vector<std::string>{"speed=3", "strike_pose"}));
  EXPECT_EQ(p.options->files, (std::vector<std::string>{"pab.ossa", "walk.ossa"}));
  EXPECT_EQ(parse({"a.ossa", "--set", "speed=3"}).exit_code, 2) << "--set needs --graph";
}

TEST(ViewerOptions, UsageErrorsExitWithTwo) {
  EXPECT_FALSE(parse({"--frames", "1"}).options);
  EXPECT_EQ(parse({"--frames", "1"}).exit_code, 2);  // no file to render (the window may start without one)
  EXPECT_EQ(parse({"a.ossa", "--size", "big"}).exit_code, 2);
  EXPECT_EQ(parse({"a.ossa", "--crowd", "0"}).exit_code, 2);
  EXPECT_EQ(parse({"a.ossa", "--help"}).exit_code, 0);
}

TEST(ViewerOptions, MorphWeightsAreNameEqualsWeight) {
  const ParsedOptions p = parse({"a.ossa", "--morph", "smile=0.5", "--morph", "brow=up=-1", "--morph", "frown=1e2"});
  ASSERT_TRUE(p.options);
  using Held = std::vector<std::pair<std::string, float>>;
  EXPECT_EQ(p.options->morphs, (Held{{"smile", 0.5f}, {"brow=up", -1.0f}, {"frown", 100.0f}}));
  EXPECT_EQ(p.options->files, (std::vector<std::string>{"a.ossa"}));
  for (const char* bad : {"smile", "smile=", "=1", "smile=x", "smile=1x", "smile=nan", "smile=inf", "smile=1001"})
    EXPECT_EQ(parse({"a.ossa", "--morph", bad}).exit_code, 2) << bad;
  EXPECT_FALSE(parse_morph("smile=-1000.5"));
  EXPECT_EQ(parse_morph("smile=-1000"), std::make_pair(std::string("smile"), -1000.0f));
}

/// Every corner of `box` projects inside the view, and the framing is tight: some corner lies
/// near the edge (within the 8 % margin and a bit).
void expect_framed(const Box& box, float yaw, float pitch, float aspect) {
  const OrbitCamera c = frame_box(box, yaw, pitch, aspect);
  const glm::mat4 vp = projection_matrix(c, aspect) * view_matrix(c);
  float extent = 0.0f;
  for (int corner = 0; corner < 8; ++corner) {
    const glm::vec3 p((corner & 1) ? box.max.x : box.min.x, (corner & 2) ? box.max.y : box.min.y,
                      (corner & 4) ? box.max.z : box.min.z);
    const glm::vec4 clip = vp * glm::vec4(p, 1.0f);
    ASSERT_GT(clip.w, 0.0f) << "corner behind the camera";
    const glm::vec3 ndc = glm::vec3(clip) / clip.w;
    EXPECT_LE(std::fabs(ndc.x), 1.0f);
    EXPECT_LE(std::fabs(ndc.y), 1.0f);
    EXPECT_GT(ndc.z, -1.0f) << "corner in front of the near plane";
    EXPECT_LT(ndc.z, 1.0f) << "corner past the far plane";
    extent = std::max({extent, std::fabs(ndc.x), std::fabs(ndc.y)});
  }
  EXPECT_GT(extent, 0.85f) << "framing is loose";
}

TEST(ViewerCamera, FrameBoxFitsEveryCornerTightly) {
  Box human;
  human.add({-0.9f, 0.0f, -0.2f});
  human.add({0.9f, 1.8f, 0.2f});
  Box fox;  // long along z, in centimetres
  fox.add({-12.6f, -0.2f, -87.0f});
  fox.add({12.6f, 78.9f, 67.8f});
  for (float aspect : {1.0f, 16.0f / 9.0f, 0.5f}) {
    for (float yaw : {0.0f, 0.52f, 2.0f}) {
      expect_framed(human, yaw, 0.17f, aspect);
      expect_framed(fox, yaw, 0.8f, aspect);
    }
  }
}

TEST(ViewerCamera, OrbitClampsPitchAndZoomStaysPositive) {
  Box b;
  b.add({-1, -1, -1});
  b.add({1, 1, 1});
  OrbitCamera c = frame_box(b, 0.0f, 0.0f, 1.0f);
  orbit(c, 0.0f, 10.0f);
  EXPECT_LT(c.pitch, 1.5708f);
  zoom(c, 1000.0f);
  EXPECT_GT(c.distance, 0.0f);
  EXPECT_GT(c.near_plane, 0.0f);
  EXPECT_LT(c.near_plane, c.far_plane);
}

std::vector<glm::mat4> bind_model(const SkeletonView& skeleton) {
  Pose pose(static_cast<uint32_t>(skeleton.joint_count()));
  set_bind_pose(skeleton, pose);
  std::vector<glm::mat4> model(skeleton.joint_count());
  local_to_model(skeleton.parents(), pose, model);
  return model;
}

TEST(ViewerBounds, BindPoseBoundsMatchTheMeshWhereSkinAndRigAgree) {
  Result<Asset> a = Asset::open(cooked("CesiumMan/CesiumMan.ossa").string());
  ASSERT_TRUE(a) << a.error().message;
  const Box b = posed_bounds(*a, bind_model(a->skeleton()));
  // CesiumMan stands 1.51 m tall in its cooked bounds, arms out to +-0.57 m.
  EXPECT_NEAR(b.size().y, 1.51f, 0.02f);
  EXPECT_NEAR(b.size().x, 1.14f, 0.02f);
}

Box synthetic_bounds(const test::SyntheticSpec& spec) {
  const std::vector<uint8_t> bytes = test::make_valid_file(spec);
  Result<Asset> a = Asset::from_bytes(bytes, "synthetic.ossa");
  EXPECT_TRUE(a) << a.error().message;
  return a ? posed_bounds(*a, bind_model(a->skeleton())) : Box{};
}

TEST(ViewerBounds, AMeshReachingPastTheSkeletonIsFramedWhole) {
  // The synthetic rig (joints over x 0..0.5, y 0..2, z 0) and its 1 x 2 x 0.2 grid of vertices:
  // the box is the mesh's.
  test::SyntheticSpec spec;
  const Box plain = synthetic_bounds(spec);
  EXPECT_NEAR(plain.min.x, -0.5f, 1e-3f);
  EXPECT_NEAR(plain.max.x, 0.5f, 1e-3f);
  EXPECT_NEAR(plain.size().y, 2.0f, 1e-3f);
  EXPECT_NEAR(plain.size().z, 0.2f, 1e-3f);
  // A vertex 4 units in front of a flat skeleton (a spear, a flag, a prop far larger than the rig)
  // is drawn there, so it is framed: the box must reach it, not stop at the joints.
  test::SyntheticVertex far = spec.meshes[0].vertices[0];
  far.position = fb::Vec3(0.0f, 1.0f, 4.0f);
  spec.meshes[0].vertices.push_back(far);
  const Box whole = synthetic_bounds(spec);
  EXPECT_NEAR(whole.max.z, 4.0f, 2e-3f);
  EXPECT_NEAR(whole.size().y, 2.0f, 1e-3f);
}

TEST(ViewerBounds, SlotsPlacedByAnotherBindPoseDoNotInflateTheBox) {
  // Pab's mesh was skinned with its fingers posed unlike the rig's bind pose: those slots place
  // the mesh box elsewhere. The box must follow the slots that agree (the T-pose, 1.73 m span).
  Result<Asset> a = Asset::open(cooked("Pab/arnaud.ossa").string());
  ASSERT_TRUE(a) << a.error().message;
  const MeshView mesh = a->mesh(0);
  const float mesh_width = mesh.fb->bounds_max()->x() - mesh.fb->bounds_min()->x();
  const Box b = posed_bounds(*a, bind_model(a->skeleton()));
  EXPECT_LT(b.size().x, 1.05f * mesh_width);
  EXPECT_GT(b.size().x, 0.95f * mesh_width);
}

TEST(ViewerScene, CharacterFirstThenClipFiles) {
  const std::vector<std::string> paths{cooked("Pab/walk.ossa").string(), cooked("Pab/arnaud.ossa").string(),
                                       cooked("Pab/run.ossa").string()};
  Result<Scene> s = load_scene(paths);
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_EQ(s->paths.front(), paths[1]) << "the file with a mesh is the character, wherever it is given";
  ASSERT_EQ(s->clips.size(), 2u);
  EXPECT_EQ(find_clip(*s, "walk"), 0);
  EXPECT_EQ(find_clip(*s, "run"), 1);
  EXPECT_EQ(find_clip(*s, "run (run.ossa)"), 1);
  EXPECT_EQ(find_clip(*s, "jog"), -1);
  EXPECT_EQ(count(*s).joints, 67u);
  EXPECT_EQ(count(*s).vertices, 3836u);  // arnaud's colour seams are separate vertices
}

TEST(ViewerScene, RefusesWithTheFileNamed) {
  const std::string walk = cooked("Pab/walk.ossa").string(), fox = cooked("Fox/Fox.ossa").string();
  Result<Scene> alone = load_scene(std::vector<std::string>{walk});
  ASSERT_FALSE(alone);
  EXPECT_NE(alone.error().message.find(walk), std::string::npos);
  EXPECT_NE(alone.error().message.find("no mesh"), std::string::npos);

  Result<Scene> mismatch = load_scene(std::vector<std::string>{fox, walk});
  ASSERT_FALSE(mismatch);
  EXPECT_NE(mismatch.error().message.find(walk), std::string::npos) << mismatch.error().message;

  Result<Scene> ok = load_scene(std::vector<std::string>{fox});
  ASSERT_TRUE(ok);
  const size_t clips = ok->clips.size();
  EXPECT_FALSE(add_clip_file(*ok, walk));
  EXPECT_EQ(ok->clips.size(), clips) << "a refused file leaves the scene as it was";
  EXPECT_EQ(ok->assets.size(), 1u);
}

// ---------------------------------------------------------------------------------------------
// Morph targets: test_files' "morph" variant (targets smile on vertices 4, 5 and frown on 2, 3, 4
// with normal deltas and default weight 0.25; the clip drives frown constant at 0.5 and smile
// 0 -> 1 over its second; its tracks are sorted by name: frown, smile).

test::SyntheticSpec morph_variant() {
  for (const auto& [name, spec] : test::valid_variants())
    if (name == "morph") return spec;
  ADD_FAILURE() << "no morph variant";
  return {};
}

Result<Scene> morph_scene(const test::SyntheticSpec& spec) {
  const fs::path file = test::make_temp_dir("viewer-morph") / "morph.ossa";
  if (!test::write_file(file, test::make_valid_file(spec))) return Error{"cannot write " + file.string()};
  return load_scene(std::vector<std::string>{file.string()});
}

TEST(ViewerMorph, SceneBindsChannelsDefaultsAndTracksByName) {
  Result<Scene> s = morph_scene(morph_variant());
  ASSERT_TRUE(s) << s.error().message;
  EXPECT_EQ(s->morph_channels, (std::vector<std::string_view>{"smile", "frown"}));
  ASSERT_EQ(s->morph_targets.size(), 1u);
  EXPECT_EQ(s->morph_targets[0], (std::vector<int32_t>{0, 1}));
  EXPECT_EQ(s->morph_defaults, (std::vector<float>{0.0f, 0.25f}));
  ASSERT_EQ(s->clips.size(), 1u);
  EXPECT_EQ(s->clips[0].morph_tracks, (std::vector<int32_t>{1, 0})) << "tracks frown, smile";
  EXPECT_EQ(find_morph_channel(*s, "frown"), 1);
  EXPECT_EQ(find_morph_channel(*s, "grin"), -1);

  Result<Scene> plain = morph_scene(test::SyntheticSpec{});
  ASSERT_TRUE(plain) << plain.error().message;
  EXPECT_TRUE(plain->morph_channels.empty());
  EXPECT_TRUE(plain->clips[0].morph_tracks.empty());
}

TEST(ViewerMorph, WeightsAreDefaultsThenTheClipThenHeldChannels) {
  Result<Scene> s = morph_scene(morph_variant());
  ASSERT_TRUE(s) << s.error().message;
  Animator a = make_animator(*s, 2);
  produce_morph_weights(*s, a);
  EXPECT_EQ(a.instances[0].morph_weights, (std::vector<float>{0.0f, 0.25f})) << "no clip: the defaults";

  ASSERT_TRUE(select_clip(*s, a, 0, false));
  set_time(*s, a, 0.5f);
  produce_morph_weights(*s, a);
  EXPECT_NEAR(a.instances[0].morph_weights[0], 0.5f, 1e-4f) << "smile: 0 -> 1 over the second";
  EXPECT_NEAR(a.instances[0].morph_weights[1], 0.5f, 1e-4f) << "frown: constant 32768 / 65535";
  // Instance 1 plays 0.618 of a loop later: its own weight.
  const float t1 = std::fmod(0.5f + a.instances[1].time_offset, 1.0f);
  EXPECT_NEAR(a.instances[1].morph_weights[0], t1, 1e-3f);

  hold_morph(a, 0, true, 0.8f);
  produce_morph_weights(*s, a);
  EXPECT_FLOAT_EQ(a.instances[0].morph_weights[0], 0.8f);
  EXPECT_FLOAT_EQ(a.instances[1].morph_weights[0], 0.8f) << "a held channel holds for the whole crowd";
  EXPECT_NEAR(a.instances[0].morph_weights[1], 0.5f, 1e-4f) << "the other channel still follows the clip";

  a.playback.bind_pose = true;
  produce_morph_weights(*s, a);
  EXPECT_EQ(a.instances[0].morph_weights, (std::vector<float>{0.8f, 0.25f})) << "bind pose: defaults and held";
  hold_morph(a, 0, false, 0.0f);
  a.playback.bind_pose = false;
  produce_morph_weights(*s, a);
  EXPECT_NEAR(a.instances[0].morph_weights[0], 0.5f, 1e-4f) << "released: the clip again";
}

TEST(ViewerMorph, EntriesAreListedPerVertexInTargetOrder) {
  const std::vector<uint8_t> bytes = test::make_valid_file(morph_variant());
  Result<Asset> a = Asset::from_bytes(bytes, "morph.ossa");
  ASSERT_TRUE(a) << a.error().message;
  const MeshView mesh = a->mesh(0);
  const std::vector<int32_t> both{0, 1};
  const MorphEntries e = build_morph_entries(mesh, both);
  ASSERT_EQ(e.entry_count, 5u);  // smile: 4, 5; frown: 2, 3, 4
  EXPECT_EQ(e.texels_per_entry, 2) << "frown has normal deltas";
  EXPECT_EQ(e.ranges, (std::vector<int32_t>{0, 0, 0, 0, 0, 1, 1, 1, 2, 2, 4, 1}));
  ASSERT_EQ(e.texels.size(), 5u * 8u);
  const auto entry = [&](size_t i) {
    const auto first = e.texels.begin() + static_cast<std::ptrdiff_t>(8 * i);
    return std::vector<float>(first, first + 8);
  };
  const auto near = [](const std::vector<float>& got, const std::vector<float>& want) {
    for (size_t k = 0; k < want.size(); ++k) EXPECT_NEAR(got[k], want[k], 1e-6f) << "component " << k;
  };
  near(entry(0), {-0.05f, 0, 0, 1, 0, 0, 0.1f, 0});  // vertex 2: frown, its normal delta
  near(entry(1), {0.05f, 0, 0, 1, 0, 0, -0.1f, 0});  // vertex 3: frown
  near(entry(2), {0, 0.1f, 0, 0, 0, 0, 0, 0});       // vertex 4: smile first (no normal deltas)
  near(entry(3), {0, -0.03f, 0, 1, 0, 0, 0, 0});     // vertex 4: then frown
  near(entry(4), {0, 0.2f, 0, 0, 0, 0, 0, 0});       // vertex 5: smile

  const MorphEntries frown_only = build_morph_entries(mesh, std::vector<int32_t>{-1, 0});
  EXPECT_EQ(frown_only.entry_count, 3u) << "a target bound to no channel is left out";
  EXPECT_TRUE(build_morph_entries(a->mesh(0), std::vector<int32_t>{-1, -1}).empty());
  const std::vector<uint8_t> plain = test::make_valid_file();
  Result<Asset> p = Asset::from_bytes(plain, "plain.ossa");
  ASSERT_TRUE(p);
  EXPECT_TRUE(build_morph_entries(p->mesh(0), {}).empty()) << "no targets, no entries";
}

/// morph_and_skin_cpu at zero weights is skin_cpu; at smile = 1 it is skin_cpu of the same file
/// with smile's deltas baked into its vertices (quantized on their own bounds), in the bind pose
/// and in a bent pose.
void check_cpu_morph(const test::SyntheticSpec& spec, const char* label) {
  SCOPED_TRACE(label);
  const std::vector<uint8_t> bytes = test::make_valid_file(spec);
  Result<Asset> a = Asset::from_bytes(bytes, "morph.ossa");
  ASSERT_TRUE(a) << a.error().message;
  const MeshView mesh = a->mesh(0);
  const size_t n = mesh.vertex_count();
  Result<MorphBase> base = decode_morph_base(mesh);
  ASSERT_TRUE(base) << base.error().message;
  const std::vector<int32_t> channels{0, 1};

  std::vector<glm::mat4> model = bind_model(a->skeleton());
  for (int pose = 0; pose < 2; ++pose) {
    if (pose == 1)  // bend the spine and the head
      for (size_t j = 1; j < model.size(); ++j)
        model[j] = glm::rotate(glm::mat4(1.0f), 0.3f * static_cast<float>(j), glm::vec3(0.3f, 1.0f, 0.2f)) * model[j];
    std::vector<glm::mat4> palette(std::max<size_t>(mesh.joints().size(), 1));
    skinning_matrices(mesh, model, palette);
    std::vector<float> ref_p(3 * n), ref_n(3 * n), got_p(3 * n), got_n(3 * n);
    skin_cpu(mesh, palette, SkinningMethod::Linear, {ref_p, ref_n, {}});
    MorphScratch scratch;
    const std::vector<float> zero{0.0f, 0.0f};
    ASSERT_TRUE(morph_and_skin_cpu(mesh, *base, channels, zero, palette, scratch, {got_p, got_n, {}}));
    for (size_t k = 0; k < 3 * n; ++k) {
      EXPECT_NEAR(got_p[k], ref_p[k], 1e-5f) << "pose " << pose << " position " << k;
      EXPECT_NEAR(got_n[k], ref_n[k], 1e-5f) << "pose " << pose << " normal " << k;
    }
    const std::vector<float> smile{1.0f, 0.0f};
    ASSERT_TRUE(morph_and_skin_cpu(mesh, *base, channels, smile, palette, scratch, {got_p, got_n, {}}));
    test::SyntheticSpec baked_spec = spec;
    baked_spec.meshes[0].morph_targets.clear();
    baked_spec.clips[0].morph_weights.clear();
    for (const auto& [v, dy] : {std::pair<size_t, float>{4, 0.1f}, {5, 0.2f}}) {
      fb::Vec3& p = baked_spec.meshes[0].vertices[v].position;
      p = fb::Vec3(p.x(), p.y() + dy, p.z());
    }
    const std::vector<uint8_t> baked_bytes = test::make_valid_file(baked_spec);
    Result<Asset> baked = Asset::from_bytes(baked_bytes, "baked.ossa");
    ASSERT_TRUE(baked) << baked.error().message;
    std::vector<glm::mat4> baked_palette(palette.size());
    skinning_matrices(baked->mesh(0), model, baked_palette);
    skin_cpu(baked->mesh(0), baked_palette, SkinningMethod::Linear, {ref_p, ref_n, {}});
    for (size_t k = 0; k < 3 * n; ++k) {
      EXPECT_NEAR(got_p[k], ref_p[k], 1e-4f) << "pose " << pose << " morphed position " << k;
      EXPECT_NEAR(got_n[k], ref_n[k], 1e-4f) << "pose " << pose << " morphed normal " << k;
    }
  }
  std::vector<float> small(3);
  MorphScratch scratch;
  EXPECT_FALSE(morph_and_skin_cpu(mesh, *base, channels, std::vector<float>{0, 0}, std::vector<glm::mat4>(4), scratch,
                                  {small, {}, {}}))
      << "positions too small for the mesh";
}

TEST(ViewerMorph, CpuMorphIsSkinCpuPlusTheDeltas) {
  check_cpu_morph(morph_variant(), "quantized");
  test::SyntheticSpec f = morph_variant();
  for (const auto& [name, spec] : test::valid_variants()) {
    if (name != "float32-layout") continue;
    f.meshes[0].layout = spec.meshes[0].layout;
    f.meshes[0].vertex_stride = spec.meshes[0].vertex_stride;
  }
  check_cpu_morph(f, "float32");
}

// ---------------------------------------------------------------------------------------------
// The graph as pose source: Pab's sample graph, cooked from assets/Pab/pab.graph.json by the
// fixture (speed 0..7 over walk 1.07 / jog 3.13 / run 5.02; crossed_arms; strike_pose).

Result<Scene> pab_graph_scene() { return load_scene(std::vector<std::string>{cooked("Pab/pab.ossa").string()}); }

TEST(ViewerGraph, ParametersSetFromText) {
  Result<Scene> scene = pab_graph_scene();
  ASSERT_TRUE(scene) << scene.error().message;
  Result<GraphDriver> g = make_graph_driver(*scene, "pab", 3);
  ASSERT_TRUE(g) << g.error().message;
  ASSERT_EQ(g->instances.size(), 3u);
  const int speed = graph_parameter(*g, "speed"), arms = graph_parameter(*g, "crossed_arms"),
            stop = graph_parameter(*g, "strike_pose");
  ASSERT_GE(speed, 0);
  ASSERT_GE(arms, 0);
  ASSERT_GE(stop, 0);
  EXPECT_TRUE(set_graph_parameter(*g, "speed", "3.5"));
  EXPECT_TRUE(set_graph_parameter(*g, "crossed_arms", "true"));
  EXPECT_TRUE(set_graph_parameter(*g, "strike_pose", ""));
  for (const GraphInstance& i : g->instances) {  // every crowd instance gets the value
    EXPECT_FLOAT_EQ(i.value(speed), 3.5f);
    EXPECT_FLOAT_EQ(i.value(arms), 1.0f);
    EXPECT_FLOAT_EQ(i.value(stop), 1.0f);
  }
  EXPECT_TRUE(set_graph_parameter(*g, "speed", "99"));  // clamped to the parameter's range
  EXPECT_FLOAT_EQ(g->instances[0].value(speed), 7.0f);
  EXPECT_FALSE(set_graph_parameter(*g, "speed", "fast"));
  EXPECT_FALSE(set_graph_parameter(*g, "velocity", "1"));
  // Crowd instances are spread in time: their poses differ.
  update_graph(*g, 0.1f);
  const ConstPoseSpan a = g->instances[0].pose(), b = g->instances[1].pose();
  bool differ = false;
  for (uint32_t k = 0; k < a.stride * kPoseComponents && !differ; ++k) differ = a.base[k] != b.base[k];
  EXPECT_TRUE(differ);
}

TEST(ViewerGraph, UnknownGraphListsTheGraphs) {
  Result<Scene> scene = pab_graph_scene();
  ASSERT_TRUE(scene) << scene.error().message;
  Result<GraphDriver> g = make_graph_driver(*scene, "locomotion", 1);
  ASSERT_FALSE(g);
  EXPECT_NE(g.error().message.find("'pab' (pab.ossa)"), std::string::npos) << g.error().message;
}

TEST(ViewerGraph, KeysDriveThePabSampleParameters) {
  Result<Scene> scene = pab_graph_scene();
  ASSERT_TRUE(scene) << scene.error().message;
  Result<GraphDriver> g = make_graph_driver(*scene, "pab", 1);
  ASSERT_TRUE(g) << g.error().message;
  const int speed = graph_parameter(*g, "speed"), arms = graph_parameter(*g, "crossed_arms");
  const KeySpeeds speeds = key_speeds(*g);
  EXPECT_FLOAT_EQ(speeds.walk, 1.07f) << "the walk sample of the blend space on speed";
  EXPECT_FLOAT_EQ(speeds.run, 5.02f) << "its run sample";
  GraphKeys keys;
  set_graph_value(*g, speed, 0.0f);
  drive_graph_keys(*g, keys, 1.0f);
  EXPECT_FLOAT_EQ(g->instances[0].value(speed), 0.0f) << "keys own speed only once W was pressed";

  EXPECT_TRUE(graph_key(*g, keys, GLFW_KEY_W, GLFW_PRESS));
  drive_graph_keys(*g, keys, 0.2f);
  EXPECT_NEAR(g->instances[0].value(speed), 0.6f, 1e-5f) << "eased at 3 units/s";
  drive_graph_keys(*g, keys, 1.0f);
  EXPECT_FLOAT_EQ(g->instances[0].value(speed), 1.07f) << "W: the walk sample";
  EXPECT_TRUE(graph_key(*g, keys, GLFW_KEY_LEFT_SHIFT, GLFW_PRESS));
  drive_graph_keys(*g, keys, 2.0f);
  EXPECT_FLOAT_EQ(g->instances[0].value(speed), 5.02f) << "Shift+W: the run sample";

  EXPECT_TRUE(graph_key(*g, keys, GLFW_KEY_W, GLFW_RELEASE));
  drive_graph_keys(*g, keys, 1.0f);
  EXPECT_NEAR(g->instances[0].value(speed), 2.02f, 1e-4f) << "releasing W eases speed down";
  drive_graph_keys(*g, keys, 1.0f);
  EXPECT_FLOAT_EQ(g->instances[0].value(speed), 0.0f);
  // Below 0.05 the sample graph strikes its pose.
  update_graph(*g, 0.1f);
  const MachineStatus st = g->instances[0].machine_status(0);
  EXPECT_EQ(g->definition->state_name(0, static_cast<size_t>(st.current)), "pose");

  EXPECT_TRUE(graph_key(*g, keys, GLFW_KEY_C, GLFW_PRESS));
  EXPECT_FLOAT_EQ(g->instances[0].value(arms), 1.0f);
  EXPECT_TRUE(graph_key(*g, keys, GLFW_KEY_C, GLFW_PRESS));
  EXPECT_FLOAT_EQ(g->instances[0].value(arms), 0.0f);
  EXPECT_FALSE(graph_key(*g, keys, GLFW_KEY_X, GLFW_PRESS));
}

}  // namespace
