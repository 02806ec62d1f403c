// viewer_test_framing.cpp — where ossa-view puts its camera: facing the character's front
// (bounds.h facing_of, issue 28: AnimeBoy opened showing its back) and framing what the clip does
// over its whole length, not only its first frame (issue 28: the Flamingo's wings left the image).
//
// The characters are generated as sources and cooked by the real ossa-cook: an OBJ figure whose
// feet point one way and whose face is painted red (its back of the head blue) by vertex colours,
// turned to face +Z, -Z or +X; and BVH skeletons whose clip reaches out late. The real characters
// (Pab from the viewer fixture; AnimeBoy and the Quaternius Cowboy from ../shared/assets, cooked
// here when present) are checked for the front the viewer reports (-v).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include "test_files.h"
#include "viewer_test_common.h"

namespace fs = std::filesystem;
using namespace ossa::test;

namespace {

/// An OBJ made of boxes with a colour per face (OBJ's "v x y z r g b"), every point turned
/// about +Y by `turn` quarter turns (a rotation, so faces keep their winding).
class ObjFigure {
 public:
  explicit ObjFigure(int turn) : turn_(turn) {}
  /// A box from lo to hi; its +Z face `front`, its -Z face `back`, the others `side`.
  void box(glm::vec3 lo, glm::vec3 hi, glm::vec3 side, glm::vec3 front, glm::vec3 back) {
    const glm::vec3 c[8] = {{lo.x, lo.y, lo.z}, {hi.x, lo.y, lo.z}, {hi.x, hi.y, lo.z}, {lo.x, hi.y, lo.z},
                            {lo.x, lo.y, hi.z}, {hi.x, lo.y, hi.z}, {hi.x, hi.y, hi.z}, {lo.x, hi.y, hi.z}};
    quad(c[4], c[5], c[6], c[7], front);  // +Z, counter-clockwise seen from outside
    quad(c[1], c[0], c[3], c[2], back);   // -Z
    quad(c[5], c[1], c[2], c[6], side);   // +X
    quad(c[0], c[4], c[7], c[3], side);   // -X
    quad(c[7], c[6], c[2], c[3], side);   // +Y
    quad(c[0], c[1], c[5], c[4], side);   // -Y
  }
  std::string text() const { return text_; }

 private:
  glm::vec3 turned(glm::vec3 p) const {
    for (int i = 0; i < ((turn_ % 4) + 4) % 4; ++i) p = glm::vec3(p.z, p.y, -p.x);  // +Z -> +X
    return p;
  }
  void quad(glm::vec3 a, glm::vec3 b, glm::vec3 c, glm::vec3 d, glm::vec3 colour) {
    char line[160];
    for (const glm::vec3& p : {a, b, c, d}) {
      const glm::vec3 q = turned(p);
      std::snprintf(line, sizeof line, "v %g %g %g %g %g %g\n", q.x, q.y, q.z, colour.r, colour.g, colour.b);
      text_ += line;
    }
    std::snprintf(line, sizeof line, "f %d %d %d\nf %d %d %d\n", n_ + 1, n_ + 2, n_ + 3, n_ + 1, n_ + 3, n_ + 4);
    text_ += line;
    n_ += 4;
  }
  int turn_;
  int n_ = 0;
  std::string text_;
};

/// A 1.8 m figure facing +Z turned by `turn` quarter turns: legs, feet reaching 0.2 m forward
/// and 0.05 m back, a body, and a head whose face is red and whose back is blue.
std::string figure(int turn) {
  ObjFigure f(turn);
  const glm::vec3 grey(0.6f), red(1.0f, 0.0f, 0.0f), blue(0.0f, 0.0f, 1.0f);
  for (const float x : {-0.15f, 0.05f}) {
    f.box({x, 0.0f, -0.05f}, {x + 0.1f, 0.08f, 0.2f}, grey, grey, grey);  // a foot
    for (int k = 0; k < 8; ++k)  // a leg, in segments: vertices all the way up, as a real mesh has
      f.box({x, 0.08f + 0.1f * static_cast<float>(k), -0.05f}, {x + 0.1f, 0.18f + 0.1f * static_cast<float>(k), 0.05f},
            grey, grey, grey);
  }
  f.box({-0.2f, 0.9f, -0.1f}, {0.2f, 1.5f, 0.1f}, grey, grey, grey);      // the body
  f.box({-0.12f, 1.52f, -0.12f}, {0.12f, 1.8f, 0.12f}, grey, red, blue);  // the head
  return f.text();
}

CommandResult cook(const fs::path& source, const fs::path& out, const std::string& extra = "") {
  return run_command(quote((bin_dir() / "ossa-cook").string()) + " " + quote(source.string()) + " -o " +
                     quote(out.string()) + " -q " + extra);
}

/// The axis ossa-view -v says the character faces ("front: -z (...)").
std::string reported_front(const std::string& err) {
  const size_t at = err.find("front: ");
  return at == std::string::npos ? std::string("(none)") : err.substr(at + 7, 2);
}

struct Colours {
  int red = 0, blue = 0;
};
Colours red_and_blue(const Image& img) {
  Colours c;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const uint8_t* p = img.at(x, y);
      c.red += p[0] > 120 && p[1] < 60 && p[2] < 60 ? 1 : 0;
      c.blue += p[2] > 120 && p[0] < 60 && p[1] < 60 ? 1 : 0;
    }
  return c;
}

}  // namespace

