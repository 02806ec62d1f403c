// validator.h — the Validator that validate_file (validate.cpp) runs over a verified .ossa file,
// shared by the files that hold its checks: validate.cpp (the order of the checks, the skeleton,
// materials), validate_mesh.cpp (meshes and their morph targets) and validate_clip.cpp (clips and
// their morph weight tracks). Internal to the runtime.
//
// Why it is shaped so: one object walks the file once and carries what later checks need (the
// skeleton once it checked out, the joint and material counts, the scan budget); its checks are
// split by the table family they read, and the small predicates every family uses (finite,
// bounded, the message labels) are inline here. The design is in validate.cpp's header.
#pragma once

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <string>
#include <string_view>

#include <ossa/format/ossa_generated.h>
#include <ossa/loader/validate.h>
#include "common/message.h"

namespace ossa::validate_detail {

using detail::format;

template <class V>
size_t count_of(const V* v) {
  return v ? v->size() : 0;
}

/// "mesh 2 'Body'", or "mesh 2" when unnamed.
inline std::string label(const char* kind, size_t index, const flatbuffers::String* name) {
  std::string out = format("%s %zu", kind, index);
  if (name && name->size() != 0) out += " '" + detail::printable(flatbuffers::GetStringView(name)) + "'";
  return out;
}

/// The part of a file a message is about ("mesh 0 'body': morph target 2 'smile'"), formatted only
/// when a message is made: a valid file pays for no label (they were ~8% of opening a small file).
struct Where {
  const Where* parent;
  const char* kind;
  size_t index;
  const flatbuffers::String* name;
  std::string text() const { return (parent ? parent->text() + ": " : std::string()) + label(kind, index, name); }
};

inline bool finite3(const fb::Vec3& v) { return std::isfinite(v.x()) && std::isfinite(v.y()) && std::isfinite(v.z()); }

/// Pose values (translations, scales) are bounded so that blending, layering and adding poses —
/// differences, weighted sums, ratios — stay finite: a finite but astronomically large value
/// (a flipped exponent bit) would overflow there. 1e7 source units is 100 km in centimetres.
inline constexpr float kMaxPoseValue = 1e7f;
inline bool bounded(float v) { return std::isfinite(v) && std::fabs(v) <= kMaxPoseValue; }
inline bool bounded3(const fb::Vec3& v) { return bounded(v.x()) && bounded(v.y()) && bounded(v.z()); }

inline bool finite4(const fb::Quat& q) {
  return std::isfinite(q.x()) && std::isfinite(q.y()) && std::isfinite(q.z()) && std::isfinite(q.w());
}

/// A rotation the sampler can normalize: finite, and a squared norm that neither underflows to
/// zero nor overflows to infinity in float, which is where normalize() would produce NaN or 0.
inline bool normalizable(const fb::Quat& q) {
  if (!finite4(q)) return false;
  const float n2 = q.x() * q.x() + q.y() * q.y() + q.z() * q.z() + q.w() * q.w();
  return n2 >= std::numeric_limits<float>::min() && n2 <= std::numeric_limits<float>::max();
}

inline bool finite_matrix(const fb::Mat4& m) {
  const auto* a = m.m();
  for (flatbuffers::uoffset_t k = 0; k < 16; ++k)
    if (!std::isfinite(a->Get(k))) return false;
  return true;
}

/// Array forms of bounded() / std::isfinite / normalizable() for the fast path of a valid file:
/// no early exit, so the compiler vectorizes them; each gives exactly the per-value answer ANDed
/// over the array (|v| <= limit is false for NaN, and for infinity when limit is finite).
/// `values` may be unaligned FlatBuffers struct storage. O(n).
inline bool all_abs_at_most(const float* values, size_t n, float limit) {
  // On the bits: for a sign-cleared float (NaN and infinity included) the integer order is the
  // float order, NaN above infinity above every finite value; so |v| <= limit exactly when
  // limit_bits - (bits & 0x7fffffff) is non-negative as a signed 32-bit number. ORing those
  // differences keeps the sign bit of any that is not: subtract, and, or per float, which
  // SSE2 vectorizes (a float compare-and-branch per value ran ~4x slower).
  uint32_t limit_bits;
  std::memcpy(&limit_bits, &limit, 4);
  constexpr size_t kLanes = 8;
  uint32_t lanes[kLanes] = {};
  size_t i = 0;
  for (; i + kLanes <= n; i += kLanes)
    for (size_t k = 0; k < kLanes; ++k) {
      uint32_t b;
      std::memcpy(&b, values + i + k, 4);
      lanes[k] |= limit_bits - (b & 0x7fffffffu);
    }
  uint32_t acc = 0;
  for (size_t k = 0; k < kLanes; ++k) acc |= lanes[k];
  for (; i < n; ++i) {
    uint32_t b;
    std::memcpy(&b, values + i, 4);
    acc |= limit_bits - (b & 0x7fffffffu);
  }
  return (acc & 0x80000000u) == 0;
}
inline bool all_bounded(const float* values, size_t n) { return all_abs_at_most(values, n, kMaxPoseValue); }
inline bool all_finite(const float* values, size_t n) {
  return all_abs_at_most(values, n, std::numeric_limits<float>::max());
}
/// normalizable() over n quaternions stored as (x, y, z, w) floats. A NaN or infinite component
/// makes the squared norm NaN or infinite, so the range test alone is normalizable()'s answer.
inline bool all_normalizable(const float* q, size_t n) {
  bool bad = false;
  for (size_t i = 0; i < n; ++i, q += 4) {
    const float n2 = q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3];
    bad |= !(n2 >= std::numeric_limits<float>::min() && n2 <= std::numeric_limits<float>::max());
  }
  return !bad;
}
static_assert(sizeof(fb::Vec3) == 12 && sizeof(fb::Quat) == 16 && sizeof(fb::Mat4) == 64,
              "the array checks read FlatBuffers structs as packed floats");

