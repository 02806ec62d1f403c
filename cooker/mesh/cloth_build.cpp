// cloth_build.cpp — cloth attributes from paint or settings, and a cooked mesh's particles and
// constraints (see cloth_build.h; colliders are cloth_colliders.cpp).
//
// Everything iterates in index order or through ordered containers, so the cloth, like the rest of
// the cook, depends only on the input.
#include "cooker/mesh/cloth_build.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <map>
#include <queue>
#include <set>
#include <unordered_map>

#include "cooker/mesh/cloth_internal.h"
#include "cooker/mesh/mesh_build.h"
#include <ossa/anim/cloth.h>
#include <ossa/format/vertex_codec.h>
#include <ossa/format/vertex_format.h>
#include <ossa/skinning/vertex_fetch.h>

namespace ossa::cook {
namespace {

constexpr float kNoLimit = 1e7f;  // a particle without a max distance or backstop among ones with

float unit_of(const SourceScene& scene) { return scene.metres_per_unit > 0.0f ? scene.metres_per_unit : 1.0f; }

bool region_matches(const ClothRegion& r, const SourceScene& scene, const SourceMesh& m) {
  if (!r.mesh.empty()) return m.name == r.mesh;
  return m.material < scene.materials.size() && scene.materials[m.material].name == r.material;
}

/// The vertex's strongest joint (-1: not skinned).
int dominant_joint(const SourceMesh& m, size_t v) {
  if (m.joints.empty()) return -1;
  int best = 0;
  for (int k = 1; k < 4; ++k)
    if (m.weights[v][k] > m.weights[v][best]) best = k;
  return m.weights[v][best] > 0.0f ? m.joints[v][static_cast<size_t>(best)] : -1;
}

/// Points hashed into cubes of `cell`, for "any point within cell of p".
struct PointGrid {
  float cell = 1.0f;
  std::unordered_map<uint64_t, std::vector<glm::vec3>> cells;
  static uint64_t key(int x, int y, int z) {
    return (static_cast<uint64_t>(static_cast<uint32_t>(x) & 0x1FFFFF) << 42) |
           (static_cast<uint64_t>(static_cast<uint32_t>(y) & 0x1FFFFF) << 21) | (static_cast<uint32_t>(z) & 0x1FFFFF);
  }
  glm::ivec3 cell_of(const glm::vec3& p) const { return glm::ivec3(glm::floor(p / cell)); }
  void add(const glm::vec3& p) {
    const glm::ivec3 c = cell_of(p);
    cells[key(c.x, c.y, c.z)].push_back(p);
  }
  bool any_within(const glm::vec3& p, float d) const {
    const glm::ivec3 c = cell_of(p);
    for (int x = -1; x <= 1; ++x)
      for (int y = -1; y <= 1; ++y)
        for (int z = -1; z <= 1; ++z) {
          const auto it = cells.find(key(c.x + x, c.y + y, c.z + z));
          if (it == cells.end()) continue;
          for (const glm::vec3& q : it->second)
            if (glm::distance(p, q) <= d) return true;
        }
    return false;
  }
};

}  // namespace

namespace detail {

std::vector<glm::mat4> bind_model_matrices(const SourceSkeleton& skeleton) {
  std::vector<glm::mat4> model(skeleton.joints.size(), glm::mat4(1.0f));
  for (size_t j = 0; j < skeleton.joints.size(); ++j) {
    const SourceJoint& joint = skeleton.joints[j];
    glm::mat4 local = glm::mat4_cast(joint.rotation);
    for (int c = 0; c < 3; ++c) local[c] *= joint.scale[c];
    local[3] = glm::vec4(joint.translation, 1.0f);
    model[j] = joint.parent >= 0 ? model[static_cast<size_t>(joint.parent)] * local : local;
  }
  return model;
}

glm::vec3 bind_position(const SourceMesh& m, size_t v, const std::vector<glm::mat4>& bind_model) {
  if (m.joints.empty()) return m.positions[v];
  glm::vec3 out(0.0f);
  for (size_t k = 0; k < 4; ++k) {
    const float w = m.weights[v][static_cast<int>(k)];
    if (!(w > 0.0f)) continue;
    const uint16_t j = m.joints[v][k];
    const auto it = std::lower_bound(m.bind.begin(), m.bind.end(), j,
                                     [](const std::pair<uint16_t, glm::mat4>& e, uint16_t x) { return e.first < x; });
    const glm::mat4 inverse_bind = it != m.bind.end() && it->first == j ? it->second : glm::mat4(1.0f);
    const glm::mat4 joint_model = j < bind_model.size() ? bind_model[j] : glm::mat4(1.0f);
    out += w * glm::vec3(joint_model * inverse_bind * glm::vec4(m.positions[v], 1.0f));
  }
  return out;
}

}  // namespace detail

Result<std::vector<std::vector<glm::vec4>>> cloth_attributes(const SourceScene& scene, const ClothOptions& options,
                                                             std::vector<std::string>* warnings) {
  const float unit = unit_of(scene);
  const float max_distance = options.max_distance_m / unit, backstop = options.backstop_m / unit;
  std::vector<std::vector<glm::vec4>> out(scene.meshes.size());
  std::vector<bool> in_region(scene.meshes.size(), false);
  for (const ClothRegion& r : options.regions) {
    bool found = false;
    for (size_t i = 0; i < scene.meshes.size(); ++i)
      if (region_matches(r, scene, scene.meshes[i])) found = in_region[i] = true;
    if (!found)
      return Error{"cloth settings: no mesh is " +
                   (r.mesh.empty() ? "of material '" + r.material + "'" : "named '" + r.mesh + "'")};
  }
  // Paint.
  for (size_t i = 0; i < scene.meshes.size(); ++i) {
    const SourceMesh& m = scene.meshes[i];
    if (!options.paint || m.cloth_paint.empty() || in_region[i]) continue;
    if (m.cloth_paint.size() != m.positions.size())
      return Error{"mesh '" + m.name + "': has " + std::to_string(m.cloth_paint.size()) + " cloth paint colours for " +
                   std::to_string(m.positions.size()) + " vertices"};
    std::vector<glm::vec4>& a = out[i];
    a.resize(m.positions.size());
    size_t simulated = 0;
    for (size_t v = 0; v < a.size(); ++v) {
      glm::vec4 c = m.cloth_paint[v];
      for (int k = 0; k < 4; ++k) c[k] = std::isfinite(c[k]) ? std::clamp(c[k], 0.0f, 1.0f) : 0.0f;
      const bool free = c.r > 0.0f;
      simulated += free ? 1 : 0;
      a[v] = glm::vec4(c.r, free && max_distance > 0.0f ? c.g * max_distance : -1.0f,
                       free && backstop > 0.0f ? c.b * backstop : -1.0f, 1.0f);
    }
    if (simulated == 0) {
      if (warnings)
        warnings->push_back("mesh '" + m.name +
                            "': its cloth paint (colour set 1) has no red anywhere: "
                            "nothing is simulated");
      a.clear();
    }
  }
  // Regions from the settings: weights from the distance to the vertices that stay skinned.
  const std::vector<glm::mat4> bind_model = detail::bind_model_matrices(scene.skeleton);
  for (const ClothRegion& r : options.regions) {
    std::vector<int> pin_joints;
    for (const std::string& name : r.pin_joints) {
      int found = -1;
      for (size_t j = 0; j < scene.skeleton.joints.size(); ++j)
        if (scene.skeleton.joints[j].name == name) found = static_cast<int>(j);
      if (found < 0) return Error{"cloth settings: pin joint '" + name + "' is not a joint of the skeleton"};
      pin_joints.push_back(found);
    }
    const float pin_within = r.pin_within_m / unit, ramp = std::max(r.ramp_m / unit, 1e-9f);
    PointGrid body;
    body.cell = std::max(pin_within, 1e-6f);
    if (pin_within > 0.0f)
      for (size_t i = 0; i < scene.meshes.size(); ++i)
        if (!in_region[i])
          for (size_t v = 0; v < scene.meshes[i].positions.size(); ++v)
            body.add(detail::bind_position(scene.meshes[i], v, bind_model));
    for (size_t i = 0; i < scene.meshes.size(); ++i) {
      const SourceMesh& m = scene.meshes[i];
      if (!region_matches(r, scene, m)) continue;
      std::vector<glm::vec3> at(m.positions.size());
      std::vector<glm::vec3> pinned;
      for (size_t v = 0; v < at.size(); ++v) {
        at[v] = detail::bind_position(m, v, bind_model);
        const int dj = dominant_joint(m, v);
        const bool by_joint = std::find(pin_joints.begin(), pin_joints.end(), dj) != pin_joints.end();
        if (by_joint || (pin_within > 0.0f && body.any_within(at[v], pin_within))) pinned.push_back(at[v]);
      }
      if (pinned.empty())
        return Error{"cloth settings: no vertex of mesh '" + m.name + "' stays skinned (name \"pin_joints\", or let " +
                     "the region touch the rest of the character within \"pin_within\")"};
      std::vector<glm::vec4>& a = out[i];
      a.resize(at.size());
      for (size_t v = 0; v < at.size(); ++v) {
        float nearest = INFINITY;
        for (const glm::vec3& p : pinned) nearest = std::min(nearest, glm::distance(at[v], p));
        const float weight = std::clamp(nearest / ramp, 0.0f, 1.0f);
        a[v] = glm::vec4(weight, weight > 0.0f && max_distance > 0.0f ? max_distance : -1.0f,
                         weight > 0.0f && backstop > 0.0f ? backstop : -1.0f, 1.0f);
      }
    }
  }
  return out;
}

Result<CookedCloth> build_cloth(const SourceScene& scene, const ClothOptions& options, const CookedMesh& mesh,
                                const std::vector<glm::vec4>& attributes, std::vector<std::string>* warnings) {
  CookedCloth out;
  const std::string label = "mesh '" + mesh.name + "': cloth: ";
  const uint32_t n = mesh.vertex_count;
  if (attributes.size() != n) return Error{label + "attributes do not match the vertices"};
  const detail::DecodedMesh decoded = detail::decode_bind_pose(scene, mesh);

  // The region: triangles with a simulated corner, and their corners.
  std::vector<uint32_t> indices(mesh.indices.size() / (mesh.index_format == fb::IndexFormat::Uint16 ? 2 : 4));
  for (size_t i = 0; i < indices.size(); ++i) {
    if (mesh.index_format == fb::IndexFormat::Uint16) {
      uint16_t v;
      std::memcpy(&v, mesh.indices.data() + 2 * i, 2);
      indices[i] = v;
    } else {
      std::memcpy(&indices[i], mesh.indices.data() + 4 * i, 4);
    }
  }
  std::vector<bool> region(n, false);
  std::vector<std::array<uint32_t, 3>> region_triangles;
  for (size_t t = 0; t + 2 < indices.size(); t += 3) {
    const std::array<uint32_t, 3> tri{indices[t], indices[t + 1], indices[t + 2]};
    if (attributes[tri[0]].x > 0.0f || attributes[tri[1]].x > 0.0f || attributes[tri[2]].x > 0.0f) {
      region_triangles.push_back(tri);
      for (const uint32_t v : tri) region[v] = true;
    }
  }
  if (region_triangles.empty()) return out;

  // Particles: region vertices welded by their cooked position bytes, in vertex order.
  const fb::VertexAttribute* pos = nullptr;
  for (const fb::VertexAttribute& a : mesh.layout)
    if (a.semantic() == fb::VertexSemantic::Position) pos = &a;
  if (!pos) return Error{label + "the mesh has no positions"};
  const uint32_t pos_size = vertex_format_info(pos->format()).size;
  std::map<std::string, uint32_t> by_position;
  std::vector<uint32_t> particle_of(n, UINT32_MAX);
  std::vector<float> weight, max_distance, backstop;
  for (uint32_t v = 0; v < n; ++v) {
    if (!region[v]) continue;
    const size_t at = static_cast<size_t>(v) * mesh.vertex_stride + pos->offset();
    const std::string key(reinterpret_cast<const char*>(mesh.vertices.data()) + at, pos_size);
    auto [it, inserted] = by_position.emplace(key, static_cast<uint32_t>(out.particle_vertices.size()));
    const glm::vec4& a = attributes[v];
    if (inserted) {
      out.particle_vertices.push_back(v);
      weight.push_back(a.x);
      max_distance.push_back(a.y);
      backstop.push_back(a.z);
    } else {  // duplicates at one position: the stricter value wins (fixed over free)
      const uint32_t p = it->second;
      weight[p] = std::min(weight[p], a.x);
      if (a.y >= 0.0f) max_distance[p] = max_distance[p] < 0.0f ? a.y : std::min(max_distance[p], a.y);
      if (a.z >= 0.0f) backstop[p] = backstop[p] < 0.0f ? a.z : std::min(backstop[p], a.z);
    }
    particle_of[v] = it->second;
  }
  const size_t count = out.particle_vertices.size();
  if (count > kMaxClothParticlesCooked)
    return Error{label + std::to_string(count) + " particles, more than the " +
                 std::to_string(kMaxClothParticlesCooked) + " one cloth may have (split the region into meshes)"};
  std::vector<glm::vec3> rest(count);
  for (size_t p = 0; p < count; ++p) rest[p] = decoded.positions[out.particle_vertices[p]];
  out.inverse_masses = weight;
  const auto per_particle = [&](const std::vector<float>& values, std::vector<float>& dst) {
    if (std::none_of(values.begin(), values.end(), [](float x) { return x >= 0.0f; })) return;
    dst.resize(count);
    for (size_t p = 0; p < count; ++p) dst[p] = weight[p] == 0.0f ? 0.0f : values[p] >= 0.0f ? values[p] : kNoLimit;
  };
  per_particle(max_distance, out.max_distances);
  per_particle(backstop, out.backstops);

  // Triangles in particles, each set of three once (a two-sided shell is one surface).
  std::set<std::array<uint32_t, 3>> seen;
  std::map<std::pair<uint32_t, uint32_t>, std::vector<uint32_t>> opposite;  // edge -> far corners
  std::vector<glm::vec3> rest_normal(count, glm::vec3(0.0f));
  for (const auto& tri : region_triangles) {
    const std::array<uint32_t, 3> p{particle_of[tri[0]], particle_of[tri[1]], particle_of[tri[2]]};
    if (p[0] == p[1] || p[1] == p[2] || p[0] == p[2]) continue;
    std::array<uint32_t, 3> sorted = p;
    std::sort(sorted.begin(), sorted.end());
    if (!seen.insert(sorted).second) continue;
    for (const uint32_t q : p) out.triangles.push_back(static_cast<uint16_t>(q));
    const glm::vec3 nrm = glm::cross(rest[p[1]] - rest[p[0]], rest[p[2]] - rest[p[0]]);
    for (int k = 0; k < 3; ++k) {
      rest_normal[p[static_cast<size_t>(k)]] += nrm;
      const uint32_t a = p[static_cast<size_t>(k)], b = p[static_cast<size_t>((k + 1) % 3)];
      opposite[{std::min(a, b), std::max(a, b)}].push_back(p[static_cast<size_t>((k + 2) % 3)]);
    }
  }
  // Stretch along every edge, bending across every edge two triangles share.
  std::vector<fb::ClothEdge> stretch, bend;
  std::set<std::pair<uint32_t, uint32_t>> bends;
  std::vector<std::vector<std::pair<uint32_t, float>>> graph(count);
  for (const auto& [edge, far] : opposite) {
    const float length = glm::distance(rest[edge.first], rest[edge.second]);
    graph[edge.first].emplace_back(edge.second, length);
    graph[edge.second].emplace_back(edge.first, length);
    const bool fixed = weight[edge.first] == 0.0f && weight[edge.second] == 0.0f;
    if (!fixed) stretch.emplace_back(static_cast<uint16_t>(edge.first), static_cast<uint16_t>(edge.second), length);
    if (far.size() < 2) continue;
    const uint32_t c = std::min(far[0], far[1]), d = std::max(far[0], far[1]);
    if (c == d || opposite.count({c, d}) || (weight[c] == 0.0f && weight[d] == 0.0f)) continue;
    if (!bends.insert({c, d}).second) continue;
    bend.emplace_back(static_cast<uint16_t>(c), static_cast<uint16_t>(d), glm::distance(rest[c], rest[d]));
  }
  out.stretch = colour_cloth_edges(stretch, count);
  out.bend = colour_cloth_edges(bend, count);

  // Tethers: each free particle to its nearest fixed one along the edges.
  std::vector<float> distance(count, INFINITY);
  std::vector<uint32_t> anchor(count, UINT32_MAX);
  using Item = std::pair<float, uint32_t>;
  std::priority_queue<Item, std::vector<Item>, std::greater<Item>> queue;
  for (uint32_t p = 0; p < count; ++p)
    if (weight[p] == 0.0f) {
      distance[p] = 0.0f;
      anchor[p] = p;
      queue.emplace(0.0f, p);
    }
  while (!queue.empty()) {
    const auto [d, p] = queue.top();
    queue.pop();
    if (d > distance[p]) continue;
    for (const auto& [q, length] : graph[p])
      if (d + length < distance[q]) {
        distance[q] = d + length;
        anchor[q] = anchor[p];
        queue.emplace(distance[q], q);
      }
  }
  size_t loose = 0;
  for (uint32_t p = 0; p < count; ++p) {
    if (weight[p] == 0.0f) continue;
    if (anchor[p] == UINT32_MAX) {
      ++loose;
      continue;
    }
    out.tethers.emplace_back(static_cast<uint16_t>(p), static_cast<uint16_t>(anchor[p]), distance[p]);
  }
  if (loose > 0 && warnings)
    warnings->push_back(label + std::to_string(loose) + " simulated particles are not connected to any that stays " +
                        "skinned: nothing holds them (paint red 0 where the cloth is attached)");

  // The vertices the cloth writes, and which of them face the other way (a two-sided shell).
  for (uint32_t v = 0; v < n; ++v) {
    if (particle_of[v] == UINT32_MAX) continue;
    out.vertices.push_back(v);
    out.vertex_particles.push_back(static_cast<uint16_t>(particle_of[v]));
    out.flipped.push_back(glm::dot(decoded.normals[v], rest_normal[particle_of[v]]) < 0.0f ? 1 : 0);
  }
  if (std::none_of(out.flipped.begin(), out.flipped.end(), [](uint8_t f) { return f != 0; })) out.flipped.clear();

  // Colliders, and the simulation's defaults in model units.
  const float unit = unit_of(scene);
  auto colliders = detail::cloth_colliders(scene, options, rest, weight, distance, label, warnings);
  if (!colliders) return colliders.error();
  out.colliders = std::move(*colliders);
  out.thickness = options.thickness_m / unit;
  out.stretch_compliance = options.stretch_compliance;
  out.bend_compliance = options.bend_compliance;
  out.tether_scale = options.tether_scale;
  out.damping = options.damping;
  out.drag = options.drag;
  out.gravity = glm::vec3(0.0f);
  out.gravity[options.up_axis % 3] = -options.gravity_ms2 / unit;
  out.linear_inertia = options.linear_inertia;
  out.angular_inertia = options.angular_inertia;
  out.teleport_distance = options.teleport_distance_m / unit;
  out.max_speed = options.max_speed_ms / unit;
  return out;
}

}  // namespace ossa::cook
