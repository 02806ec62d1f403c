// first_frame_assimp.h — the comparison side of ossa-bench-first-frame: the same character shown
// the way a viewer without a cooker would do it, in its own process.
//
// Import the source with Assimp (the cooker's flags plus smooth normals and the 4-weight limit a
// GPU skinning shader needs), build interleaved float vertex buffers and per-vertex joint slots /
// weights from Assimp's per-bone weight lists, compute the bind palette from the node hierarchy,
// decode diffuse textures with stb_image, upload, compile a skinning + Phong program, and draw one
// frame into the same offscreen framebuffer the viewer's headless mode uses. Everything a cooked
// file makes unnecessary is here, and nothing more.
#pragma once
#include <string>

namespace ossa::bench {

/// Runs the child: prints "first-frame-ms X" (since main) once the frame is finished, returns the
/// exit status (1 with a message on stderr on failure).
int run_assimp_first_frame(const std::string& source, int width, int height, int samples);

}  // namespace ossa::bench
