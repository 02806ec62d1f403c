// validate.cpp — the semantic checks of a verified .ossa file (see validate.h for the list).
//
// Shape: one Validator walks the file once, skeleton first (meshes and clips check against it),
// and stops at the first failure with a message that names the mesh/clip/joint/field at fault, so
// a user can find the problem in the source asset. Everything here runs on bytes an attacker may
// have written, after flatbuffers::Verifier has proven every offset and vector lies inside the
// buffer; so the checks may read any vector element, but never trust a count or index stored in
// the file to address anything else until it has been compared with the thing it addresses.
//
// Two costs matter:
// - Per-vertex/per-index work is the only thing that grows with mesh size, so it is done by plain
//   max-reductions over the index array and over the joint-slot bytes, which the compiler turns
//   into SIMD code and which allocate nothing. Only when a maximum is out of range does a second,
//   scalar pass look for the first offender to name it.
// - FlatBuffers tables form a DAG: a crafted file can point a thousand meshes at one mesh with a
//   million indices. The verifier bounds the number of tables (max_tables), but not how often the
//   same big vector is reached, so the checks keep a budget of vector bytes they may scan (a few
//   times the buffer size, which a file without shared vectors can never reach) and reject a file
//   that would need more. That keeps validation O(buffer size) on any input.
#include "runtime/validate.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <vector>

#include "format/hash.h"
#include "format/vertex_format.h"
#include "runtime/message.h"

namespace ossa {
namespace {

using detail::format;

template <class V>
size_t count_of(const V* v) {
  return v ? v->size() : 0;
}

std::string_view view_of(const flatbuffers::String* s) {
  return s ? std::string_view(s->c_str(), s->size()) : std::string_view();
}

/// "mesh 2 'Body'", or "mesh 2" when unnamed.
std::string label(const char* kind, size_t index, const flatbuffers::String* name) {
  std::string out = format("%s %zu", kind, index);
  if (name && name->size() != 0) out += " '" + detail::printable(view_of(name)) + "'";
  return out;
}

bool finite3(const fb::Vec3& v) { return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z()); }

bool finite4(const fb::Quat& q) {
  return std::isfinite(q.x()) && std::isfinite(q.y()) && std::isfinite(q.z()) && std::isfinite(q.w());
}

/// A rotation the sampler can normalize: finite, and a squared norm that neither underflows to
/// zero nor overflows to infinity in float, which is where normalize() would produce NaN or 0.
bool normalizable(const fb::Quat& q) {
  if (!finite4(q)) return false;
  const float n2 = q.x() * q.x() + q.y() * q.y() + q.z() * q.z() + q.w() * q.w();
  return n2 >= std::numeric_limits<float>::min() && n2 <= std::numeric_limits<float>::max();
}

bool finite_matrix(const fb::Mat4& m) {
  const auto* a = m.m();
  for (flatbuffers::uoffset_t k = 0; k < 16; ++k)
    if (!std::isfinite(a->Get(k))) return false;
  return true;
}

/// "1 joint", "3 joints".
std::string count_text(size_t n, const char* noun) { return format("%zu %s%s", n, noun, n == 1 ? "" : "s"); }

std::string vec3_text(const fb::Vec3& v) { return format("(%g, %g, %g)", v.x(), v.y(), v.z()); }

const char* semantic_name(fb::VertexSemantic s) {
  const char* n = fb::EnumNameVertexSemantic(s);
  return *n ? n : "unknown semantic";
}
const char* format_name(fb::VertexFormat f) {
  const char* n = fb::EnumNameVertexFormat(f);
  return *n ? n : "unknown format";
}

// ---- the O(n) loops -------------------------------------------------------------------------
//
// Written as fixed-width blocks so that GCC's -O2 "very cheap" vectorizer (which refuses loops
// needing a scalar epilogue) still vectorizes the block, and Clang at any level; the tail is at
// most one block of scalar work.

template <class T>
T max_value(const T* values, size_t n) {
  constexpr size_t kLanes = 32;
  T lanes[kLanes] = {};
  size_t i = 0;
  for (; i + kLanes <= n; i += kLanes)
    for (size_t k = 0; k < kLanes; ++k) lanes[k] = values[i + k] > lanes[k] ? values[i + k] : lanes[k];
  T m = 0;
  for (size_t k = 0; k < kLanes; ++k) m = lanes[k] > m ? lanes[k] : m;
  for (; i < n; ++i) m = values[i] > m ? values[i] : m;
  return m;
}

/// Largest index in an index buffer. `bytes` is 16-byte aligned (checked before) and holds n
/// indices of type T.
template <class T>
uint32_t max_index(const uint8_t* bytes, size_t n) {
  return max_value(reinterpret_cast<const T*>(bytes), n);
}

/// Largest joint slot over 4 components of n vertices: `first` points at vertex 0's Joints
/// attribute, vertices are `stride` bytes apart. T is uint8_t or uint16_t; memcpy keeps the read
/// defined whatever the attribute's alignment and compiles to one load.
template <class T>
uint32_t max_joint_slot(const uint8_t* first, size_t n, size_t stride) {
  T m[4] = {0, 0, 0, 0};
  for (size_t v = 0; v < n; ++v) {
    T s[4];
    std::memcpy(s, first + v * stride, sizeof s);
    for (int k = 0; k < 4; ++k) m[k] = s[k] > m[k] ? s[k] : m[k];
  }
  T r = m[0];
  for (int k = 1; k < 4; ++k) r = m[k] > r ? m[k] : r;
  return r;
}

template <class T>
size_t first_joint_slot_at_least(const uint8_t* first, size_t n, size_t stride, uint32_t limit,
                                 uint32_t* slot) {
  for (size_t v = 0; v < n; ++v) {
    T s[4];
    std::memcpy(s, first + v * stride, sizeof s);
    for (int k = 0; k < 4; ++k)
      if (s[k] >= limit) {
        *slot = s[k];
        return v;
      }
  }
  return n;
}

// ---------------------------------------------------------------------------------------------

class Validator {
 public:
  Validator(const fb::File& file, std::string_view name, size_t buffer_size)
      : file_(file), name_(name) {
    // Every vector element is scanned once in a file without shared vectors, and a few vectors
    // may legitimately be shared (one times vector for several channels); 4x leaves room for
    // that while bounding a crafted DAG. 0 = the caller gave no size: no bound.
    budget_ = buffer_size ? 4 * static_cast<uint64_t>(buffer_size) + 4096 : UINT64_MAX;
  }

