// graph_keys.cpp — see graph_keys.h.
#include "viewer/graph_keys.h"

#include <algorithm>

#include "viewer/gl.h"
#include "viewer/montage_control.h"

namespace ossa::view {
namespace {

constexpr float kEasePerSecond = 3.0f;

}  // namespace

KeySpeeds key_speeds(const GraphDriver& graph) {
  KeySpeeds k;
  const int speed = graph_parameter(graph, "speed");
  if (speed < 0) return k;
  for (const fb::Node* node : *graph.definition->graph().nodes()) {
    const fb::BlendSpaceNode* b = node->data_as_BlendSpaceNode();
    if (b == nullptr || b->x_parameter() != speed || b->samples()->size() < 2) continue;
    float lo = b->samples()->Get(0)->x(), hi = lo;
    for (const fb::BlendSample* smp : *b->samples()) {
      lo = std::min(lo, smp->x());
      hi = std::max(hi, smp->x());
    }
    return KeySpeeds{lo, hi};
  }
  return k;
}

bool graph_key(GraphDriver& graph, GraphKeys& keys, int key, int action) {
  const bool down = action != GLFW_RELEASE;
  if (key == GLFW_KEY_LEFT_SHIFT || key == GLFW_KEY_RIGHT_SHIFT) {
    keys.run = down;
    return true;
  }
  if (key == GLFW_KEY_W && graph_parameter(graph, "speed") >= 0) {
    if (action == GLFW_PRESS && !keys.driving) {
      keys.driving = true;
      keys.speed = graph.instances.empty() ? 0.0f : graph.instances.front().value(graph_parameter(graph, "speed"));
    }
    if (action != GLFW_REPEAT) keys.walk = down;
    return true;
  }
  if (key == GLFW_KEY_M && action == GLFW_PRESS) return toggle_montage(graph);
  if (key == GLFW_KEY_C && action == GLFW_PRESS) {
    const int arms = graph_parameter(graph, "crossed_arms");
    if (arms < 0 || graph.instances.empty()) return false;
    set_graph_value(graph, arms, graph.instances.front().value(arms) != 0.0f ? 0.0f : 1.0f);
    return true;
  }
  return false;
}

void drive_graph_keys(GraphDriver& graph, GraphKeys& keys, float dt) {
  const int speed = graph_parameter(graph, "speed");
  if (!keys.driving || speed < 0) return;
  const KeySpeeds k = key_speeds(graph);
  const float target = keys.walk ? (keys.run ? k.run : k.walk) : 0.0f;
  const float step = kEasePerSecond * dt;
  keys.speed = keys.speed < target ? std::min(target, keys.speed + step) : std::max(target, keys.speed - step);
  set_graph_value(graph, speed, keys.speed);
}

}  // namespace ossa::view
