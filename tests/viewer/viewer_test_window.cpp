// viewer_test_window.cpp — ossa-view's window as a first-time user meets it, end to end on Xvfb:
// the panel is a sidebar the scene is laid out beside (the character centred in what the panel
// leaves, or in the whole window when the panel is collapsed), --ui-scale widens it, a source file
// is cooked in the background into the cache folder and shown, a broken source shows the
// cooker's error in red and exits 1 without crashing, the timeline strip under the scene appears
// with a clip, and the window starts without a file in the file browser.
//
// The window mode prints its layout with -v ("layout: panel P, scene X Y W H, timeline T"), so
// the tests measure the screenshot in the regions the viewer says it used, and compare those with
// what was drawn there. Kept apart from the headless suites because every test here runs the
// window (--window-frames) and reads -v's lines.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <thread>
#include <vector>

#include "test_files.h"
#include "viewer_test_common.h"

namespace fs = std::filesystem;
using namespace ossa::test;

namespace {

struct Layout {
  float panel = -1.0f, x = 0.0f, y = 0.0f, width = 0.0f, height = 0.0f, timeline = -1.0f;
  bool found() const { return panel >= 0.0f; }
};

/// The "layout: ..." line -v prints for the captured frame.
Layout parse_layout(const std::string& err) {
  Layout l;
  const size_t at = err.find("layout: panel ");
  if (at != std::string::npos)
    std::sscanf(err.c_str() + at, "layout: panel %f, scene %f %f %f %f, timeline %f", &l.panel, &l.x, &l.y, &l.width,
                &l.height, &l.timeline);
  return l;
}

struct Box {
  int x0 = 1 << 30, y0 = 1 << 30, x1 = -1, y1 = -1;
  bool empty() const { return x1 < x0; }
  double cx() const { return 0.5 * (x0 + x1); }
  double cy() const { return 0.5 * (y0 + y1); }
};

/// Bounding box of the pixels in the scene rectangle that differ from its top-right corner (the
/// scene's background there; --no-grid). The top 48 rows are left out: the collapsed panel's
/// button sits there.
Box scene_foreground(const Image& img, const Layout& l) {
  Box b;
  const int x0 = static_cast<int>(l.x), y0 = static_cast<int>(l.y) + 48;
  const int x1 = std::min(static_cast<int>(l.x + l.width), img.width),
            y1 = std::min(static_cast<int>(l.y + l.height), img.height);
  const uint8_t* bg = img.at(x1 - 2, y0 + 2);
  for (int y = y0; y < y1; ++y) {
    for (int x = x0; x < x1; ++x) {
      const uint8_t* p = img.at(x, y);
      if (std::abs(p[0] - bg[0]) <= 12 && std::abs(p[1] - bg[1]) <= 12 && std::abs(p[2] - bg[2]) <= 12) continue;
      b.x0 = std::min(b.x0, x);
      b.y0 = std::min(b.y0, y);
      b.x1 = std::max(b.x1, x);
      b.y1 = std::max(b.y1, y);
    }
  }
  return b;
}

/// Pixels in [x0, x1) x [y0, y1) that are clearly red (the error status, the playhead).
int red_pixels(const Image& img, int x0, int y0, int x1, int y1) {
  int n = 0;
  for (int y = std::max(y0, 0); y < std::min(y1, img.height); ++y)
    for (int x = std::max(x0, 0); x < std::min(x1, img.width); ++x) {
      const uint8_t* p = img.at(x, y);
      n += p[0] > 190 && p[1] < 130 && p[2] < 130 ? 1 : 0;
    }
  return n;
}

class ViewerWindow : public Viewer {
 protected:
  /// Runs the window for 3 frames (after any cook / open) with -v and a screenshot, in `env`.
  CommandResult window(const std::string& args, const std::string& tag, const std::string& env = "") {
    const fs::path png = dir_ / (tag + ".png");
    std::string why;
    const auto display = test_display(&why);
    if (!display) return {-1, "", "no display: " + why};
    return run_command(env + " DISPLAY=" + quote(*display) + " " + quote((bin_dir() / "ossa-view").string()) + " " +
                       args + " -v --window-frames 3 --screenshot " + quote(png.string()));
  }
  Image shot(const std::string& tag) { return load_png(dir_ / (tag + ".png")); }
  std::string fox() const { return quote(cooked("Fox/Fox.ossa").string()); }
  std::string cache_env() const { return "XDG_CACHE_HOME=" + quote((dir_ / "cache").string()); }
};

// The fox seen from the front in its bind pose is symmetric about its middle, so its silhouette's
// box is centred in whatever region the scene is drawn in: beside the open panel it is centred in
// the region right of the panel (drawn there, not under the panel), collapsed in the whole width.
TEST_F(ViewerWindow, PanelDoesNotHideTheCharacter) {
  const std::string view = fox() + " --bind-pose --yaw 0 --pitch 0 --no-grid --size 900x500";
  const CommandResult open = window(view, "open");
  ASSERT_EQ(open.exit_code, 0) << open.err;
  const Layout lo = parse_layout(open.err);
  ASSERT_TRUE(lo.found()) << open.err;
  EXPECT_GT(lo.panel, 200.0f);
  EXPECT_EQ(lo.x, lo.panel) << "the scene starts where the panel ends";
  EXPECT_EQ(lo.x + lo.width, 900.0f);
  const Image io = shot("open");
  const Box bo = scene_foreground(io, lo);
  ASSERT_FALSE(bo.empty()) << "no character beside the panel";
  EXPECT_GT(bo.x0, lo.panel) << "the character reaches under the panel";
  EXPECT_NEAR(bo.cx(), lo.x + 0.5 * lo.width, 0.06 * lo.width) << "not centred in the region the panel leaves";
  EXPECT_NEAR(bo.cy(), lo.y + 0.5 * lo.height, 0.1 * lo.height);

  const CommandResult collapsed = window(view + " --panel collapsed", "collapsed");
  ASSERT_EQ(collapsed.exit_code, 0) << collapsed.err;
  const Layout lc = parse_layout(collapsed.err);
  EXPECT_EQ(lc.panel, 0.0f);
  EXPECT_EQ(lc.x, 0.0f);
  EXPECT_EQ(lc.width, 900.0f);
  const Box bc = scene_foreground(shot("collapsed"), lc);
  ASSERT_FALSE(bc.empty());
  EXPECT_NEAR(bc.cx(), 450.0, 0.06 * 900.0) << "collapsed: not centred in the window";
  EXPECT_GT(bc.x1 - bc.x0, bo.x1 - bo.x0 - 4) << "the same framing height, so at least as wide";
}

TEST_F(ViewerWindow, UiScaleTwoMakesThePanelWider) {
  const CommandResult one = window(fox() + " --size 1200x600 --ui-scale 1", "one");
  const CommandResult two = window(fox() + " --size 1200x600 --ui-scale 2", "two");
  ASSERT_EQ(one.exit_code + two.exit_code, 0) << one.err << two.err;
  const Layout l1 = parse_layout(one.err), l2 = parse_layout(two.err);
  EXPECT_NEAR(l2.panel, 2.0f * l1.panel, 2.0f);
  EXPECT_GT(l2.timeline, l1.timeline) << "the timeline scales too";
  // Between the two panel edges the scale-1 image shows the scene, the scale-2 image the panel:
  // they differ there on most rows.
  const Image a = shot("one"), b = shot("two");
  int differing = 0;
  const int x = static_cast<int>(0.5f * (l1.panel + l2.panel));
  for (int y = 0; y < a.height; ++y) {
    const uint8_t *p = a.at(x, y), *q = b.at(x, y);
    differing += std::abs(p[0] - q[0]) + std::abs(p[1] - q[1]) + std::abs(p[2] - q[2]) > 12 ? 1 : 0;
  }
  EXPECT_GT(differing, a.height / 2);
}

// A gate between the viewer and its cooker: OSSA_COOK names a script that marks that it started,
// waits until the test opens the gate, then runs the real ossa-cook. With it the cook tests wait
// for events (the cook started, the viewer reported frames drawn meanwhile, the viewer opened the
// output, it exited), never for a frame count within a time; each wait is bounded only so that a
// hang fails instead of stalling the suite.
class GatedCook {
 public:
  explicit GatedCook(const fs::path& dir) : dir_(dir / "gate") {
    fs::create_directories(dir_);
    const fs::path script = dir_ / "ossa-cook";
    write_file(script, "#!/bin/sh\n: > " + quote((dir_ / "started").string()) + "\nwhile [ ! -e " +
                           quote((dir_ / "open").string()) + " ]; do sleep 0.02; done\nexec " +
                           quote((bin_dir() / "ossa-cook").string()) + " \"$@\"\n");
    fs::permissions(script, fs::perms::owner_all);
  }
  std::string env() const { return "OSSA_COOK=" + quote((dir_ / "ossa-cook").string()); }
  bool started() const { return fs::exists(dir_ / "started"); }
  void open() const { write_file(dir_ / "open", std::string_view("")); }