  Status run() {
    if (!std::isfinite(file_.metres_per_unit()) || !(file_.metres_per_unit() > 0.0f))
      return fail("", format("metres_per_unit %g must be a finite number > 0", file_.metres_per_unit()));
    material_count_ = count_of(file_.materials());
    if (const fb::Skeleton* s = file_.skeleton()) {
      if (Status st = check_skeleton(*s); !st) return st;
    }
    if (const auto* meshes = file_.meshes()) {
      for (flatbuffers::uoffset_t i = 0; i < meshes->size(); ++i)
        if (Status st = check_mesh(*meshes->Get(i), i); !st) return st;
    }
    if (const auto* clips = file_.clips()) {
      for (flatbuffers::uoffset_t i = 0; i < clips->size(); ++i)
        if (Status st = check_clip(*clips->Get(i), i); !st) return st;
    }
    if (const auto* materials = file_.materials()) {
      for (flatbuffers::uoffset_t i = 0; i < materials->size(); ++i)
        if (Status st = check_material(*materials->Get(i), i); !st) return st;
    }
    return {};
  }

 private:
  Error fail(const std::string& where, const std::string& what) const {
    return Error{std::string(name_) + ": " + (where.empty() ? what : where + ": " + what)};
  }

  /// Charges `bytes` of scanning to the budget; false once it is spent.
  bool spend(uint64_t bytes) {
    if (bytes > budget_) return false;
    budget_ -= bytes;
    return true;
  }
  Error over_budget(const std::string& where) const {
    return fail(where, "tables reference far more data than the file holds (vectors shared between "
                       "tables); refusing to scan it");
  }

  std::string joint_label(size_t joint) const {
    std::string out = format("joint %zu", joint);
    if (skeleton_ && joint < joint_count_) {
      const auto name = view_of(skeleton_->joint_names()->Get(static_cast<flatbuffers::uoffset_t>(joint)));
      out += " '" + detail::printable(name) + "'";
    }
    return out;
  }

  // ---- skeleton ----

