// interactive.h — ossa-view in a window: orbit camera, keyboard, Dear ImGui panels, drag and drop.
//
// The scene is drawn beside the panel (layout.h), files and sources are opened and cooked behind
// a loading indicator (cook_job.h), and the window may start with no file at all (the panel's
// file browser). --window-frames N counts frames once no open or cook is pending.
#pragma once
#include "viewer/options.h"

namespace ossa::view {

/// Runs until the window is closed. Returns the exit status (options.h): 2 after printing why no
/// window could be made, 1 after printing why the files could not be opened or shown.
int run_interactive(const ViewerOptions& options);

}  // namespace ossa::view
