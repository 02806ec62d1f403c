// procedural_info.h — what a graph's procedural nodes expose to the viewer, and the small pieces
// of math the overlays, the panel and the mouse share.
//
// Shaped so because three front-end parts need the same facts about the procedural nodes (IK /
// aim targets, foot placement legs, spring chains and colliders) and none of them should walk the
// flatbuffer node tables every frame: describe_procedural reads them once, when a graph is
// instantiated (graph_driver.h keeps the result beside the definition), into plain vectors. The
// rest is pure math with no GL and no ImGui — where a target parameter is drawn, how a mouse drag
// in the view plane moves it, the ground normal a tilt angle gives — so the window mode, the
// headless mode and the tests move targets and ground the same way. This header depends only on
// the runtime (graph_driver.h includes it; the renderer must not be pulled in here).
#pragma once
#include <cstdint>
#include <span>
#include <string>
#include <vector>

#include <glm/glm.hpp>

#include <ossa/graph/graph.h>

namespace ossa::view {

/// A Vector parameter that an AimNode or TwoBoneIkNode reaches for (or bends towards): a gizmo.
struct TargetHandle {
  int parameter = -1;
  bool pole = false;   // a two-bone node's pole, not a target
  bool world = false;  // ParameterSpace::World (else model space)
  int node = -1;       // the first node that reads it (GraphInstance::reached)
  int effector = -1;   // the joint that reaches (aim: the chain's last), or -1
  std::string name;    // the parameter's name, for the panel
};

/// One leg of a FootPlacementNode.
struct FootLegInfo {
  uint16_t ankle = 0;
  int ground = -1;    // a Float parameter: the ground's height under the foot (model units), or -1
  int normal = -1;    // a Vector parameter: the ground's normal (model space), or -1
  bool left = false;  // the ankle's name says left (else: the first leg is the left one)
};

struct SpringChainInfo {
  std::vector<uint16_t> joints;
  float radius = 0.0f;
};

struct SpringColliderInfo {
  uint16_t joint = 0;
  glm::vec3 offset{0.0f}, tail{0.0f};  // in the joint's local space; tail == offset: a sphere
  float radius = 0.0f;
};

struct ProceduralInfo {
  std::vector<TargetHandle> targets;    // one per distinct parameter
  std::vector<FootLegInfo> legs;        // of every FootPlacementNode
  std::vector<SpringChainInfo> chains;  // of every SpringNode
  std::vector<SpringColliderInfo> colliders;
  bool empty() const { return targets.empty() && legs.empty() && chains.empty() && colliders.empty(); }
};

/// Reads the procedural nodes of `definition` once. O(nodes + chain joints + colliders).
ProceduralInfo describe_procedural(const GraphDefinition& definition);

/// Where handle `h` is drawn in the viewer's world: a model-space value is carried by the
/// instance's placement `offset`; a world-space value is where it says.
glm::vec3 handle_position(const GraphInstance& instance, const TargetHandle& h, const glm::vec3& offset);
/// The parameter value that puts handle `h` at world point `p` (the inverse of handle_position).
glm::vec3 handle_value(const TargetHandle& h, const glm::vec3& p, const glm::vec3& offset);

/// The ground normal for a slope of `degrees` about the character's x axis: +y turned towards +z.
glm::vec3 tilted_normal(float degrees);
/// The tilt (degrees about x) of a ground normal; 0 for a degenerate one.
float tilt_degrees(const glm::vec3& normal);

/// The centre of the ground patch under an ankle at `ankle` (model space) for ground height
/// `height` and unit normal `normal`: the point of that ground plane the ankle stands above along
/// the normal (foot placement keeps the clearance along the normal, so the foot lands on it), at
/// height `height` exactly (the plane passes there under the animated ankle).
glm::vec3 ground_point(const glm::vec3& ankle, float height, const glm::vec3& normal);

/// Window pixel (origin top left) of world point `p`, and its depth (< 0: behind the camera).
struct ScreenPoint {
  glm::vec2 pixel{0.0f};
  float w = 0.0f;
};
ScreenPoint project(const glm::mat4& view_projection, const glm::vec2& viewport, const glm::vec3& p);

/// The point among `points` whose projection is nearest `cursor` within `max_pixels` (and in
/// front of the camera), or -1.
int pick_point(const glm::mat4& view_projection, const glm::vec2& viewport, std::span<const glm::vec3> points,
               const glm::vec2& cursor, float max_pixels);

/// `p` moved in the camera's view plane by a mouse drag of (dx, dy) pixels (y down), so that it
/// stays under the cursor: `view` the view matrix, `fov_y` the vertical field of view, `height`
/// the viewport's height in pixels.
glm::vec3 drag_in_view_plane(const glm::vec3& p, const glm::mat4& view, float fov_y, float height, float dx, float dy);

}  // namespace ossa::view
