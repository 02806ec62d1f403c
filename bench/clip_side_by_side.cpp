// clip_side_by_side.cpp — clip_side_by_side.h.
#include "bench/clip_side_by_side.h"

#include <algorithm>
#include <chrono>

#include "cooker/clip/clip_compress.h"
#include "cooker/clip/clip_reference.h"
#include "cooker/write/write_ossa.h"
#include <ossa/anim/pose_error.h>

namespace ossa::bench {
namespace {

volatile float g_sink;  // keeps the timed loop's results alive

RawTransform raw_transform(const cook::ClipSamples& s, uint32_t joint, uint32_t frame) {
  const glm::vec4 t = s.channel(joint, cook::kTranslation)[frame];
  const glm::vec4 q = s.channel(joint, cook::kRotation)[frame];
  const glm::vec4 sc = s.channel(joint, cook::kScale)[frame];
  return RawTransform{{t.x, t.y, t.z}, {q.x, q.y, q.z, q.w}, {sc.x, sc.y, sc.z}};
}

/// The raw keys at frame + alpha as the runtime plays a clip keyed at every frame.
void reference_pose(const SideBySideClip& c, uint32_t frame, float alpha, PoseSpan out) {
  const cook::ClipSamples& r = c.reference;
  const uint32_t next = std::min(frame + 1, r.frame_count - 1);
  for (uint32_t j = 0; j < r.joint_count; ++j) {
    glm::vec4 v[3];
    for (uint32_t ch = 0; ch < cook::kChannelsPerJoint; ++ch) {
      const glm::vec4* k = r.channel(j, ch);
      v[ch] = alpha == 0.0f ? k[frame] : cook::interpolate_keys(ch, k[frame], k[next], alpha);
    }
    const float values[kPoseComponents] = {v[0].x, v[0].y, v[0].z, v[1].x, v[1].y,
                                           v[1].z, v[1].w, v[2].x, v[2].y, v[2].z};
    for (uint32_t comp = 0; comp < kPoseComponents; ++comp) out[static_cast<PoseComponent>(comp)][j] = values[comp];
  }
}

}  // namespace

Result<SideBySideFile> cook_side_by_side(const std::string& path, const cook::ImportOptions& options) {
  auto scene = cook::import_scene(path, options);
  if (!scene) return scene.error();
  if (scene->skeleton.joints.empty() && !scene->clips.empty()) return Error{path + ": clips without a skeleton"};
  SideBySideFile file;
  std::vector<cook::CompressedClip> compressed;
  std::vector<cook::ClipSamples> references;
  for (const cook::SourceClip& clip : scene->clips) {
    auto c = cook::compress_clip(clip, scene->skeleton, scene->metres_per_unit, cook::ClipCompressionOptions{});
    if (!c) return Error{path + ": " + c.error().message};
    references.push_back(cook::reference_samples(clip, scene->skeleton, c->grid));
    compressed.push_back(std::move(*c));
  }
  cook::SourceScene written;
  written.skeleton = scene->skeleton;
  written.clips = scene->clips;
  written.metres_per_unit = scene->metres_per_unit;
  file.bytes = cook::write_ossa(written, {}, compressed, cook::WriteProvenance{}, cook::WriteOptions{});
  auto asset = Asset::from_bytes(file.bytes, path);
  if (!asset) return asset.error();
  file.asset = std::make_unique<Asset>(std::move(*asset));

  const auto joints = static_cast<uint32_t>(scene->skeleton.joints.size());
  for (size_t i = 0; i < compressed.size(); ++i) {
    SideBySideClip c;
    c.clip = file.asset->clip(i);
    c.rig = file.asset->skeleton();
    c.pose = Pose(joints);
    c.reference = std::move(references[i]);
    for (SamplingCache* cache : {&c.cache, &c.forward_cache, &c.random_cache}) {
      auto made = make_sampling_cache(c.clip, c.rig);
      if (!made) return Error{path + ": " + made.error().message};
      *cache = std::move(*made);
    }
    c.metres_per_unit = scene->metres_per_unit > 0.0f ? scene->metres_per_unit : 1.0;
    c.probe = kProbeMetres / c.metres_per_unit;
    c.ossa_bytes = compressed[i].cooked_bytes;
    RawClipData& raw = c.raw;
    raw.joints = joints;
    raw.frames = c.reference.frame_count;
    raw.sample_rate = compressed[i].grid.sample_rate;
    for (uint32_t j = 0; j < joints; ++j) {
      const cook::SourceJoint& sj = scene->skeleton.joints[j];
      raw.parents.push_back(sj.parent);
      c.parents.push_back(static_cast<int16_t>(sj.parent));
      raw.bind.push_back(RawTransform{{sj.translation.x, sj.translation.y, sj.translation.z},
                                      {sj.rotation.x, sj.rotation.y, sj.rotation.z, sj.rotation.w},
                                      {sj.scale.x, sj.scale.y, sj.scale.z}});
    }
    // ossa's probe points sit `probe` from each joint in model space (probe_error); ACL takes one
    // shell distance per joint in its local units, so the probe over the joint's model scale (at
    // the first frame; real rigs' scales do not animate).
    std::vector<cook::Affine> model(joints);
    cook::model_at_frame(scene->skeleton, c.reference, 0, model);
    for (uint32_t j = 0; j < joints; ++j) {
      double scale = 0.0;
      for (int k = 0; k < 3; ++k) scale = std::max(scale, glm::length(model[j].linear[k]));
      c.shell.push_back(scale > 0.0 ? c.probe / scale : c.probe);
    }
    raw.samples.resize(static_cast<size_t>(raw.frames) * joints);
    for (uint32_t f = 0; f < raw.frames; ++f)
      for (uint32_t j = 0; j < joints; ++j)
        raw.samples[static_cast<size_t>(f) * joints + j] = raw_transform(c.reference, j, f);
    file.clips.push_back(std::move(c));
  }
  return file;
}

ClipMeasure measure_clip(const SideBySideClip& c, const std::function<void(float, PoseSpan)>& candidate) {
  ClipMeasure m;
  const uint32_t joints = c.raw.joints, frames = c.raw.frames;
  Pose reference(joints), test(joints);
  std::vector<ModelAffine> ref_model(joints), test_model(joints);
  const float rate = c.raw.sample_rate;
  for (uint32_t f = 0; f < frames; ++f) {
    for (uint32_t k = 0; k <= kPointsBetweenFrames; ++k) {
      if (k > 0 && f + 1 >= frames) break;
      const float alpha = static_cast<float>(k) / static_cast<float>(kPointsBetweenFrames + 1);
      const float position = static_cast<float>(f) + alpha;
      reference_pose(c, f, alpha, reference);
      candidate(position / rate, test);
      local_to_model_affine(c.parents, reference, ref_model);
      local_to_model_affine(c.parents, test, test_model);
      for (uint32_t j = 0; j < joints; ++j) {
        const double e = probe_error(ref_model[j], test_model[j], c.probe);
        double& worst = k == 0 ? m.at_frames : m.between;
        if (e > worst) worst = e;
        if (e >= m.max()) {
          m.worst_joint = j;
          m.worst_frame = position;
        }
      }
    }
  }
  return m;
}

void sample_ossa(SideBySideClip& c, float time, PoseSpan out) {
  sample(c.clip, time, SampleOptions{false, RotationInterpolation::Nlerp}, c.cache, out);
}

double time_ossa(SideBySideClip& c, SamplingCache& cache, std::span<const float> times) {
  const SampleOptions play;  // looping, nlerp: the defaults
  float sink = 0.0f;
  const auto start = std::chrono::steady_clock::now();
  for (const float t : times) {
    sample(c.clip, t, play, cache, c.pose);
    sink += c.pose.span().base[0];
  }
  const auto stop = std::chrono::steady_clock::now();
  g_sink = sink;
  return std::chrono::duration<double, std::nano>(stop - start).count() / static_cast<double>(times.size());
}

}  // namespace ossa::bench
