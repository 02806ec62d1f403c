// viewer_unit_test_drive.cpp — --move / --turn (animation.h Drive) reach the cloth as a world
// transform: the character's drawn model matrices hold the turn, the cloth is simulated without it
// in the character's own space and receives it as its model-to-world transform (cloth_view.h), so
// the pinned particles stay on the drawn body while the free ones swing out of the turn. On the
// bundled CapedMan (viewer_cook.cmake), its own walk, 2 s at 60 Hz, no window needed.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <vector>

#include <glm/glm.hpp>
#include <glm/gtc/constants.hpp>

#include <ossa/anim/cloth.h>
#include <ossa/skinning/skinning.h>

#include "viewer/animation.h"
#include "viewer/cloth_view.h"
#include "viewer/options.h"
#include "viewer/scene.h"
#include "viewer_unit_common.h"

using namespace ossa;
using namespace ossa::view;

namespace {

struct DriveRun {
  std::vector<glm::vec3> particles;   // the simulation's output, the character's own space
  std::vector<glm::vec3> drawn_skin;  // the cloth particles skinned with the drawn model matrices
  std::vector<float> inverse_masses;
  glm::mat4 cloth_world{1.0f};  // the model-to-world transform the cloth last received
  glm::mat4 drive_world{1.0f};
  float heading = 0.0f;
  float metres_per_unit = 1.0f;
};

DriveRun run_caped_man(float turn_degrees_per_second, float speed) {
  DriveRun out;
  const std::vector<std::string> paths = {test::viewer_unit_cooked("CapedMan/CapedMan.ossa").string()};
  Result<Scene> scene = load_scene(paths);
  EXPECT_TRUE(scene) << (scene ? "" : scene.error().message);
  if (!scene) return out;
  Animator a = make_animator(*scene, 1);
  EXPECT_TRUE(select_clip(*scene, a, 0, false));
  a.drive.speed = speed;
  a.drive.turn_rate = glm::radians(turn_degrees_per_second);
  Result<ViewerCloth> cloth = make_viewer_cloth(*scene, 1);
  EXPECT_TRUE(cloth && !cloth->empty());
  if (!cloth || cloth->empty()) return out;
  const Asset& character = scene->character();
  std::vector<std::vector<glm::mat4>> bind;
  for (size_t m = 0; m < character.mesh_count(); ++m) {
    bind.emplace_back(character.mesh(m).joints().size());
    prepare_bind_matrices(character.mesh(m), bind.back());
  }
  const std::vector<glm::vec3> offsets = {glm::vec3(0.0f)};
  PoseTimings ignored;
  for (int k = 0; k < 120; ++k) {
    advance(*scene, a, 1.0f / 60.0f);
    produce_local_poses(*scene, a, ignored);
    compute_model_poses(*scene, a, ignored);
    const Status s = step_viewer_cloth(*cloth, *scene, a, bind, offsets, 1.0f / 60.0f);
    EXPECT_TRUE(s) << (s ? "" : s.message());
  }
  const ClothSim& sim = cloth->sims.front();
  const auto p = sim.state.positions();
  out.particles.assign(p.begin(), p.end());
  out.inverse_masses.assign(sim.state.source.inverse_masses.begin(), sim.state.source.inverse_masses.end());
  out.cloth_world = sim.state.world_before;
  out.drive_world = a.drive.world;
  out.heading = a.drive.heading;
  const MeshView mesh = character.mesh(sim.mesh);
  std::vector<glm::mat4> palette(mesh.joints().size());
  skinning_matrices(mesh.joints(), bind[sim.mesh], a.instances.front().model, palette);
  out.drawn_skin.resize(out.particles.size());
  std::vector<glm::vec3> normals(out.particles.size());
  EXPECT_TRUE(skin_cloth_particles(sim.state.source, mesh, palette, out.drawn_skin, normals));
  out.metres_per_unit = std::max(scene->character().file().metres_per_unit(), 1e-6f);
  return out;
}

}  // namespace

