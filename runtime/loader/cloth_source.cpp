// cloth_source.cpp — a cloth's cooked data as spans, and check_cloth, the one list of the cloth
// solver's preconditions (see cloth_source.h): the loader runs it on every cooked cloth (with the
// mesh's vertex count and the skeleton's joint count), and make_cloth_instance on any source, so a
// hand-built cloth is held to the same rules as a file. It reads every entry once and allocates
// nothing unless it fails (the message).
#include <ossa/loader/cloth_source.h>

#include <algorithm>
#include <cmath>
#include <string>

#include "common/message.h"

namespace ossa {
namespace {

using detail::format;

/// Lengths, offsets and masses beyond this are damage, not cloth (the loader's pose bound).
constexpr float kMaxLength = 1e7f;
constexpr float kMaxInverseMass = 1e3f;

bool within(float v, float lo, float hi) { return v >= lo && v <= hi; }  // false for NaN
bool bounded3(const fb::Vec3& v) {
  return within(v.x(), -kMaxLength, kMaxLength) && within(v.y(), -kMaxLength, kMaxLength) &&
         within(v.z(), -kMaxLength, kMaxLength);
}
bool bounded3(const glm::vec3& v) {
  return within(v.x, -kMaxLength, kMaxLength) && within(v.y, -kMaxLength, kMaxLength) &&
         within(v.z, -kMaxLength, kMaxLength);
}

template <class T>
std::span<const T> span_of(const flatbuffers::Vector<T>* v) {
  return v ? std::span<const T>(v->data(), v->size()) : std::span<const T>();
}
template <class T>
std::span<const T> span_of(const flatbuffers::Vector<const T*>* v) {  // vectors of structs
  return v ? std::span<const T>(reinterpret_cast<const T*>(v->Data()), v->size()) : std::span<const T>();
}

Error fail(const std::string& what) { return Error{"cloth: " + what}; }

Status check_edges(std::span<const fb::ClothEdge> edges, const char* name, size_t particles) {
  for (size_t k = 0; k < edges.size(); ++k) {
    const fb::ClothEdge& e = edges[k];
    if (e.a() >= particles || e.b() >= particles)
      return fail(format("%s edge %zu joins particles %u and %u, the cloth has %zu", name, k, e.a(), e.b(), particles));
    if (e.a() == e.b()) return fail(format("%s edge %zu joins particle %u to itself", name, k, e.a()));
    if (!within(e.rest(), 0.0f, kMaxLength))
      return fail(format("%s edge %zu has rest length %g (must be finite, in [0, 1e7])", name, k, e.rest()));
  }
  return {};
}

Status check_per_particle(std::span<const float> values, const char* name, size_t particles, float hi) {
  if (values.empty()) return {};
  if (values.size() != particles)
    return fail(format("%s has %zu entries for %zu particles", name, values.size(), particles));
  for (size_t i = 0; i < values.size(); ++i)
    if (!within(values[i], 0.0f, hi))
      return fail(format("%s of particle %zu is %g (must be finite, in [0, %g])", name, i, values[i], hi));
  return {};
}

glm::vec3 vec3_of(const fb::Vec3* v) { return v ? glm::vec3(v->x(), v->y(), v->z()) : glm::vec3(0.0f); }

}  // namespace

ClothSource cloth_source(const MeshView& mesh) {
  const fb::Cloth* c = mesh.fb ? mesh.fb->cloth() : nullptr;
  ClothSource s;
  if (!c) return s;
  s.particle_vertices = span_of(c->particle_vertices());
  s.inverse_masses = span_of(c->inverse_masses());
  s.max_distances = span_of(c->max_distances());
  s.backstops = span_of(c->backstops());
  s.vertices = span_of(c->vertices());
  s.vertex_particles = span_of(c->vertex_particles());
  s.flipped = span_of(c->flipped());
  s.triangles = span_of(c->triangles());
  s.stretch = span_of(c->stretch());
  s.bend = span_of(c->bend());
  s.tethers = span_of(c->tethers());
  s.colliders = span_of(c->colliders());
  ClothSettings& d = s.settings;
  d.thickness = c->thickness();
  d.stretch_compliance = c->stretch_compliance();
  d.bend_compliance = c->bend_compliance();
  d.tether_scale = c->tether_scale();
  d.damping = c->damping();
  d.drag = c->drag();
  d.gravity = vec3_of(c->gravity());
  d.linear_inertia = c->linear_inertia();
  d.angular_inertia = c->angular_inertia();
  d.teleport_distance = c->teleport_distance();
  d.max_speed = c->max_speed();
  return s;
}

Status check_cloth_settings(const ClothSettings& s) {
  const struct {
    const char* name;
    float value, lo, hi;
  } ranges[] = {{"substep", s.substep, 1e-4f, 0.05f},
                {"thickness", s.thickness, 0.0f, kMaxLength},
                {"stretch_compliance", s.stretch_compliance, 0.0f, 1e6f},
                {"bend_compliance", s.bend_compliance, 0.0f, 1e6f},
                {"tether_scale", s.tether_scale, 1.0f, 2.0f},
                {"damping", s.damping, 0.0f, 1e3f},
                {"drag", s.drag, 0.0f, 1e3f},
                {"linear_inertia", s.linear_inertia, 0.0f, 1.0f},
                {"angular_inertia", s.angular_inertia, 0.0f, 1.0f},
                {"teleport_distance", s.teleport_distance, 0.0f, kMaxLength},
                {"teleport_angle", s.teleport_angle, 0.0f, 7.0f},
                {"max_speed", s.max_speed, 0.0f, kMaxLength}};
  for (const auto& r : ranges)
    if (!within(r.value, r.lo, r.hi))
      return fail(format("setting %s is %g, outside [%g, %g]", r.name, r.value, r.lo, r.hi));
  if (s.iterations < 1 || s.iterations > 16)
    return fail(format("setting iterations is %u, outside [1, 16]", s.iterations));
  if (!bounded3(s.gravity)) return fail("setting gravity is not finite or past 1e7");
  if (!bounded3(s.wind)) return fail("setting wind is not finite or past 1e7");
  return {};
}

Status check_cloth(const ClothSource& c, uint32_t vertex_count, size_t joint_count) {
  const size_t n = c.particle_vertices.size();
  if (n == 0) return fail("has no particles");
  if (n > kMaxClothParticles) return fail(format("has %zu particles, more than %u", n, kMaxClothParticles));
  for (size_t i = 0; i < n; ++i)
    if (c.particle_vertices[i] >= vertex_count)
      return fail(
          format("particle %zu is driven by vertex %u, the mesh has %u", i, c.particle_vertices[i], vertex_count));
  if (c.inverse_masses.size() != n)
    return fail(format("inverse_masses has %zu entries for %zu particles", c.inverse_masses.size(), n));
  if (Status st = check_per_particle(c.inverse_masses, "inverse_masses", n, kMaxInverseMass); !st) return st;
  if (Status st = check_per_particle(c.max_distances, "max_distances", n, kMaxLength); !st) return st;
  if (Status st = check_per_particle(c.backstops, "backstops", n, kMaxLength); !st) return st;

  if (c.vertex_particles.size() != c.vertices.size())
    return fail(
        format("vertex_particles has %zu entries for %zu vertices", c.vertex_particles.size(), c.vertices.size()));
  if (!c.flipped.empty() && c.flipped.size() != c.vertices.size())
    return fail(format("flipped has %zu entries for %zu vertices", c.flipped.size(), c.vertices.size()));
  for (size_t k = 0; k < c.vertices.size(); ++k) {
    if (c.vertices[k] >= vertex_count)
      return fail(format("vertex entry %zu is vertex %u, the mesh has %u", k, c.vertices[k], vertex_count));
    if (k > 0 && c.vertices[k] <= c.vertices[k - 1])
      return fail(format("vertices are not strictly increasing at entry %zu (%u after %u)", k, c.vertices[k],
                         c.vertices[k - 1]));
    if (c.vertex_particles[k] >= n)
      return fail(format("vertex entry %zu uses particle %u, the cloth has %zu", k, c.vertex_particles[k], n));
    if (!c.flipped.empty() && c.flipped[k] > 1)
      return fail(format("flipped entry %zu is %u, not 0 or 1", k, c.flipped[k]));
  }

  if (c.triangles.size() % 3 != 0)
    return fail(format("has %zu triangle indices, not a multiple of 3", c.triangles.size()));
  for (size_t k = 0; k < c.triangles.size(); ++k)
    if (c.triangles[k] >= n)
      return fail(format("triangle %zu uses particle %u, the cloth has %zu", k / 3, c.triangles[k], n));
  if (Status st = check_edges(c.stretch, "stretch", n); !st) return st;
  if (Status st = check_edges(c.bend, "bend", n); !st) return st;
  for (size_t k = 0; k < c.tethers.size(); ++k) {
    const fb::ClothTether& t = c.tethers[k];
    if (t.particle() >= n || t.anchor() >= n)
      return fail(
          format("tether %zu joins particle %u to anchor %u, the cloth has %zu", k, t.particle(), t.anchor(), n));
    if (c.inverse_masses[t.anchor()] != 0.0f)
      return fail(format("tether %zu is anchored at particle %u, which is not fixed (inverse mass %g)", k, t.anchor(),
                         c.inverse_masses[t.anchor()]));
    if (!within(t.length(), 0.0f, kMaxLength))
      return fail(format("tether %zu has length %g (must be finite, in [0, 1e7])", k, t.length()));
  }
  for (size_t k = 0; k < c.colliders.size(); ++k) {
    const fb::ClothCollider& col = c.colliders[k];
    if (col.joint() >= joint_count)
      return fail(format("collider %zu is on joint %u, the skeleton has %zu", k, col.joint(), joint_count));
    if (!bounded3(col.offset()) || !bounded3(col.tail()))
      return fail(format("collider %zu has an offset or tail that is not finite or past 1e7", k));
    if (!within(col.radius(), 0.0f, kMaxLength))
      return fail(format("collider %zu has radius %g (must be finite, in [0, 1e7])", k, col.radius()));
  }
  return check_cloth_settings(c.settings);
}

}  // namespace ossa
