// cloth_setup.cpp — a cloth's data checked and its instance made, and the per-vertex glue between
// the solver's particles and a mesh's vertex streams (see cloth.h; the solver is cloth_solve.cpp).
//
// check_cloth is the one list of the solver's preconditions: the loader runs it on every cooked
// cloth (with the mesh's vertex count and the skeleton's joint count), and make_cloth_instance on
// any source, so a hand-built cloth is held to the same rules as a file. It reads every entry
// once and allocates nothing unless it fails (the message).
#include <ossa/anim/cloth.h>

#include <algorithm>
#include <cmath>
#include <string>

#include <ossa/format/vertex_codec.h>
#include <ossa/skinning/vertex_fetch.h>
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
  if (s.iterations < 1 || s.iterations > 16) return fail(format("setting iterations is %u, outside [1, 16]", s.iterations));
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
      return fail(format("particle %zu is driven by vertex %u, the mesh has %u", i, c.particle_vertices[i], vertex_count));
  if (c.inverse_masses.size() != n)
    return fail(format("inverse_masses has %zu entries for %zu particles", c.inverse_masses.size(), n));
  if (Status st = check_per_particle(c.inverse_masses, "inverse_masses", n, kMaxInverseMass); !st) return st;
  if (Status st = check_per_particle(c.max_distances, "max_distances", n, kMaxLength); !st) return st;
  if (Status st = check_per_particle(c.backstops, "backstops", n, kMaxLength); !st) return st;

  if (c.vertex_particles.size() != c.vertices.size())
    return fail(format("vertex_particles has %zu entries for %zu vertices", c.vertex_particles.size(), c.vertices.size()));
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
    if (!c.flipped.empty() && c.flipped[k] > 1) return fail(format("flipped entry %zu is %u, not 0 or 1", k, c.flipped[k]));
  }

  if (c.triangles.size() % 3 != 0) return fail(format("has %zu triangle indices, not a multiple of 3", c.triangles.size()));
  for (size_t k = 0; k < c.triangles.size(); ++k)
    if (c.triangles[k] >= n)
      return fail(format("triangle %zu uses particle %u, the cloth has %zu", k / 3, c.triangles[k], n));
  if (Status st = check_edges(c.stretch, "stretch", n); !st) return st;
  if (Status st = check_edges(c.bend, "bend", n); !st) return st;
  for (size_t k = 0; k < c.tethers.size(); ++k) {
    const fb::ClothTether& t = c.tethers[k];
    if (t.particle() >= n || t.anchor() >= n)
      return fail(format("tether %zu joins particle %u to anchor %u, the cloth has %zu", k, t.particle(), t.anchor(), n));
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

Result<ClothInstance> make_cloth_instance(const ClothSource& source, uint32_t vertex_count, size_t joint_count) {
  if (Status st = check_cloth(source, vertex_count, joint_count); !st) return st.error();
  const size_t n = source.particle_count();
  ClothInstance c;
  c.source = source;
  c.settings = source.settings;
  c.current.assign(n, glm::vec4(0.0f));
  c.previous.assign(n, glm::vec4(0.0f));
  for (size_t i = 0; i < n; ++i) c.current[i].w = c.previous[i].w = source.inverse_masses[i];
  c.skinned_before.assign(n, glm::vec3(0.0f));
  c.skinned_older.assign(n, glm::vec3(0.0f));
  c.skinned_normal_before.assign(n, glm::vec3(0.0f));
  c.out_positions.assign(n, glm::vec3(0.0f));
  c.out_normals.assign(n, glm::vec3(0.0f, 1.0f, 0.0f));
  c.colliders_before.assign(2 * source.colliders.size(), glm::vec3(0.0f));
  c.colliders_older.assign(2 * source.colliders.size(), glm::vec3(0.0f));
  c.colliders_now.assign(2 * source.colliders.size(), glm::vec3(0.0f));
  c.lambda.assign(source.stretch.size() + source.bend.size(), 0.0f);
  // The wind acts along each particle's normal every substep: one triangle's, the first it is a
  // corner of (a particle in no triangle faces along a zero normal, and feels no wind).
  c.facing.assign(3 * n, 0);
  std::vector<bool> seen(n, false);
  for (size_t t = 0; t + 2 < source.triangles.size(); t += 3)
    for (size_t k = 0; k < 3; ++k) {
      const uint16_t p = source.triangles[t + k];
      if (seen[p]) continue;
      seen[p] = true;
      for (size_t j = 0; j < 3; ++j) c.facing[3 * p + j] = source.triangles[t + (k + j) % 3];
    }
  return c;
}

void reset_cloth(ClothInstance& cloth) { cloth.started = false; }

Status skin_cloth_particles(const ClothSource& source, const MeshView& mesh, std::span<const glm::mat4> palette,
                            std::span<glm::vec3> positions, std::span<glm::vec3> normals) {
  const size_t n = source.particle_count();
  if (positions.size() < n || normals.size() < n)
    return fail(format("skin_cloth_particles needs %zu positions and normals, got %zu and %zu", n, positions.size(),
                       normals.size()));
  const fb::VertexAttribute* pa = mesh.attribute(fb::VertexSemantic::Position);
  const fb::VertexAttribute* na = mesh.attribute(fb::VertexSemantic::Normal);
  const fb::VertexAttribute* ja = mesh.attribute(fb::VertexSemantic::Joints);
  const fb::VertexAttribute* wa = mesh.attribute(fb::VertexSemantic::Weights);
  if (!pa) return fail("skin_cloth_particles: the mesh has no positions");
  const size_t slots = std::max<size_t>(1, mesh.joints().size());
  if (palette.size() < slots)
    return fail(format("skin_cloth_particles: the palette has %zu matrices, the mesh needs %zu", palette.size(), slots));
  // Directions must not see the de-quantization folded into the palette (skinning.h).
  glm::vec3 prescale(1.0f);
  if (pa->format() == fb::VertexFormat::Unorm16x4 && mesh.fb->position_scale()) {
    const fb::Vec3* s = mesh.fb->position_scale();
    prescale = glm::vec3(1.0f / s->x(), 1.0f / s->y(), 1.0f / s->z());
  }
  const uint8_t* bytes = mesh.vertex_bytes().data();
  const uint32_t stride = mesh.vertex_stride();
  for (size_t i = 0; i < n; ++i) {
    const uint32_t v = source.particle_vertices[i];
    if (v >= mesh.vertex_count())
      return fail(format("skin_cloth_particles: particle %zu's vertex %u is past the mesh's %u", i, v, mesh.vertex_count()));
    const uint8_t* vb = bytes + static_cast<size_t>(v) * stride;
    glm::mat4 m = palette[0];
    if (ja && wa) {
      const glm::vec4 slot = fetch_vertex_attribute(vb + ja->offset(), ja->format());
      const glm::vec4 weight = fetch_vertex_attribute(vb + wa->offset(), wa->format());
      m = glm::mat4(0.0f);
      for (int k = 0; k < 4; ++k)
        if (weight[k] != 0.0f) m += weight[k] * palette[static_cast<size_t>(slot[k])];
    }
    const glm::vec4 p = fetch_vertex_attribute(vb + pa->offset(), pa->format());
    positions[i] = glm::vec3(m * glm::vec4(p.x, p.y, p.z, 1.0f));
    glm::vec3 nrm(0.0f, 1.0f, 0.0f);
    if (na) {
      const glm::vec4 e = fetch_vertex_attribute(vb + na->offset(), na->format());
      if (na->format() == fb::VertexFormat::Snorm16x2) {
        const Float3 d = octahedral_decode(Float2{e.x, e.y});
        nrm = glm::vec3(d.x, d.y, d.z);
      } else {
        nrm = glm::vec3(e);
      }
      nrm = glm::mat3(m) * (nrm * prescale);
      const float len = glm::length(nrm);
      nrm = len > 1e-20f ? nrm / len : glm::vec3(0.0f, 1.0f, 0.0f);
    }
    normals[i] = nrm;
  }
  return {};
}

Status gather_cloth_particles(const ClothSource& source, std::span<const float> skinned_positions,
                              std::span<const float> skinned_normals, std::span<glm::vec3> positions,
                              std::span<glm::vec3> normals) {
  const size_t n = source.particle_count();
  if (positions.size() < n || (!skinned_normals.empty() && normals.size() < n))
    return fail(format("gather_cloth_particles needs %zu positions and normals", n));
  for (size_t i = 0; i < n; ++i) {
    const size_t v = source.particle_vertices[i];
    if (3 * v + 2 >= skinned_positions.size() || (!skinned_normals.empty() && 3 * v + 2 >= skinned_normals.size()))
      return fail(format("gather_cloth_particles: particle %zu's vertex %zu is past the skinned streams", i, v));
    positions[i] = glm::vec3(skinned_positions[3 * v], skinned_positions[3 * v + 1], skinned_positions[3 * v + 2]);
    if (!skinned_normals.empty())
      normals[i] = glm::vec3(skinned_normals[3 * v], skinned_normals[3 * v + 1], skinned_normals[3 * v + 2]);
  }
  return {};
}

Status write_cloth_vertices(const ClothInstance& cloth, std::span<float> positions, std::span<float> normals) {
  const ClothSource& s = cloth.source;
  for (size_t k = 0; k < s.vertices.size(); ++k) {
    const size_t v = s.vertices[k];
    const size_t p = s.vertex_particles[k];
    if ((!positions.empty() && 3 * v + 2 >= positions.size()) || (!normals.empty() && 3 * v + 2 >= normals.size()))
      return fail(format("write_cloth_vertices: vertex %zu is past the streams", v));
    if (p >= cloth.out_positions.size()) return fail("write_cloth_vertices: the instance does not match its source");
    if (!positions.empty()) {
      const glm::vec3& x = cloth.out_positions[p];
      positions[3 * v] = x.x;
      positions[3 * v + 1] = x.y;
      positions[3 * v + 2] = x.z;
    }
    if (!normals.empty()) {
      const glm::vec3 nrm = !s.flipped.empty() && s.flipped[k] ? -cloth.out_normals[p] : cloth.out_normals[p];
      normals[3 * v] = nrm.x;
      normals[3 * v + 1] = nrm.y;
      normals[3 * v + 2] = nrm.z;
    }
  }
  return {};
}

}  // namespace ossa