// The same figure facing +Z, -Z and +X: the viewer finds each front from the feet, and with
// --yaw 0 the camera looks at the red face, not the blue back of the head. With --front naming
// the wrong axis the back is what is seen, so the check can tell.
TEST_F(Viewer, DefaultViewFacesTheCharactersFront) {
  const struct {
    int turn;
    const char* front;
  } cases[] = {{0, "+z"}, {2, "-z"}, {1, "+x"}};
  for (const auto& c : cases) {
    const std::string stem = std::string("figure") + std::to_string(c.turn);
    ASSERT_TRUE(write_file(dir_ / (stem + ".obj"), figure(c.turn)));
    const CommandResult cooked = cook(dir_ / (stem + ".obj"), dir_);
    ASSERT_EQ(cooked.exit_code, 0) << cooked.err;
    const std::string base =
        quote((dir_ / (stem + ".ossa")).string()) + " --size 160x240 --no-grid --yaw 0 --pitch 0 -v";
    const fs::path png = dir_ / (stem + ".png");
    const CommandResult r = run_viewer(base + " --screenshot " + quote(png.string()));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(reported_front(r.err), c.front) << r.err;
    const Colours seen = red_and_blue(load_png(png));
    EXPECT_GT(seen.red, 100) << stem << ": the face is not in view";
    EXPECT_EQ(seen.blue, 0) << stem << ": the back of the head is in view";
    const std::string wrong = std::string(c.front[0] == '+' ? "-" : "+") + c.front[1];  // the back
    const fs::path back_png = dir_ / (stem + "-back.png");
    const CommandResult back = run_viewer(base + " --front " + wrong + " --screenshot " + quote(back_png.string()));
    ASSERT_EQ(back.exit_code, 0) << back.err;
    EXPECT_GT(red_and_blue(load_png(back_png)).blue, 100) << stem << " --front " << wrong;
  }
}

