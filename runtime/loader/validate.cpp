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
//
// Files: the Validator class and the predicates all checks share are in internal/validator.h;
// this file runs the checks in order and holds the skeleton and material checks; meshes are in
// validate_mesh.cpp, clips in validate_clip.cpp, graphs in validate_graph.cpp.
#include <ossa/loader/validate.h>

#include <cmath>
#include <cstdint>
#include <string>

#include <ossa/format/hash.h>
#include <ossa/loader/texture.h>
#include "common/message.h"
#include "internal/validator.h"

namespace ossa {
namespace validate_detail {

Status Validator::run() {
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
  if (const auto* graphs = file_.graphs()) {
    for (flatbuffers::uoffset_t i = 0; i < graphs->size(); ++i)
      if (Status st = validate_graph(*graphs->Get(i), i, name_, budget_); !st) return st;
  }
  return {};
}

// ---- skeleton ----

Status Validator::check_skeleton(const fb::Skeleton& s) {
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
  // The pose values are checked as whole arrays first (branch-free scans the compiler
  // vectorizes); only a file that fails one walks the joints again to name the culprit.
  const bool values_ok = all_bounded(reinterpret_cast<const float*>(s.bind_translations()->Data()), 3 * n) &&
                         all_bounded(reinterpret_cast<const float*>(s.bind_scales()->Data()), 3 * n) &&
                         all_finite(reinterpret_cast<const float*>(s.inverse_bind()->Data()), 16 * n) &&
                         all_normalizable(reinterpret_cast<const float*>(s.bind_rotations()->Data()), n);
  uint64_t hash_sum = 0;
  for (size_t i = 0; i < n; ++i) {
    const auto idx = static_cast<flatbuffers::uoffset_t>(i);
    const std::string_view name = flatbuffers::GetStringView(s.joint_names()->Get(idx));
    if (name.empty()) return fail(where, format("joint %zu has an empty name", i));
    const auto jl = [&] { return format("joint %zu '%s'", i, detail::printable(name).c_str()); };
    const int parent = parents[i];
    if (parent != -1 && (parent < 0 || static_cast<size_t>(parent) >= i)) {
      if (i == 0) return fail(where, jl() + format(" has parent %d, must be -1 (the first joint is a root)", parent));
      return fail(where, jl() + format(" has parent %d, must be -1 or < %zu (parents come first)", parent, i));
    }
    hash_sum += skeleton_hash_joint(i, name, parents[i]);
    if (values_ok) continue;
    if (!bounded3(*s.bind_translations()->Get(idx))) return fail(where, jl() + ": bind translation is not finite");
    if (!normalizable(*s.bind_rotations()->Get(idx)))
      return fail(where, jl() + ": bind rotation is not a finite, non-zero quaternion");
    if (!bounded3(*s.bind_scales()->Get(idx))) return fail(where, jl() + ": bind scale is not finite (or beyond 1e7)");
    if (!finite_matrix(*s.inverse_bind()->Get(idx))) return fail(where, jl() + ": inverse bind matrix is not finite");
  }
  const uint64_t computed = skeleton_hash_finish(hash_sum, n);
  if (computed != s.hash())
    return fail(where, format("stored hash %016llx does not match the joints' hash %016llx (names or "
                              "parents changed after cooking)",
                              static_cast<unsigned long long>(s.hash()), static_cast<unsigned long long>(computed)));
  skeleton_ = &s;
  joint_count_ = n;
  return {};
}

// ---- materials ----

/// A cooked mip chain (texture.h): a known encoding, a size within kMaxTextureSide, a mip
/// count from 1 to the full chain, and data exactly the chain's bytes. A Source texture carries
/// no size or levels. O(mip count).
Status Validator::check_texture(const fb::Texture& t, size_t data_size) {
  const fb::TextureEncoding e = t.encoding();
  if (static_cast<unsigned>(e) > static_cast<unsigned>(fb::TextureEncoding::MAX))
    return Error{format("unknown encoding %u", static_cast<unsigned>(e))};
  if (e == fb::TextureEncoding::Source) {
    if (t.mip_count() != 0) return Error{"source bytes cannot have mip levels"};
    return {};
  }
  const char* name = fb::EnumNameTextureEncoding(e);
  if (data_size == 0) return Error{format("%s texture has no data", name)};
  if (t.width() == 0 || t.height() == 0 || t.width() > kMaxTextureSide || t.height() > kMaxTextureSide)
    return Error{format("%s texture is %u x %u texels (each side must be 1 to %u)", name, t.width(), t.height(),
                        kMaxTextureSide)};
  const uint32_t full = texture_full_mip_count(t.width(), t.height());
  if (t.mip_count() == 0 || t.mip_count() > full)
    return Error{format("%u mip levels for %u x %u texels (1 to %u)", static_cast<unsigned>(t.mip_count()), t.width(),
                        t.height(), full)};
  const uint64_t expected = texture_chain_bytes(e, t.width(), t.height(), t.mip_count());
  if (expected != data_size)
    return Error{format("%s chain of %u levels from %u x %u is %llu bytes, the data is %zu", name,
                        static_cast<unsigned>(t.mip_count()), t.width(), t.height(),
                        static_cast<unsigned long long>(expected), data_size)};
  return {};
}

Status Validator::check_material(const fb::Material& m, size_t material_index) {
  const Where where{nullptr, "material", material_index, m.name()};
  const struct {
    const char* field;
    const fb::Vec3* value;
  } colours[] = {{"ambient", m.ambient()}, {"diffuse", m.diffuse()}, {"specular", m.specular()}};
  for (const auto& c : colours)
    if (c.value && !finite3(*c.value))
      return fail(where, format("%s colour %s is not finite", c.field, vec3_text(*c.value).c_str()));
  if (!std::isfinite(m.shininess())) return fail(where, "shininess is not finite");
  if (!std::isfinite(m.opacity())) return fail(where, "opacity is not finite");
  if (m.emissive() && !finite3(*m.emissive()))
    return fail(where, format("emissive colour %s is not finite", vec3_text(*m.emissive()).c_str()));
  if (const fb::PbrFactors* p = m.pbr();
      p && !(p->metallic() >= 0.0f && p->metallic() <= 1.0f && p->roughness() >= 0.0f && p->roughness() <= 1.0f))
    return fail(where, format("metallic %g / roughness %g outside [0, 1]", static_cast<double>(p->metallic()),
                              static_cast<double>(p->roughness())));
  const auto* textures = m.textures();
  if (!textures) return {};
  if (!spend(static_cast<uint64_t>(textures->size()) * 4)) return over_budget(where);
  for (flatbuffers::uoffset_t k = 0; k < textures->size(); ++k) {
    const fb::Texture& t = *textures->Get(k);
    if (static_cast<unsigned>(t.role()) > static_cast<unsigned>(fb::TextureRole::MAX))
      return fail(where, format("texture %u has unknown role %u", k, static_cast<unsigned>(t.role())));
    const size_t data_size = count_of(t.data());
    if (data_size == 0 && flatbuffers::GetStringView(t.path()).empty())
      return fail(where,
                  format("texture %u (%s) has neither embedded data nor a path", k, fb::EnumNameTextureRole(t.role())));
    if (data_size != 0 && reinterpret_cast<uintptr_t>(t.data()->Data()) % 16 != 0)
      return fail(
          where, format("texture %u (%s): embedded data is not 16-byte aligned", k, fb::EnumNameTextureRole(t.role())));
    if (Status s = check_texture(t, data_size); !s)
      return fail(where, format("texture %u (%s): %s", k, fb::EnumNameTextureRole(t.role()), s.message().c_str()));
  }
  return {};
}

}  // namespace validate_detail

Status validate_file(const fb::File& file, std::string_view name, size_t buffer_size) {
  return validate_detail::Validator(file, name, buffer_size).run();
}

}  // namespace ossa
