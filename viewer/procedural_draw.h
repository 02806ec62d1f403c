// procedural_draw.h — the overlays of a graph's procedural nodes: target gizmos, the ground
// under each placed foot, spring chains and their colliders.
//
// Shaped so because the renderer already draws coloured lines (the skeleton, the grid) with one
// tiny program: these overlays are more of the same, built on the CPU each frame into the
// Renderer's OverlayGeometry (whose vectors keep their capacity, so a steady scene allocates
// nothing) and drawn by render_frame after the mesh. Building is separate from drawing so it reads
// only the animator's model matrices and the graph's parameter values (procedural_info.h says
// which), with no GL, and so the window mode and the headless screenshots draw the same thing.
//
// What is drawn, in the viewer's world (model space carried by each instance's placement):
//  - every IK / aim target or pole parameter: a 3-axis cross and a small diamond (instance 0's
//    value; a pole in magenta), and a line from the joint that reaches for it, green when the node
//    reached the target in the last update, grey when not; the handle being dragged is white;
//  - per foot placement leg and instance: a translucent ground patch with a grid, centred where the
//    foot lands, at the leg's ground height and tilted to its normal;
//  - per spring chain and instance: lines through the chain's joints with a cross at each; per
//    collider: a wire sphere, or a capsule (two end spheres and four side lines), placed by its
//    joint's model matrix.
#pragma once
#include <span>

#include <glm/glm.hpp>

#include "viewer/animation.h"
#include "viewer/renderer.h"

namespace ossa::view {

/// Rebuilds `out` for the graph driving `animator` (nothing without one). `size` is the
/// character's radius (the markers and patches are sized from it); `active` the handle index
/// (ProceduralInfo::targets) being dragged, or -1. O(instances * (legs + chain joints +
/// colliders)); allocation-free once the vectors have grown.
void build_procedural_overlay(const Animator& animator, std::span<const glm::vec3> offsets, float size, int active,
                              OverlayGeometry& out);

/// World positions of the target handles (instance 0), for picking; `out` is resized.
void handle_positions(const Animator& animator, std::span<const glm::vec3> offsets, std::vector<glm::vec3>& out);

}  // namespace ossa::view
