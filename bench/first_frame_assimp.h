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
#include <chrono>
#include <cstdint>
#include <span>
#include <string>

#include <ossa/format/result.h>
#include "viewer/window.h"

namespace ossa::bench {

/// Runs the child: prints "texture-bytes N" and "first-frame-ms X" (since main) once the frame is
/// finished, returns the exit status (1 with a message on stderr on failure). With several
/// sources, one context shows each in turn (one frame each, as a viewer opening them one after
/// another) and the time is to the last frame.
int run_assimp_first_frame(std::span<const std::string> sources, int width, int height, int samples);

/// The cooked side of the same: one context, each .ossa file opened with the viewer's own code
/// (load_scene, setup_app: upload, textures) and one frame drawn. Same output.
int run_ossa_first_frame(std::span<const std::string> files, int width, int height, int samples);

/// The floor under both: a child that makes the same hidden window, context and offscreen
/// framebuffer, clears it, finishes and prints "first-frame-ms X". What a side takes beyond this
/// is the work it does for its asset.
int run_empty_first_frame(int width, int height, int samples);

// What every child shares.

/// The hidden 64 x 64 window with the 3.3 core context each child makes first.
Result<view::Window> child_window();
/// The child's report: "texture-bytes N", then "first-frame-ms X" since `start` (the parent stops
/// reading at the second line).
void print_first_frame(uint64_t texture_bytes, std::chrono::steady_clock::time_point start);
/// 0 for success, else 1 with the message on stderr.
int exit_status(const Status& status);

}  // namespace ossa::bench