  Status check_skeleton(const fb::Skeleton& s) {
    const std::string where = "skeleton";
    const size_t n = s.joint_names()->size();
    const struct {
      const char* field;
      size_t size;
    } arrays[] = {{"parents", s.parents()->size()},
                  {"bind_translations", s.bind_translations()->size()},
                  {"bind_rotations", s.bind_rotations()->size()},
                  {"bind_scales", s.bind_scales()->size()},
                  {"inverse_bind", s.inverse_bind()->size()}};
    for (const auto& a : arrays)
      if (a.size != n) return fail(where, format("has %zu joint names but %zu %s", n, a.size, a.field));
    if (!spend(static_cast<uint64_t>(n) * (4 + 2 + 12 + 16 + 12 + 64))) return over_budget(where);

    const int16_t* parents = s.parents()->data();
    std::vector<std::string_view> names;
    names.reserve(n);
    for (size_t i = 0; i < n; ++i) {
      const auto idx = static_cast<flatbuffers::uoffset_t>(i);
      const std::string_view name = view_of(s.joint_names()->Get(idx));
      if (name.empty()) return fail(where, format("joint %zu has an empty name", i));
      names.push_back(name);
      const auto jl = [&] { return format("joint %zu '%s'", i, detail::printable(name).c_str()); };
      const int parent = parents[i];
      if (parent != -1 && (parent < 0 || static_cast<size_t>(parent) >= i)) {
        if (i == 0)
          return fail(where, jl() + format(" has parent %d, must be -1 (the first joint is a root)", parent));
        return fail(where, jl() + format(" has parent %d, must be -1 or < %zu (parents come first)", parent, i));
      }
      if (!finite3(*s.bind_translations()->Get(idx)))
        return fail(where, jl() + ": bind translation is not finite");
      if (!normalizable(*s.bind_rotations()->Get(idx)))
        return fail(where, jl() + ": bind rotation is not a finite, non-zero quaternion");
      if (!finite3(*s.bind_scales()->Get(idx))) return fail(where, jl() + ": bind scale is not finite");
      if (!finite_matrix(*s.inverse_bind()->Get(idx)))
        return fail(where, jl() + ": inverse bind matrix is not finite");
    }
    const uint64_t computed = skeleton_hash(names, std::span<const int16_t>(parents, n));
    if (computed != s.hash())
      return fail(where, format("stored hash %016llx does not match the joints' hash %016llx (names or "
                                "parents changed after cooking)",
                                static_cast<unsigned long long>(s.hash()),
                                static_cast<unsigned long long>(computed)));
    skeleton_ = &s;
    joint_count_ = n;
    return {};
  }

  // ---- meshes ----

