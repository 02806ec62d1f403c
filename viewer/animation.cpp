// animation.cpp — see animation.h.
#include "viewer/animation.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <utility>

#include <glm/gtc/matrix_transform.hpp>

#include <ossa/anim/morph.h>
#include <ossa/anim/pose_ops.h>

namespace ossa::view {
namespace {

using Clock = std::chrono::steady_clock;

double ms_since(Clock::time_point t0) { return std::chrono::duration<double, std::milli>(Clock::now() - t0).count(); }

float duration_of(const Scene& scene, int clip) {
  return clip >= 0 ? scene.clips[static_cast<size_t>(clip)].clip.duration() : 0.0f;
}

float instance_time(float time, float offset, float duration, bool loop) {
  return offset == 0.0f ? time : advance_time(time, offset, 1.0f, duration, loop);
}

}  // namespace

Animator make_animator(const Scene& scene, size_t instance_count) {
  Animator a;
  const auto joints = static_cast<uint32_t>(scene.joint_count());
  a.instances.resize(instance_count == 0 ? 1 : instance_count);
  for (size_t i = 0; i < a.instances.size(); ++i) {
    AnimInstance& inst = a.instances[i];
    inst.local = Pose(joints);
    inst.from_local = Pose(joints);
    inst.model.assign(joints, glm::mat4(1.0f));
    inst.morph_weights = scene.morph_defaults;
    inst.from_morph_weights = scene.morph_defaults;
    if (joints > 0) set_bind_pose(scene.skeleton(), inst.local);
    const double phase = static_cast<double>(i) * 0.6180339887;
    inst.time_offset = static_cast<float>(phase - std::floor(phase));  // fraction of a loop; scaled per clip
  }
  a.morph_overrides.held.assign(scene.morph_channels.size(), 0);
  a.morph_overrides.value.assign(scene.morph_channels.size(), 0.0f);
  return a;
}

Status select_clip(const Scene& scene, Animator& animator, int clip, bool crossfade) {
  Playback& p = animator.playback;
  const bool fade = crossfade && p.clip >= 0 && clip >= 0 && clip != p.clip && !p.bind_pose;
  std::vector<SamplingCache> caches;
  if (clip >= 0) {
    const ClipView view = scene.clips[static_cast<size_t>(clip)].clip;
    for (size_t i = 0; i < animator.instances.size(); ++i) {
      // A morph-only clip of a file without joints samples weights only: no pose, no cache.
      if (scene.joint_count() == 0) {
        caches.emplace_back();
        continue;
      }
      Result<SamplingCache> c = make_sampling_cache(view, scene.skeleton());
      if (!c) return c.error();
      caches.push_back(std::move(*c));
    }
  }
  for (size_t i = 0; i < animator.instances.size(); ++i) {
    AnimInstance& inst = animator.instances[i];
    if (fade) inst.from_cache = std::move(inst.cache);
    inst.cache = clip >= 0 ? std::move(caches[i]) : SamplingCache();
  }
  if (fade) {
    p.from_clip = p.clip;
    p.from_time = p.time;
    p.fade = 0.0f;
  } else {
    p.from_clip = -1;
    p.fade = 1.0f;
  }
  p.clip = clip;
  p.time = 0.0f;
  p.loop_start = p.loop_end = 0.0f;
  return {};
}

float loop_time(float time, float lo, float hi) {
  if (!(hi > lo) || !std::isfinite(time)) return lo;
  if (time >= lo && time <= hi) return time;
  const float length = hi - lo;
  float r = std::fmod(time - lo, length);
  if (r < 0.0f) r += length;
  return lo + r;
}

float clip_duration(const Scene& scene, const Animator& animator) { return duration_of(scene, animator.playback.clip); }

void advance_drive(Drive& d, float played) {
  if (!d.active() || !(played > 0.0f)) return;
  constexpr float kStep = 1.0f / 240.0f;
  for (float left = played; left > 0.0f; left -= kStep) {
    const float h = std::min(left, kStep);
    const float turning = std::clamp(d.clock + h - d.turn_after, 0.0f, h);  // the part of the step after turn_after
    d.heading += d.turn_rate * turning;
    const glm::vec3 ahead =
        glm::vec3(glm::rotate(glm::mat4(1.0f), d.heading, glm::vec3(0, 1, 0)) * glm::vec4(d.forward, 0.0f));
    d.position += ahead * (d.speed * h);
    d.clock += h;
  }
  d.world = glm::rotate(glm::translate(glm::mat4(1.0f), d.position), d.heading, glm::vec3(0, 1, 0));
}

void advance(const Scene& scene, Animator& animator, float dt) {
  Playback& p = animator.playback;
  if (!p.playing) return;
  advance_drive(animator.drive, (animator.graph && animator.use_graph) ? dt : dt * std::fabs(p.speed));
  if (animator.graph && animator.use_graph && !p.bind_pose) animator.graph_dt += dt * std::max(p.speed, 0.0f);
  if (p.clip >= 0) {
    const float duration = duration_of(scene, p.clip);
    const float end = std::min(p.loop_end, duration);
    p.time = p.loop && end > p.loop_start ? loop_time(p.time + dt * p.speed, p.loop_start, end)
                                          : advance_time(p.time, dt, p.speed, duration, p.loop);
  }
  if (p.fade < 1.0f) {
    p.from_time = advance_time(p.from_time, dt, p.speed, duration_of(scene, p.from_clip), true);
    p.fade = p.fade_seconds > 0.0f ? std::min(1.0f, p.fade + dt / p.fade_seconds) : 1.0f;
    if (p.fade >= 1.0f) p.from_clip = -1;
  }
}

void set_time(const Scene& scene, Animator& animator, float time) {
  Playback& p = animator.playback;
  p.time = p.clip >= 0 ? advance_time(0.0f, time, 1.0f, duration_of(scene, p.clip), p.loop) : 0.0f;
}

void produce_local_poses(const Scene& scene, Animator& animator, PoseTimings& timings) {
  const Playback& p = animator.playback;
  if (scene.joint_count() == 0) return;
  if (p.bind_pose || (p.clip < 0 && !(animator.graph && animator.use_graph))) {
    const auto t0 = Clock::now();
    for (AnimInstance& inst : animator.instances) set_bind_pose(scene.skeleton(), inst.local);
    timings.sample_ms += ms_since(t0);
    return;
  }
  if (animator.graph && animator.use_graph) {
    const auto t0 = Clock::now();
    GraphDriver& g = *animator.graph;
    update_graph(g, animator.graph_dt);
    animator.graph_dt = 0.0f;
    for (size_t i = 0; i < animator.instances.size() && i < g.instances.size(); ++i) {
      copy_pose(g.instances[i].pose(), animator.instances[i].local);
    }
    timings.graph_ms += ms_since(t0);
    return;
  }
  const ClipView clip = scene.clips[static_cast<size_t>(p.clip)].clip;
  SampleOptions options;
  options.loop = p.loop;
  SampleOptions looping;
  looping.loop = true;
  const float duration = clip.duration();
  const bool fading = p.fade < 1.0f && p.from_clip >= 0;
  const auto t0 = Clock::now();
  for (AnimInstance& inst : animator.instances) {
    sample(clip, instance_time(p.time, inst.time_offset * duration, duration, p.loop), options, inst.cache, inst.local);
    if (fading) {
      const ClipView from = scene.clips[static_cast<size_t>(p.from_clip)].clip;
      const float d = from.duration();
      sample(from, instance_time(p.from_time, inst.time_offset * d, d, true), looping, inst.from_cache,
             inst.from_local);
    }
  }
  timings.sample_ms += ms_since(t0);
  if (fading) {
    const auto t1 = Clock::now();
    for (AnimInstance& inst : animator.instances) blend(inst.from_local, inst.local, p.fade, inst.local);
    timings.blend_ms += ms_since(t1);
  }
}

void produce_morph_weights(const Scene& scene, Animator& animator) {
  const size_t channels = scene.morph_channels.size();
  if (channels == 0) return;
  const Playback& p = animator.playback;
  const bool graph = animator.graph && animator.use_graph && !p.bind_pose;
  const bool clip = p.clip >= 0 && !p.bind_pose && !(animator.graph && animator.use_graph);
  const bool fading = clip && p.fade < 1.0f && p.from_clip >= 0;
  const MorphOverrides& o = animator.morph_overrides;
  for (size_t i = 0; i < animator.instances.size(); ++i) {
    AnimInstance& inst = animator.instances[i];
    std::copy(scene.morph_defaults.begin(), scene.morph_defaults.end(), inst.morph_weights.begin());
    if (graph && i < animator.graph->instances.size()) {
      // The graph's output weights (GraphInstance::morph_weights), mapped onto the scene's channels.
      const std::span<const float> w = animator.graph->instances[i].morph_weights();
      const std::vector<int32_t>& map = animator.graph->morph_map;
      for (size_t ch = 0; ch < channels && ch < map.size(); ++ch)
        if (map[ch] >= 0 && static_cast<size_t>(map[ch]) < w.size())
          inst.morph_weights[ch] = w[static_cast<size_t>(map[ch])];
    }
    if (clip) {
      const SceneClip& c = scene.clips[static_cast<size_t>(p.clip)];
      const float duration = c.clip.duration();
      (void)sample_morph_weights(c.clip, instance_time(p.time, inst.time_offset * duration, duration, p.loop),
                                 c.morph_tracks, inst.morph_weights);
      if (fading) {
        const SceneClip& from = scene.clips[static_cast<size_t>(p.from_clip)];
        const float d = from.clip.duration();
        std::copy(scene.morph_defaults.begin(), scene.morph_defaults.end(), inst.from_morph_weights.begin());
        (void)sample_morph_weights(from.clip, instance_time(p.from_time, inst.time_offset * d, d, true),
                                   from.morph_tracks, inst.from_morph_weights);
        (void)blend_morph_weights(inst.from_morph_weights, inst.morph_weights, p.fade, inst.morph_weights);
      }
    }
    for (size_t ch = 0; ch < channels && ch < o.held.size(); ++ch)
      if (o.held[ch]) inst.morph_weights[ch] = o.value[ch];
  }
}

void hold_morph(Animator& animator, size_t channel, bool held, float weight) {
  MorphOverrides& o = animator.morph_overrides;
  if (channel >= o.held.size()) return;
  o.held[channel] = held ? 1 : 0;
  o.value[channel] = weight;
}

void compute_model_poses(const Scene& scene, Animator& animator, PoseTimings& timings) {
  if (scene.joint_count() == 0) return;
  const auto t0 = Clock::now();
  const auto parents = scene.skeleton().parents();
  for (AnimInstance& inst : animator.instances) {
    local_to_model(parents, inst.local, inst.model);
    if (animator.drive.active())
      for (glm::mat4& m : inst.model) m = animator.drive.world * m;
  }
  timings.blend_ms += ms_since(t0);
}

}  // namespace ossa::view
