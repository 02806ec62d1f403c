// viewer_test_cli.cpp — ossa-view's failures and command line end to end: refused files exit
// non-zero naming the file, a skeleton-only or vertex-coloured file draws as it should, a prop is
// framed whole, usage errors exit 2, -q / -v, hostile textures are left out by name in bounded
// time. Split from viewer_test.cpp by subject; helpers in viewer_test_common.h.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include <ossa/loader/asset.h>

#include "test_files.h"
#include "viewer_test_common.h"

namespace fs = std::filesystem;
using namespace ossa::test;

namespace {

// ---------------------------------------------------------------------------------------------
// Failures: non-zero exit, and a message naming the file.

TEST_F(Viewer, CorruptFileIsRefusedByName) {
  const fs::path bad = dir_ / "garbage.ossa";
  ASSERT_TRUE(write_file(bad, std::string(4096, 'x')));
  const CommandResult r = run_viewer(quote(bad.string()) + " --screenshot " + quote((dir_ / "x.png").string()));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find(bad.string()), std::string::npos) << r.err;
  EXPECT_FALSE(fs::exists(dir_ / "x.png"));
}

TEST_F(Viewer, TruncatedFileIsRefusedByName) {
  const auto bytes = read_file(cooked("Fox/Fox.ossa"));
  ASSERT_TRUE(bytes.has_value());
  const fs::path bad = dir_ / "truncated.ossa";
  ASSERT_TRUE(write_file(bad, std::span<const uint8_t>(bytes->data(), bytes->size() / 2)));
  const CommandResult r = run_viewer(quote(bad.string()) + " --screenshot " + quote((dir_ / "x.png").string()));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find(bad.string()), std::string::npos) << r.err;
}

/// A source model given where a cooked file is expected: the message names it and says how to cook
/// it (ossa-cook, or --cook-and-open in the window).
TEST_F(Viewer, SourceModelGivenSaysHowToCookIt) {
  for (const char* name : {"Fox/Fox.glb", "Pab/walk.fbx"}) {
    const fs::path source = ossa::test::source_dir() / "assets" / name;
    const CommandResult r = run_viewer(quote(source.string()) + " --screenshot " + quote((dir_ / "x.png").string()));
    EXPECT_EQ(r.exit_code, 1) << name;
    EXPECT_NE(r.err.find(source.string()), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("ossa-cook '" + source.string() + "' -o cooked"), std::string::npos) << r.err;
    EXPECT_NE(r.err.find("--cook-and-open"), std::string::npos) << r.err;
    EXPECT_FALSE(fs::exists(dir_ / "x.png"));
  }
  // A corrupt .ossa is not taken for a source.
  const fs::path bad = dir_ / "garbage.ossa";
  ASSERT_TRUE(write_file(bad, std::string(4096, 'x')));
  EXPECT_EQ(run_viewer(quote(bad.string()) + " --frames 1").err.find("ossa-cook"), std::string::npos);
}

TEST_F(Viewer, MissingFileIsNamed) {
  const fs::path missing = dir_ / "no-such-file.ossa";
  const CommandResult r = run_viewer(quote(missing.string()) + " --frames 1");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find(missing.string()), std::string::npos) << r.err;
}

TEST_F(Viewer, ClipOnlyFileAloneHasNoMesh) {
  const CommandResult r = run_viewer(quote(cooked("Pab/walk.ossa").string()) + " --frames 1");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("walk.ossa"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("no mesh"), std::string::npos) << r.err;
}

