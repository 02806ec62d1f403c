// viewer_harness.h — driving ossa-view from tests: a private X server, runs, and image measures.
//
// The viewer needs an X display for its (hidden) GLX window. Tests start their own Xvfb (one per
// test process, on a display number Xvfb picks itself with -displayfd, so parallel ctest runs
// cannot collide and CI needs no xvfb-run wrapper) and render with Mesa's llvmpipe, the same
// software renderer everywhere, which is what makes pixel tolerances meaningful. When Xvfb is
// not installed, an existing DISPLAY is used; with neither, tests fail with that message.
//
// Images are read back with stb_image; the measures are plain: the fraction of pixels that are
// not background (estimated from the corners, so no colour is hard-coded here), and per-pixel
// differences between two renders of the same scene.
#pragma once
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "test_files.h"

namespace ossa::test {

/// The cooked samples from the viewer_cook.cmake fixture (OSSA_VIEWER_COOKED or the build's).
std::filesystem::path viewer_cooked_dir();

/// The display tests render on (":N"), starting Xvfb on first use; nullopt + why when none.
std::optional<std::string> test_display(std::string* why = nullptr);

/// Runs `ossa-view ARGS` on the test display (ARGS already shell-quoted as needed), for at most
/// 600 s (exit 124 after that).
CommandResult run_viewer(const std::string& args);

/// Shell-quotes a path or argument.
std::string quote(const std::string& s);

struct Image {
  int width = 0, height = 0;
  std::vector<uint8_t> rgb;  // top row first
  bool empty() const { return rgb.empty(); }
  const uint8_t* at(int x, int y) const { return rgb.data() + (static_cast<size_t>(y) * width + x) * 3; }
};
/// Decodes a PNG to RGB8; an empty Image when it cannot.
Image load_png(const std::filesystem::path& path);

/// Fraction of pixels whose colour differs (max channel > 6 / 255) from the background, taken as
/// the colour the most corners share.
double coverage(const Image& image);

struct ImageDiff {
  double mean_abs = 0.0;   // mean |a - b| over all channels, in 0..255 units
  double differing = 0.0;  // fraction of pixels with any channel differing by > threshold
  int max_channel = 0;     // largest channel difference
};
/// Pixel differences between two images of equal size (threshold in 0..255 units).
ImageDiff compare(const Image& a, const Image& b, int threshold);

}  // namespace ossa::test
