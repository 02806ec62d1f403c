// graph_driver.h — an animation graph as the viewer's pose source (--graph NAME).
//
// The graph is looked up by name in every opened file; its definition binds its clips by name
// across all of them (a graph file usually names clips cooked into other files), and each crowd
// instance gets its own GraphInstance. The host side of the graph — what a game's "event graph"
// does — is this viewer: the panel writes parameters, the keyboard drives the Pab sample's
// parameters, and each frame update(dt) runs and its output pose is copied into the instance's
// local pose, after which the frame continues exactly as for a clip.
#pragma once
#include <cstddef>
#include <deque>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <ossa/format/result.h>
#include <ossa/graph/graph.h>
#include <ossa/anim/pose.h>
#include "viewer/procedural_info.h"
#include "viewer/scene.h"

namespace ossa::view {

/// Lines GraphDriver::recent_events keeps.
inline constexpr size_t kGraphEventLog = 12;

/// A montage call the viewer makes at a graph time (--montage, --montage-next, --montage-jump;
/// montage_control.h): when the graph's time reaches `time`, before the update that passes it.
struct MontageCommand {
  enum class Kind { Play, Next, Jump } kind = Kind::Play;
  double time = 0.0;
  int montage = -1;
  int section = -1, next = -1;  // Next: section's next becomes next (-1: the end); Jump: section
  bool done = false;
};

struct GraphDriver {
  std::string name;
  size_t asset = 0;                             // Scene::assets index of the file holding it
  std::unique_ptr<GraphDefinition> definition;  // stays put: the instances point at it
  std::vector<GraphInstance> instances;         // one per crowd instance
  std::deque<std::string> recent_events;        // instance 0's last events, newest first
  double time = 0.0;                            // seconds of graph time played
  /// Per scene morph channel (Scene::morph_channels): the graph's channel of that name, or -1.
  std::vector<int32_t> morph_map;
  /// What the procedural nodes read and move, for the overlays and the panel's ground controls.
  ProceduralInfo procedural;
  /// Montages: calls waiting for their time, and the montage the panel and the timeline show
  /// (the last one played; -1 before any).
  std::vector<MontageCommand> montage_commands;
  int shown_montage = -1;
};

/// Finds graph `name` in the scene's files and instantiates it `instances` times. Instance i > 0
/// is pre-rolled by a fraction of a second so a crowd is not in lock-step. Errors name the files:
/// no such graph (listing the graphs there are), a graph for another skeleton, a clip it needs
/// that no file has.
Result<GraphDriver> make_graph_driver(const Scene& scene, std::string_view name, size_t instances);

/// Index of the parameter called `name`, or -1.
int graph_parameter(const GraphDriver& driver, std::string_view name);

/// Sets a parameter on every instance from text: floats and ints as numbers, bools as
/// true/false/1/0, enums by value name or index, triggers fire (any value), vectors as three
/// comma-separated numbers "x,y,z". Errors name the parameter (and list the parameters when the
/// name is unknown).
Status set_graph_parameter(GraphDriver& driver, std::string_view name, std::string_view value);

/// Sets parameter `index` to a float value on every instance (the panel's and keyboard's path).
void set_graph_value(GraphDriver& driver, int index, float value);
/// Sets Vector parameter `index` on every instance (the panel, the target gizmo); false when an
/// instance refused it.
bool set_graph_vector(GraphDriver& driver, int index, const glm::vec3& value);
/// "1.5,160,-2" -> the vector; nullopt unless exactly three finite numbers.
std::optional<glm::vec3> parse_vector(std::string_view text);
/// Fires trigger `index` on every instance.
void fire_graph_trigger(GraphDriver& driver, int index);

/// Advances every instance by dt (their poses are then GraphInstance::pose()) and logs instance
/// 0's events. Allocation-free except the event log's strings.
void update_graph(GraphDriver& driver, float dt);

/// "stop" -> "trigger", for the panel.
const char* parameter_type_name(fb::ParameterType type);

}  // namespace ossa::view
