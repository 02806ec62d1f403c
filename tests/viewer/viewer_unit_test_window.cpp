// viewer_unit_test_window.cpp — the window's new parts that need no display, in the
// viewer_unit_test target beside viewer_unit_test.cpp (kept apart so neither file passes 600
// lines): where the scene goes beside the panel and the timeline (layout.h), the UI scale, the
// loop range and the timeline's geometry and marks (animation.h, layout.h), the file browser's
// listing (file_browser.h), finding and running the cooker and the cook cache (cook_job.h), the
// pending opens behind the loading indicator (cook_job.h), and the window's options.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include <chrono>
#include <cmath>
#include <filesystem>
#include <limits>
#include <string>
#include <thread>
#include <vector>

#include "test_files.h"
#include "viewer/animation.h"
#include "viewer/cook_job.h"
#include "viewer/file_browser.h"
#include "viewer/layout.h"
#include "viewer/options.h"
#include "viewer/panel_fit.h"
#include "viewer/scene.h"
#include "viewer_unit_common.h"

namespace fs = std::filesystem;
using namespace ossa;
using namespace ossa::view;

namespace {

fs::path cooked(const char* rel) { return test::viewer_unit_cooked(rel); }

// The panel's sections share its height (panel_fit.h): one that needs less than an equal share
// gets what it needs, the others split the rest; closed ones get nothing; an unmeasured one (-1)
// takes what is fair; minimums hold even when they overflow.
TEST(ViewerLayout, SectionsShareThePanelsHeight) {
  const std::vector<float> wanted = {900.0f, 80.0f, 100.0f, 500.0f, -1.0f};
  const std::vector<bool> open = {true, true, true, false, false};
  const std::vector<float> h = share_heights(600.0f, wanted, open, 60.0f);
  ASSERT_EQ(h.size(), 5u);
  EXPECT_FLOAT_EQ(h[1], 80.0f) << "a short section gets all it needs";
  EXPECT_FLOAT_EQ(h[2], 100.0f);
  EXPECT_FLOAT_EQ(h[0], 420.0f) << "the long one gets the rest";
  EXPECT_FLOAT_EQ(h[3], 0.0f);
  EXPECT_FLOAT_EQ(h[4], 0.0f);
  const std::vector<float> all = share_heights(600.0f, wanted, {true, true, true, true, true}, 60.0f);
  float sum = 0.0f;
  for (const float v : all) sum += v;
  EXPECT_LE(sum, 600.0f + 1e-3f);
  EXPECT_FLOAT_EQ(all[4], all[0]) << "unmeasured and long sections split equally";
  EXPECT_FLOAT_EQ(all[0], all[3]);
  const std::vector<float> tiny = share_heights(50.0f, {300.0f, 300.0f, 20.0f}, {true, true, true}, 60.0f);
  EXPECT_FLOAT_EQ(tiny[0], 60.0f) << "minimums hold (the column scrolls then)";
  EXPECT_FLOAT_EQ(tiny[2], 20.0f) << "but never more than wanted";
}

// Regions of the panel whose items reach past their clip rectangle are reported; a scrolling
// region only sideways; a region outside the panel is reported too.
TEST(ViewerLayout, PanelAuditNamesWhatIsCutOff) {
  PanelAudit a;
  a.panel = Rect{0.0f, 0.0f, 380.0f, 720.0f};
  a.regions.push_back({"fits", Rect{8, 40, 364, 200}, Rect{8, 40, 364, 200}, 372.0f, 500.0f, true});
  EXPECT_TRUE(a.problems().empty());
  a.regions.push_back({"label", Rect{8, 40, 364, 200}, Rect{8, 40, 364, 200}, 391.0f, 100.0f, true});
  a.regions.push_back({"below", Rect{0, 0, 380, 720}, Rect{0, 0, 380, 719}, 370.0f, 1188.0f, false});
  a.regions.push_back({"outside", Rect{8, 700, 364, 200}, Rect{8, 700, 364, 200}, 300.0f, 710.0f, true});
  const std::vector<std::string> p = a.problems();
  ASSERT_EQ(p.size(), 3u);
  EXPECT_NE(p[0].find("label: items reach x 391"), std::string::npos) << p[0];
  EXPECT_NE(p[1].find("below: items reach y 1188"), std::string::npos) << p[1];
  EXPECT_NE(p[2].find("outside: region"), std::string::npos) << p[2];
}

TEST(ViewerLayout, SceneTakesWhatThePanelAndTimelineLeave) {
  const SceneLayout l = compute_layout(800, 500, 800, 500, 380.0f, 56.0f);
  EXPECT_FLOAT_EQ(l.scene.x, 380.0f);
  EXPECT_FLOAT_EQ(l.scene.width, 420.0f);
  EXPECT_FLOAT_EQ(l.scene.height, 444.0f);
  EXPECT_FLOAT_EQ(l.timeline.y, 444.0f);
  EXPECT_FLOAT_EQ(l.timeline.height, 56.0f);
  EXPECT_EQ(l.fb_x, 380);
  EXPECT_EQ(l.fb_y, 56);  // GL's origin is the bottom left: the viewport starts above the strip
  EXPECT_EQ(l.fb_width, 420);
  EXPECT_EQ(l.fb_height, 444);
  EXPECT_FLOAT_EQ(l.aspect, 420.0f / 444.0f);
  EXPECT_TRUE(l.scene.contains(500.0f, 100.0f));
  EXPECT_FALSE(l.scene.contains(100.0f, 100.0f)) << "a press on the panel is not the scene's";
  EXPECT_FALSE(l.scene.contains(500.0f, 480.0f)) << "nor one on the timeline";

  const SceneLayout collapsed = compute_layout(800, 500, 800, 500, 0.0f, 0.0f);
  EXPECT_EQ(collapsed.fb_x, 0);
  EXPECT_EQ(collapsed.fb_width, 800);
  EXPECT_FLOAT_EQ(collapsed.aspect, 1.6f);

  // A framebuffer twice the window (macOS Retina): window units for the cursor, pixels for GL.
  const SceneLayout hidpi = compute_layout(800, 500, 1600, 1000, 380.0f, 56.0f);
  EXPECT_FLOAT_EQ(hidpi.scene.x, 380.0f);
  EXPECT_EQ(hidpi.fb_x, 760);
  EXPECT_EQ(hidpi.fb_y, 112);
  EXPECT_EQ(hidpi.fb_width, 840);
  EXPECT_FLOAT_EQ(hidpi.aspect, l.aspect);

  // A panel wider than the window still leaves the scene a pixel.
  const SceneLayout squeezed = compute_layout(300, 200, 300, 200, 1000.0f, 1000.0f);
  EXPECT_GE(squeezed.fb_width, 1);
  EXPECT_GE(squeezed.fb_height, 1);
  EXPECT_GT(squeezed.aspect, 0.0f);
}

TEST(ViewerLayout, UiScaleIsContentScaleOverFramebufferRatio) {
  EXPECT_FLOAT_EQ(ui_scale_for(1.0f, 1.0f), 1.0f);
  EXPECT_FLOAT_EQ(ui_scale_for(2.0f, 1.0f), 2.0f);  // X11 / Windows at 200 %
  EXPECT_FLOAT_EQ(ui_scale_for(2.0f, 2.0f), 1.0f);  // Retina: window units are points already
  EXPECT_FLOAT_EQ(ui_scale_for(1.5f, 1.0f), 1.5f);
  EXPECT_FLOAT_EQ(ui_scale_for(0.0f, 1.0f), 1.0f);
  EXPECT_FLOAT_EQ(ui_scale_for(std::numeric_limits<float>::quiet_NaN(), 1.0f), 1.0f);
  EXPECT_FLOAT_EQ(ui_scale_for(10.0f, 1.0f), 4.0f);
}

TEST(ViewerTimeline, LoopTimeWrapsWithinTheRange) {
  EXPECT_FLOAT_EQ(loop_time(1.5f, 1.0f, 2.0f), 1.5f);
  EXPECT_FLOAT_EQ(loop_time(2.0f, 1.0f, 2.0f), 2.0f);  // the end is inside
  EXPECT_FLOAT_EQ(loop_time(2.25f, 1.0f, 2.0f), 1.25f);
  EXPECT_FLOAT_EQ(loop_time(0.75f, 1.0f, 2.0f), 1.75f);  // backwards past the start
  EXPECT_FLOAT_EQ(loop_time(5.5f, 1.0f, 2.0f), 1.5f);
  EXPECT_FLOAT_EQ(loop_time(1.5f, 2.0f, 2.0f), 2.0f);  // an empty range: its start
}

TEST(ViewerTimeline, PlaybackLoopsWithinTheLoopRangeOnlyWithLoopOn) {
  const std::vector<std::string> files = {cooked("Fox/Fox.ossa").string()};
  Result<Scene> scene = load_scene(files);
  ASSERT_TRUE(scene) << scene.error().message;
  Animator a = make_animator(*scene, 1);
  ASSERT_TRUE(select_clip(*scene, a, 0, false));
  const float duration = clip_duration(*scene, a);
  ASSERT_GT(duration, 1.0f);
  a.playback.loop_start = 0.5f;
  a.playback.loop_end = 0.8f;
  set_time(*scene, a, 0.6f);
  for (int i = 0; i < 100; ++i) {
    advance(*scene, a, 1.0f / 60.0f);
    ASSERT_GE(a.playback.time, 0.5f);
    ASSERT_LE(a.playback.time, 0.8f);
  }
  a.playback.loop = false;  // loop off: the range does not hold playback
  for (int i = 0; i < 120; ++i) advance(*scene, a, 1.0f / 60.0f);
  EXPECT_GT(a.playback.time, 0.8f);
  EXPECT_TRUE(select_clip(*scene, a, 1, false));
  EXPECT_EQ(a.playback.loop_end, 0.0f) << "another clip starts with the whole clip as its range";
}

TEST(ViewerTimeline, GeometryMapsTimeToTheTrackAndBack) {
  EXPECT_FLOAT_EQ(time_to_x(1.0f, 4.0f, 100.0f, 400.0f), 200.0f);
  EXPECT_FLOAT_EQ(time_to_x(9.0f, 4.0f, 100.0f, 400.0f), 500.0f);
  EXPECT_FLOAT_EQ(x_to_time(300.0f, 4.0f, 100.0f, 400.0f), 2.0f);
  EXPECT_FLOAT_EQ(x_to_time(50.0f, 4.0f, 100.0f, 400.0f), 0.0f);
  EXPECT_FLOAT_EQ(x_to_time(300.0f, 0.0f, 100.0f, 400.0f), 0.0f);
  EXPECT_EQ(timeline_grab(203.0f, true, 200.0f, 400.0f, 8.0f), TimelineGrab::kLoopStart);
  EXPECT_EQ(timeline_grab(395.0f, true, 200.0f, 400.0f, 8.0f), TimelineGrab::kLoopEnd);
  EXPECT_EQ(timeline_grab(300.0f, true, 200.0f, 400.0f, 8.0f), TimelineGrab::kPlayhead);
  EXPECT_EQ(timeline_grab(203.0f, false, 200.0f, 400.0f, 8.0f), TimelineGrab::kPlayhead) << "the track scrubs";
  EXPECT_EQ(timeline_grab(302.0f, true, 300.0f, 300.0f, 8.0f), TimelineGrab::kLoopEnd);
  EXPECT_EQ(timeline_grab(298.0f, true, 300.0f, 300.0f, 8.0f), TimelineGrab::kLoopStart);
}

TEST(ViewerTimeline, MarksAreTheClipsKeyedFramesAndEvents) {
  const std::vector<std::string> files = {cooked("Pab/arnaud.ossa").string(), cooked("Pab/walk.ossa").string()};
  Result<Scene> scene = load_scene(files);
  ASSERT_TRUE(scene) << scene.error().message;
  const int walk = find_clip(*scene, "walk");
  ASSERT_GE(walk, 0);
  const ClipView clip = scene->clips[static_cast<size_t>(walk)].clip;
  const std::vector<KeyMark> keys = clip_key_marks(clip);
  ASSERT_FALSE(keys.empty());
  size_t channels = 0;
  for (size_t i = 0; i < keys.size(); ++i) {
    EXPECT_GE(keys[i].time, 0.0f);
    EXPECT_LE(keys[i].time, clip.duration());
    if (i > 0) {
      EXPECT_GT(keys[i].time, keys[i - 1].time);
    }
    channels += keys[i].channels;
  }
  size_t keys_stored = 0;
  for (const ossa::fb::AnimatedChannel& a : clip.animated()) keys_stored += a.key_count();
  EXPECT_EQ(channels, keys_stored) << "every channel's every key is on a mark";
  EXPECT_FLOAT_EQ(keys.front().time, 0.0f);
  const std::vector<EventMark> events = clip_event_marks(clip);  // assets/Pab/walk.events.json
  ASSERT_FALSE(events.empty());
  for (const EventMark& e : events) {
    EXPECT_FALSE(e.name.empty());
    EXPECT_GE(e.time, 0.0f);
    EXPECT_LE(e.time, clip.duration());
  }
}

TEST(ViewerBrowser, ListsFoldersFirstThenUsableFilesIgnoringCase) {
  const fs::path dir = test::make_temp_dir("browser");
  fs::create_directories(dir / "b");
  fs::create_directories(dir / "A");
  fs::create_directories(dir / ".git");
  for (const char* f :
       {"z.ossa", "Fox.GLB", "notes.txt", ".hidden.ossa", "a.fbx", "walk.bvh", "scene.gltf", "x.dae", "m.obj"})
    ASSERT_TRUE(test::write_file(dir / f, std::string("x")));
  std::string error;
  const std::vector<BrowserEntry> e = list_folder(dir, error);
  EXPECT_TRUE(error.empty()) << error;
  std::vector<std::string> names;
  for (const BrowserEntry& x : e) names.push_back(x.name);
  EXPECT_EQ(names, (std::vector<std::string>{"A", "b", "a.fbx", "Fox.GLB", "m.obj", "scene.gltf", "walk.bvh", "x.dae",
                                             "z.ossa"}));
  EXPECT_EQ(e[0].kind, EntryKind::kFolder);
  EXPECT_EQ(e[2].kind, EntryKind::kSource);
  EXPECT_EQ(e.back().kind, EntryKind::kOssa);

  std::vector<BrowserEntry> same_but_case = {
      {"b.ossa", EntryKind::kOssa}, {"B.ossa", EntryKind::kOssa}, {"c", EntryKind::kFolder}};
  sort_entries(same_but_case);
  EXPECT_EQ(same_but_case[0].name, "c");
  EXPECT_EQ(same_but_case[1].name, "B.ossa");  // ties by byte order

  list_folder(dir / "missing", error);
  EXPECT_NE(error.find("missing"), std::string::npos) << error;

  FileBrowser browser;
  browse(browser, dir / "b" / "..");
  EXPECT_EQ(browser.folder, dir.lexically_normal());
  EXPECT_EQ(start_folder({(dir / "z.ossa").string()}, "/somewhere"), dir);
  EXPECT_EQ(start_folder({}, "/somewhere"), fs::path("/somewhere"));
}

TEST(ViewerCook, SourcesAreKnownByExtension) {
  for (const char* s : {"a.fbx", "a.FBX", "b.gltf", "c.glb", "d.dae", "e.bvh", "f.obj"})
    EXPECT_TRUE(is_cook_source(s)) << s;
  for (const char* s : {"a.ossa", "a.txt", "fbx", "a.graph.json", "a.fbx.bak"}) EXPECT_FALSE(is_cook_source(s)) << s;
  EXPECT_EQ(file_kind("a.OSSA"), EntryKind::kOssa);
  EXPECT_FALSE(file_kind("a.png"));
}

TEST(ViewerCook, CookerIsFoundBesideTheViewerThenOnPath) {
  const fs::path dir = test::make_temp_dir("find-cooker");
  const fs::path beside = dir / "bin", on_path = dir / "path", empty = dir / "empty";
  for (const fs::path& d : {beside, on_path, empty}) fs::create_directories(d);
  const auto make_tool = [](const fs::path& p, bool executable) {
    ASSERT_TRUE(test::write_file(p, std::string("#!/bin/sh\n")));
    ::chmod(p.c_str(), executable ? 0755 : 0644);
  };
  make_tool(on_path / "ossa-cook", true);
  const std::string path = empty.string() + ":" + on_path.string();
  EXPECT_EQ(find_cooker(beside, path), on_path / "ossa-cook");
  make_tool(beside / "ossa-cook", false);
  EXPECT_EQ(find_cooker(beside, path), on_path / "ossa-cook") << "not executable: not a cooker";
  make_tool(beside / "ossa-cook", true);
  EXPECT_EQ(find_cooker(beside, path), beside / "ossa-cook");
  EXPECT_FALSE(find_cooker(empty, empty.string()));
  EXPECT_FALSE(find_cooker(fs::path(), ""));
  EXPECT_EQ(executable_dir(), test::bin_dir().lexically_normal()) << "/proc/self/exe's folder";
}

TEST(ViewerCook, CacheRootFollowsXdgThenHome) {
  EXPECT_EQ(cook_cache_root("/x/cache", "/home/u"), fs::path("/x/cache/ossa-view"));
  EXPECT_EQ(cook_cache_root("relative", "/home/u"), fs::path("/home/u/.cache/ossa-view"))
      << "XDG paths must be absolute";
  EXPECT_EQ(cook_cache_root(nullptr, "/home/u"), fs::path("/home/u/.cache/ossa-view"));
  EXPECT_EQ(cook_cache_root(nullptr, nullptr).filename(), "ossa-view-cache");
  const fs::path a = cook_output_for("/c", "/assets/one/Fox.glb"), b = cook_output_for("/c", "/assets/two/Fox.glb");
  EXPECT_EQ(a.filename(), "Fox.ossa");
  EXPECT_NE(a.parent_path(), b.parent_path()) << "two sources of one name must not share an output";
  EXPECT_EQ(a, cook_output_for("/c", "/assets/one/../one/Fox.glb"));
  EXPECT_EQ(a.parent_path().parent_path(), fs::path("/c"));
}

/// Waits for a started job (at most 120 s), counting the polls made meanwhile.
int wait_for(CookJob& job) {
  int polls = 0;
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::seconds(120);
  while (!job.finished() && std::chrono::steady_clock::now() < give_up) {
    ++polls;
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
  }
  return polls;
}

TEST(ViewerCook, JobCooksOnAThreadAndReportsTheCookersError) {
  const fs::path dir = test::make_temp_dir("cook-job");
  const fs::path cooker = test::bin_dir() / "ossa-cook";
  const fs::path source = test::source_dir() / "assets" / "Fox" / "Fox.glb";
  CookJob job;
  std::string error;
  const fs::path out = cook_output_for(dir, source);
  ASSERT_TRUE(job.start(cooker, source, out, error)) << error;
  EXPECT_FALSE(job.start(cooker, source, out, error)) << "one cook at a time";
  EXPECT_NE(error.find("already running"), std::string::npos);
  EXPECT_GT(wait_for(job), 2) << "start() returned before the cook ended";
  EXPECT_TRUE(job.result().ok) << job.result().error;
  EXPECT_TRUE(fs::is_regular_file(out));

  const fs::path bad = dir / "broken.fbx";
  ASSERT_TRUE(test::write_file(bad, std::string(3000, 'x')));
  ASSERT_TRUE(job.start(cooker, bad, cook_output_for(dir, bad), error)) << error;
  wait_for(job);
  EXPECT_FALSE(job.result().ok);
  EXPECT_NE(job.result().error.find("broken.fbx"), std::string::npos) << job.result().error;
  EXPECT_EQ(job.result().error.find("[1/1"), std::string::npos) << "progress lines are left out";

  ASSERT_TRUE(job.start(dir / "no-such-cooker", source, out, error)) << error;
  wait_for(job);
  EXPECT_FALSE(job.result().ok);
  EXPECT_NE(job.result().error.find("no-such-cooker"), std::string::npos) << job.result().error;
}

TEST(ViewerPending, OpensWaitForTheIndicatorAndSourcesAreCooked) {
  PendingWork work;
  EXPECT_FALSE(busy(work));
  EXPECT_FALSE(indicator_text(work));
  request_paths(work, {"/nowhere/model.fbx", "/nowhere/missing.ossa"});
  EXPECT_EQ(work.cook_queue.size(), 1u);
  EXPECT_EQ(work.open, std::vector<std::string>{"/nowhere/missing.ossa"});
  EXPECT_TRUE(busy(work));
  EXPECT_EQ(*indicator_text(work), "loading missing.ossa...");

  App app;  // no renderer: the open below fails before it needs one
  std::string status;
  work.cook_queue.clear();
  step_pending_work(work, app, 1.0f, status);
  EXPECT_EQ(work.open.size(), 1u) << "opened before a frame said 'loading'";
  note_indicator_drawn(work);
  step_pending_work(work, app, 1.0f, status);
  EXPECT_TRUE(work.open.empty());
  EXPECT_NE(status.find("missing.ossa"), std::string::npos) << status;
  EXPECT_FALSE(busy(work));
}

ParsedOptions parse(std::vector<const char*> args) {
  args.insert(args.begin(), "ossa-view");
  return parse_options(static_cast<int>(args.size()), args.data());
}

TEST(ViewerOptions, WindowOptionsAndStartingWithoutAFile) {
  const ParsedOptions p = parse({"a.ossa", "--panel", "collapsed", "--ui-scale", "2", "--browse", "/d",
                                 "--cook-and-open", "x.fbx", "--cook-and-open", "y.glb"});
  ASSERT_TRUE(p.options);
  EXPECT_TRUE(p.options->panel_collapsed);
  EXPECT_FLOAT_EQ(p.options->ui_scale, 2.0f);
  EXPECT_EQ(p.options->browse, "/d");
  EXPECT_EQ(p.options->cook_and_open, (std::vector<std::string>{"x.fbx", "y.glb"}));
  EXPECT_EQ(p.options->files, std::vector<std::string>{"a.ossa"});
  EXPECT_FALSE(parse({"a.ossa"}).options->panel_collapsed);
  EXPECT_TRUE(parse({}).options) << "the window starts without a file";
  EXPECT_TRUE(parse({"--cook-and-open", "x.fbx", "--window-frames", "3"}).options);
  EXPECT_EQ(parse({"--frames", "1"}).exit_code, 2) << "headless needs a file";
  EXPECT_EQ(parse({"a.ossa", "--panel", "half"}).exit_code, 2);
  EXPECT_EQ(parse({"a.ossa", "--ui-scale", "9"}).exit_code, 2);
  EXPECT_EQ(parse({"a.ossa", "--cook-and-open", "x.fbx", "--screenshot", "a.png"}).exit_code, 2) << "window only";
}

}  // namespace