// A file with a skeleton and no mesh (mocap) is shown as its bones, with its clip playing.
TEST_F(Viewer, SkeletonOnlyFileIsShownAsBones) {
  const std::string bvh =
      "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation "
      "Yrotation\n  JOINT Spine\n  {\n    OFFSET 0 0.5 0\n    CHANNELS 3 Zrotation Xrotation Yrotation\n    JOINT "
      "Head\n"
      "    {\n      OFFSET 0 0.5 0\n      CHANNELS 3 Zrotation Xrotation Yrotation\n      End Site\n      {\n"
      "        OFFSET 0 0.2 0\n      }\n    }\n  }\n}\nMOTION\nFrames: 3\nFrame Time: 0.5\n"
      "0 1 0 0 0 0 0 0 0 0 0 0\n0 1 0 0 0 0 40 0 0 0 0 0\n0 1 0 0 0 0 80 0 0 0 0 0\n";
  ASSERT_TRUE(ossa::test::write_file(dir_ / "mocap.bvh", bvh));
  const CommandResult cooked_bvh =
      ossa::test::run_command(quote((ossa::test::bin_dir() / "ossa-cook").string()) + " " +
                              quote((dir_ / "mocap.bvh").string()) + " -o " + quote(dir_.string()) + " -q");
  ASSERT_EQ(cooked_bvh.exit_code, 0) << cooked_bvh.err;
  const std::string base = quote((dir_ / "mocap.ossa").string()) + " --size 192x192 --no-grid";
  const CommandResult start = run_viewer(base + " --time 0 --screenshot " + quote((dir_ / "bones0.png").string()));
  const CommandResult bent = run_viewer(base + " --time 0.5 --screenshot " + quote((dir_ / "bones1.png").string()));
  ASSERT_EQ(start.exit_code + bent.exit_code, 0) << start.err << bent.err;
  const Image a = load_png(dir_ / "bones0.png"), b = load_png(dir_ / "bones1.png");
  EXPECT_GT(coverage(a), 0.002) << "bones drawn";
  EXPECT_LT(coverage(a), 0.3);
  EXPECT_GT(compare(a, b, kPixelThreshold).differing, 0.001) << "the clip bends the spine between t = 0 and t = 0.5";
}

