// tiny_values.cpp — flushing values below kTinyValue to zero (see tiny_values.h).
#include "cooker/import/tiny_values.h"

#include <bit>
#include <cmath>
#include <cstdint>

namespace ossa::cook {
namespace {

struct Flusher {
  size_t changed = 0;
  void operator()(float& v) {
    if (std::fabs(v) < kTinyValue && std::bit_cast<uint32_t>(v) != 0u) {
      v = 0.0f;
      ++changed;
    }
  }
  void operator()(glm::vec2& v) { (*this)(v.x), (*this)(v.y); }
  void operator()(glm::vec3& v) { (*this)(v.x), (*this)(v.y), (*this)(v.z); }
  void operator()(glm::vec4& v) { (*this)(v.x), (*this)(v.y), (*this)(v.z), (*this)(v.w); }
  void operator()(glm::quat& q) { (*this)(q.x), (*this)(q.y), (*this)(q.z), (*this)(q.w); }
  void operator()(glm::mat4& m) {
    for (int c = 0; c < 4; ++c) (*this)(m[c]);
  }
  template <class T>
  void operator()(std::vector<T>& values) {
    for (T& v : values) (*this)(v);
  }
};

}  // namespace

size_t flush_tiny_values(std::span<glm::vec4> values) {
  Flusher flush;
  for (glm::vec4& v : values) flush(v);
  return flush.changed;
}

size_t flush_tiny_values(SourceScene& scene) {
  Flusher flush;
  for (SourceJoint& j : scene.skeleton.joints) {
    flush(j.translation);
    flush(j.rotation);
    flush(j.scale);
    flush(j.inverse_bind);
  }
  for (SourceMesh& m : scene.meshes) {
    flush(m.positions);
    flush(m.normals);
    flush(m.tangents);
    for (auto& [joint, matrix] : m.bind) flush(matrix);
    for (SourceMorphTarget& t : m.morph_targets) {
      flush(t.positions);
      flush(t.normals);
      flush(t.tangents);
    }
  }
  for (SourceClip& c : scene.clips) {
    for (SourceTrack& t : c.tracks) {
      flush(t.translations);
      flush(t.rotations);
      flush(t.scales);
    }
    flush(c.root_motion.translations);
    flush(c.root_motion.yaws);
    for (SourceMorphTrack& m : c.morph_weights) flush(m.weights);
  }
  return flush.changed;
}

}  // namespace ossa::cook
