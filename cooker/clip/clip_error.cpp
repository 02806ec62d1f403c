// clip_error.cpp — decoding compressed clips as a runtime does, and the probe-point error metric
// (clip_error.h).
#include "cooker/clip/clip_error.h"

#include <algorithm>
#include <cmath>

#include <ossa/format/clip_codec.h>

namespace ossa::cook {

glm::vec4 bind_value(const SourceJoint& joint, uint32_t channel) {
  switch (channel) {
    case kTranslation: return glm::vec4(joint.translation, 0.0f);
    case kRotation: return glm::vec4(joint.rotation.x, joint.rotation.y, joint.rotation.z, joint.rotation.w);
    default: return glm::vec4(joint.scale, 0.0f);
  }
}

glm::vec4 key_sample(uint32_t channel, uint32_t dropped, const float stored[3]) {
  if (channel != kRotation) return glm::vec4(stored[0], stored[1], stored[2], 0.0f);
  float q[4];
  rotation_from_stored(stored, dropped, q);
  return glm::vec4(q[0], q[1], q[2], q[3]);
}

glm::vec4 interpolate_keys(uint32_t channel, const glm::vec4& a, glm::vec4 b, float alpha) {
  // runtime/anim/sample.cpp's arithmetic: a * (1 - w) + b * w (exact at both ends), the shortest-arc
  // sign folded into b's weight, then a multiply by 1 / |q|.
  const float wa = 1.0f - alpha;
  if (channel != kRotation) return a * wa + b * alpha;
  const float dot = a.x * b.x + a.y * b.y + a.z * b.z + a.w * b.w;
  const float wb = dot < 0.0f ? -alpha : alpha;
  const glm::vec4 q = a * wa + b * wb;
  return q * (1.0f / std::sqrt(q.x * q.x + q.y * q.y + q.z * q.z + q.w * q.w));
}

void decode_clip(const CompressedClip& clip, const SourceSkeleton& skeleton, ClipSamples& out, uint32_t subdivisions) {
  const auto joints = static_cast<uint32_t>(skeleton.joints.size());
  const uint32_t frames = clip.grid.frame_count;
  const uint32_t n = subdivisions == 0 ? 1 : subdivisions;
  const uint32_t positions = (frames - 1) * n + 1;
  out.resize(joints, positions);
  for (uint32_t j = 0; j < joints; ++j)
    for (uint32_t ch = 0; ch < kChannelsPerJoint; ++ch)
      std::fill_n(out.channel(j, ch), positions, bind_value(skeleton.joints[j], ch));
  for (const CompressedConstant& c : clip.constants) {
    if (c.joint >= joints || c.channel >= kChannelsPerJoint) continue;
    std::fill_n(out.channel(c.joint, c.channel), positions, glm::vec4(c.value[0], c.value[1], c.value[2], c.value[3]));
  }
  const float step = 1.0f / static_cast<float>(n);  // exact: n is a power of two in practice
  for (const CompressedAnimated& a : clip.animated) {
    if (a.joint >= joints || a.channel >= kChannelsPerJoint || a.key_count < 2) continue;
    glm::vec4* dst = out.channel(a.joint, a.channel);
    const auto frame_of = [&](uint32_t k) {
      return key_frame(clip.key_frames.data(), a.first_key, a.key_count, frames, k);
    };
    float xyz[3];
    decode_key(clip.key_values.data(), a.bit_offset, a.bits, a.segment_offset_bits, a.range_min, a.range_extent, 0,
               xyz);
    glm::vec4 prev = key_sample(a.channel, a.dropped, xyz);
    for (uint32_t k = 1; k < a.key_count; ++k) {
      decode_key(clip.key_values.data(), a.bit_offset, a.bits, a.segment_offset_bits, a.range_min, a.range_extent, k,
                 xyz);
      const glm::vec4 next = key_sample(a.channel, a.dropped, xyz);
      const uint32_t f0 = frame_of(k - 1), f1 = frame_of(k);
      const float inv_length = 1.0f / static_cast<float>(f1 - f0);
      for (uint32_t p = f0 * n; p <= f1 * n && p < positions; ++p) {
        const float x = static_cast<float>(p / n) + static_cast<float>(p % n) * step;
        dst[p] = interpolate_keys(a.channel, prev, next, (x - static_cast<float>(f0)) * inv_length);
      }
      prev = next;
    }
  }
}

ClipSamples between_frames(const ClipSamples& frames) {
  ClipSamples out;
  const uint32_t n = kErrorSubdivisions;
  out.resize(frames.joint_count, frames.frame_count == 0 ? 0 : (frames.frame_count - 1) * n + 1);
  for (uint32_t j = 0; j < frames.joint_count; ++j) {
    for (uint32_t ch = 0; ch < kChannelsPerJoint; ++ch) {
      const glm::vec4* src = frames.channel(j, ch);
      glm::vec4* dst = out.channel(j, ch);
      for (uint32_t p = 0; p < out.frame_count; ++p) {
        const uint32_t f = p / n, k = p % n;
        dst[p] =
            k == 0 ? src[f] : interpolate_keys(ch, src[f], src[f + 1], static_cast<float>(k) / static_cast<float>(n));
      }
    }
  }
  return out;
}

Affine affine_from_trs(const glm::vec4& t, const glm::vec4& r, const glm::vec4& s) {
  return ossa::affine_from_trs(glm::vec3(t), glm::quat(r.w, r.x, r.y, r.z), glm::vec3(s));
}

void model_at_frame(const SourceSkeleton& skeleton, const ClipSamples& samples, uint32_t frame, std::span<Affine> out) {
  for (uint32_t j = 0; j < samples.joint_count; ++j) {
    const Affine local = affine_from_trs(samples.channel(j, kTranslation)[frame], samples.channel(j, kRotation)[frame],
                                         samples.channel(j, kScale)[frame]);
    const int parent = skeleton.joints[j].parent;
    if (parent < 0) {
      out[j] = local;
    } else {
      const Affine& p = out[static_cast<size_t>(parent)];
      out[j].linear = p.linear * local.linear;
      out[j].origin = p.linear * local.origin + p.origin;
    }
  }
}

ClipError measure_clip_error(const SourceSkeleton& skeleton, const ClipSamples& reference, const ClipSamples& test,
                             double probe, const std::vector<Affine>* reference_models, uint32_t subdivisions) {
  ClipError e;
  const uint32_t joints = reference.joint_count;
  const uint32_t n = subdivisions == 0 ? 1 : subdivisions;
  e.joint_max.assign(joints, 0.0);
  std::vector<Affine> ref_model(joints), test_model(joints);
  double sum = 0.0;
  for (uint32_t p = 0; p < reference.frame_count; ++p) {
    if (reference_models == nullptr) model_at_frame(skeleton, reference, p, ref_model);
    model_at_frame(skeleton, test, p, test_model);
    for (uint32_t j = 0; j < joints; ++j) {
      const Affine& r =
          reference_models ? (*reference_models)[static_cast<size_t>(j) * reference.frame_count + p] : ref_model[j];
      const double err = probe_error(r, test_model[j], probe);
      sum += err;
      e.joint_max[j] = std::max(e.joint_max[j], err);
      if (p % n == 0) e.max_at_frames = std::max(e.max_at_frames, err);
      if (err > e.max) {
        e.max = err;
        e.worst_joint = static_cast<uint16_t>(j);
        e.worst_frame = static_cast<float>(p) / static_cast<float>(n);
      }
    }
  }
  const double count = static_cast<double>(joints) * static_cast<double>(reference.frame_count);
  e.mean = count > 0.0 ? sum / count : 0.0;
  return e;
}

}  // namespace ossa::cook
