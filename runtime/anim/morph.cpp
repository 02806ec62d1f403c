// morph.cpp — morph weights and the CPU morph (morph.h).
//
// The delta loops convert each int16 to float and multiply by a per-target, per-axis factor
// (weight * step) hoisted out of the loop: one multiply-add per component, no branch. Vertices are
// listed in increasing order, so the scattered writes still walk memory forwards.
#include <ossa/anim/morph.h>

#include <algorithm>
#include <cmath>

namespace ossa {
namespace {

std::string_view name_of(const flatbuffers::String* s) { return flatbuffers::GetStringView(s); }

int32_t find(std::span<const std::string_view> channels, std::string_view name) {
  for (size_t c = 0; c < channels.size(); ++c)
    if (channels[c] == name) return static_cast<int32_t>(c);
  return -1;
}

float decode(const fb::MorphTrack& track, uint16_t q) {
  return track.range_min() + track.range_extent() * (static_cast<float>(q) * (1.0f / 65535.0f));
}

/// Adds w * step * deltas to out[vertices[i]] for every listed vertex.
void accumulate(const uint32_t* vertices, size_t n, const int16_t* deltas, glm::vec3 factor, glm::vec3* out) {
  for (size_t i = 0; i < n; ++i) {
    glm::vec3& o = out[vertices[i]];
    o.x += factor.x * static_cast<float>(deltas[3 * i + 0]);
    o.y += factor.y * static_cast<float>(deltas[3 * i + 1]);
    o.z += factor.z * static_cast<float>(deltas[3 * i + 2]);
  }
}

glm::vec3 to_vec3(const fb::Vec3* v) { return v ? glm::vec3(v->x(), v->y(), v->z()) : glm::vec3(0.0f); }

}  // namespace

void collect_morph_channels(const MeshView& mesh, std::vector<std::string_view>& channels) {
  for (size_t t = 0; t < mesh.morph_target_count(); ++t) {
    const std::string_view name = name_of(mesh.morph_target(t).name());
    if (find(channels, name) < 0) channels.push_back(name);
  }
}

bool bind_morph_targets(const MeshView& mesh, std::span<const std::string_view> channels,
                        std::span<int32_t> target_channel) {
  if (target_channel.size() < mesh.morph_target_count()) return false;
  for (size_t t = 0; t < mesh.morph_target_count(); ++t)
    target_channel[t] = find(channels, name_of(mesh.morph_target(t).name()));
  return true;
}

bool bind_morph_tracks(const ClipView& clip, std::span<const std::string_view> channels,
                       std::span<int32_t> track_channel) {
  if (track_channel.size() < clip.morph_track_count()) return false;
  for (size_t k = 0; k < clip.morph_track_count(); ++k)
    track_channel[k] = find(channels, name_of(clip.morph_track(k).name()));
  return true;
}

bool default_morph_weights(const MeshView& mesh, std::span<const int32_t> target_channel, std::span<float> weights) {
  const size_t n = mesh.morph_target_count();
  if (target_channel.size() < n) return false;
  for (size_t t = 0; t < n; ++t)
    if (target_channel[t] >= 0 && static_cast<size_t>(target_channel[t]) >= weights.size()) return false;
  for (size_t t = 0; t < n; ++t)
    if (target_channel[t] >= 0) weights[static_cast<size_t>(target_channel[t])] = mesh.morph_target(t).default_weight();
  return true;
}

float sample_morph_track(const ClipView& clip, const fb::MorphTrack& track, float time) {
  const uint16_t* frames = track.key_frames()->data();
  const uint16_t* values = track.values()->data();
  const uint32_t n = track.key_frames()->size();
  if (n == 1) return decode(track, values[0]);
  const float last = static_cast<float>(clip.frame_count() - 1);
  float f = time * clip.sample_rate();
  f = std::isfinite(f) ? std::clamp(f, 0.0f, last) : 0.0f;
  // The last key whose frame is <= f (frames start at 0 and end at the last frame).
  const uint16_t* hi = std::upper_bound(frames, frames + n, static_cast<uint16_t>(f));
  const size_t b = std::min<size_t>(static_cast<size_t>(hi - frames), n - 1);
  const size_t a = b - 1;
  const float fa = frames[a], fb = frames[b];
  const float u = std::clamp((f - fa) / (fb - fa), 0.0f, 1.0f);
  const float va = decode(track, values[a]), vb = decode(track, values[b]);
  return va + (vb - va) * u;
}

bool sample_morph_weights(const ClipView& clip, float time, std::span<const int32_t> track_channel,
                          std::span<float> weights) {
  const size_t n = clip.morph_track_count();
  if (track_channel.size() < n) return false;
  for (size_t k = 0; k < n; ++k)
    if (track_channel[k] >= 0 && static_cast<size_t>(track_channel[k]) >= weights.size()) return false;
  for (size_t k = 0; k < n; ++k)
    if (track_channel[k] >= 0)
      weights[static_cast<size_t>(track_channel[k])] = sample_morph_track(clip, clip.morph_track(k), time);
  return true;
}

bool blend_morph_weights(std::span<const float> a, std::span<const float> b, float t, std::span<float> out) {
  if (a.size() != b.size() || out.size() < a.size()) return false;
  for (size_t c = 0; c < a.size(); ++c) out[c] = a[c] + (b[c] - a[c]) * t;
  return true;
}

bool apply_morphs(const MeshView& mesh, std::span<const int32_t> target_channel, std::span<const float> weights,
                  std::span<glm::vec3> positions, std::span<glm::vec3> normals, std::span<glm::vec3> tangents) {
  const size_t targets = mesh.morph_target_count();
  const size_t vertex_count = mesh.vertex_count();
  if (target_channel.size() < targets || positions.size() < vertex_count) return false;
  if (!normals.empty() && normals.size() < vertex_count) return false;
  if (!tangents.empty() && tangents.size() < vertex_count) return false;
  for (size_t t = 0; t < targets; ++t)
    if (target_channel[t] >= 0 && static_cast<size_t>(target_channel[t]) >= weights.size()) return false;
  for (size_t t = 0; t < targets; ++t) {
    if (target_channel[t] < 0) continue;
    const float w = weights[static_cast<size_t>(target_channel[t])];
    if (w == 0.0f) continue;
    const fb::MorphTarget& target = mesh.morph_target(t);
    const uint32_t* vertices = target.vertices()->data();
    const size_t n = target.vertices()->size();
    accumulate(vertices, n, target.position_deltas()->data(), w * to_vec3(target.position_step()), positions.data());
    if (!normals.empty() && target.normal_deltas() && target.normal_deltas()->size() != 0)
      accumulate(vertices, n, target.normal_deltas()->data(), w * to_vec3(target.normal_step()), normals.data());
    if (!tangents.empty() && target.tangent_deltas() && target.tangent_deltas()->size() != 0)
      accumulate(vertices, n, target.tangent_deltas()->data(), w * to_vec3(target.tangent_step()), tangents.data());
  }
  return true;
}

}  // namespace ossa
