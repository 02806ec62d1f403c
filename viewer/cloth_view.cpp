// cloth_view.cpp — see cloth_view.h.
#include "viewer/cloth_view.h"

#include <algorithm>
#include <cmath>

#include <glm/gtc/matrix_transform.hpp>

#include <ossa/skinning/skinning.h>
#include "viewer/animation.h"
#include "viewer/renderer.h"
#include "viewer/scene.h"

namespace ossa::view {
namespace {

constexpr glm::vec4 kFixed{1.0f, 0.25f, 0.2f, 1.0f};
constexpr glm::vec4 kFree{1.0f, 0.9f, 0.3f, 1.0f};
constexpr glm::vec4 kEdge{0.9f, 0.9f, 0.9f, 0.35f};
constexpr glm::vec4 kCollider{0.3f, 0.8f, 1.0f, 0.8f};

void line(std::vector<LineVertex>& v, const glm::vec3& a, const glm::vec3& b, const glm::vec4& c) {
  v.push_back({a, c});
  v.push_back({b, c});
}

void ring(std::vector<LineVertex>& v, const glm::vec3& c, const glm::vec3& u, const glm::vec3& w, float r,
          const glm::vec4& colour) {
  constexpr int kSegments = 16;
  for (int i = 0; i < kSegments; ++i) {
    const float a = 6.2831853f * static_cast<float>(i) / kSegments;
    const float b = 6.2831853f * static_cast<float>(i + 1) / kSegments;
    line(v, c + r * (std::cos(a) * u + std::sin(a) * w), c + r * (std::cos(b) * u + std::sin(b) * w), colour);
  }
}

/// A capsule (or a sphere when a == b) as three rings at each end and four lines along it.
void capsule(std::vector<LineVertex>& v, const glm::vec3& a, const glm::vec3& b, float r) {
  const glm::vec3 d = glm::length(b - a) > 1e-6f ? glm::normalize(b - a) : glm::vec3(0.0f, 1.0f, 0.0f);
  const glm::vec3 helper = std::fabs(d.y) < 0.9f ? glm::vec3(0.0f, 1.0f, 0.0f) : glm::vec3(1.0f, 0.0f, 0.0f);
  const glm::vec3 u = glm::normalize(glm::cross(d, helper)), w = glm::cross(d, u);
  for (const glm::vec3& c : {a, b}) {
    ring(v, c, u, w, r, kCollider);
    ring(v, c, d, u, r, kCollider);
    ring(v, c, d, w, r, kCollider);
  }
  for (const glm::vec3& s : {u, -u, w, -w}) line(v, a + r * s, b + r * s, kCollider);
}

}  // namespace

const ClothInstance* ViewerCloth::find(size_t instance, size_t mesh) const {
  if (!enabled) return nullptr;
  for (const ClothSim& s : sims)
    if (s.instance == instance && s.mesh == mesh) return &s.state;
  return nullptr;
}

Result<ViewerCloth> make_viewer_cloth(const Scene& scene, size_t instances) {
  ViewerCloth out;
  if (scene.assets.empty()) return out;
  const Asset& character = scene.character();
  size_t slots = 0, particles = 0;
  for (size_t m = 0; m < character.mesh_count(); ++m) {
    const MeshView mesh = character.mesh(m);
    if (!mesh.fb->cloth()) continue;
    const ClothSource source = cloth_source(mesh);
    for (size_t i = 0; i < instances; ++i) {
      Result<ClothInstance> state = make_cloth_instance(source, mesh.vertex_count(), scene.joint_count());
      if (!state) return Error{scene.paths.front() + ": mesh " + std::to_string(m) + ": " + state.error().message};
      out.sims.push_back(ClothSim{i, m, std::move(*state), glm::vec3(0.0f)});
    }
    slots = std::max(slots, mesh.joints().size());
    particles = std::max(particles, source.particle_count());
  }
  std::stable_sort(out.sims.begin(), out.sims.end(),
                   [](const ClothSim& a, const ClothSim& b) { return a.instance < b.instance; });
  out.palette.resize(slots);
  out.own_model.resize(scene.joint_count());
  out.positions.resize(particles);
  out.normals.resize(particles);
  return out;
}

Status step_viewer_cloth(ViewerCloth& cloth, const Scene& scene, const Animator& animator,
                         std::span<const std::vector<glm::mat4>> bind, std::span<const glm::vec3> offsets, float dt) {
  if (!cloth.enabled || cloth.sims.empty()) return {};
  const Asset& character = scene.character();
  const bool driven = animator.drive.active();
  cloth.world = driven ? animator.drive.world : glm::mat4(1.0f);
  const glm::mat4 unworld = glm::inverse(cloth.world);
  for (ClothSim& sim : cloth.sims) {
    if (sim.instance >= animator.instances.size() || sim.mesh >= bind.size()) continue;
    const AnimInstance& inst = animator.instances[sim.instance];
    // The character's own space: the drawn model matrices without its motion through the world.
    std::span<const glm::mat4> model = inst.model;
    if (driven && cloth.own_model.size() >= inst.model.size()) {
      for (size_t j = 0; j < inst.model.size(); ++j) cloth.own_model[j] = unworld * inst.model[j];
      model = std::span<const glm::mat4>(cloth.own_model.data(), inst.model.size());
    }
    const MeshView mesh = character.mesh(sim.mesh);
    const std::span<glm::mat4> palette(cloth.palette.data(), mesh.joints().size());
    skinning_matrices(mesh.joints(), bind[sim.mesh], model, palette);
    const size_t n = sim.state.particle_count();
    const std::span<glm::vec3> pos(cloth.positions.data(), n), nrm(cloth.normals.data(), n);
    if (Status s = skin_cloth_particles(sim.state.source, mesh, palette, pos, nrm); !s) return s;

    // Settings the panel changes, over the cooked defaults (stiffness scales compliance down).
    const ClothSettings& cooked = sim.state.source.settings;
    ClothSettings& live = sim.state.settings;
    live.wind = cloth.wind;
    const float k = std::max(cloth.stiffness, 1e-3f);
    live.stretch_compliance = cooked.stretch_compliance / k;
    live.bend_compliance = cooked.bend_compliance / k;

    const glm::vec3 root = inst.model.empty() ? glm::vec3(0.0f) : glm::vec3(inst.model[0][3]);  // as drawn
    if (cooked.teleport_distance > 0.0f && glm::distance(root, sim.last_root) > cooked.teleport_distance)
      reset_cloth(sim.state);
    sim.last_root = root;

    ClothInput in;
    in.skinned_positions = pos;
    in.skinned_normals = nrm;
    in.model = model;
    const glm::vec3 o = sim.instance < offsets.size() ? offsets[sim.instance] : glm::vec3(0.0f);
    in.model_to_world = glm::translate(glm::mat4(1.0f), o) * cloth.world;
    in.dt = dt;
    if (Status s = update_cloth(sim.state, in); !s)
      return Error{scene.paths.front() + ": cloth of mesh " + std::to_string(sim.mesh) + ": " + s.message()};
  }
  return {};
}

void reset_viewer_cloth(ViewerCloth& cloth) {
  for (ClothSim& s : cloth.sims) reset_cloth(s.state);
}

void build_cloth_overlay(const ViewerCloth& cloth, const Animator& animator, std::span<const glm::vec3> offsets,
                         OverlayGeometry& out) {
  if (!cloth.enabled) return;
  for (const ClothSim& sim : cloth.sims) {
    if (sim.instance >= animator.instances.size()) continue;
    const glm::vec3 o = sim.instance < offsets.size() ? offsets[sim.instance] : glm::vec3(0.0f);
    const std::span<const glm::vec3> p = sim.state.positions();
    if (p.size() != sim.state.particle_count()) continue;  // not updated yet
    const ClothSource& src = sim.state.source;
    const auto at = [&](size_t i) { return glm::vec3(cloth.world * glm::vec4(p[i], 1.0f)) + o; };  // as drawn
    for (const fb::ClothEdge& e : src.stretch) line(out.on_top, at(e.a()), at(e.b()), kEdge);
    const float s = 0.006f;
    for (size_t i = 0; i < p.size(); ++i) {
      const glm::vec4 c = src.inverse_masses[i] == 0.0f ? kFixed : kFree;
      line(out.on_top, at(i) - glm::vec3(s, 0, 0), at(i) + glm::vec3(s, 0, 0), c);
      line(out.on_top, at(i) - glm::vec3(0, s, 0), at(i) + glm::vec3(0, s, 0), c);
    }
    const auto& model = animator.instances[sim.instance].model;
    for (const fb::ClothCollider& c : src.colliders) {
      if (c.joint() >= model.size()) continue;
      const glm::mat4& m = model[c.joint()];
      const glm::vec3 a = glm::vec3(m * glm::vec4(c.offset().x(), c.offset().y(), c.offset().z(), 1.0f)) + o;
      const glm::vec3 b = glm::vec3(m * glm::vec4(c.tail().x(), c.tail().y(), c.tail().z(), 1.0f)) + o;
      capsule(out.on_top, a, b, c.radius());
    }
  }
}

}  // namespace ossa::view
