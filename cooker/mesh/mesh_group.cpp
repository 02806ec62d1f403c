// mesh_group.cpp — one group of cleaned meshes into one CookedMesh: the joint palette,
// concatenated streams with one submesh per member, meshoptimizer's reorders and the interleaved
// quantized (or float32) encoding (mesh_build.cpp's header lists the stages and says why).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstring>
#include <limits>
#include <map>
#include <set>
#include <utility>

#include <ossa/format/vertex_codec.h>
#include <ossa/format/vertex_format.h>
#include "cooker/mesh/mesh_build_internal.h"

namespace ossa::cook::mesh_detail {
namespace {

struct Streams {
  std::vector<glm::vec3> positions, normals;
  std::vector<glm::vec4> tangents;
  std::vector<glm::vec2> uv0;
  std::vector<glm::vec4> colors;
  std::vector<std::array<uint16_t, 4>> slots;
  std::vector<glm::vec4> weights;
  std::vector<glm::vec4> cloth;       // cloth attributes; zeros where a member has none
  std::vector<MorphStreams> targets;  // merged by name over the members; zeros where a member lacks one
};

/// Renumbers a weld's remap (old vertex -> new, the new ones numbered in first use order, ~0u for
/// a vertex no triangle uses) so that the kept vertices keep their order: each merged set is
/// numbered where its first member stands. O(vertices).
void keep_vertex_order(std::vector<unsigned>& remap, size_t unique) {
  std::vector<unsigned> renumbered(unique, ~0u);
  unsigned next = 0;
  for (unsigned& r : remap) {
    if (r == ~0u) continue;
    if (renumbered[r] == ~0u) renumbered[r] = next++;
    r = renumbered[r];
  }
}

struct PaletteEntry {
  uint16_t joint = 0;
  glm::mat4 inverse_bind{1.0f};
};

bool same_matrix(const glm::mat4& a, const glm::mat4& b) {
  for (int c = 0; c < 4; ++c)
    for (int r = 0; r < 4; ++r)
      if (!(a[c][r] == b[c][r])) return false;
  return true;
}

template <class T>
void put(uint8_t* dst, const T& value) {
  std::memcpy(dst, &value, sizeof(T));
}

struct Layout {
  std::vector<fb::VertexAttribute> attributes;
  uint16_t stride = 0;
  uint16_t add(fb::VertexSemantic semantic, fb::VertexFormat format) {
    const uint16_t offset = stride;
    attributes.emplace_back(semantic, format, offset);
    stride = static_cast<uint16_t>(stride + vertex_format_info(format).size);
    return offset;
  }
};

}  // namespace

// Builds the merged mesh of one group. `members` index `cleaned`, in scene order.
Result<CookedMesh> build_group(const SourceScene& scene, const std::vector<CleanMesh>& cleaned,
                               const std::vector<size_t>& members, const AttributeSet& attrs,
                               const MeshOptions& options, MeshBuildStats& stats, std::vector<std::string>& warnings,
                               double& misses_before, double& misses_after) {
  const size_t joint_count = scene.skeleton.joints.size();
  CookedMesh out;
  out.name = cleaned[members.front()].mesh.name;

  // Sanitized weights per member, and the palette: distinct (joint, inverse bind) pairs, grouped
  // by joint (std::map order) and by first appearance within a joint.
  std::vector<std::vector<glm::vec4>> weights(members.size());
  std::map<uint16_t, std::vector<std::pair<glm::mat4, uint32_t>>> pairs;  // joint -> (matrix, id)
  std::vector<std::map<uint16_t, uint32_t>> member_ids(members.size());   // joint -> pair id
  uint32_t pair_count = 0;
  if (attrs.skinned) {
    for (size_t mi = 0; mi < members.size(); ++mi) {
      const size_t si = cleaned[members[mi]].source;
      const SourceMesh& m = cleaned[members[mi]].mesh;
      std::map<uint16_t, const glm::mat4*> bind;
      for (const auto& [joint, matrix] : m.bind) bind.emplace(joint, &matrix);  // first one wins
      std::vector<bool> used(joint_count, false);
      weights[mi].resize(m.weights.size());
      uint32_t empty_vertices = 0;
      for (size_t v = 0; v < m.weights.size(); ++v) {
        bool was_empty = false;
        weights[mi][v] = sanitize_weights(m.weights[v], &was_empty);
        empty_vertices += was_empty ? 1u : 0u;
        for (int k = 0; k < 4; ++k) {
          if (!(weights[mi][v][k] > 0.0f)) continue;
          const uint16_t joint = m.joints[v][static_cast<size_t>(k)];
          if (joint >= joint_count)
            return mesh_error(m, si,
                              "vertex " + std::to_string(v) + " references joint " + std::to_string(joint) +
                                  ", not below the skeleton's joint count " + std::to_string(joint_count));
          used[joint] = true;
        }
      }
      if (empty_vertices > 0)
        warnings.push_back(mesh_label(m, si) + ": " + std::to_string(empty_vertices) +
                           " vertices had no skin weight; bound fully to their first influence");
      uint32_t unbound = 0;
      for (size_t j = 0; j < joint_count; ++j) {
        if (!used[j]) continue;
        const auto joint = static_cast<uint16_t>(j);
        const auto found = bind.find(joint);
        glm::mat4 matrix = scene.skeleton.joints[j].inverse_bind;
        if (found != bind.end()) {
          matrix = *found->second;
        } else {
          ++unbound;  // no skin entry: the skeleton's own inverse bind is the best guess
        }
        auto& candidates = pairs[joint];
        uint32_t id = pair_count;
        for (const auto& [existing, existing_id] : candidates)
          if (same_matrix(existing, matrix)) id = existing_id;
        if (id == pair_count) {
          candidates.emplace_back(matrix, pair_count);
          ++pair_count;
        }
        member_ids[mi].emplace(joint, id);
      }
      if (unbound > 0)
        warnings.push_back(mesh_label(m, si) + ": " + std::to_string(unbound) +
                           " skinned joints had no inverse bind in the skin; used the skeleton's");
    }
    if (pair_count > 65536u)
      return Error{"mesh '" + out.name + "': " + std::to_string(pair_count) +
                   " distinct joint slots, more than the 65536 a Uint16x4 joint index can address"};
  }
  std::vector<uint32_t> slot_of_pair(pair_count, 0);
  for (const auto& [joint, candidates] : pairs) {
    for (const auto& [matrix, id] : candidates) {
      slot_of_pair[id] = static_cast<uint32_t>(out.joints.size());
      out.joints.push_back(joint);
      out.inverse_bind.push_back(matrix);
    }
  }

  // Concatenate the members' streams and indices; one submesh each.
  bool colored = false;
  bool clothed = false;
  for (const size_t member : members) colored = colored || !cleaned[member].mesh.colors.empty();
  for (const size_t member : members) clothed = clothed || !cleaned[member].mesh.cloth.empty();
  Streams s;
  // Morph targets merge by name across members (a head split by material shares its "smile"); a
  // stream is present when any member's target of that name has it.
  for (const size_t member : members) {
    for (const SourceMorphTarget& t : cleaned[member].mesh.morph_targets) {
      auto it =
          std::find_if(s.targets.begin(), s.targets.end(), [&](const MorphStreams& m) { return m.name == t.name; });
      if (it == s.targets.end()) {
        s.targets.push_back({t.name, t.default_weight, {}, {}, {}});
        it = s.targets.end() - 1;
      }
      if (!t.normals.empty()) it->normals.resize(1);  // marks the stream present; filled below
      if (!t.tangents.empty() && attrs.tangents) it->tangents.resize(1);
    }
  }
  std::vector<bool> target_normals, target_tangents;
  for (MorphStreams& t : s.targets) {
    target_normals.push_back(!t.normals.empty());
    target_tangents.push_back(!t.tangents.empty());
    t.normals.clear();
    t.tangents.clear();
  }
  std::vector<unsigned> indices;
  std::vector<uint32_t> member_base(members.size());
  for (size_t mi = 0; mi < members.size(); ++mi) {
    const CleanMesh& c = cleaned[members[mi]];
    const SourceMesh& m = c.mesh;
    const size_t base = s.positions.size();
    if (base + m.positions.size() > std::numeric_limits<uint32_t>::max())
      return Error{"mesh '" + out.name + "': more than 2^32 - 1 vertices"};
    member_base[mi] = static_cast<uint32_t>(base);
    s.positions.insert(s.positions.end(), m.positions.begin(), m.positions.end());
    s.normals.insert(s.normals.end(), m.normals.begin(), m.normals.end());
    if (attrs.tangents) s.tangents.insert(s.tangents.end(), m.tangents.begin(), m.tangents.end());
    if (attrs.uv0) s.uv0.insert(s.uv0.end(), m.uv0.begin(), m.uv0.end());
    if (colored) {
      if (m.colors.empty()) {
        s.colors.insert(s.colors.end(), m.positions.size(), glm::vec4(1.0f));
      } else {
        uint32_t clamped = 0;
        for (const glm::vec4& col : m.colors) {
          const glm::vec4 in_range = glm::clamp(col, glm::vec4(0.0f), glm::vec4(1.0f));
          clamped += in_range != col ? 1u : 0u;
          s.colors.push_back(in_range);
        }
        if (clamped > 0)
          warnings.push_back(mesh_label(m, c.source) + ": " + std::to_string(clamped) +
                             " vertex colours outside [0, 1] were clamped");
      }
    }
    if (clothed) {
      if (m.cloth.empty()) s.cloth.insert(s.cloth.end(), m.positions.size(), glm::vec4(0.0f));
      else s.cloth.insert(s.cloth.end(), m.cloth.begin(), m.cloth.end());
    }
    if (attrs.skinned) {
      for (size_t v = 0; v < m.joints.size(); ++v) {
        std::array<uint16_t, 4> slots{0, 0, 0, 0};
        for (size_t k = 0; k < 4; ++k)
          if (weights[mi][v][static_cast<int>(k)] > 0.0f)
            slots[k] = static_cast<uint16_t>(slot_of_pair[member_ids[mi].at(m.joints[v][k])]);
        s.slots.push_back(slots);
        s.weights.push_back(weights[mi][v]);
      }
    }
    for (size_t k = 0; k < s.targets.size(); ++k) {
      MorphStreams& t = s.targets[k];
      const auto own = std::find_if(m.morph_targets.begin(), m.morph_targets.end(),
                                    [&](const SourceMorphTarget& mt) { return mt.name == t.name; });
      const bool has = own != m.morph_targets.end();
      const size_t nv = m.positions.size();
      const auto append = [&](std::vector<glm::vec3>& dst, const std::vector<glm::vec3>* src) {
        if (has && src && !src->empty()) dst.insert(dst.end(), src->begin(), src->end());
        else dst.insert(dst.end(), nv, glm::vec3(0.0f));
      };
      append(t.positions, has ? &own->positions : nullptr);
      if (target_normals[k]) append(t.normals, has ? &own->normals : nullptr);
      if (target_tangents[k]) append(t.tangents, has ? &own->tangents : nullptr);
    }
    if (indices.size() + m.indices.size() > std::numeric_limits<uint32_t>::max())
      return Error{"mesh '" + out.name + "': more than 2^32 - 1 indices"};
    fb::Submesh submesh(static_cast<uint32_t>(indices.size()), static_cast<uint32_t>(m.indices.size()), m.material);
    for (const uint32_t i : m.indices) indices.push_back(static_cast<unsigned>(base + i));
    out.submeshes.push_back(submesh);
  }
  size_t vertex_count = s.positions.size();

  const auto before = meshopt_analyzeVertexCache(indices.data(), indices.size(), vertex_count, kCacheSize, 0, 0);
  misses_before += before.vertices_transformed;

  if (options.optimize) {
    for (size_t mi = 0; mi < members.size(); ++mi) {
      const fb::Submesh& sub = out.submeshes[mi];
      const size_t count = cleaned[members[mi]].mesh.positions.size();
      const uint32_t base = member_base[mi];
      std::vector<unsigned> local(indices.begin() + sub.first_index(),
                                  indices.begin() + sub.first_index() + sub.index_count());
      for (unsigned& i : local) i -= base;
      std::vector<unsigned> optimized(local.size());
      meshopt_optimizeVertexCache(optimized.data(), local.data(), local.size(), count);
      for (size_t i = 0; i < optimized.size(); ++i) indices[sub.first_index() + i] = optimized[i] + base;
    }
    const auto renumber = [&](const std::vector<unsigned>& remap, size_t unique) {
      meshopt_remapIndexBuffer(indices.data(), indices.data(), indices.size(), remap.data());
      compact(s.positions, remap, unique);
      compact(s.normals, remap, unique);
      compact(s.tangents, remap, unique);
      compact(s.uv0, remap, unique);
      compact(s.colors, remap, unique);
      compact(s.slots, remap, unique);
      compact(s.weights, remap, unique);
      compact(s.cloth, remap, unique);
      for (MorphStreams& t : s.targets) {
        compact(t.positions, remap, unique);
        compact(t.normals, remap, unique);
        compact(t.tangents, remap, unique);
      }
    };
    std::vector<unsigned> remap(vertex_count);
    const size_t unique = meshopt_optimizeVertexFetchRemap(remap.data(), indices.data(), indices.size(), vertex_count);
    renumber(remap, unique);
    if (unique < vertex_count)
      warnings.push_back("mesh '" + out.name + "': dropped " + std::to_string(vertex_count - unique) +
                         " vertices only degenerate triangles used");
    vertex_count = unique;
    if (attrs.skinned) {
      remap = influence_class_order(s.weights);
      renumber(remap, vertex_count);
    }
  }

  const auto after = meshopt_analyzeVertexCache(indices.data(), indices.size(), vertex_count, kCacheSize, 0, 0);
  misses_after += after.vertices_transformed;

  // Bounds and the de-quantizing affine.
  glm::vec3 lo(0.0f), hi(0.0f);
  if (vertex_count > 0) {
    lo = hi = s.positions[0];
    for (const glm::vec3& p : s.positions) {
      lo = glm::min(lo, p);
      hi = glm::max(hi, p);
    }
  }
  out.bounds_min = lo;
  out.bounds_max = hi;
  const bool quantized = !options.float_vertices;
  if (quantized) {
    out.position_offset = lo;
    for (int a = 0; a < 3; ++a) {
      const float extent = hi[a] - lo[a];
      out.position_scale[a] = extent > 0.0f && std::isfinite(extent) ? extent : 1.0f;
    }
  } else {
    out.position_offset = glm::vec3(0.0f);
    out.position_scale = glm::vec3(1.0f);
  }

  // Layout: Position, Normal, Tangent, TexCoord0, Color0, Joints, Weights; every size is a
  // multiple of 4.
  using Sem = fb::VertexSemantic;
  using Fmt = fb::VertexFormat;
  const bool wide_slots = out.joints.size() > 256;
  Layout layout;
  const uint16_t at_position = layout.add(Sem::Position, quantized ? Fmt::Unorm16x4 : Fmt::Float32x3);
  const uint16_t at_normal = layout.add(Sem::Normal, quantized ? Fmt::Snorm16x2 : Fmt::Float32x3);
  const uint16_t at_tangent =
      attrs.tangents ? layout.add(Sem::Tangent, quantized ? Fmt::Snorm16x4 : Fmt::Float32x4) : 0;
  const uint16_t at_uv0 = attrs.uv0 ? layout.add(Sem::TexCoord0, quantized ? Fmt::Float16x2 : Fmt::Float32x2) : 0;
  const uint16_t at_color = colored ? layout.add(Sem::Color0, quantized ? Fmt::Unorm8x4 : Fmt::Float32x4) : 0;
  const uint16_t at_joints =
      attrs.skinned ? layout.add(Sem::Joints, quantized && !wide_slots ? Fmt::Uint8x4 : Fmt::Uint16x4) : 0;
  const uint16_t at_weights = attrs.skinned ? layout.add(Sem::Weights, quantized ? Fmt::Unorm8x4 : Fmt::Float32x4) : 0;
  layout.stride = static_cast<uint16_t>((layout.stride + 3u) & ~3u);

  out.vertex_count = static_cast<uint32_t>(vertex_count);
  out.vertex_stride = layout.stride;
  out.layout = layout.attributes;
  out.vertices.assign(vertex_count * layout.stride, 0);
  for (size_t v = 0; v < vertex_count; ++v) {
    uint8_t* dst = out.vertices.data() + v * layout.stride;
    const glm::vec3& p = s.positions[v];
    const glm::vec3& n = s.normals[v];
    if (quantized) {
      const glm::vec3 q = (p - out.position_offset) / out.position_scale;
      put(dst + at_position,
          std::array<uint16_t, 4>{float_to_unorm16(q.x), float_to_unorm16(q.y), float_to_unorm16(q.z), 0});
      const Float2 e = octahedral_encode({n.x, n.y, n.z});
      put(dst + at_normal, std::array<int16_t, 2>{float_to_snorm16(e.x), float_to_snorm16(e.y)});
      if (attrs.tangents) {
        const glm::vec4& t = s.tangents[v];
        const Float2 te = octahedral_encode({t.x, t.y, t.z});
        const int16_t sign = t.w < 0.0f ? int16_t{-32767} : int16_t{32767};
        put(dst + at_tangent, std::array<int16_t, 4>{float_to_snorm16(te.x), float_to_snorm16(te.y), sign, 0});
      }
      if (attrs.uv0) put(dst + at_uv0, std::array<uint16_t, 2>{float_to_half(s.uv0[v].x), float_to_half(s.uv0[v].y)});
      if (colored) {
        const glm::vec4& c = s.colors[v];
        put(dst + at_color, std::array<uint8_t, 4>{float_to_unorm8(c.r), float_to_unorm8(c.g), float_to_unorm8(c.b),
                                                   float_to_unorm8(c.a)});
      }
      if (attrs.skinned) {
        const auto& slots = s.slots[v];
        if (wide_slots) {
          put(dst + at_joints, slots);
        } else {
          put(dst + at_joints, std::array<uint8_t, 4>{static_cast<uint8_t>(slots[0]), static_cast<uint8_t>(slots[1]),
                                                      static_cast<uint8_t>(slots[2]), static_cast<uint8_t>(slots[3])});
        }
        put(dst + at_weights, quantize_weights(s.weights[v]));
      }
    } else {
      put(dst + at_position, p);
      put(dst + at_normal, n);
      if (attrs.tangents) put(dst + at_tangent, s.tangents[v]);
      if (attrs.uv0) put(dst + at_uv0, s.uv0[v]);
      if (colored) put(dst + at_color, s.colors[v]);
      if (attrs.skinned) {
        put(dst + at_joints, s.slots[v]);
        put(dst + at_weights, s.weights[v]);
      }
    }
  }

  // Morph targets, quantized against the bounds in mesh units, still dense (morph_build.h).
  std::vector<DenseMorph> dense;
  if (!s.targets.empty()) {
    MorphBounds bounds;
    const float mpu =
        scene.metres_per_unit > 0.0f && std::isfinite(scene.metres_per_unit) ? scene.metres_per_unit : 1.0f;
    bounds.position = options.morph_position_bound_m / mpu;
    bounds.angle = options.morph_angle_bound;
    std::vector<glm::vec3> base_tangents;
    if (attrs.tangents)
      for (const glm::vec4& t : s.tangents) base_tangents.emplace_back(t);
    // The bound stated and met: the absolute one, or 2e-5 of the mesh's own size where that is
    // larger. 16-bit deltas err by up to 1/65534 of a target's largest delta, so a target that
    // moves vertices by up to the mesh's size (whole-body vertex animation, or a model whose
    // stated unit is not the one it was authored in) meets it; the absolute bound alone could not.
    const float size_bound = 2e-5f * glm::length(out.bounds_max - out.bounds_min);
    const float bound = std::max(bounds.position, std::isfinite(size_bound) ? size_bound : 0.0f);
    for (const MorphStreams& t : s.targets) {
      dense.push_back(quantize_morph(t, s.normals, base_tangents, bounds));
      dense.back().position_bound = bound;
      if (dense.back().position_error > bound * 1.0001f)
        warnings.push_back("mesh '" + out.name + "': morph target '" + t.name + "' moves vertices so far that its " +
                           "16-bit deltas err by " + std::to_string(dense.back().position_error) +
                           " units, past the bound " + std::to_string(bound) + " (the larger of " +
                           std::to_string(bounds.position) + " and 2e-5 of the mesh's size)");
    }
  }

  // Vertices the quantized layout made identical (source vertices a rounding error apart, which
  // Assimp used to merge by epsilon) are one vertex: equal bytes draw exactly alike. The merged
  // vertex takes its first member's place and the others keep their order (keep_vertex_order),
  // so a skinned mesh stays ordered by influence class (merged vertices have equal weights) and
  // every class range keeps its fetch order. With morph targets, the targets' quantized deltas are
  // part of the key: two vertices merge only when every target moves them alike.
  if (quantized && vertex_count > 0) {
    std::vector<unsigned> remap(vertex_count);
    size_t unique = 0;
    if (dense.empty() && s.cloth.empty()) {
      unique = meshopt_generateVertexRemap(remap.data(), indices.data(), indices.size(), out.vertices.data(),
                                           vertex_count, layout.stride);
    } else {
      unique = remap_by_key(indices, vertex_count, &remap, [&](std::string& key, size_t i) {
        key.append(reinterpret_cast<const char*>(out.vertices.data()) + i * layout.stride, layout.stride);
        append_bytes(key, s.cloth, i);
        for (const DenseMorph& d : dense) {
          append_bytes(key, d.positions, i);
          append_bytes(key, d.normals, i);
          append_bytes(key, d.tangents, i);
        }
      });
    }
    if (unique < vertex_count) {
      keep_vertex_order(remap, unique);
      for (DenseMorph& d : dense) remap_morph(d, remap, unique);
      compact(s.cloth, remap, unique);
      std::vector<uint8_t> merged(unique * layout.stride);
      meshopt_remapVertexBuffer(merged.data(), out.vertices.data(), vertex_count, layout.stride, remap.data());
      meshopt_remapIndexBuffer(indices.data(), indices.data(), indices.size(), remap.data());
      out.vertices = std::move(merged);
      vertex_count = unique;
      out.vertex_count = static_cast<uint32_t>(unique);
    }
  }

  // Indices: 16-bit while every index fits (0xFFFF stays free for primitive restart).
  if (vertex_count <= 65535) {
    out.index_format = fb::IndexFormat::Uint16;
    out.indices.resize(indices.size() * 2);
    for (size_t i = 0; i < indices.size(); ++i) put(out.indices.data() + 2 * i, static_cast<uint16_t>(indices[i]));
  } else {
    out.index_format = fb::IndexFormat::Uint32;
    out.indices.resize(indices.size() * 4);
    if (!indices.empty()) std::memcpy(out.indices.data(), indices.data(), indices.size() * 4);
  }

  for (const DenseMorph& d : dense) out.morph_targets.push_back(sparsify(d));
  out.cloth_attributes = std::move(s.cloth);

  stats.cooked_vertices += out.vertex_count;
  stats.triangles += static_cast<uint32_t>(indices.size() / 3);
  return out;
}

}  // namespace ossa::cook::mesh_detail
