// spring.cpp — spring bone chains (see spring.h for the model and why it is shaped so).
//
// One pass over the chain, parents first, serves both the simulation step and the final pose:
// it rebuilds each joint's animated model matrix under its (already corrected) parent, finds the
// animated tail, optionally integrates the tail particle, and turns the joint onto its tail. The
// chain is short (a few to a few dozen joints) and every step is O(joints * colliders) with no
// allocation: the state vectors are sized in make_spring_chain.
#include <ossa/anim/spring.h>

#include "internal/rotation.h"

#include <algorithm>
#include <cmath>
#include <string>

namespace ossa {
namespace {

using detail::from_to;
using detail::orientation;

constexpr int kMaxStepsPerUpdate = 64;  // a longer dt (a hitch, a debugger pause) is dropped

glm::mat4 compose(const Transform& t) {
  glm::mat4 m = glm::mat4_cast(t.rotation);
  m[0] *= t.scale.x;
  m[1] *= t.scale.y;
  m[2] *= t.scale.z;
  m[3] = glm::vec4(t.translation, 1.0f);
  return m;
}

glm::mat4 base_of(const SpringChain& chain, std::span<const int16_t> parents, std::span<const glm::mat4> model) {
  const int16_t p = parents[chain.joints.front()];
  return p >= 0 && static_cast<size_t>(p) < model.size() ? model[static_cast<size_t>(p)] : glm::mat4(1.0f);
}

// The base between the last update's (f = 0) and this one's (f = 1).
glm::mat4 interpolate(const glm::mat4& a, const glm::mat4& b, float f) {
  const glm::quat r = glm::slerp(orientation(a), orientation(b), f);
  glm::mat4 m = glm::mat4_cast(r);
  for (int c = 0; c < 3; ++c) m[c] *= glm::length(glm::vec3(b[c]));
  m[3] = glm::vec4(glm::mix(glm::vec3(a[3]), glm::vec3(b[3]), f), 1.0f);
  return m;
}

// The joint's bone in its own local space: towards the next chain joint, or the last joint's
// tail (its offset from its parent's direction, settings.tail_length long).
glm::vec3 bone_of(const SpringChain& chain, ConstPoseSpan local, size_t i, const Transform& t) {
  if (i + 1 < chain.joints.size()) return get_transform(local, chain.joints[i + 1]).translation;
  const float len = glm::length(t.translation);
  const glm::vec3 dir = len > 1e-9f ? t.translation / len : glm::vec3(0.0f, 1.0f, 0.0f);
  return dir * chain.settings.tail_length;
}

glm::vec3 closest_on_segment(const glm::vec3& p, const glm::vec3& a, const glm::vec3& b) {
  const glm::vec3 ab = b - a;
  const float len2 = glm::dot(ab, ab);
  if (!(len2 > 0.0f)) return a;
  return a + ab * std::clamp(glm::dot(p - a, ab) / len2, 0.0f, 1.0f);
}

enum class Pass { Reset, Step, Pose };

// One parents-first pass (see the file comment). Step integrates the tails over h seconds;
// Reset puts them at the animated tails; Pose only turns the joints onto the current tails,
// carried `ahead` seconds further along their last step's velocity (the banked time, so the
// pose shown at a frame is the simulation's at that frame's time, not up to a step behind). The
// joints' new local rotations go to chain.scratch_rotation, their model matrices to `out` when
// given.
void pass(SpringChain& chain, Pass mode, float h, float ahead, const glm::mat4& base, ConstPoseSpan local,
          std::span<const glm::mat4> colliders_model, std::span<const SpringCollider> colliders,
          std::span<glm::mat4> out) {
  const SpringSettings& s = chain.settings;
  glm::mat4 parent = base;
  for (size_t i = 0; i < chain.joints.size(); ++i) {
    const uint16_t j = chain.joints[i];
    const Transform t = get_transform(local, j);
    const glm::mat4 animated = parent * compose(t);
    const glm::vec3 head(animated[3]);
    const glm::vec3 rest = glm::vec3(animated * glm::vec4(bone_of(chain, local, i, t), 1.0f));
    const float length = glm::length(rest - head);
    glm::vec3& current = chain.current[i];
    glm::vec3& previous = chain.previous[i];
    if (mode == Pass::Reset) {
      current = previous = rest;
    } else if (mode == Pass::Step) {
      const glm::vec3 velocity = (current - previous) * (1.0f - s.drag);
      glm::vec3 next = current + velocity + (rest - current) * std::min(1.0f, s.stiffness * h) + s.gravity * (h * h);
      const glm::vec3 d = next - head;
      const float dl = glm::length(d);
      if (length > 0.0f) next = head + (dl > 1e-9f ? d / dl : (rest - head) / length) * length;
      for (const SpringCollider& c : colliders) {
        if (c.joint >= colliders_model.size()) continue;
        const glm::mat4& cm = colliders_model[c.joint];
        const glm::vec3 a(cm * glm::vec4(c.offset, 1.0f)), b(cm * glm::vec4(c.tail, 1.0f));
        const glm::vec3 q = closest_on_segment(next, a, b);
        const float reach = c.radius + s.radius;
        const glm::vec3 away = next - q;
        const float dist = glm::length(away);
        if (dist >= reach) continue;
        // Out along the shortest way; a tail exactly on the axis goes out on the head's side.
        glm::vec3 dir = dist > 1e-9f ? away / dist : head - q;
        const float hl = glm::length(dir);
        dir = hl > 1e-9f ? dir / hl : glm::vec3(0.0f, 1.0f, 0.0f);
        next = q + dir * reach;
      }
      previous = current;
      current = next;
    }
    // Turn the joint from its animated bone direction onto its tail.
    glm::quat rotation = t.rotation;
    const glm::vec3 shown =
        mode == Pass::Pose && ahead > 0.0f ? current + (current - previous) * (ahead / s.step) : current;
    const glm::vec3 to_tail = shown - head;
    const float tl = glm::length(to_tail);
    if (length > 0.0f && tl > 1e-9f) {
      const glm::quat turn = from_to((rest - head) / length, to_tail / tl);
      const glm::quat frame = orientation(animated);
      rotation = glm::normalize(t.rotation * (glm::inverse(frame) * turn * frame));
    }
    chain.scratch_rotation[i] = rotation;
    Transform corrected = t;
    corrected.rotation = rotation;
    parent = parent * compose(corrected);
    if (!out.empty() && j < out.size()) out[j] = parent;
  }
}

bool finite3(const glm::vec3& v) { return std::isfinite(v.x) && std::isfinite(v.y) && std::isfinite(v.z); }

}  // namespace

Result<SpringChain> make_spring_chain(std::span<const int16_t> parents, std::span<const uint16_t> joints,
                                      const SpringSettings& settings) {
  if (joints.empty()) return Error{"spring chain: no joints"};
  for (size_t i = 0; i < joints.size(); ++i) {
    if (joints[i] >= parents.size())
      return Error{"spring chain: joint " + std::to_string(joints[i]) + " is not below the skeleton's joint count " +
                   std::to_string(parents.size())};
    if (i > 0 && parents[joints[i]] != static_cast<int16_t>(joints[i - 1]))
      return Error{"spring chain: joint " + std::to_string(joints[i]) + " is not a child of joint " +
                   std::to_string(joints[i - 1]) + " (a chain lists each joint's child next)"};
  }
  const SpringSettings& s = settings;
  if (!(s.step > 0.0f) || !std::isfinite(s.step)) return Error{"spring chain: step must be a finite number > 0"};
  if (!(s.drag >= 0.0f && s.drag <= 1.0f)) return Error{"spring chain: drag must be in [0, 1]"};
  if (!(s.stiffness >= 0.0f) || !std::isfinite(s.stiffness) || !finite3(s.gravity) || !(s.radius >= 0.0f) ||
      !std::isfinite(s.radius) || !(s.teleport_distance >= 0.0f) || !std::isfinite(s.teleport_distance) ||
      !(s.tail_length >= 0.0f) || !std::isfinite(s.tail_length))
    return Error{
        "spring chain: stiffness, radius, teleport_distance and tail_length must be finite and >= 0, "
        "gravity finite"};
  SpringChain chain;
  chain.joints.assign(joints.begin(), joints.end());
  chain.current.assign(joints.size(), glm::vec3(0.0f));
  chain.previous.assign(joints.size(), glm::vec3(0.0f));
  chain.scratch_rotation.assign(joints.size(), glm::quat(1.0f, 0.0f, 0.0f, 0.0f));
  chain.settings = settings;
  return chain;
}

void reset_spring_chain(SpringChain& chain, std::span<const int16_t> parents, ConstPoseSpan local,
                        std::span<const glm::mat4> model) {
  const glm::mat4 base = base_of(chain, parents, model);
  pass(chain, Pass::Reset, 0.0f, 0.0f, base, local, model, {}, {});
  chain.base_before = base;
  chain.banked = 0.0f;
  chain.started = true;
}

void update_spring_chain(SpringChain& chain, float dt, std::span<const int16_t> parents, PoseSpan local,
                         std::span<glm::mat4> model, std::span<const SpringCollider> colliders) {
  if (chain.joints.empty()) return;
  const glm::mat4 base = base_of(chain, parents, model);
  const float teleport = chain.settings.teleport_distance;
  if (!chain.started ||
      (teleport > 0.0f && glm::length(glm::vec3(base[3]) - glm::vec3(chain.base_before[3])) > teleport))
    reset_spring_chain(chain, parents, local, model);
  const float h = chain.settings.step;
  if (std::isfinite(dt) && dt > 0.0f) {
    const float banked_before = chain.banked;
    const float total = banked_before + dt;
    int steps = static_cast<int>(std::floor(total / h));
    chain.banked = total - static_cast<float>(steps) * h;
    if (steps > kMaxStepsPerUpdate) {
      steps = kMaxStepsPerUpdate;
      chain.banked = 0.0f;
    }
    for (int k = 1; k <= steps; ++k) {
      const float f = std::clamp((static_cast<float>(k) * h - banked_before) / dt, 0.0f, 1.0f);
      pass(chain, Pass::Step, h, 0.0f, interpolate(chain.base_before, base, f), local, model, colliders, {});
    }
  }
  chain.base_before = base;
  pass(chain, Pass::Pose, 0.0f, chain.banked, base, local, model, {}, model);
  for (size_t i = 0; i < chain.joints.size(); ++i) {
    Transform t = get_transform(local, chain.joints[i]);
    t.rotation = chain.scratch_rotation[i];
    set_transform(local, chain.joints[i], t);
  }
}

}  // namespace ossa