  Status check_mesh(const fb::Mesh& m, size_t mesh_index) {
    const std::string where = label("mesh", mesh_index, m.name());
    const uint32_t vertex_count = m.vertex_count();
    const uint32_t stride = m.vertex_stride();

    // Layout.
    const auto* layout = m.layout();
    if (!spend(static_cast<uint64_t>(layout->size()) * sizeof(fb::VertexAttribute))) return over_budget(where);
    if (stride % 4 != 0) return fail(where, format("vertex stride %u is not a multiple of 4", stride));
    const fb::VertexAttribute* by_semantic[8] = {};
    for (flatbuffers::uoffset_t k = 0; k < layout->size(); ++k) {
      const fb::VertexAttribute& a = *layout->Get(k);
      const auto sem = static_cast<unsigned>(a.semantic());
      if (sem > static_cast<unsigned>(fb::VertexSemantic::MAX))
        return fail(where, format("layout attribute %u has unknown semantic %u", k, sem));
      const VertexFormatInfo info = vertex_format_info(a.format());
      const std::string al = format("layout attribute %u (%s)", k, semantic_name(a.semantic()));
      if (info.size == 0)
        return fail(where, al + format(" has unknown format %u", static_cast<unsigned>(a.format())));
      if (by_semantic[sem]) return fail(where, format("layout has two %s attributes", semantic_name(a.semantic())));
      by_semantic[sem] = &a;
      const std::string fl = al + format(" %s @%u", format_name(a.format()), a.offset());
      if (static_cast<uint32_t>(a.offset()) + info.size > stride)
        return fail(where, fl + format(" ends at byte %u, past the vertex stride %u",
                                       static_cast<unsigned>(a.offset() + info.size), stride));
      const unsigned component = info.size / info.components;
      if (a.offset() % component != 0)
        return fail(where, fl + format(" is not aligned to its %u-byte components", component));
      // Formats a reader can interpret for this semantic: integer formats only for joint slots
      // (glVertexAttribIPointer), never for anything else; positions need x, y and z.
      const bool joints = a.semantic() == fb::VertexSemantic::Joints;
      if (joints != info.integer)
        return fail(where, fl + (joints ? " must use an integer format (Uint8x4 or Uint16x4)"
                                        : " must not use an integer format"));
      if (a.semantic() == fb::VertexSemantic::Position && info.components < 3)
        return fail(where, fl + " has fewer than 3 components");
    }
    const fb::VertexAttribute* joints_attr = by_semantic[static_cast<int>(fb::VertexSemantic::Joints)];
    const fb::VertexAttribute* weights_attr = by_semantic[static_cast<int>(fb::VertexSemantic::Weights)];
    if (vertex_count > 0 && !by_semantic[static_cast<int>(fb::VertexSemantic::Position)])
      return fail(where, format("has %u vertices but no Position attribute", vertex_count));

    // Vertex bytes.
    const auto* vertices = m.vertices();
    const uint64_t expected = static_cast<uint64_t>(vertex_count) * stride;
    if (vertices->size() != expected)
      return fail(where, format("vertex data is %u bytes, expected vertex_count %u * stride %u = %llu",
                                vertices->size(), vertex_count, stride,
                                static_cast<unsigned long long>(expected)));
    if (vertices->size() != 0 && reinterpret_cast<uintptr_t>(vertices->Data()) % 16 != 0)
      return fail(where, "vertex data is not 16-byte aligned");

    // Indices.
    const auto* indices = m.indices();
    size_t index_size = 0;
    switch (m.index_format()) {
      case fb::IndexFormat::Uint16: index_size = 2; break;
      case fb::IndexFormat::Uint32: index_size = 4; break;
    }
    if (index_size == 0)
      return fail(where, format("unknown index format %u", static_cast<unsigned>(m.index_format())));
    const char* index_format = fb::EnumNameIndexFormat(m.index_format());
    if (indices->size() % index_size != 0)
      return fail(where, format("index data is %u bytes, not a multiple of %zu (%s)", indices->size(), index_size,
                                index_format));
    const size_t index_count = indices->size() / index_size;
    if (index_count % 3 != 0)
      return fail(where, format("has %zu indices, not a multiple of 3 (triangle list)", index_count));
    if (index_count != 0) {
      if (reinterpret_cast<uintptr_t>(indices->Data()) % 16 != 0)
        return fail(where, "index data is not 16-byte aligned");
      if (!spend(indices->size())) return over_budget(where);
      const uint32_t max = index_size == 2 ? max_index<uint16_t>(indices->Data(), index_count)
                                           : max_index<uint32_t>(indices->Data(), index_count);
      if (max >= vertex_count) {
        for (size_t i = 0; i < index_count; ++i) {
          uint32_t v = 0;
          if (index_size == 2) {
            uint16_t v16;
            std::memcpy(&v16, indices->Data() + 2 * i, 2);
            v = v16;
          } else {
            std::memcpy(&v, indices->Data() + 4 * i, 4);
          }
          if (v >= vertex_count)
            return fail(where, format("index %zu is %u, past the vertex count %u", i, v, vertex_count));
        }
      }
    }

    // Submeshes.
    const auto* submeshes = m.submeshes();
    if (!spend(static_cast<uint64_t>(submeshes->size()) * sizeof(fb::Submesh))) return over_budget(where);
    const size_t material_limit = material_count_ > 0 ? material_count_ : 1;
    for (flatbuffers::uoffset_t k = 0; k < submeshes->size(); ++k) {
      const fb::Submesh& sm = *submeshes->Get(k);
      const uint64_t end = static_cast<uint64_t>(sm.first_index()) + sm.index_count();
      if (end > index_count)
        return fail(where, format("submesh %u covers indices [%u, %llu), past the index count %zu", k,
                                  sm.first_index(), static_cast<unsigned long long>(end), index_count));
      if (sm.index_count() % 3 != 0)
        return fail(where, format("submesh %u has %u indices, not a multiple of 3", k, sm.index_count()));
      if (sm.material() >= material_limit)
        return fail(where, material_count_ == 0
                               ? format("submesh %u uses material %u, but the file has no materials (only 0 "
                                        "is allowed)", k, sm.material())
                               : format("submesh %u uses material %u, the file has %s", k, sm.material(),
                                        count_text(material_count_, "material").c_str()));
    }

    // Joint slots.
    const size_t slot_count = count_of(m.joints());
    const size_t inverse_bind_count = count_of(m.inverse_bind());
    if (slot_count != inverse_bind_count)
      return fail(where, format("has %zu joint slots but %zu inverse bind matrices", slot_count, inverse_bind_count));
    if (!spend(static_cast<uint64_t>(slot_count) * (2 + 64))) return over_budget(where);
    if (slot_count > 0) {
      if (!skeleton_) return fail(where, format("has %zu joint slots but the file has no skeleton", slot_count));
      for (size_t k = 0; k < slot_count; ++k) {
        const auto idx = static_cast<flatbuffers::uoffset_t>(k);
        const uint16_t joint = m.joints()->Get(idx);
        if (joint >= joint_count_)
          return fail(where, format("joint slot %zu names joint %u, the skeleton has %s", k, joint,
                                    count_text(joint_count_, "joint").c_str()));
        if (!finite_matrix(*m.inverse_bind()->Get(idx)))
          return fail(where, format("joint slot %zu (", k) + joint_label(joint) + "): inverse bind matrix is not finite");
      }
    }
    if (weights_attr && !joints_attr) return fail(where, "has a Weights attribute but no Joints attribute");
    if (joints_attr) {
      if (!weights_attr) return fail(where, "has a Joints attribute but no Weights attribute");
      if (slot_count == 0) return fail(where, "has a Joints attribute but no joint slots");
      if (vertex_count > 0) {
        if (!spend(vertices->size())) return over_budget(where);
        const uint8_t* first = vertices->Data() + joints_attr->offset();
        const bool wide = joints_attr->format() == fb::VertexFormat::Uint16x4;
        const uint32_t max = wide ? max_joint_slot<uint16_t>(first, vertex_count, stride)
                                  : max_joint_slot<uint8_t>(first, vertex_count, stride);
        if (max >= slot_count) {
          uint32_t slot = 0;
          const auto limit = static_cast<uint32_t>(slot_count);
          const size_t v = wide ? first_joint_slot_at_least<uint16_t>(first, vertex_count, stride, limit, &slot)
                                : first_joint_slot_at_least<uint8_t>(first, vertex_count, stride, limit, &slot);
          return fail(where, format("vertex %zu uses joint slot %u, the mesh has %s", v, slot,
                                    count_text(slot_count, "slot").c_str()));
        }
      }
    }

    // Bounds and the position de-quantization.
    const struct {
      const char* field;
      const fb::Vec3* value;
    } vectors[] = {{"bounds_min", m.bounds_min()},
                   {"bounds_max", m.bounds_max()},
                   {"position_offset", m.position_offset()},
                   {"position_scale", m.position_scale()}};
    for (const auto& v : vectors)
      if (v.value && !finite3(*v.value)) return fail(where, format("%s is not finite", v.field));
    return {};
  }

