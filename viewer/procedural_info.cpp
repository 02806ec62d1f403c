// procedural_info.cpp — see procedural_info.h.
#include "viewer/procedural_info.h"

#include <algorithm>
#include <cctype>
#include <cmath>

namespace ossa::view {
namespace {

bool says_left(std::string_view name) {
  std::string lower(name);
  for (char& c : lower) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  if (lower.find("left") != std::string::npos) return true;
  const size_t n = lower.size();
  return n >= 2 && (lower.compare(n - 2, 2, "_l") == 0 || lower.compare(n - 2, 2, ".l") == 0);
}

void add_target(ProceduralInfo& info, const GraphDefinition& def, int parameter, bool pole, int node, int effector) {
  if (parameter < 0 || static_cast<size_t>(parameter) >= def.parameter_count()) return;
  if (def.parameter_type(static_cast<size_t>(parameter)) != fb::ParameterType::Vector) return;
  for (const TargetHandle& t : info.targets)
    if (t.parameter == parameter) return;
  TargetHandle h;
  h.parameter = parameter;
  h.pole = pole;
  h.node = node;
  h.effector = effector;
  h.name = std::string(def.parameter_name(static_cast<size_t>(parameter)));
  const fb::Parameter* p = def.graph().parameters()->Get(static_cast<flatbuffers::uoffset_t>(parameter));
  h.world = p->space() == fb::ParameterSpace::World;
  info.targets.push_back(std::move(h));
}

glm::vec3 vec(const fb::Vec3& v) { return {v.x(), v.y(), v.z()}; }

}  // namespace

ProceduralInfo describe_procedural(const GraphDefinition& def) {
  ProceduralInfo info;
  const auto* nodes = def.graph().nodes();
  if (nodes == nullptr) return info;
  const SkeletonView skeleton = def.skeleton();
  for (flatbuffers::uoffset_t i = 0; i < nodes->size(); ++i) {
    const fb::Node& n = *nodes->Get(i);
    const int node = static_cast<int>(i);
    switch (n.data_type()) {
      case fb::NodeData::TwoBoneIkNode: {
        const fb::TwoBoneIkNode& t = *n.data_as_TwoBoneIkNode();
        add_target(info, def, t.target_parameter(), false, node, t.end());
        add_target(info, def, t.pole_parameter(), true, node, t.mid());
        break;
      }
      case fb::NodeData::AimNode: {
        const fb::AimNode& a = *n.data_as_AimNode();
        const int effector = a.chain()->size() > 0 ? a.chain()->Get(a.chain()->size() - 1)->joint() : -1;
        add_target(info, def, a.target_parameter(), false, node, effector);
        break;
      }
      case fb::NodeData::FootPlacementNode: {
        const fb::FootPlacementNode& f = *n.data_as_FootPlacementNode();
        const size_t first = info.legs.size();
        bool any_named = false;
        for (const fb::FootLeg* leg : *f.legs()) {
          FootLegInfo l;
          l.ankle = leg->ankle();
          l.ground = leg->ground_parameter();
          l.normal = leg->normal_parameter();
          l.left = says_left(skeleton.joint_name(leg->ankle()));
          any_named = any_named || l.left;
          info.legs.push_back(l);
        }
        if (!any_named && info.legs.size() > first) info.legs[first].left = true;
        break;
      }
      case fb::NodeData::SpringNode: {
        const fb::SpringNode& s = *n.data_as_SpringNode();
        for (const fb::SpringChainSettings* c : *s.chains()) {
          SpringChainInfo chain;
          chain.joints.assign(c->joints()->begin(), c->joints()->end());
          chain.radius = c->radius();
          info.chains.push_back(std::move(chain));
        }
        if (s.colliders() != nullptr) {
          for (const fb::SpringColliderShape* c : *s.colliders())
            info.colliders.push_back(SpringColliderInfo{c->joint(), vec(c->offset()), vec(c->tail()), c->radius()});
        }
        break;
      }
      default: break;
    }
  }
  // Joints out of range would index past the model matrices: validation forbids them, but the
  // overlays must not trust that.
  const auto joints = static_cast<uint32_t>(def.joint_count());
  std::erase_if(info.legs, [&](const FootLegInfo& l) { return l.ankle >= joints; });
  std::erase_if(info.colliders, [&](const SpringColliderInfo& c) { return c.joint >= joints; });
  for (SpringChainInfo& c : info.chains) std::erase_if(c.joints, [&](uint16_t j) { return j >= joints; });
  for (TargetHandle& t : info.targets)
    if (t.effector >= static_cast<int>(joints)) t.effector = -1;
  return info;
}

glm::vec3 handle_position(const GraphInstance& instance, const TargetHandle& h, const glm::vec3& offset) {
  const glm::vec3 v = instance.vector(h.parameter);
  return h.world ? v : v + offset;
}

glm::vec3 handle_value(const TargetHandle& h, const glm::vec3& p, const glm::vec3& offset) {
  return h.world ? p : p - offset;
}

glm::vec3 tilted_normal(float degrees) {
  const float a = glm::radians(std::clamp(degrees, -89.0f, 89.0f));
  return {0.0f, std::cos(a), std::sin(a)};
}

float tilt_degrees(const glm::vec3& n) {
  if (!(std::fabs(n.y) + std::fabs(n.z) > 1e-6f)) return 0.0f;
  return glm::degrees(std::atan2(n.z, n.y));
}

glm::vec3 ground_point(const glm::vec3& ankle, float height, const glm::vec3& normal) {
  // Foot placement puts the ankle at G + normal * clearance, G = (x, height, z) under the animated
  // ankle: so G is the ankle moved back along the normal until its height is `height`.
  if (!(normal.y > 1e-3f)) return glm::vec3(ankle.x, height, ankle.z);
  return ankle - normal * ((ankle.y - height) / normal.y);
}

ScreenPoint project(const glm::mat4& view_projection, const glm::vec2& viewport, const glm::vec3& p) {
  const glm::vec4 c = view_projection * glm::vec4(p, 1.0f);
  ScreenPoint s;
  s.w = c.w;
  if (std::fabs(c.w) < 1e-12f) return s;
  const glm::vec2 ndc(c.x / c.w, c.y / c.w);
  s.pixel = glm::vec2((ndc.x * 0.5f + 0.5f) * viewport.x, (0.5f - ndc.y * 0.5f) * viewport.y);
  return s;
}

int pick_point(const glm::mat4& view_projection, const glm::vec2& viewport, std::span<const glm::vec3> points,
               const glm::vec2& cursor, float max_pixels) {
  int best = -1;
  float best_d = max_pixels;
  for (size_t i = 0; i < points.size(); ++i) {
    const ScreenPoint s = project(view_projection, viewport, points[i]);
    if (!(s.w > 0.0f)) continue;
    const float d = glm::length(s.pixel - cursor);
    if (d <= best_d) {
      best_d = d;
      best = static_cast<int>(i);
    }
  }
  return best;
}

glm::vec3 drag_in_view_plane(const glm::vec3& p, const glm::mat4& view, float fov_y, float height, float dx, float dy) {
  const glm::vec3 right(view[0][0], view[1][0], view[2][0]), up(view[0][1], view[1][1], view[2][1]);
  const float depth = std::max(-(view * glm::vec4(p, 1.0f)).z, 1e-4f);
  const float per_pixel = 2.0f * depth * std::tan(0.5f * fov_y) / std::max(height, 1.0f);
  return p + right * (dx * per_pixel) - up * (dy * per_pixel);
}

}  // namespace ossa::view
