// ui.h — the Dear ImGui panels: clip list and playback, morph target weights, view toggles,
// crowd, stats, a file browser (file_browser.h) and the open field; the loading indicator.
//
// The panel is a sidebar pinned to the window's left edge, full height, its width scaled with the
// UI scale (layout.h): the scene is drawn in the rest of the window, so the panel never hides the
// character; its sections share its height (panel_fit.h), so it fits any window. "Hide panel" (or Tab) collapses it to
// a small button and gives the scene the whole width. A click on an .ossa in the browser, or Open, is a request
// (cook_job.h): the indicator says "loading NAME..." for a frame before the open runs; a source file is cooked in the
// background, the indicator showing a spinner, the elapsed time and the file name.
//
// Immediate mode: every frame the panels read the App and write back what the user changed, so
// there is no UI state to keep in sync beyond the text field and the smoothed timings. With a
// graph, its panel shows one widget per parameter (slider, checkbox, combo, trigger button), each
// state machine's state and running transition, the weights of the nodes that contributed to the
// pose, and the events the graph reported. With morph targets, one slider per channel shows the
// weight the clip gives it live, and holds it where the user moves it (a tick box per channel).
#pragma once
#include <string>
#include <vector>

#include "viewer/app.h"
#include "viewer/file_browser.h"
#include "viewer/layout.h"
#include "viewer/panel_fit.h"
#include "viewer/cook_job.h"

namespace ossa::view {

struct UiState {
  char open_path[1024] = {};
  FrameTimings smoothed;              // exponential moving average of the per-frame timings
  double frame_ms = 0.0;              // smoothed wall time between frames
  std::string status;                 // last error, shown in red until the next success
  bool graph_slider_touched = false;  // the user moved a graph's `speed` this frame
  bool panel_open = true;             // false: collapsed to a button, the scene takes the whole window
  float ui_scale = 1.0f;              // layout.h ui_scale_for, or --ui-scale
  FileBrowser browser;
  TimelineState timeline;
  PendingWork work;                  // opens and cooks in progress
  std::vector<SectionFit> sections;  // what each open section needed when last drawn (panel_fit.h)
  float footer_height = 0.0f;        // the help and status lines' height when last drawn
  PanelAudit audit;                  // this frame's panel regions (panel_fit.h): printed by -v, checked by the tests
};

/// The panel's width in window units for the UI state (0 when collapsed).
float panel_width(const UiState& ui);

/// Folds one frame's timings into the smoothed ones.
void record_frame(UiState& ui, const FrameTimings& frame, double frame_ms);

/// Builds this frame's panels (between ImGui::NewFrame and ImGui::Render): the sidebar (or, when
/// collapsed, the button that opens it), the timeline under the scene and the loading indicator
/// over it. `layout` is this frame's (layout.h); its aspect frames the camera.
void draw_panels(App& app, UiState& ui, const SceneLayout& layout);

}  // namespace ossa::view
