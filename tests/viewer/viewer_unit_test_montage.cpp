// viewer_unit_test_montage.cpp — the viewer as the host of montages (viewer/montage_control.h), no
// window: the command line's timed calls are checked and made at their graph times on every crowd
// instance, M plays the Pab sample's montage and, pressed again, lets it finish, and montage
// events reach the panel's event log.
#include <gtest/gtest.h>

#include <string>
#include <vector>

#include "viewer/gl.h"
#include "viewer/graph_driver.h"
#include "viewer/graph_keys.h"
#include "viewer/montage_control.h"
#include "viewer/scene.h"
#include "viewer_unit_common.h"

using namespace ossa;
using namespace ossa::view;

namespace {

Result<GraphDriver> pab(size_t instances) {
  Result<Scene> scene = load_scene(std::vector<std::string>{test::viewer_unit_cooked("Pab/pab.ossa").string()});
  if (!scene) return scene.error();
  static std::vector<Scene> keep;  // the driver's definition points into the scene's assets
  keep.push_back(std::move(*scene));
  return make_graph_driver(keep.back(), "pab", instances);
}

TEST(MontageHost, CommandLineCallsAreMadeAtTheirGraphTimes) {
  Result<GraphDriver> g = pab(2);
  ASSERT_TRUE(g) << g.error().message;
  ASSERT_TRUE(add_montage_commands(*g, {"cross_arms@0.5"}, {"loop=end@2"}, {}));
  for (int f = 0; f < 29; ++f) update_graph(*g, 1.0f / 60.0f);
  EXPECT_FALSE(g->instances[0].montage_playing(0)) << "not before 0.5 s";
  for (int f = 0; f < 3; ++f) update_graph(*g, 1.0f / 60.0f);
  for (const GraphInstance& inst : g->instances) EXPECT_TRUE(inst.montage_playing(0)) << "every crowd instance";
  EXPECT_EQ(g->shown_montage, 0);
  bool logged = false;
  for (const std::string& line : g->recent_events) logged |= line.find("cross_arms: started") != std::string::npos;
  EXPECT_TRUE(logged);
  // Told at 2 s to leave the loop: it ends within the loop pass, the end section and its blend out.
  for (int f = 0; f < 60 * 5; ++f) update_graph(*g, 1.0f / 60.0f);
  EXPECT_FALSE(g->instances[0].montage_playing(0));
  EXPECT_FALSE(g->instances[1].montage_playing(0));
}

TEST(MontageHost, MistakesNameTheMontageOrSection) {
  Result<GraphDriver> g = pab(1);
  ASSERT_TRUE(g) << g.error().message;
  Status s = add_montage_commands(*g, {"crossarms"}, {}, {});
  ASSERT_FALSE(s);
  EXPECT_NE(s.message().find("no montage named 'crossarms' (montages: 'cross_arms')"), std::string::npos)
      << s.message();
  s = add_montage_commands(*g, {"cross_arms@soon"}, {}, {});
  ASSERT_FALSE(s);
  EXPECT_NE(s.message().find("NAME@SECONDS"), std::string::npos) << s.message();
  s = add_montage_commands(*g, {"cross_arms"}, {"lop=end@1"}, {});
  ASSERT_FALSE(s);
  EXPECT_NE(s.message().find("no section 'lop' (sections: 'start', 'loop', 'end')"), std::string::npos) << s.message();
  s = add_montage_commands(*g, {}, {}, {"end@1"});
  ASSERT_FALSE(s);
  EXPECT_NE(s.message().find("needs a --montage"), std::string::npos) << s.message();
  EXPECT_TRUE(add_montage_commands(*g, {"cross_arms@1"}, {"loop=@3"}, {"end@4"}));
}

TEST(MontageHost, MPlaysTheMontageAndMAgainLetsItFinish) {
  Result<GraphDriver> g = pab(1);
  ASSERT_TRUE(g) << g.error().message;
  GraphKeys keys;
  EXPECT_TRUE(graph_key(*g, keys, GLFW_KEY_M, GLFW_PRESS));
  for (int f = 0; f < 60 * 6; ++f) update_graph(*g, 1.0f / 60.0f);
  MontageStatus st = g->instances[0].montage_status(0);
  ASSERT_TRUE(st.playing) << "the loop section holds it";
  EXPECT_EQ(st.section, 1);
  EXPECT_TRUE(graph_key(*g, keys, GLFW_KEY_M, GLFW_PRESS));
  for (int f = 0; f < 60 * 4; ++f) update_graph(*g, 1.0f / 60.0f);
  EXPECT_FALSE(g->instances[0].montage_playing(0)) << "let go, it played out";
  EXPECT_TRUE(graph_key(*g, keys, GLFW_KEY_M, GLFW_PRESS));
  update_graph(*g, 1.0f / 60.0f);
  EXPECT_TRUE(g->instances[0].montage_playing(0)) << "M plays it again";
}

}  // namespace
