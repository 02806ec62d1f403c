// ui.h — the Dear ImGui panels: clip list and playback, view toggles, crowd, stats, open file.
//
// Immediate mode: every frame the panels read the App and write back what the user changed, so
// there is no UI state to keep in sync beyond the text field and the smoothed timings. The panel
// is where an animation graph's parameters will appear (one widget per parameter) next to the
// clip list.
#pragma once
#include <string>

#include "viewer/app.h"

namespace ossa::view {

struct UiState {
  char open_path[1024] = {};
  FrameTimings smoothed;     // exponential moving average of the per-frame timings
  double frame_ms = 0.0;     // smoothed wall time between frames
  std::string status;        // last error, shown in red until the next success
};

/// Folds one frame's timings into the smoothed ones.
void record_frame(UiState& ui, const FrameTimings& frame, double frame_ms);

/// Builds this frame's panels (between ImGui::NewFrame and ImGui::Render).
void draw_panels(App& app, UiState& ui, float aspect);

}  // namespace ossa::view