// The real characters: Pab (the fixture's cook of assets/Pab) faces +Z; AnimeBoy faces -Z (it
// opened showing its back); the Quaternius Cowboy's FBX faces +X.
TEST_F(Viewer, RealCharactersFaceTheCamera) {
  const CommandResult pab = run_viewer(quote(cooked("Pab/pab.ossa").string()) + " --size 64x64 -v --screenshot " +
                                       quote((dir_ / "pab.png").string()));
  ASSERT_EQ(pab.exit_code, 0) << pab.err;
  EXPECT_EQ(reported_front(pab.err), "+z") << pab.err;
  const struct {
    const char* source;
    const char* cooked;
    const char* front;
  } shared[] = {{"AnimeBoy/scene.gltf", "AnimeBoy/scene.ossa", "-z"},
                {"Quaternius_Cowboy/Cowboy.fbx", "Quaternius_Cowboy/Cowboy.ossa", "+x"}};
  for (const auto& s : shared) {
    const fs::path source = shared_assets() / s.source;
    if (!fs::exists(source)) {
      std::printf("skipped %s: not in the shared assets\n", s.source);
      continue;
    }
    const CommandResult c = cook(source, dir_, "--root " + quote(shared_assets().string()));
    ASSERT_EQ(c.exit_code, 0) << c.err;
    const CommandResult r = run_viewer(quote((dir_ / s.cooked).string()) + " --size 64x64 -v --screenshot " +
                                       quote((dir_ / "shared.png").string()));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    EXPECT_EQ(reported_front(r.err), s.front) << s.source << "\n" << r.err;
  }
}

namespace {

/// A BVH figure (hips 1 m up, spine, head, one arm, one leg) whose arm hangs down for the first
/// 0.85 s of a 1 s clip and then points straight up, reaching 0.9 m above the head: the clip's
/// extent grows late.
std::string late_reach_bvh() {
  std::string bvh =
      "HIERARCHY\nROOT Hips\n{\n  OFFSET 0 0 0\n  CHANNELS 6 Xposition Yposition Zposition Zrotation Xrotation "
      "Yrotation\n"
      "  JOINT Spine\n  {\n    OFFSET 0 0.5 0\n    CHANNELS 3 Zrotation Xrotation Yrotation\n"
      "    JOINT Head\n    {\n      OFFSET 0 0.5 0\n      CHANNELS 3 Zrotation Xrotation Yrotation\n"
      "      End Site\n      {\n        OFFSET 0 0.2 0\n      }\n    }\n"
      "    JOINT Arm\n    {\n      OFFSET 0.2 0.4 0\n      CHANNELS 3 Zrotation Xrotation Yrotation\n"
      "      JOINT Hand\n      {\n        OFFSET 0 -1.0 0\n        CHANNELS 3 Zrotation Xrotation Yrotation\n"
      "        End Site\n        {\n          OFFSET 0 -0.1 0\n        }\n      }\n    }\n  }\n"
      "  JOINT Leg\n  {\n    OFFSET 0.1 0 0\n    CHANNELS 3 Zrotation Xrotation Yrotation\n"
      "    End Site\n    {\n      OFFSET 0 -1.0 0\n    }\n  }\n}\n"
      "MOTION\nFrames: 21\nFrame Time: 0.05\n";
  for (int f = 0; f <= 20; ++f) {
    const int arm = f >= 18 ? 180 : 0;  // Z rotation of the arm: hanging, then up
    bvh += "0 1 0 0 0 0  0 0 0  0 0 0  " + std::to_string(arm) + " 0 0  0 0 0  0 0 0\n";
  }
  return bvh;
}

struct Framed {
  glm::vec3 min{0.0f}, max{0.0f};
  bool found = false;
};
/// ossa-view --stats's "framed (x y z) .. (x y z)" line.
Framed parse_framed(const std::string& out) {
  Framed f;
  const size_t at = out.find("framed (");
  if (at == std::string::npos) return f;
  f.found = std::sscanf(out.c_str() + at, "framed (%f %f %f) .. (%f %f %f)", &f.min.x, &f.min.y, &f.min.z, &f.max.x,
                        &f.max.y, &f.max.z) == 6;
  return f;
}

/// Pixels on the image's outermost two rows and columns that differ from its corner's colour.
int border_foreground(const Image& img) {
  int n = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      if (x >= 2 && y >= 2 && x < img.width - 2 && y < img.height - 2) continue;
      n += foreground(img, x, y) ? 1 : 0;
    }
  return n;
}

}  // namespace