 private:
  fs::path dir_;
};

/// ossa-view run in the background: its stderr and exit status land in files the test polls.
class BackgroundViewer {
 public:
  BackgroundViewer(const fs::path& dir, const std::string& env, const std::string& args) : dir_(dir / "bg") {
    fs::create_directories(dir_);
    std::string why;
    const auto display = test_display(&why);
    if (!display) return;
    run_command("( " + env + " DISPLAY=" + quote(*display) + " " + quote((bin_dir() / "ossa-view").string()) + " " +
                args + " -v >/dev/null 2>" + quote(err_path().string()) + " & echo $! > " +
                quote((dir_ / "pid").string()) + "; wait $!; echo $? > " + quote((dir_ / "rc.tmp").string()) + "; mv " +
                quote((dir_ / "rc.tmp").string()) + " " + quote((dir_ / "rc").string()) + " ) >/dev/null 2>&1 &");
  }
  ~BackgroundViewer() { stop(); }
  std::string err() const { return read_text(err_path()).value_or(""); }
  bool exited() const { return fs::exists(dir_ / "rc"); }
  int exit_code() const { return std::atoi(read_text(dir_ / "rc").value_or("-1").c_str()); }
  void stop() const {
    if (exited()) return;
    if (const auto pid = read_text(dir_ / "pid")) run_command("kill " + std::to_string(std::atoi(pid->c_str())));
    wait_for([&] { return exited(); }, 60.0);
  }
  /// Polls `done` every 20 ms until it holds or `seconds` pass; whether it held.
  template <class F>
  static bool wait_for(F&& done, double seconds) {
    for (int i = 0; i < static_cast<int>(seconds * 50.0); ++i) {
      if (done()) return true;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return done();
  }

 private:
  fs::path err_path() const { return dir_ / "err.txt"; }
  fs::path dir_;
};

/// The largest frame count in the viewer's "cooking SOURCE: N s, F frames drawn" progress lines.
int frames_reported_while_cooking(const std::string& err) {
  int most = 0;
  for (size_t at = err.find(" frames drawn\n"); at != std::string::npos; at = err.find(" frames drawn\n", at + 1)) {
    const size_t comma = err.rfind(", ", at);
    if (comma != std::string::npos) most = std::max(most, std::atoi(err.c_str() + comma + 2));
  }
  return most;
}

// A source given to --cook-and-open (as a dropped one) is cooked by ossa-cook into the cache
// folder while frames keep being drawn, then opened and shown; --window-frames counts only the
// frames after that, so the capture shows the cooked character.
TEST_F(ViewerWindow, CookAndOpenShowsTheCookedCharacter) {
  const fs::path source = source_dir() / "assets" / "Fox" / "Fox.glb";
  const GatedCook gate(dir_);
  const fs::path png = dir_ / "cooked.png";
  BackgroundViewer viewer(dir_, cache_env() + " " + gate.env(),
                          "--cook-and-open " + quote(source.string()) +
                              " --no-grid --size 800x500 --window-frames 3 --screenshot " + quote(png.string()));
  ASSERT_TRUE(BackgroundViewer::wait_for([&] { return gate.started() || viewer.exited(); }, 120.0)) << viewer.err();
  ASSERT_FALSE(viewer.exited()) << "the viewer ended before its cook:\n" << viewer.err();
  // The cook is held at the gate: the window must go on drawing meanwhile.
  ASSERT_TRUE(BackgroundViewer::wait_for(
      [&] { return frames_reported_while_cooking(viewer.err()) >= 2 || viewer.exited(); }, 120.0))
      << "the window stopped drawing while the cooker ran:\n"
      << viewer.err();
  ASSERT_FALSE(viewer.exited()) << viewer.err();
  gate.open();
  ASSERT_TRUE(BackgroundViewer::wait_for([&] { return viewer.exited(); }, 600.0)) << viewer.err();
  const std::string err = viewer.err();
  ASSERT_EQ(viewer.exit_code(), 0) << err;
  std::vector<fs::path> outputs;
  for (const auto& e : fs::recursive_directory_iterator(dir_ / "cache" / "ossa-view"))
    if (e.path().extension() == ".ossa") outputs.push_back(e.path());
  ASSERT_EQ(outputs.size(), 1u) << "expected one cooked file under the cache";
  EXPECT_EQ(outputs.front().filename(), "Fox.ossa");
  EXPECT_NE(err.find("opened " + outputs.front().string()), std::string::npos) << err;
  EXPECT_NE(err.find("frames drawn meanwhile"), std::string::npos) << err;
  const Layout l = parse_layout(err);
  const Box b = scene_foreground(shot("cooked"), l);
  ASSERT_FALSE(b.empty()) << "the cooked fox is not shown";
  EXPECT_GT((b.x1 - b.x0) * (b.y1 - b.y0), static_cast<int>(0.05 * l.width * l.height));
}

// Without --window-frames the window stays: through the cook, after the character is opened,
// until it is closed (here: terminated by the test). It once closed itself at once, exit 0, with
// nothing cooked (issue 26 item 6).
TEST_F(ViewerWindow, CookAndOpenWithoutAFrameLimitKeepsTheWindow) {
  const fs::path source = source_dir() / "assets" / "Fox" / "Fox.glb";
  const GatedCook gate(dir_);
  BackgroundViewer viewer(dir_, cache_env() + " " + gate.env(),
                          "--cook-and-open " + quote(source.string()) + " --size 640x400");
  ASSERT_TRUE(BackgroundViewer::wait_for([&] { return gate.started() || viewer.exited(); }, 120.0)) << viewer.err();
  ASSERT_FALSE(viewer.exited()) << "the window closed before its cook (exit " << viewer.exit_code() << "):\n"
                                << viewer.err();
  gate.open();
  ASSERT_TRUE(BackgroundViewer::wait_for(
      [&] { return viewer.err().find("opened ") != std::string::npos || viewer.exited(); }, 600.0))
      << viewer.err();
  EXPECT_NE(viewer.err().find("cooked " + source.string()), std::string::npos) << viewer.err();
  // A window that closes by itself does so within a frame or two; a second is ample to see it.
  EXPECT_FALSE(BackgroundViewer::wait_for([&] { return viewer.exited(); }, 1.0))
      << "the window closed by itself after opening the character (exit " << viewer.exit_code() << "):\n"
      << viewer.err();
  viewer.stop();
}

// A source the cooker refuses: the cooker's message in the panel, in red, and on stderr; exit 1
// (the panel's error status, options.h), not a signal.
TEST_F(ViewerWindow, BrokenSourceShowsTheCookersErrorInRed) {
  const fs::path bad = dir_ / "garbage.fbx";
  ASSERT_TRUE(write_file(bad, std::string(2000, 'x')));
  const CommandResult r = window("--cook-and-open " + quote(bad.string()) + " --size 800x500", "bad", cache_env());
  EXPECT_EQ(r.exit_code, 1) << r.err;
  EXPECT_NE(r.err.find("garbage.fbx"), std::string::npos) << r.err;
  EXPECT_NE(r.err.find("FBX"), std::string::npos) << "the cooker's own words: " << r.err;
  const Image img = shot("bad");
  ASSERT_FALSE(img.empty());
  const Layout l = parse_layout(r.err);
  EXPECT_GT(red_pixels(img, 0, 0, static_cast<int>(l.panel), img.height), 40) << "no red status text in the panel";

  const CommandResult fine = window(fox() + " --size 800x500 --paused --bind-pose", "fine");
  ASSERT_EQ(fine.exit_code, 0) << fine.err;
  EXPECT_LT(red_pixels(shot("fine"), 0, 0, static_cast<int>(parse_layout(fine.err).panel), img.height), 10);
}

// With a clip the strip under the scene shows its keys and a red playhead; a character without
// clips has no strip and the scene reaches the bottom.
TEST_F(ViewerWindow, TimelineAppearsUnderTheSceneWithAClip) {
  SyntheticSpec spec;
  const fs::path with_clip = dir_ / "clip.ossa";
  ASSERT_TRUE(write_file(with_clip, make_valid_file(spec)));
  spec.clips.clear();
  const fs::path without = dir_ / "noclip.ossa";
  ASSERT_TRUE(write_file(without, make_valid_file(spec)));
  const std::string view = " --no-grid --paused --size 800x500";
  const CommandResult a = window(quote(with_clip.string()) + view, "clip");
  const CommandResult b = window(quote(without.string()) + view, "noclip");
  ASSERT_EQ(a.exit_code + b.exit_code, 0) << a.err << b.err;
  const Layout la = parse_layout(a.err), lb = parse_layout(b.err);
  EXPECT_GT(la.timeline, 20.0f);
  EXPECT_EQ(lb.timeline, 0.0f);
  EXPECT_EQ(la.height + la.timeline, 500.0f);
  EXPECT_EQ(lb.height, 500.0f);
  const Image ia = shot("clip"), ib = shot("noclip");
  const int top = static_cast<int>(la.y + la.height), left = static_cast<int>(la.x);
  int differing = 0, total = 0;
  for (int y = top; y < ia.height; ++y)
    for (int x = left; x < ia.width; ++x, ++total) {
      const uint8_t *p = ia.at(x, y), *q = ib.at(x, y);
      differing += std::abs(p[0] - q[0]) + std::abs(p[1] - q[1]) + std::abs(p[2] - q[2]) > 12 ? 1 : 0;
    }
  EXPECT_GT(differing, total / 2) << "the strip under the scene looks like the scene";
  EXPECT_GT(red_pixels(ia, left, top, ia.width, ia.height), 5) << "no playhead";
}

// The window starts without a file: the browser lists the folder given to --browse.
TEST_F(ViewerWindow, StartsWithoutAFileInTheBrowser) {
  fs::create_directories(dir_ / "assets" / "sub");
  ASSERT_TRUE(write_file(dir_ / "assets" / "a.ossa", std::string("x")));
  ASSERT_TRUE(write_file(dir_ / "assets" / "b.glb", std::string("x")));
  ASSERT_TRUE(write_file(dir_ / "assets" / "notes.txt", std::string("x")));
  const CommandResult r = window("--browse " + quote((dir_ / "assets").string()) + " --size 640x400", "browse");
  ASSERT_EQ(r.exit_code, 0) << r.err;
  EXPECT_NE(r.err.find("browsing " + (dir_ / "assets").string() + ": 3 entries"), std::string::npos) << r.err;
  EXPECT_GT(coverage(shot("browse")), 0.1) << "expected the panel";
}

}  // namespace

namespace {

struct PanelCheck {
  int regions = -1, cut = -1;
  std::vector<std::string> region_lines, cut_lines;
};

/// -v's panel lines (interactive.cpp print_panel_audit) for the captured frame.
PanelCheck parse_panel_check(const std::string& err) {
  PanelCheck c;
  const size_t at = err.find("panel check: ");
  if (at != std::string::npos) std::sscanf(err.c_str() + at, "panel check: %d regions, %d cut off", &c.regions, &c.cut);
  size_t from = 0;
  for (size_t eol; (eol = err.find('\n', from)) != std::string::npos; from = eol + 1) {
    const std::string line = err.substr(from, eol - from);
    if (line.find("panel region ") != std::string::npos) c.region_lines.push_back(line);
    if (line.find("panel cut off: ") != std::string::npos) c.cut_lines.push_back(line);
  }
  return c;
}

}  // namespace

// The panel fits the window (issue 28): at the default 1280x720 and at 1600x1000, with the Pab
// graph's long panel, with the Pab clips and with no file (the browser), every region of the
// panel (its sections, the help lines) lies inside it and no widget reaches past a region's edge,
// sideways (labels) or downwards where the region does not scroll. The rectangles are Dear
// ImGui's own, printed by -v (panel_fit.h).
TEST_F(ViewerWindow, PanelFitsTheWindowAt1280x720And1600x1000) {
  const std::string pab_graph = quote(cooked("Pab/pab.ossa").string()) + " --graph pab --ui-scale 1";
  std::string clips = quote(cooked("Pab/arnaud.ossa").string());
  for (const char* c : {"walk", "jog", "run", "crossarms"})
    clips += " " + quote(cooked((std::string("Pab/") + c + ".ossa").c_str()).string());
  const std::string browser = "--browse " + quote(cooked("").string()) + " --ui-scale 1";
  int n = 0;
  for (const std::string& files : {pab_graph, clips + " --ui-scale 1", browser}) {
    for (const char* size : {"1280x720", "1600x1000"}) {
      const std::string tag = "fit" + std::to_string(n++);
      const CommandResult r = window(files + " --size " + size, tag);
      ASSERT_EQ(r.exit_code, 0) << r.err;
      const PanelCheck c = parse_panel_check(r.err);
      ASSERT_GE(c.regions, 1) << files << " at " << size << ": no panel check in\n" << r.err;
      EXPECT_EQ(c.cut, 0) << files << " at " << size << ":\n" << r.err;
      for (const std::string& line : c.region_lines) {
        float x, y, w, h, px, py, pw, ph;
        const size_t at = line.find(": ", line.find("panel region "));
        const int got =
            std::sscanf(line.c_str() + at + 2, "%f %f %f %f in panel %f %f %f %f", &x, &y, &w, &h, &px, &py, &pw, &ph);
        ASSERT_EQ(got, 8) << line;
        EXPECT_GE(x, px - 1.0f) << line;
        EXPECT_GE(y, py - 1.0f) << line;
        EXPECT_LE(x + w, px + pw + 1.0f) << line;
        EXPECT_LE(y + h, py + ph + 1.0f) << line;
      }
    }
  }
}
