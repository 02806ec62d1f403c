// graph_keys.h — keyboard control of a graph's parameters, for the Pab sample graph.
//
// The sample graph (tests/graph_fixture.h pab_sample_graph, assets/Pab's graph) has a float
// `speed` feeding a walk / jog / run blend space and a sprint state, a bool `crossed_arms`
// layering the crossarms clip over the upper body, and a trigger `stop` into a standing pose.
// Keys, when the graph has those parameters: W held walks (speed eases to 1.2, the walk sample),
// Shift+W runs (4.0, the run sample), releasing W eases speed to 0 and fires `stop`; C toggles
// crossed_arms. Speed eases at 3 units/s, as a game's input smoothing would, so the blend space
// and the transitions are visible. The keys take over `speed` only once W has been pressed; the
// panel's slider hands it back.
#pragma once
#include "viewer/graph_driver.h"

namespace ossa::view {

struct GraphKeys {
  bool walk = false;      // W held
  bool run = false;       // Shift held
  bool driving = false;   // the keys own `speed` (until the panel touches it)
  float speed = 0.0f;     // the eased value last written
};

/// Key events (GLFW key codes and actions). Returns true when the key was one of these.
bool graph_key(GraphDriver& graph, GraphKeys& keys, int key, int action);

/// Eases `speed` towards the keys' target and writes it, once per frame.
void drive_graph_keys(GraphDriver& graph, GraphKeys& keys, float dt);

}  // namespace ossa::view