// The camera frames the clip's whole motion (bounds.h, app.h frame_camera): a BVH whose arm
// reaches up only in its last 0.15 s is framed alike at t = 0 and at t = 0.95, the frame box
// reaching over the raised hand, and the raised arm stays inside the image.
TEST_F(Viewer, FramingCoversTheWholeClip) {
  ASSERT_TRUE(write_file(dir_ / "reach.bvh", late_reach_bvh()));
  const CommandResult c = cook(dir_ / "reach.bvh", dir_);
  ASSERT_EQ(c.exit_code, 0) << c.err;
  const std::string base =
      quote((dir_ / "reach.ossa").string()) + " --size 200x200 --no-grid --yaw 0 --pitch 0 --stats";
  const CommandResult early = run_viewer(base + " --time 0 --screenshot " + quote((dir_ / "early.png").string()));
  const CommandResult late = run_viewer(base + " --time 0.95 --screenshot " + quote((dir_ / "late.png").string()));
  ASSERT_EQ(early.exit_code + late.exit_code, 0) << early.err << late.err;
  const Framed a = parse_framed(early.out), b = parse_framed(late.out);
  ASSERT_TRUE(a.found && b.found) << early.out << late.out;
  const float size = glm::length(b.max - b.min);
  EXPECT_LT(glm::length(a.min - b.min) + glm::length(a.max - b.max), 0.01f * size)
      << "t = 0 framed (" << a.min.y << " .. " << a.max.y << "), t = 0.95 (" << b.min.y << " .. " << b.max.y << ")";
  // The raised hand is 0.9 (in the file's units) above the head joint, which is 2 above the ground.
  EXPECT_GT(a.max.y - a.min.y, 1.4f * 2.0f) << "t = 0's framing leaves out the raised arm";
  EXPECT_EQ(border_foreground(load_png(dir_ / "late.png")), 0) << "the raised arm touches the image's edge";
}

// The CMU capture in ../shared/assets (when present) walks and then rises by a third of its height
// late in the clip; framed on the first frame, the window (which follows the root only over the
// ground) showed it leaving through the top edge (issue 28). The framing's heights are the same
// whatever time is shown (the horizontal centre follows the root) and each image keeps the
// skeleton off the edges.
TEST_F(Viewer, CapturedClipIsFramedOverItsWholeLength) {
  const fs::path source = shared_assets() / "CMU_BVH" / "01_03.bvh";
  if (!fs::exists(source)) GTEST_SKIP() << "not in the shared assets: " << source;
  const CommandResult c = cook(source, dir_, "--root " + quote(shared_assets().string()));
  ASSERT_EQ(c.exit_code, 0) << c.err;
  std::vector<Framed> framed;
  for (const char* t : {"0", "2", "5"}) {
    const fs::path png = dir_ / (std::string("cmu-") + t + ".png");
    const CommandResult r =
        run_viewer(quote((dir_ / "CMU_BVH" / "01_03.ossa").string()) + " --no-grid --size 320x180 --stats --time " + t +
                   " --screenshot " + quote(png.string()));
    ASSERT_EQ(r.exit_code, 0) << r.err;
    framed.push_back(parse_framed(r.out));
    ASSERT_TRUE(framed.back().found) << r.out;
    EXPECT_EQ(border_foreground(load_png(png)), 0) << "t = " << t << ": the skeleton touches the image's edge";
  }
  const float height = framed.front().max.y - framed.front().min.y;
  for (const Framed& f : framed) {
    EXPECT_NEAR(f.min.y, framed.front().min.y, 0.01f * height);
    EXPECT_NEAR(f.max.y, framed.front().max.y, 0.01f * height) << "framed on the shown frame, not the whole clip";
  }
}
