// procedural_draw.cpp — see procedural_draw.h.
#include "viewer/procedural_draw.h"

#include <algorithm>
#include <array>
#include <cmath>

namespace ossa::view {
namespace {

constexpr glm::vec4 kAxisX{0.95f, 0.25f, 0.25f, 1.0f};
constexpr glm::vec4 kAxisY{0.3f, 0.95f, 0.3f, 1.0f};
constexpr glm::vec4 kAxisZ{0.3f, 0.5f, 1.0f, 1.0f};
constexpr glm::vec4 kTarget{1.0f, 0.9f, 0.2f, 1.0f};
constexpr glm::vec4 kPole{0.95f, 0.3f, 0.95f, 1.0f};
constexpr glm::vec4 kActive{1.0f, 1.0f, 1.0f, 1.0f};
constexpr glm::vec4 kReached{0.3f, 1.0f, 0.45f, 0.8f};
constexpr glm::vec4 kNotReached{0.6f, 0.6f, 0.6f, 0.6f};
constexpr glm::vec4 kGroundFill{0.25f, 0.65f, 0.45f, 0.35f};
constexpr glm::vec4 kGroundLine{0.45f, 0.95f, 0.6f, 0.9f};
constexpr glm::vec4 kChain{0.2f, 0.9f, 1.0f, 1.0f};
constexpr glm::vec4 kCollider{0.85f, 0.45f, 1.0f, 0.9f};  // violet: visible on an orange fox

constexpr int kCircleSegments = 20;
constexpr int kPatchCells = 4;

/// The unit circle, computed once.
const std::array<glm::vec2, kCircleSegments + 1>& unit_circle() {
  static const std::array<glm::vec2, kCircleSegments + 1> circle = [] {
    std::array<glm::vec2, kCircleSegments + 1> c{};
    for (int i = 0; i <= kCircleSegments; ++i) {
      const float a = 6.2831853f * static_cast<float>(i) / kCircleSegments;
      c[static_cast<size_t>(i)] = glm::vec2(std::cos(a), std::sin(a));
    }
    return c;
  }();
  return circle;
}

void line(std::vector<LineVertex>& v, const glm::vec3& a, const glm::vec3& b, const glm::vec4& color) {
  v.push_back({a, color});
  v.push_back({b, color});
}

void circle(std::vector<LineVertex>& v, const glm::vec3& c, const glm::vec3& u, const glm::vec3& w, float r,
            const glm::vec4& color) {
  const auto& unit = unit_circle();
  for (int i = 0; i < kCircleSegments; ++i) {
    const glm::vec2 a = unit[static_cast<size_t>(i)], b = unit[static_cast<size_t>(i) + 1];
    line(v, c + r * (a.x * u + a.y * w), c + r * (b.x * u + b.y * w), color);
  }
}

/// Two unit vectors perpendicular to unit `d` and to each other.
void perpendiculars(const glm::vec3& d, glm::vec3& u, glm::vec3& w) {
  const glm::vec3 helper = std::fabs(d.y) < 0.9f ? glm::vec3(0.0f, 1.0f, 0.0f) : glm::vec3(1.0f, 0.0f, 0.0f);
  u = glm::normalize(glm::cross(d, helper));
  w = glm::cross(d, u);
}

void wire_sphere(std::vector<LineVertex>& v, const glm::vec3& c, float r, const glm::vec3& axis,
                 const glm::vec4& color) {
  glm::vec3 u, w;
  perpendiculars(axis, u, w);
  circle(v, c, u, w, r, color);
  circle(v, c, axis, u, r, color);
  circle(v, c, axis, w, r, color);
}

void cross_marker(std::vector<LineVertex>& v, const glm::vec3& p, float s, const glm::vec4& color) {
  line(v, p - glm::vec3(s, 0, 0), p + glm::vec3(s, 0, 0), color);
  line(v, p - glm::vec3(0, s, 0), p + glm::vec3(0, s, 0), color);
  line(v, p - glm::vec3(0, 0, s), p + glm::vec3(0, 0, s), color);
}

void target_gizmo(std::vector<LineVertex>& v, const glm::vec3& p, float s, const glm::vec4& diamond, bool active) {
  line(v, p - glm::vec3(s, 0, 0), p + glm::vec3(s, 0, 0), active ? kActive : kAxisX);
  line(v, p - glm::vec3(0, s, 0), p + glm::vec3(0, s, 0), active ? kActive : kAxisY);
  line(v, p - glm::vec3(0, 0, s), p + glm::vec3(0, 0, s), active ? kActive : kAxisZ);
  // An octahedron's twelve edges, 0.4 s across.
  const float d = 0.4f * s;
  const glm::vec3 tips[6] = {{d, 0, 0}, {-d, 0, 0}, {0, d, 0}, {0, -d, 0}, {0, 0, d}, {0, 0, -d}};
  const glm::vec4 c = active ? kActive : diamond;
  for (int a = 0; a < 2; ++a) {
    for (int b = 2; b < 6; ++b) line(v, p + tips[a], p + tips[b], c);
  }
  for (int a = 2; a < 4; ++a) {
    for (int b = 4; b < 6; ++b) line(v, p + tips[a], p + tips[b], c);
  }
}

glm::vec3 position(const glm::mat4& m) { return glm::vec3(m[3]); }

void targets(const GraphDriver& g, const AnimInstance& shown, const glm::vec3& offset, float size, int active,
             OverlayGeometry& out) {
  const GraphInstance& inst = g.instances.front();
  const float s = 0.06f * size;
  for (size_t i = 0; i < g.procedural.targets.size(); ++i) {
    const TargetHandle& h = g.procedural.targets[i];
    const glm::vec3 p = handle_position(inst, h, offset);
    target_gizmo(out.on_top, p, s, h.pole ? kPole : kTarget, static_cast<int>(i) == active);
    if (h.effector >= 0 && static_cast<size_t>(h.effector) < shown.model.size() && h.node >= 0 &&
        inst.node_weight(static_cast<size_t>(h.node)) > 0.0f) {
      const bool reached = !h.pole && inst.reached(static_cast<size_t>(h.node));
      line(out.on_top, position(shown.model[static_cast<size_t>(h.effector)]) + offset, p,
           reached ? kReached : kNotReached);
    }
  }
}

void ground_patches(const GraphDriver& g, const GraphInstance& inst, const AnimInstance& shown, const glm::vec3& offset,
                    float size, OverlayGeometry& out) {
  const glm::vec3 up(0.0f, 1.0f, 0.0f);
  const float half = 0.2f * size;
  for (const FootLegInfo& leg : g.procedural.legs) {
    if (leg.ankle >= shown.model.size()) continue;
    const float height = leg.ground >= 0 ? inst.value(leg.ground) : 0.0f;
    glm::vec3 n = leg.normal >= 0 ? inst.vector(leg.normal) : up;
    const float len = glm::length(n);
    n = len > 1e-6f && glm::dot(n, up) > 0.05f * len ? n / len : up;  // as the node: a wall is no ground
    const glm::vec3 c =
        ground_point(position(shown.model[leg.ankle]), std::isfinite(height) ? height : 0.0f, n) + offset;
    // Patch axes: the character's x kept in the plane, and the slope's direction.
    glm::vec3 a = glm::cross(n, glm::vec3(0.0f, 0.0f, 1.0f));
    a = glm::length(a) > 1e-4f ? glm::normalize(a) : glm::vec3(1.0f, 0.0f, 0.0f);
    const glm::vec3 b = glm::normalize(glm::cross(a, n));
    const glm::vec3 corner[4] = {c - half * a - half * b, c + half * a - half * b, c + half * a + half * b,
                                 c - half * a + half * b};
    const glm::vec3 lift = n * (0.002f * size);  // off the plane a little: the lines stay visible over the fill
    out.ground_fill.push_back({corner[0], kGroundFill});
    out.ground_fill.push_back({corner[1], kGroundFill});
    out.ground_fill.push_back({corner[2], kGroundFill});
    out.ground_fill.push_back({corner[0], kGroundFill});
    out.ground_fill.push_back({corner[2], kGroundFill});
    out.ground_fill.push_back({corner[3], kGroundFill});
    for (int k = 0; k <= kPatchCells; ++k) {
      const float f = -half + 2.0f * half * static_cast<float>(k) / kPatchCells;
      line(out.ground_lines, c + f * a - half * b + lift, c + f * a + half * b + lift, kGroundLine);
      line(out.ground_lines, c - half * a + f * b + lift, c + half * a + f * b + lift, kGroundLine);
    }
  }
}

void springs(const GraphDriver& g, const AnimInstance& shown, const glm::vec3& offset, float size,
             OverlayGeometry& out) {
  const size_t joints = shown.model.size();
  for (const SpringChainInfo& chain : g.procedural.chains) {
    const float s = std::max(chain.radius, 0.01f * size);
    for (size_t k = 0; k < chain.joints.size(); ++k) {
      if (chain.joints[k] >= joints) continue;
      const glm::vec3 p = position(shown.model[chain.joints[k]]) + offset;
      cross_marker(out.on_top, p, s, kChain);
      if (k + 1 < chain.joints.size() && chain.joints[k + 1] < joints)
        line(out.on_top, p, position(shown.model[chain.joints[k + 1]]) + offset, kChain);
    }
  }
  for (const SpringColliderInfo& c : g.procedural.colliders) {
    if (c.joint >= joints) continue;
    const glm::mat4& m = shown.model[c.joint];
    const glm::vec3 a = glm::vec3(m * glm::vec4(c.offset, 1.0f)) + offset;
    const glm::vec3 b = glm::vec3(m * glm::vec4(c.tail, 1.0f)) + offset;
    const float length = glm::length(b - a);
    if (length < 1e-6f * std::max(size, 1e-6f)) {
      wire_sphere(out.on_top, a, c.radius, glm::vec3(0.0f, 1.0f, 0.0f), kCollider);
      continue;
    }
    const glm::vec3 d = (b - a) / length;
    glm::vec3 u, w;
    perpendiculars(d, u, w);
    wire_sphere(out.on_top, a, c.radius, d, kCollider);
    wire_sphere(out.on_top, b, c.radius, d, kCollider);
    line(out.on_top, a + c.radius * u, b + c.radius * u, kCollider);
    line(out.on_top, a - c.radius * u, b - c.radius * u, kCollider);
    line(out.on_top, a + c.radius * w, b + c.radius * w, kCollider);
    line(out.on_top, a - c.radius * w, b - c.radius * w, kCollider);
  }
}

}  // namespace

void build_procedural_overlay(const Animator& animator, std::span<const glm::vec3> offsets, float size, int active,
                              OverlayGeometry& out) {
  out.clear();
  if (!animator.graph || !animator.use_graph || animator.graph->instances.empty() || animator.instances.empty()) return;
  const GraphDriver& g = *animator.graph;
  if (g.procedural.empty()) return;
  const auto offset_of = [&](size_t i) { return i < offsets.size() ? offsets[i] : glm::vec3(0.0f); };
  targets(g, animator.instances.front(), offset_of(0), size, active, out);
  const size_t n = std::min(animator.instances.size(), g.instances.size());
  for (size_t i = 0; i < n; ++i) {
    ground_patches(g, g.instances[i], animator.instances[i], offset_of(i), size, out);
    springs(g, animator.instances[i], offset_of(i), size, out);
  }
}

void handle_positions(const Animator& animator, std::span<const glm::vec3> offsets, std::vector<glm::vec3>& out) {
  out.clear();
  if (!animator.graph || animator.graph->instances.empty()) return;
  const GraphDriver& g = *animator.graph;
  const glm::vec3 offset = offsets.empty() ? glm::vec3(0.0f) : offsets.front();
  for (const TargetHandle& h : g.procedural.targets) out.push_back(handle_position(g.instances.front(), h, offset));
}

}  // namespace ossa::view
