// viewer_test_retarget.cpp — ossa-view's retarget mode (viewer/retarget_view.h): Pab's walk,
// cooked for Pab, played on CesiumMan (mapped by its map file) with Pab drawn beside it and the
// joint mapping drawn between them, headless and in the window; and its mistakes named.
//
// Every check reads the images the viewer wrote when it exited (the window after its three frames,
// which --window-frames counts once the files are open): what is drawn, never how fast.
#include "viewer_test_common.h"

#include <algorithm>
#include <cstdlib>
#include <utility>

#include <string>
#include <vector>

namespace ossa::test {
namespace {

namespace fs = std::filesystem;

/// Pixels of the mapping's colours: left bones cyan (0.2, 0.85, 1), right bones magenta (1, 0.3, 0.85).
int mapping_pixels(const Image& img) {
  int n = 0;
  for (int y = 0; y < img.height; ++y)
    for (int x = 0; x < img.width; ++x) {
      const uint8_t* p = img.at(x, y);
      const bool cyan = p[0] < 110 && p[1] > 170 && p[2] > 210;
      const bool magenta = p[0] > 210 && p[1] < 120 && p[2] > 170;
      n += cyan || magenta ? 1 : 0;
    }
  return n;
}

/// The horizontal runs of columns holding foreground, as [first, last] pairs.
std::vector<std::pair<int, int>> foreground_columns(const Image& img) {
  std::vector<std::pair<int, int>> runs;
  for (int x = 0; x < img.width; ++x) {
    bool any = false;
    for (int y = 0; y < img.height && !any; ++y) any = foreground(img, x, y);
    if (!any) continue;
    if (!runs.empty() && runs.back().second == x - 1) runs.back().second = x;
    else runs.emplace_back(x, x);
  }
  return runs;
}

class ViewerRetarget : public Viewer {
 protected:
  std::string args() const {
    const fs::path map = source_dir() / "assets" / "CesiumMan" / "CesiumMan.humanoid.json";
    return quote(cooked("CesiumMan/CesiumMan.ossa").string()) + " --retarget-from " +
           quote(cooked("Pab/arnaud.ossa").string()) + " --retarget-from " + quote(cooked("Pab/walk.ossa").string()) +
           " --retarget-map " + quote(map.string()) +
           " --retarget-clip walk --no-grid --yaw 0 --pitch 0 --size 640x360";
  }
};

// Headless: the two characters stand apart (two runs of foreground columns with background
// between), and the mapping's lines appear only with --show-mapping.
TEST_F(ViewerRetarget, SourceBesideTheCharacterAndTheMappingOnRequest) {
  const Image plain =
      screenshot(args() + " --time 0.4 --screenshot " + quote((dir_ / "plain.png").string()), dir_ / "plain.png");
  ASSERT_FALSE(plain.empty());
  const auto runs = foreground_columns(plain);
  ASSERT_GE(runs.size(), 2u) << "one figure only: the source is not drawn beside the character";
  const int widest_gap = [&] {
    int g = 0;
    for (size_t i = 1; i < runs.size(); ++i) g = std::max(g, runs[i].first - runs[i - 1].second);
    return g;
  }();
  EXPECT_GT(widest_gap, 10) << "the two figures touch";
  const int plain_lines = mapping_pixels(plain);  // the characters have a few such pixels of their own

  const Image mapped = screenshot(
      args() + " --time 0.4 --show-mapping --screenshot " + quote((dir_ / "mapped.png").string()), dir_ / "mapped.png");
  ASSERT_FALSE(mapped.empty());
  EXPECT_GT(mapping_pixels(mapped), plain_lines + 300) << "no mapping lines with --show-mapping";
  // The lines span the gap between the figures: foreground in it now.
  EXPECT_LT(foreground_columns(mapped).size(), runs.size()) << "no line crosses between the figures";
}

/// Fraction of the pixels in columns [x0, x1] that differ by more than kPixelThreshold.
double differing_in_columns(const Image& a, const Image& b, int x0, int x1) {
  int n = 0, all = 0;
  for (int y = 0; y < a.height; ++y)
    for (int x = x0; x <= x1; ++x, ++all) {
      const uint8_t *p = a.at(x, y), *q = b.at(x, y);
      n += std::abs(p[0] - q[0]) > kPixelThreshold || std::abs(p[1] - q[1]) > kPixelThreshold ||
                   std::abs(p[2] - q[2]) > kPixelThreshold
               ? 1
               : 0;
    }
  return all > 0 ? static_cast<double>(n) / all : 0.0;
}

// The source clip drives the character: with --bind-pose its own clip is off, yet two times of the
// walk give two poses of the character (the left figure; the source stands on its left, the
// right of a front view).
TEST_F(ViewerRetarget, TheSourceClipDrivesTheCharacter) {
  const std::string still = args() + " --bind-pose";
  const Image a = screenshot(still + " --time 0.1 --screenshot " + quote((dir_ / "a.png").string()), dir_ / "a.png");
  const Image b = screenshot(still + " --time 0.6 --screenshot " + quote((dir_ / "b.png").string()), dir_ / "b.png");
  ASSERT_FALSE(a.empty() || b.empty());
  const auto runs = foreground_columns(a);
  ASSERT_GE(runs.size(), 2u);
  EXPECT_GT(differing_in_columns(a, b, 0, runs.front().second), kMinDifferingPosed)
      << "the character stands still: the source clip does not drive it";
}

// The window draws the source and the mapping by default (the panel's Retarget section toggles them).
TEST_F(ViewerRetarget, WindowShowsTheMappingByDefault) {
  std::string why;
  const auto display = test_display(&why);
  ASSERT_TRUE(display) << why;
  const fs::path png = dir_ / "window.png";
  const CommandResult r =
      run_command("DISPLAY=" + quote(*display) + " " + quote((bin_dir() / "ossa-view").string()) + " " + args() +
                  " --panel collapsed --window-frames 3 --screenshot " + quote(png.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  const Image img = load_png(png);
  ASSERT_FALSE(img.empty());
  EXPECT_GT(mapping_pixels(img), 300);
}

TEST_F(ViewerRetarget, MistakesAreNamed) {
  const std::string character = quote(cooked("CesiumMan/CesiumMan.ossa").string());
  const std::string pab = " --retarget-from " + quote(cooked("Pab/arnaud.ossa").string()) + " --retarget-from " +
                          quote(cooked("Pab/walk.ossa").string());
  const std::string shot = " --screenshot " + quote((dir_ / "x.png").string());
  // CesiumMan's names say nothing: without its map file every missing bone is named.
  const CommandResult unmapped = run_viewer(character + pab + shot);
  EXPECT_EQ(unmapped.exit_code, 1);
  EXPECT_NE(unmapped.err.find("CesiumMan.ossa: missing humanoid bones: hips"), std::string::npos) << unmapped.err;
  const fs::path map = source_dir() / "assets" / "CesiumMan" / "CesiumMan.humanoid.json";
  const CommandResult clip =
      run_viewer(character + pab + " --retarget-map " + quote(map.string()) + " --retarget-clip wlak" + shot);
  EXPECT_EQ(clip.exit_code, 1);
  EXPECT_NE(clip.err.find("no clip named 'wlak' to retarget (clips: 'walk"), std::string::npos) << clip.err;
  const CommandResult bad_map =
      run_viewer(character + pab + " --retarget-map " + quote((dir_ / "none.json").string()) + shot);
  EXPECT_EQ(bad_map.exit_code, 1);
  EXPECT_NE(bad_map.err.find("none.json: cannot read the map file"), std::string::npos) << bad_map.err;
  const CommandResult alone = run_viewer(character + " --retarget-map " + quote(map.string()) + shot);
  EXPECT_EQ(alone.exit_code, 2) << alone.err;
}

}  // namespace
}  // namespace ossa::test