  // ---- clips ----

  /// One channel of one track: as many values as times; times finite, strictly increasing,
  /// inside [0, duration] up to a 1e-4 relative slack (float seconds computed from ticks do not
  /// land exactly on the duration); values finite, rotations normalizable.
  template <class Value, class Check>
  Status check_channel(const std::string& where, const char* channel, const flatbuffers::Vector<float>* times,
                       const flatbuffers::Vector<const Value*>* values, float duration, Check value_ok,
                       const char* value_problem) {
    const size_t n = count_of(times);
    if (count_of(values) != n)
      return fail(where, format("%zu %s times but %zu %s values", n, channel, count_of(values), channel));
    if (n == 0) return {};
    if (!spend(static_cast<uint64_t>(n) * (sizeof(float) + sizeof(Value)))) return over_budget(where);
    const float slack = 1e-4f * duration;
    const float* t = times->data();
    for (size_t i = 0; i < n; ++i) {
      if (!std::isfinite(t[i])) return fail(where, format("%s key %zu: time is not finite", channel, i));
      if (t[i] < -slack || t[i] > duration + slack)
        return fail(where, format("%s key %zu at %g s is outside the clip [0, %g s]", channel, i, t[i], duration));
      if (i > 0 && !(t[i] > t[i - 1]))
        return fail(where, format("%s key %zu at %g s is not after key %zu at %g s (times must strictly increase)",
                                  channel, i, t[i], i - 1, t[i - 1]));
      if (!value_ok(*values->Get(static_cast<flatbuffers::uoffset_t>(i))))
        return fail(where, format("%s key %zu: %s", channel, i, value_problem));
    }
    return {};
  }

