// graph_keys.h — keyboard control of a graph's parameters, for the Pab sample graph.
//
// The sample graph (assets/Pab/pab.graph.json) has a float `speed` feeding a walk / jog / run
// blend space (a sprint state above it, a standing pose below 0.05) and a bool `crossed_arms`
// layering the crossarms clip over the upper body. Keys, when the graph has those parameters: W
// held walks (speed eases to the blend space's slowest sample, the walk), Shift+W runs (its
// fastest sample), releasing W eases speed to 0 (the sample graph then strikes its pose); C
// toggles crossed_arms; M plays the graph's montage (the one shown, or its first) and, pressed while
// it plays, lets it finish (montage_control.h toggle_montage). The target speeds are read from the blend space driven
// by `speed`, not hard-coded (1.0 and 3.0 without one). Speed eases at 3 units/s, as a game's input smoothing would, so
// the blend space and the transitions are visible. The keys take over `speed` only once W has been pressed; the panel's
// slider hands it back.
#pragma once
#include "viewer/graph_driver.h"

namespace ossa::view {

/// The slowest and fastest sample positions of a blend space driven by `speed` (walk and run).
struct KeySpeeds {
  float walk = 1.0f, run = 3.0f;
};
KeySpeeds key_speeds(const GraphDriver& graph);

struct GraphKeys {
  bool walk = false;     // W held
  bool run = false;      // Shift held
  bool driving = false;  // the keys own `speed` (until the panel touches it)
  float speed = 0.0f;    // the eased value last written
};

/// Key events (GLFW key codes and actions). Returns true when the key was one of these.
bool graph_key(GraphDriver& graph, GraphKeys& keys, int key, int action);

/// Eases `speed` towards the keys' target and writes it, once per frame.
void drive_graph_keys(GraphDriver& graph, GraphKeys& keys, float dt);

}  // namespace ossa::view