// A model coloured only by its vertex colours (no texture, a grey default material) is drawn in
// those colours: the left half of the quad red, the right half blue.
TEST_F(Viewer, VertexColoursTintTheSurface) {
  ASSERT_TRUE(ossa::test::write_file(
      dir_ / "painted.obj",
      std::string("v -1 0 0 1 0 0\nv 0 0 0 1 0 0\nv 0 2 0 1 0 0\nv -1 2 0 1 0 0\n"
                  "v 0 0 0 0 0 1\nv 1 0 0 0 0 1\nv 1 2 0 0 0 1\nv 0 2 0 0 0 1\n"
                  "vn 0 0 1\nf 1//1 2//1 3//1\nf 1//1 3//1 4//1\nf 5//1 6//1 7//1\nf 5//1 7//1 8//1\n")));
  const CommandResult cooked_obj =
      ossa::test::run_command(quote((ossa::test::bin_dir() / "ossa-cook").string()) + " " +
                              quote((dir_ / "painted.obj").string()) + " -o " + quote(dir_.string()) + " -q");
  ASSERT_EQ(cooked_obj.exit_code, 0) << cooked_obj.err;
  const CommandResult r =
      run_viewer(quote((dir_ / "painted.ossa").string()) + " --size 128x128 --no-grid --yaw 0 --pitch 0 " +
                 "--screenshot " + quote((dir_ / "painted.png").string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Image img = load_png(dir_ / "painted.png");
  ASSERT_FALSE(img.empty());
  // Mean colour of the left and right thirds' non-background pixels.
  const uint8_t* bg = img.at(0, 0);
  glm::dvec3 left(0.0), right(0.0);
  double nl = 0, nr = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const uint8_t* p = img.at(x, y);
      if (std::abs(p[0] - bg[0]) + std::abs(p[1] - bg[1]) + std::abs(p[2] - bg[2]) < 30) continue;
      const glm::dvec3 c(p[0], p[1], p[2]);
      if (x < img.width / 3) {
        left += c;
        ++nl;
      }
      if (x >= 2 * img.width / 3) {
        right += c;
        ++nr;
      }
    }
  ASSERT_GT(nl, 20.0);
  ASSERT_GT(nr, 20.0);
  left /= nl;
  right /= nr;
  EXPECT_GT(left.r, 3.0 * std::max(left.g, left.b) + 10.0) << "red half: " << left.r << " " << left.g << " " << left.b;
  EXPECT_GT(right.b, 3.0 * std::max(right.r, right.g) + 10.0)
      << "blue half: " << right.r << " " << right.g << " " << right.b;
}

// A prop far larger than its rig (a 4 m plank held by a 0.2 m two-joint rig) is framed whole:
// the camera frames the skinned vertices, not the joints plus a margin, so no edge of the plank
// touches the image border.
TEST_F(Viewer, APropLargerThanItsSkeletonIsFramedWhole) {
  const std::string dae = R"(<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
  <asset><unit name="meter" meter="1"/><up_axis>Y_UP</up_axis></asset>
  <library_geometries>
    <geometry id="plank-mesh" name="plank">
      <mesh>
        <source id="plank-pos">
          <float_array id="plank-pos-array" count="12">-2 0.95 0  2 0.95 0  2 1.45 0  -2 1.45 0</float_array>
          <technique_common><accessor source="#plank-pos-array" count="4" stride="3">
            <param name="X" type="float"/><param name="Y" type="float"/><param name="Z" type="float"/></accessor>
              </technique_common>
        </source>
        <vertices id="plank-verts"><input semantic="POSITION" source="#plank-pos"/></vertices>
        <triangles count="2"><input semantic="VERTEX" source="#plank-verts" offset="0"/><p>0 1 2 0 2 3</p></triangles>
      </mesh>
    </geometry>
  </library_geometries>
  <library_controllers>
    <controller id="plank-skin">
      <skin source="#plank-mesh">
        <bind_shape_matrix>1 0 0 0 0 1 0 0 0 0 1 0 0 0 0 1</bind_shape_matrix>
        <source id="plank-joints"><Name_array id="plank-joints-array" count="2">Hips Hand</Name_array>
          <technique_common><accessor source="#plank-joints-array" count="2" stride="1">
            <param name="JOINT" type="name"/></accessor></technique_common></source>
        <source id="plank-ibm">
          <float_array id="plank-ibm-array" count="32">1 0 0 0 0 1 0 -1 0 0 1 0 0 0 0 1  1 0 0 0 0 1 0 -1.2 0 0 1 0 0
            0 0 1</float_array>
          <technique_common><accessor source="#plank-ibm-array" count="2" stride="16">
            <param name="TRANSFORM" type="float4x4"/></accessor></technique_common></source>
        <source id="plank-weights"><float_array id="plank-weights-array" count="1">1</float_array>
          <technique_common><accessor source="#plank-weights-array" count="1" stride="1">
            <param name="WEIGHT" type="float"/></accessor></technique_common></source>
        <joints><input semantic="JOINT" source="#plank-joints"/>
          <input semantic="INV_BIND_MATRIX" source="#plank-ibm"/></joints>
        <vertex_weights count="4">
          <input semantic="JOINT" source="#plank-joints" offset="0"/>
            <input semantic="WEIGHT" source="#plank-weights" offset="1"/>
          <vcount>1 1 1 1</vcount>
          <v>1 0 1 0 1 0 1 0</v>
        </vertex_weights>
      </skin>
    </controller>
  </library_controllers>
  <library_visual_scenes>
    <visual_scene id="Scene" name="Scene">
      <node id="Hips" name="Hips" sid="Hips" type="JOINT">
        <matrix sid="transform">1 0 0 0 0 1 0 1 0 0 1 0 0 0 0 1</matrix>
        <node id="Hand" name="Hand" sid="Hand" type="JOINT">
          <matrix sid="transform">1 0 0 0 0 1 0 0.2 0 0 1 0 0 0 0 1</matrix>
        </node>
      </node>
      <node id="plank" name="plank">
        <instance_controller url="#plank-skin"><skeleton>#Hips</skeleton></instance_controller>
      </node>
    </visual_scene>
  </library_visual_scenes>
  <scene><instance_visual_scene url="#Scene"/></scene>
</COLLADA>
)";
  ASSERT_TRUE(ossa::test::write_file(dir_ / "plank.dae", dae));
  const CommandResult cooked_dae =
      ossa::test::run_command(quote((ossa::test::bin_dir() / "ossa-cook").string()) + " " +
                              quote((dir_ / "plank.dae").string()) + " -o " + quote(dir_.string()) + " -q");
  ASSERT_EQ(cooked_dae.exit_code, 0) << cooked_dae.err;
  auto plank = ossa::Asset::open((dir_ / "plank.ossa").string());
  ASSERT_TRUE(plank.ok()) << plank.error().message;
  ASSERT_EQ(plank->skeleton().joint_count(), 2u) << "the plank is skinned to a rig, not baked";
  const CommandResult r =
      run_viewer(quote((dir_ / "plank.ossa").string()) + " --size 160x120 --no-grid --yaw 0 --pitch 0 " +
                 "--screenshot " + quote((dir_ / "plank.png").string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Image img = load_png(dir_ / "plank.png");
  ASSERT_FALSE(img.empty());
  const uint8_t* bg = img.at(0, 0);
  const auto foreground = [&](int x, int y) {
    const uint8_t* p = img.at(x, y);
    return std::abs(p[0] - bg[0]) + std::abs(p[1] - bg[1]) + std::abs(p[2] - bg[2]) > 18;
  };
  int left = img.width, right = -1;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x)
      if (foreground(x, y)) {
        left = std::min(left, x);
        right = std::max(right, x);
      }
  ASSERT_GE(right, 0) << "the plank is drawn";
  EXPECT_GT(left, 0) << "the plank's left end is cut off";
  EXPECT_LT(right, img.width - 1) << "the plank's right end is cut off";
  EXPECT_GT(right - left, img.width / 2) << "and it is framed, not lost in the distance";
}

TEST_F(Viewer, ClipOfAnotherSkeletonIsRefused) {
  const CommandResult r = run_viewer(quote(cooked("Fox/Fox.ossa").string()) + " " +
                                     quote(cooked("Pab/walk.ossa").string()) + " --frames 1");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("walk.ossa"), std::string::npos) << r.err;
}

