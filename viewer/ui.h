// ui.h — the Dear ImGui panels: clip list and playback, morph target weights, view toggles,
// crowd, stats, open file.
//
// Immediate mode: every frame the panels read the App and write back what the user changed, so
// there is no UI state to keep in sync beyond the text field and the smoothed timings. With a
// graph, its panel shows one widget per parameter (slider, checkbox, combo, trigger button), each
// state machine's state and running transition, the weights of the nodes that contributed to the
// pose, and the events the graph reported. With morph targets, one slider per channel shows the
// weight the clip gives it live, and holds it where the user moves it (a tick box per channel).
#pragma once
#include <string>

#include "viewer/app.h"

namespace ossa::view {

struct UiState {
  char open_path[1024] = {};
  FrameTimings smoothed;     // exponential moving average of the per-frame timings
  double frame_ms = 0.0;     // smoothed wall time between frames
  std::string status;        // last error, shown in red until the next success
  bool graph_slider_touched = false;  // the user moved a graph's `speed` this frame
};

/// Folds one frame's timings into the smoothed ones.
void record_frame(UiState& ui, const FrameTimings& frame, double frame_ms);

/// Builds this frame's panels (between ImGui::NewFrame and ImGui::Render).
void draw_panels(App& app, UiState& ui, float aspect);

}  // namespace ossa::view
