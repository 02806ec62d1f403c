// graph_fixture.h — graph files for runtime tests and benchmarks, built in C++ (cooker/model/graph_def.h)
// around Pab's real clips, so the tests pin the evaluator without depending on the JSON compiler.
//
// pab_rig() reads Pab's 67-joint skeleton and its walk, jog, run and crossarms clips (cooked against
// it with the default tolerance) from the committed fixtures (tests/fixtures/Pab, cooked by
// ossa-cook; tests/cooker/fixtures_test.cpp re-cooks them and checks they are current and that
// reading them back gives what importing and compressing gives). make_graph_file() writes one .ossa
// holding that skeleton, the clips (with any events given) and the graphs, through the writer
// ossa-cook uses (ossa_cook_base), and opens it with the runtime's verified loader. Neither needs
// Assimp: the runtime-only and Windows builds run these suites too.
#pragma once
#include <map>
#include <memory>
#include <string>
#include <vector>

#include "cooker/clip/clip_compress.h"
#include "cooker/model/graph_def.h"
#include "cooker/model/source_scene.h"
#include <glm/glm.hpp>
#include <ossa/graph/graph.h>
#include <ossa/loader/asset.h>

/// In a test: `rig` is Pab's rig (a missing or unreadable fixture is a failure, named).
#define NEED_RIG()                                           \
  const ::ossa::test::PabRig* rig = ::ossa::test::pab_rig(); \
  ASSERT_NE(rig, nullptr) << "tests/fixtures/Pab could not be read"

namespace ossa::test {

struct PabRig {
  cook::SourceSkeleton skeleton;
  float metres_per_unit = 0.01f;
  std::vector<cook::CompressedClip> clips;  // walk, jog, run, crossarms
  int joint(std::string_view name) const;   // -1 when absent
};

/// Null (after a test failure naming the file) when a fixture is missing or unreadable.
const PabRig* pab_rig();

/// Clip index in PabRig::clips / GraphDef::clips order.
enum PabClip : uint16_t { kWalk = 0, kJog = 1, kRun = 2, kCrossarms = 3 };

/// A graph over Pab's rig with the four clips named walk, jog, run, crossarms (indices PabClip).
cook::GraphDef pab_graph(const PabRig& rig, std::string name = "test");

/// Writes rig + clips (events added per clip name) + graphs and loads it. Errors carry the
/// validator's message (for tests of invalid graphs).
Result<Asset> make_graph_file(const PabRig& rig, const std::vector<cook::GraphDef>& graphs,
                              const std::map<std::string, std::vector<cook::SourceEvent>>& events = {});

// Small builders: append a node, return its index.
uint16_t add_node(cook::GraphDef& g, cook::NodeKind kind, std::string name = "");
uint16_t add_param(cook::GraphDef& g, std::string name, cook::ParamType type, float value = 0.0f,
                   std::vector<std::string> enum_values = {});
uint16_t clip_node(cook::GraphDef& g, uint16_t clip, float rate = 1.0f, bool loop = true);

/// A loaded graph: the file, its definition and one instance (in that order, so each outlives
/// what points at it), with the output's model matrices rebuilt by local_to_model on demand.
struct Played {
  std::unique_ptr<Asset> asset;
  std::unique_ptr<GraphDefinition> def;
  std::unique_ptr<GraphInstance> inst;
  int param(std::string_view name) const { return def->find_parameter(name); }
  std::vector<glm::mat4> model() const;
  glm::vec3 position(int joint) const { return glm::vec3(model()[static_cast<size_t>(joint)][3]); }
};

/// Writes `g` over the rig (make_graph_file), binds it and makes one instance; a failing step is a
/// test failure (GoogleTest's EXPECT) and leaves the later members null.
Played play(const PabRig& rig, const cook::GraphDef& g,
            const std::map<std::string, std::vector<cook::SourceEvent>>& events = {});

}  // namespace ossa::test