TEST_F(Viewer, UnknownClipNameListsTheClips) {
  const CommandResult r = run_viewer(quote(cooked("Fox/Fox.ossa").string()) + " --clip Gallop --frames 1");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("Gallop"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("'Survey', 'Walk', 'Run'"), std::string::npos) << r.err;
}

TEST_F(Viewer, UnwritableScreenshotIsNamed) {
  const fs::path out = dir_ / "missing-dir" / "out.png";
  const CommandResult r =
      run_viewer(quote(cooked("Fox/Fox.ossa").string()) + " --size 64x64 --screenshot " + quote(out.string()));
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find(out.string()), std::string::npos) << r.err;
}

TEST_F(Viewer, BadSizeIsAUsageError) {
  const CommandResult r = run_viewer(quote(cooked("Fox/Fox.ossa").string()) + " --size 640by480 --frames 1");
  EXPECT_EQ(r.exit_code, 2);
  EXPECT_NE(r.err.find("--size"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("run 'ossa-view --help'"), std::string::npos) << r.err;
}

// -q / -v (tools/cli/cli.h) on a rendered scene. The synthetic file's normal map is a path
// that does not exist, so a plain run warns that it was left out.
TEST_F(Viewer, QuietHidesWarningsVerboseNamesTheContext) {
  const fs::path file = dir_ / "synthetic.ossa";
  ASSERT_TRUE(write_file(file, make_valid_file()));
  const std::string args = quote(file.string()) + " --size 64x64 --frames 1";

  const CommandResult normal = run_viewer(args);
  ASSERT_EQ(normal.exit_code, 0) << normal.err;
  EXPECT_NE(normal.err.find("warning: "), std::string::npos) << normal.err;
  EXPECT_NE(normal.err.find("left out"), std::string::npos) << normal.err;

  const CommandResult quiet = run_viewer(args + " -q");
  ASSERT_EQ(quiet.exit_code, 0) << quiet.err;
  EXPECT_TRUE(quiet.err.empty()) << quiet.err;
  EXPECT_TRUE(quiet.out.empty()) << quiet.out;

  const CommandResult verbose = run_viewer(args + " --verbose");
  ASSERT_EQ(verbose.exit_code, 0) << verbose.err;
  EXPECT_NE(verbose.err.find("OpenGL "), std::string::npos) << verbose.err;
  EXPECT_NE(verbose.err.find("4 joints, 1 meshes"), std::string::npos) << verbose.err;
  EXPECT_NE(verbose.err.find("left out"), std::string::npos) << "-v keeps the warnings: " << verbose.err;
}

// The viewer trusts the loader, so whatever a loadable file names must be safe to show: texture
// paths that leave the file's folder, a directory, a FIFO or /dev/zero as a texture, and an
// embedded PNG claiming 16384 x 16384 pixels are each left out with a warning naming why, in
// bounded time and memory; --time beyond an hour is a usage error rather than a long hang.
TEST_F(Viewer, HostileTexturesAreLeftOutByName) {
  ASSERT_EQ(::mkfifo((dir_ / "pipe.png").c_str(), 0644), 0);
  fs::create_directories(dir_ / "folder.png");
  const auto png = tiny_png();
  std::vector<uint8_t> bomb(png.begin(), png.end());
  for (int k = 0; k < 2; ++k) {  // IHDR width and height -> 16384
    bomb.at(16 + 4 * k) = 0;     // at(): GCC 12 -O3 warns of a write past an empty vector with []
    bomb.at(17 + 4 * k) = 0;
    bomb.at(18 + 4 * k) = 0x40;
    bomb.at(19 + 4 * k) = 0;
  }
  SyntheticSpec spec;
  spec.materials[0].textures = {{ossa::fb::TextureRole::Diffuse, "", "image/png", bomb},
                                {ossa::fb::TextureRole::Normal, "../../../../../../etc/passwd", "", std::nullopt},
                                {ossa::fb::TextureRole::Specular, "pipe.png", "", std::nullopt}};
  SyntheticMaterial second;
  second.textures = {{ossa::fb::TextureRole::Diffuse, "/dev/zero", "", std::nullopt},
                     {ossa::fb::TextureRole::Normal, "folder.png", "", std::nullopt}};
  spec.materials.push_back(second);
  const fs::path file = dir_ / "hostile.ossa";
  ASSERT_TRUE(write_file(file, make_valid_file(spec)));
  // A FIFO opened for reading would wait for a writer forever, and /dev/zero never ends: the run
  // is bounded (a hang fails as exit 124, not as a stalled suite) and each is named as left out.
  const CommandResult r = run_viewer("--size 64x64 --frames 1 " + quote(file.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("over the viewer's limit of 16384 per side and 67108864 pixels"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("passwd left out: it lies outside the file's folder"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("pipe.png left out: it is not a regular file"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("/dev/zero left out: a texture path must be relative to the file"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("folder.png left out: it is not a regular file"), std::string::npos) << r.err;

  const CommandResult forever = run_viewer(quote(cooked("Fox/Fox.ossa").string()) + " --time inf --frames 1");
  EXPECT_EQ(forever.exit_code, 2);
  EXPECT_NE(forever.err.find("--time: expected a finite number of seconds"), std::string::npos) << forever.err;
  const CommandResult long_one = run_viewer(quote(cooked("Fox/Fox.ossa").string()) + " --time 1e9 --frames 1");
  EXPECT_EQ(long_one.exit_code, 2) << long_one.err;
}

}  // namespace
