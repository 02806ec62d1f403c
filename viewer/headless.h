// headless.h — ossa-view without a user: render frames, write a PNG, exit.
//
// This is what the tests, the README screenshot and the first-frame benchmark drive. It runs the
// same App as the window mode in a hidden window, drawing into an offscreen framebuffer, and it
// is strict: any failure — a file that does not open, no mesh, no GL 3.3 context, a shader that
// does not compile, any glGetError after setup or after a frame — ends it with a message naming
// the file and a non-zero status, never a silently wrong image.
#pragma once
#include "viewer/options.h"

namespace ossa::view {

/// Returns the process exit status (options.h): 0; or after printing "ossa-view: <what failed>" to
/// stderr, 2 when no window could be made, 1 for any other failure.
int run_headless(const ViewerOptions& options);

}  // namespace ossa::view
