// bounds.h — how big the character is, for framing the camera and sizing the grid.
//
// The box is the one the character is drawn in: every vertex skinned on the CPU (skin_cpu, the
// reference path) with the pose's palette, plus the joints. Boxes derived from each mesh's cooked
// bounds went through a palette matrix and needed guesses (whose matrix places the box; clipping a
// box implausibly larger than the skeleton), and those guesses cut off props and meshes larger than
// the skeleton; skinning the vertices needs none. It costs one CPU skin of the character, done
// when the camera is framed (a file is opened, the crowd changes, R is pressed), never per frame:
// about a millisecond for the largest shared character (AnimeBoy, 22,000 vertices). Morph targets
// are left out: the framing is the unmorphed character's, so holding a morph weight (a slider,
// --morph) never moves the camera and two renders that differ only in weights share their framing.
#pragma once
#include <limits>
#include <span>

#include <glm/glm.hpp>

#include <ossa/loader/asset.h>

namespace ossa::view {

struct Box {
  glm::vec3 min{std::numeric_limits<float>::max()};
  glm::vec3 max{-std::numeric_limits<float>::max()};

  bool empty() const { return min.x > max.x; }
  void add(glm::vec3 p) {
    min = glm::min(min, p);
    max = glm::max(max, p);
  }
  void add(const Box& b) {
    if (!b.empty()) {
      add(b.min);
      add(b.max);
    }
  }
  glm::vec3 centre() const { return (min + max) * 0.5f; }
  glm::vec3 size() const { return max - min; }
};

/// The character as drawn in a pose, in model space: its vertices skinned with `model` (one
/// model matrix per skeleton joint; empty for a file without skeleton, whose meshes are already
/// in model space) and its joints' positions. Non-finite skinned positions are left out.
/// Allocates one position buffer of the largest mesh. O(vertices * influences + joints).
Box posed_bounds(const Asset& asset, std::span<const glm::mat4> model);

/// Box of the joint positions of a posed skeleton (model matrices' translations). O(joints).
Box joint_bounds(std::span<const glm::mat4> model);

/// Which way a character faces, read from its skinned vertices in a pose (the bind pose), in the
/// model's Y-up space. The feet point forward: the vertices in the lowest 10 % of the height (feet,
/// shoes, paws) reach further forward than those of the next 25 % (shins, the legs above the
/// paws) reach backward, while sideways they are symmetric. The axis of the four horizontal ones
/// (+Z, -Z, +X, -X) along which the foot band's extent is most lopsided, relative to the band
/// above, is the front; when no axis stands out (lopsided by less than 1.5 % of the height:
/// a ball, a figure without feet) it is +Z, glTF's convention (and most exporters' "forward").
/// A skeleton without a mesh (a BVH capture) is judged by its joints the same way.
struct Facing {
  glm::vec3 forward{0.0f, 0.0f, 1.0f};  // unit, one of the four horizontal axes
  float yaw = 0.0f;                     // radians about +Y from +Z to `forward`
  float evidence = 0.0f;                // the lopsidedness found along `forward`, in units of the height
  bool from_feet = false;               // false: the +Z default
};
Facing facing_of(const Asset& asset, std::span<const glm::mat4> model);
/// "+z", "-z", "+x" or "-x".
const char* axis_name(glm::vec3 forward);

}  // namespace ossa::view