TEST(ViewerDrive, ClothReceivesTheTurningWorldTransform) {
  // 90 degrees per second for 2 s, walking forwards at 1 m/s.
  const DriveRun still = run_caped_man(0.0f, 0.0f);
  const float unit = still.metres_per_unit;
  const DriveRun turning = run_caped_man(90.0f, 1.0f / unit);
  ASSERT_FALSE(turning.particles.empty());
  ASSERT_EQ(turning.particles.size(), still.particles.size());
  EXPECT_NEAR(turning.heading, glm::half_pi<float>() * 2.0f, 1e-3f);
  // The cloth's last model-to-world transform is the drive's (no crowd offset here), a half turn.
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      EXPECT_NEAR(turning.cloth_world[c][r], turning.drive_world[c][r], 1e-4f) << c << "," << r;
  EXPECT_NEAR(turning.cloth_world[0][0], -1.0f, 1e-3f) << "x turned to -x: the cloth saw the turn";
  EXPECT_NEAR(still.cloth_world[0][0], 1.0f, 1e-6f);
  // Pinned particles, put where they are drawn, lie on the drawn (turned) body.
  size_t pinned = 0;
  for (size_t i = 0; i < turning.particles.size(); ++i) {
    if (turning.inverse_masses[i] != 0.0f) continue;
    ++pinned;
    const glm::vec3 drawn = glm::vec3(turning.drive_world * glm::vec4(turning.particles[i], 1.0f));
    EXPECT_LT(glm::distance(drawn, turning.drawn_skin[i]), 1e-3f / unit) << "pinned particle " << i;
  }
  EXPECT_GT(pinned, 0u);
  // The free ones swing: the same walk without the turn leaves them elsewhere (by centimetres).
  float most = 0.0f;
  for (size_t i = 0; i < turning.particles.size(); ++i)
    most = std::max(most, glm::distance(turning.particles[i], still.particles[i]) * unit);
  EXPECT_GT(most, 0.02f) << "the cape did not react to the turn (metres)";
}

TEST(ViewerDrive, TurnOptionParses) {
  EXPECT_EQ(parse_turn("90"), std::make_pair(90.0f, 0.0f));
  EXPECT_EQ(parse_turn("-45@1.5"), std::make_pair(-45.0f, 1.5f));
  EXPECT_FALSE(parse_turn(""));
  EXPECT_FALSE(parse_turn("fast"));
  EXPECT_FALSE(parse_turn("90@"));
  EXPECT_FALSE(parse_turn("90@-1"));
  EXPECT_FALSE(parse_turn("9000"));
  EXPECT_FALSE(parse_turn("nan"));
}

// The path: straight along the front until the turn starts, then a circle of radius speed / rate;
// the same at 30 and 144 Hz (1/240 s steps inside).
TEST(ViewerDrive, PathIsTheSameAtAnyFrameRate) {
  const auto drive_at = [](float hz) {
    Drive d;
    d.speed = 2.0f;
    d.turn_rate = glm::half_pi<float>();
    d.turn_after = 1.0f;
    d.forward = glm::vec3(1.0f, 0.0f, 0.0f);
    const int frames = static_cast<int>(std::lround(3.0f * hz));
    for (int k = 0; k < frames; ++k) advance_drive(d, 1.0f / hz);
    return d;
  };
  const Drive a = drive_at(30.0f), b = drive_at(144.0f);
  EXPECT_NEAR(a.heading, glm::pi<float>(), 1e-3f) << "2 s of a quarter turn per second";
  EXPECT_NEAR(glm::distance(a.position, b.position), 0.0f, 5e-3f);  // measured 1.1 mm over the 6 m path
  // 2 m straight along +x, then a half circle of radius 4 / pi turning towards -z (+Y rotation of +x).
  const float r = 2.0f / glm::half_pi<float>();
  EXPECT_NEAR(a.position.x, 2.0f, 2e-2f);
  EXPECT_NEAR(a.position.z, -2.0f * r, 2e-2f);
  EXPECT_NEAR(a.world[3][0], a.position.x, 1e-6f);
}
