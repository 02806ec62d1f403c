// viewer_test_montage.cpp — ossa-view playing the Pab sample's upper-body montage (format v9,
// --montage NAME@T): it changes the picture while it plays, and once it has ended the picture is
// exactly the one without it (the slot passed the graph's own pose through); the window shows the
// montage panel and timeline. Helpers in viewer_test_common.h.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>

#include "test_files.h"
#include "viewer_test_common.h"

namespace fs = std::filesystem;
using namespace ossa::test;

namespace {

class ViewerMontage : public Viewer {
 protected:
  std::string files() const { return quote(cooked("Pab/pab.ossa").string()); }
  Image render(const std::string& tag, const std::string& extra) {
    const fs::path png = dir_ / (tag + ".png");
    const CommandResult r =
        run_viewer(files() + " --graph pab --no-grid --size 192x192 --screenshot " + quote(png.string()) + " " + extra);
    EXPECT_EQ(r.exit_code, 0) << r.err;
    return load_png(png);
  }
};

TEST_F(ViewerMontage, ChangesThePictureWhilePlayingAndGivesItBackAfter) {
  const Image during_without = render("during-without", "--time 2.5");
  const Image during = render("during", "--time 2.5 --montage cross_arms@0.5");
  EXPECT_GT(compare(during, during_without, kPixelThreshold).differing, kMinDifferingPosed) << "the arms did not cross";
  // Told at 2.6 s to leave its loop, it has ended by 5 s (0.8 s of loop, 0.5 s of end).
  const Image after_without = render("after-without", "--time 5");
  const Image after = render("after", "--time 5 --montage cross_arms@0.5 --montage-next loop=end@2.6");
  EXPECT_EQ(compare(after, after_without, 0).max_channel, 0) << "after the montage the graph's own pose is back";
}

TEST_F(ViewerMontage, UnknownMontageIsNamed) {
  const CommandResult r = run_viewer(files() + " --graph pab --montage wave --frames 1 --size 32x32");
  EXPECT_NE(r.exit_code, 0);
  EXPECT_NE(r.err.find("no montage named 'wave' (montages: 'cross_arms')"), std::string::npos) << r.err;
}

TEST_F(ViewerMontage, WindowShowsTheMontagePanelAndTimeline) {
  const fs::path png = dir_ / "window.png";
  const CommandResult r =
      run_viewer(files() + " --graph pab --montage cross_arms --size 640x400 --window-frames 3 -v --screenshot " +
                 quote(png.string()));
  ASSERT_EQ(r.exit_code, 0) << r.err;
  // The strip under the scene is the montage timeline (a graph without montages has none).
  const size_t at = r.err.find("timeline ");
  ASSERT_NE(at, std::string::npos) << r.err;
  EXPECT_GT(std::stod(r.err.substr(at + 9)), 0.0) << r.err;
  EXPECT_GT(coverage(load_png(png)), 0.05);
}

}  // namespace