/// "1 joint", "3 joints".
inline std::string count_text(size_t n, const char* noun) { return format("%zu %s%s", n, noun, n == 1 ? "" : "s"); }

inline std::string vec3_text(const fb::Vec3& v) { return format("(%g, %g, %g)", v.x(), v.y(), v.z()); }

inline const char* semantic_name(fb::VertexSemantic s) {
  const char* n = fb::EnumNameVertexSemantic(s);
  return *n ? n : "unknown semantic";
}
inline const char* format_name(fb::VertexFormat f) {
  const char* n = fb::EnumNameVertexFormat(f);
  return *n ? n : "unknown format";
}

class Validator {
 public:
  Validator(const fb::File& file, std::string_view name, size_t buffer_size) : file_(file), name_(name) {
    // Every vector element is scanned once in a file without shared vectors, and a few vectors
    // may legitimately be shared (one times vector for several channels); 4x leaves room for
    // that while bounding a crafted DAG. 0 = the caller gave no size: no bound.
    budget_ = buffer_size ? 4 * static_cast<uint64_t>(buffer_size) + 4096 : UINT64_MAX;
  }

  /// Every check, in file order; the first failure is the result.
  Status run();

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
  Error fail(const Where& where, const std::string& what) const { return fail(where.text(), what); }
  Error over_budget(const Where& where) const { return over_budget(where.text()); }
  Error over_budget(const std::string& where) const {
    return fail(where,
                "tables reference far more data than the file holds (vectors shared between "
                "tables); refusing to scan it");
  }

  std::string joint_label(size_t joint) const {
    std::string out = format("joint %zu", joint);
    if (skeleton_ && joint < joint_count_) {
      const auto name =
          flatbuffers::GetStringView(skeleton_->joint_names()->Get(static_cast<flatbuffers::uoffset_t>(joint)));
      out += " '" + detail::printable(name) + "'";
    }
    return out;
  }

  // validate.cpp
  Status check_skeleton(const fb::Skeleton& s);
  static Status check_texture(const fb::Texture& t, size_t data_size);
  Status check_material(const fb::Material& m, size_t material_index);

  // validate_mesh.cpp
  Status check_mesh(const fb::Mesh& m, size_t mesh_index);
  /// Largest |weight| a file may store (defaults, weight keys): far past any authored face (glTF
  /// weights are usually in [0, 1], sometimes [-1, 1]), and small enough that weights * deltas stay
  /// finite.
  static constexpr float kMaxMorphWeight = 1e3f;
  /// Largest per-axis step: 32767 steps stay within the pose bound.
  static constexpr float kMaxMorphStep = kMaxPoseValue / 32767.0f;
  static bool step_ok(const fb::Vec3& s);
  Status check_morph_targets(const fb::Mesh& m, const Where& mesh_where);

  // validate_clip.cpp
  std::string channel_label(const char* kind, size_t index, size_t joint, unsigned channel, bool binds_here) const;
  static uint32_t channel_key(uint16_t joint, fb::Channel channel);
  /// A rotation component bound: xyz of a unit quaternion lie in [-1, 1]; the slack admits a
  /// cooker's rounding. Bounding them keeps the squared norm far from overflow when normalizing.
  static constexpr float kRotationComponentLimit = 1.01f;
  Status check_clip(const fb::Clip& c, size_t clip_index);
  Status check_morph_weights(const fb::Clip& c, const Where& clip_where);

  const fb::File& file_;
  std::string_view name_;
  uint64_t budget_ = 0;
  size_t material_count_ = 0;
  const fb::Skeleton* skeleton_ = nullptr;  // set once the skeleton checked out
  size_t joint_count_ = 0;
};

}  // namespace ossa::validate_detail