  Status check_clip(const fb::Clip& c, size_t clip_index) {
    const std::string where = label("clip", clip_index, c.name());
    const float duration = c.duration();
    if (!std::isfinite(duration) || duration < 0.0f)
      return fail(where, format("duration %g s must be a finite number >= 0", duration));
    if (!std::isfinite(c.sample_rate()) || c.sample_rate() < 0.0f)
      return fail(where, format("sample rate %g must be a finite number >= 0", c.sample_rate()));
    const size_t joint_count = c.joint_count();
    const bool binds_here = skeleton_ && c.skeleton_hash() == skeleton_->hash();
    if (binds_here && joint_count != joint_count_)
      return fail(where, format("addresses %s, but its skeleton (this file's, by hash) has %zu",
                                count_text(joint_count, "joint").c_str(), joint_count_));

    const auto* tracks = c.tracks();
    if (!spend(static_cast<uint64_t>(tracks->size()) * 4)) return over_budget(where);
    long previous = -1;
    for (flatbuffers::uoffset_t k = 0; k < tracks->size(); ++k) {
      const fb::Track& t = *tracks->Get(k);
      const size_t joint = t.joint();
      std::string tl = format("track %u (", k) + (binds_here ? joint_label(joint) : format("joint %zu", joint)) + ")";
      if (static_cast<long>(joint) <= previous)
        return fail(where, tl + format(" is not after track %u (joint %ld): tracks are sorted by joint, one per joint",
                                       k - 1, previous));
      previous = static_cast<long>(joint);
      if (joint >= joint_count)
        return fail(where, tl + format(" addresses a joint past the clip's joint count %zu", joint_count));
      const std::string track_where = where + ": " + tl;
      if (Status s = check_channel(track_where, "translation", t.translation_times(), t.translations(), duration,
                                   finite3, "translation is not finite");
          !s)
        return s;
      if (Status s = check_channel(track_where, "rotation", t.rotation_times(), t.rotations(), duration,
                                   normalizable, "rotation is not a finite, non-zero quaternion");
          !s)
        return s;
      if (Status s = check_channel(track_where, "scale", t.scale_times(), t.scales(), duration, finite3,
                                   "scale is not finite");
          !s)
        return s;
    }
    return {};
  }

  // ---- materials ----

  Status check_material(const fb::Material& m, size_t material_index) {
    const std::string where = label("material", material_index, m.name());
    const struct {
      const char* field;
      const fb::Vec3* value;
    } colours[] = {{"ambient", m.ambient()}, {"diffuse", m.diffuse()}, {"specular", m.specular()}};
    for (const auto& c : colours)
      if (c.value && !finite3(*c.value)) return fail(where, format("%s colour %s is not finite", c.field, vec3_text(*c.value).c_str()));
    if (!std::isfinite(m.shininess())) return fail(where, "shininess is not finite");
    if (!std::isfinite(m.opacity())) return fail(where, "opacity is not finite");
    const auto* textures = m.textures();
    if (!textures) return {};
    if (!spend(static_cast<uint64_t>(textures->size()) * 4)) return over_budget(where);
    for (flatbuffers::uoffset_t k = 0; k < textures->size(); ++k) {
      const fb::Texture& t = *textures->Get(k);
      if (static_cast<unsigned>(t.role()) > static_cast<unsigned>(fb::TextureRole::MAX))
        return fail(where, format("texture %u has unknown role %u", k, static_cast<unsigned>(t.role())));
      const size_t data_size = count_of(t.data());
      if (data_size == 0 && view_of(t.path()).empty())
        return fail(where, format("texture %u (%s) has neither embedded data nor a path", k,
                                  fb::EnumNameTextureRole(t.role())));
      if (data_size != 0 && reinterpret_cast<uintptr_t>(t.data()->Data()) % 16 != 0)
        return fail(where, format("texture %u (%s): embedded data is not 16-byte aligned", k,
                                  fb::EnumNameTextureRole(t.role())));
    }
    return {};
  }

  const fb::File& file_;
  std::string_view name_;
  uint64_t budget_ = 0;
  size_t material_count_ = 0;
  const fb::Skeleton* skeleton_ = nullptr;  // set once the skeleton checked out
  size_t joint_count_ = 0;
};

}  // namespace

Status validate_file(const fb::File& file, std::string_view name, size_t buffer_size) {
  return Validator(file, name, buffer_size).run();
}

}  // namespace ossa
