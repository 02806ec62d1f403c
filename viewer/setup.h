// setup.h — turning command-line options into a running App, the same way for both front ends.
#pragma once
#include <ossa/format/result.h>
#include "viewer/app.h"
#include "viewer/options.h"

namespace ossa::view {

/// Applies the view options (camera angles, toggles), opens `scene` into `app` (whose renderer
/// must exist) and starts playback as asked: --clip (an error lists the clips when the name is
/// unknown), --time, --speed, --paused, --bind-pose, --graph and its --set values (errors list
/// the graphs or the parameters there are), --morph (an error lists the morph targets when the
/// name is unknown). Warnings (textures left out) go to stderr unless --quiet; --verbose adds the
/// GL version and renderer and the loaded scene's counts.
Status setup_app(App& app, Scene scene, const ViewerOptions& options, float aspect);

/// The view options alone (camera angles, toggles): what setup_app applies first, and all the
/// window applies when it starts with no file (it opens them later, from the browser or a cook).
void apply_view_options(App& app, const ViewerOptions& options);

}  // namespace ossa::view
