// interactive.h — ossa-view in a window: orbit camera, keyboard, Dear ImGui panels, drag and drop.
#pragma once
#include "viewer/options.h"

namespace ossa::view {

/// Runs until the window is closed. Returns the exit status (1 after printing why the window or
/// the files could not be opened).
int run_interactive(const ViewerOptions& options);

}  // namespace ossa::view
