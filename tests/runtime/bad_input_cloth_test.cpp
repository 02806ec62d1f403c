// bad_input_cloth_test.cpp — the bad-input suite (bad_input_test.cpp) on a mesh's cloth (ossa.fbs
// Cloth, format v9): the loader runs ossa/anim/cloth.h's check_cloth on every file's cloth, so
// each case starts from a valid synthetic cloth, breaks one field the solver indexes or divides by,
// and must be refused with a message naming the file, the mesh, "cloth" and the field.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>
#include <vector>

#include "bad_input.h"
#include <ossa/anim/cloth.h>
#include <ossa/loader/asset.h>
#include "test_files.h"

namespace ossa::test {
namespace {

SyntheticSpec cloth_spec() {
  SyntheticSpec spec;
  spec.meshes[0].cloth = SyntheticCloth{};
  return spec;
}

Keywords cloth_error(std::vector<std::string> words) { return with(kMesh, {"cloth"}, std::move(words)); }

TEST(Cloth, TheClothSpecIsAccepted) {
  const std::vector<uint8_t> bytes = make_valid_file(cloth_spec());
  const auto asset = Asset::from_bytes(bytes, "cloth.ossa");
  ASSERT_TRUE(asset.ok()) << asset.error().message;
  const ClothSource cloth = cloth_source(asset->mesh(0));
  EXPECT_EQ(cloth.particle_vertices.size(), 6u);
  EXPECT_EQ(cloth.tethers.size(), 4u);
}

TEST(Cloth, ParticleDrivenByAVertexPastTheMesh) {
  SyntheticSpec spec = cloth_spec();
  spec.meshes[0].cloth->particle_vertices[3] = 6;
  EXPECT_TRUE(rejects(spec, cloth_error({"particle 3", "vertex 6"})));
}

TEST(Cloth, InverseMassesOfTheWrongCountOrOutOfRange) {
  SyntheticSpec spec = cloth_spec();
  spec.meshes[0].cloth->inverse_masses.pop_back();
  EXPECT_TRUE(rejects(spec, cloth_error({"inverse_masses"})));
  for (float bad : {-1.0f, std::numeric_limits<float>::quiet_NaN(), 1e9f}) {
    spec = cloth_spec();
    spec.meshes[0].cloth->inverse_masses[4] = bad;
    EXPECT_TRUE(rejects(spec, cloth_error({"inverse_masses"}))) << bad;
  }
}

TEST(Cloth, MaxDistancesOfTheWrongCount) {
  SyntheticSpec spec = cloth_spec();
  spec.meshes[0].cloth->max_distances = {0.1f, 0.1f};
  EXPECT_TRUE(rejects(spec, cloth_error({"max_distances"})));
}

TEST(Cloth, VerticesNotIncreasingOrPastTheMesh) {
  SyntheticSpec spec = cloth_spec();
  spec.meshes[0].cloth->vertices = {0, 1, 3, 2, 4, 5};
  EXPECT_TRUE(rejects(spec, cloth_error({"strictly increasing"})));
  spec = cloth_spec();
  spec.meshes[0].cloth->vertices[5] = 9;
  EXPECT_TRUE(rejects(spec, cloth_error({"vertex 9"})));
  spec = cloth_spec();
  spec.meshes[0].cloth->vertex_particles.pop_back();
  EXPECT_TRUE(rejects(spec, cloth_error({"vertex_particles"})));
  spec = cloth_spec();
  spec.meshes[0].cloth->vertex_particles[2] = 6;
  EXPECT_TRUE(rejects(spec, cloth_error({"particle 6"})));
}

TEST(Cloth, TrianglesNotTriplesOrPastTheParticles) {
  SyntheticSpec spec = cloth_spec();
  spec.meshes[0].cloth->triangles.pop_back();
  EXPECT_TRUE(rejects(spec, cloth_error({"multiple of 3"})));
  spec = cloth_spec();
  spec.meshes[0].cloth->triangles[4] = 60;
  EXPECT_TRUE(rejects(spec, cloth_error({"triangle 1", "particle 60"})));
}

TEST(Cloth, StretchEdgeOutOfRangeDegenerateOrBadLength) {
  SyntheticSpec spec = cloth_spec();
  spec.meshes[0].cloth->stretch[2] = fb::ClothEdge(4, 7, 1.0f);
  EXPECT_TRUE(rejects(spec, cloth_error({"stretch edge 2"})));
  spec = cloth_spec();
  spec.meshes[0].cloth->stretch[2] = fb::ClothEdge(4, 4, 1.0f);
  EXPECT_TRUE(rejects(spec, cloth_error({"stretch edge 2", "itself"})));
  spec = cloth_spec();
  spec.meshes[0].cloth->stretch[0] = fb::ClothEdge(0, 1, std::numeric_limits<float>::infinity());
  EXPECT_TRUE(rejects(spec, cloth_error({"stretch edge 0", "rest length"})));
}

TEST(Cloth, TetherToAFreeParticleOrPastTheParticles) {
  SyntheticSpec spec = cloth_spec();
  spec.meshes[0].cloth->tethers[1] = fb::ClothTether(3, 2, 1.0f);  // particle 2 is simulated
  EXPECT_TRUE(rejects(spec, cloth_error({"tether 1", "not fixed"})));
  spec = cloth_spec();
  spec.meshes[0].cloth->tethers[0] = fb::ClothTether(20, 0, 1.0f);
  EXPECT_TRUE(rejects(spec, cloth_error({"tether 0"})));
  spec = cloth_spec();
  spec.meshes[0].cloth->tethers[0] = fb::ClothTether(2, 0, -1.0f);
  EXPECT_TRUE(rejects(spec, cloth_error({"tether 0", "length"})));
}

TEST(Cloth, ColliderOnAMissingJointOrWithABadShape) {
  SyntheticSpec spec = cloth_spec();
  spec.meshes[0].cloth->colliders[0] = fb::ClothCollider(40, fb::Vec3(0, 0, 0), fb::Vec3(0, 1, 0), 0.1f);
  EXPECT_TRUE(rejects(spec, cloth_error({"collider 0", "joint 40"})));
  spec = cloth_spec();
  spec.meshes[0].cloth->colliders[0] = fb::ClothCollider(1, fb::Vec3(std::nanf(""), 0, 0), fb::Vec3(0, 1, 0), 0.1f);
  EXPECT_TRUE(rejects(spec, cloth_error({"collider 0", "not finite"})));
  spec = cloth_spec();
  spec.meshes[0].cloth->colliders[0] = fb::ClothCollider(1, fb::Vec3(0, 0, 0), fb::Vec3(0, 1, 0), -0.5f);
  EXPECT_TRUE(rejects(spec, cloth_error({"collider 0", "radius"})));
}

TEST(Cloth, SettingOutOfRange) {
  SyntheticSpec spec = cloth_spec();
  spec.meshes[0].cloth->damping = std::numeric_limits<float>::quiet_NaN();
  EXPECT_TRUE(rejects(spec, cloth_error({"damping"})));
}

}  // namespace
}  // namespace ossa::test
