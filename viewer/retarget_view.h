// retarget_view.h — the viewer's retarget mode: a clip of another humanoid rig played on the
// opened character through the live retarget job (ossa/retarget/retarget.h), with the source
// character drawn beside it and the joint mapping drawn between them.
//
//   ossa-view CesiumMan.ossa --retarget-from Pab/skeleton.ossa --retarget-from Pab/walk.ossa
//             [--retarget-map CesiumMan.humanoid.json] [--retarget-clip walk] [--show-mapping]
//
// The source files are opened as a scene of their own (scene.h: the first with a mesh is the
// source character, the others add clips cooked for it) with a Renderer and an Animator of their
// own, so the source is drawn with its own meshes and materials by the same render_frame, into
// the same framebuffer, before the opened character (RetargetView::renderer keeps its frame for
// the second pass: ViewToggles::keep_frame). Each frame the source clip is sampled at the
// source's time, and its pose retargeted into every instance of the opened character, in place of
// the character's own clip; the contact fix-up is not run (no held feet: the graph's retarget node
// and ossa-cook --retarget-to hold them).
//
// The source is drawn beside the character: its model space carried onto the character's by the
// retarget's own map (RetargetMap::map_point: its pelvis onto the character's, turned into the
// character's facing and scaled to its hips height), then moved aside by a character's width, so
// the two stand alike and a motion compares limb for limb. The mapping is a line per humanoid
// bone both rigs have, from the source's joint to the character's (left bones cyan, right
// magenta, the spine, neck and head yellow), drawn over everything (OverlayGeometry::on_top).
// Built on the CPU each frame into vectors that keep their capacity; no GL outside the Renderer.
#pragma once
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include <ossa/format/result.h>
#include <ossa/retarget/retarget.h>

#include "viewer/animation.h"
#include "viewer/bounds.h"
#include "viewer/renderer.h"
#include "viewer/scene.h"

namespace ossa::view {

struct RetargetView {
  Scene source;       // the source character and its clips
  Renderer renderer;  // its GPU form (create_renderer), released by release_retarget_view
  Animator animator;  // one instance playing the source clip
  RetargetMap map;
  RetargetScratch scratch;
  glm::mat4 place{1.0f};           // source model space -> the character's model space, beside it
  std::vector<std::string> files;  // what it was opened from (the panel lists them)
  std::string map_file;
  bool show_source = true;  // the panel's toggle: draw the source character
  Box framing;              // the source as first shown, which the camera frames with the character
};

/// Opens the source files, maps both rigs (by name, or the map file's sections: tools/retarget
/// map_file.h) and selects `clip` (empty: the source's first clip). Needs a GL context (it
/// uploads the source). Errors name the file and what is missing (every humanoid bone a rig
/// lacks), or list the source's clips when `clip` is not one of them.
Result<std::unique_ptr<RetargetView>> make_retarget_view(const Scene& target, std::span<const std::string> files,
                                                         const std::string& map_file, const std::string& clip);

/// Frees the source's GPU objects (the context must be current).
void release_retarget_view(RetargetView& view);

/// Advances the source's playback by dt (its own speed and loop), samples it, retargets its pose
/// into the local pose of every instance of `target`, and places the source's model matrices
/// beside the character (`one`: the character's bind-pose box, for the spacing). Allocation-free.
void retarget_poses(RetargetView& view, Animator& target, const Box& one, float dt);

/// Appends the mapping lines (source joint to instance 0's joint, `offset` its placement) to
/// `out.on_top`.
void build_mapping_lines(const RetargetView& view, const Animator& target, const glm::vec3& offset,
                         OverlayGeometry& out);

/// Bounds of the source as drawn (its meshes posed by the placed matrices; its joints when it has
/// none).
Box source_bounds(const RetargetView& view);

}  // namespace ossa::view
