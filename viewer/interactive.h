// interactive.h — ossa-view in a window: orbit camera, keyboard, Dear ImGui panels, drag and drop.
#pragma once
#include "viewer/options.h"

namespace ossa::view {

/// Runs until the window is closed. Returns the exit status (options.h): 2 after printing why no
/// window could be made, 1 after printing why the files could not be opened or shown.
int run_interactive(const ViewerOptions& options);

}  // namespace ossa::view
