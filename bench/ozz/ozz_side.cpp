// ozz_side.cpp — bench_vs_ozz's workloads written against ozz-animation 0.16.0's runtime jobs, on
// ozz's own media of the same character (pab_skeleton / pab_walk, jog, run / arnaud_mesh.ozz: Pab,
// 67 joints, from the FBX files ossa cooks in assets/Pab).
//
// Compiled once per ozz build; OSSA_OZZ_SIDE names the entry point (ozz_side_o3 / ozz_side_avx2)
// and the AVX2 copy is compiled with -Dozz=ozz_avx2 so the two builds' symbols differ. Each
// workload is written the way ozz's samples use the jobs (a SamplingJob::Context per clip, the
// skeleton's rest pose as the blend's fallback, one SkinningJob per mesh part: ozz splits a mesh
// by influence count), with every job built once and only `ratio` changed per call.
#include "bench/ozz/ozz_side.h"

#include <cmath>
#include <cstdio>
#include <cstring>

#include "framework/mesh.h"
#include "ozz/animation/runtime/animation.h"
#include "ozz/animation/runtime/blending_job.h"
#include "ozz/animation/runtime/local_to_model_job.h"
#include "ozz/animation/runtime/sampling_job.h"
#include "ozz/animation/runtime/skeleton.h"
#include "ozz/base/containers/vector.h"
#include "ozz/base/io/archive.h"
#include "ozz/base/io/stream.h"
#include "ozz/base/maths/simd_math.h"
#include "ozz/base/maths/soa_transform.h"
#include "ozz/geometry/runtime/skinning_job.h"

#ifndef OSSA_OZZ_SIDE
#error "OSSA_OZZ_SIDE names the entry point (bench/ozz/CMakeLists.txt)"
#endif

namespace ossa::bench {
namespace {

using ozz::animation::Animation;
using ozz::animation::Skeleton;
using ozz::math::Float4x4;
using ozz::math::SoaTransform;

constexpr size_t kTimes = 4096;  // precomputed times per sampling workload (a power of two)

template <typename T>
bool load(const char* media, const char* name, T& out, AnchorSide* side) {
  char path[1024];
  std::snprintf(path, sizeof path, "%s/%s", media, name);
  ozz::io::File file(path, "rb");
  if (!file.opened()) {
    std::snprintf(side->error, sizeof side->error, "cannot open %s", path);
    return false;
  }
  ozz::io::IArchive archive(&file);
  if (!archive.TestTag<T>()) {
    std::snprintf(side->error, sizeof side->error, "%s is not an ozz %s archive of this version", path, name);
    return false;
  }
  archive >> out;
  return true;
}

bool load_meshes(const char* media, const char* name, ozz::vector<ozz::sample::Mesh>& out, AnchorSide* side) {
  char path[1024];
  std::snprintf(path, sizeof path, "%s/%s", media, name);
  ozz::io::File file(path, "rb");
  if (!file.opened()) {
    std::snprintf(side->error, sizeof side->error, "cannot open %s", path);
    return false;
  }
  ozz::io::IArchive archive(&file);
  while (archive.TestTag<ozz::sample::Mesh>()) {
    out.resize(out.size() + 1);
    archive >> out.back();
  }
  if (out.empty()) std::snprintf(side->error, sizeof side->error, "%s holds no mesh", path);
  return !out.empty();
}

float lane(const ozz::math::SimdFloat4& v, int i) {
  float f[4];
  ozz::math::StorePtrU(v, f);
  return f[i];
}
void set_lane(ozz::math::SimdFloat4& v, int i, float x) {
  float f[4];
  ozz::math::StorePtrU(v, f);
  f[i] = x;
  v = ozz::math::simd_float4::LoadPtrU(f);
}

/// The rest pose with nudge(seed, j) applied to every joint (ozz_side.h); rotation only unless `trs`.
ozz::vector<SoaTransform> nudged_rest_pose(const Skeleton& s, uint32_t seed, bool trs) {
  ozz::vector<SoaTransform> pose(s.joint_rest_poses().begin(), s.joint_rest_poses().end());
  for (int j = 0; j < s.num_joints(); ++j) {
    SoaTransform& t = pose[size_t(j) / 4];
    const int l = j & 3;
    const Nudge n = nudge(seed, uint32_t(j));
    const float al = std::sqrt(n.axis[0] * n.axis[0] + n.axis[1] * n.axis[1] + n.axis[2] * n.axis[2]);
    const float sh = std::sin(0.5f * n.angle) / al, ch = std::cos(0.5f * n.angle);
    const float dx = n.axis[0] * sh, dy = n.axis[1] * sh, dz = n.axis[2] * sh, dw = ch;
    const float x = lane(t.rotation.x, l), y = lane(t.rotation.y, l), z = lane(t.rotation.z, l),
                w = lane(t.rotation.w, l);
    // rest * delta, normalized
    float r[4] = {w * dx + x * dw + y * dz - z * dy, w * dy - x * dz + y * dw + z * dx,
                  w * dz + x * dy - y * dx + z * dw, w * dw - x * dx - y * dy - z * dz};
    const float rl = std::sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2] + r[3] * r[3]);
    set_lane(t.rotation.x, l, r[0] / rl);
    set_lane(t.rotation.y, l, r[1] / rl);
    set_lane(t.rotation.z, l, r[2] / rl);
    set_lane(t.rotation.w, l, r[3] / rl);
    if (!trs) continue;
    const float tx = lane(t.translation.x, l), ty = lane(t.translation.y, l), tz = lane(t.translation.z, l);
    const float k = 0.01f * (1.0f + std::sqrt(tx * tx + ty * ty + tz * tz));
    set_lane(t.translation.x, l, tx + n.move[0] * k);
    set_lane(t.translation.y, l, ty + n.move[1] * k);
    set_lane(t.translation.z, l, tz + n.move[2] * k);
    const float sc = 1.0f + 0.02f * n.scale;
    set_lane(t.scale.x, l, lane(t.scale.x, l) * sc);
    set_lane(t.scale.y, l, lane(t.scale.y, l) * sc);
    set_lane(t.scale.z, l, lane(t.scale.z, l) * sc);
  }
  return pose;
}

struct Sampler {
  ozz::animation::SamplingJob::Context context;
  ozz::vector<SoaTransform> locals;
  ozz::animation::SamplingJob job;
  ozz::vector<float> ratios;
  size_t next = 0;
};

struct Skin {
  ozz::vector<ozz::geometry::SkinningJob> jobs;
};

struct State {
  Skeleton skeleton;
  Animation walk, jog, run;
  ozz::vector<ozz::sample::Mesh> arnaud;

  Sampler forward, seek;
  // blend3 and local_to_model
  ozz::vector<SoaTransform> inputs[3], blended, nudged;
  ozz::animation::BlendingJob::Layer layers[3];
  ozz::animation::BlendingJob blend;
  ozz::vector<Float4x4> model;
  ozz::animation::LocalToModelJob to_model;
  // frame
  ozz::animation::SamplingJob::Context contexts[3];
  ozz::vector<SoaTransform> locals[3], frame_blended;
  ozz::animation::SamplingJob samplers[3];
  ozz::animation::BlendingJob::Layer frame_layers[3];
  ozz::animation::BlendingJob frame_blend;
  ozz::vector<Float4x4> frame_model, frame_palette;
  ozz::animation::LocalToModelJob frame_to_model;
  ozz::vector<float> phase;
  size_t frame_next = 0;
  // skinning
  ozz::vector<Float4x4> skin_palette;
  ozz::vector<float> positions, normals;
  Skin skin_positions, skin_normals;
};

bool failed(const char* what, AnchorSide* side) {
  std::snprintf(side->error, sizeof side->error, "ozz %s job failed validation", what);
  return false;
}

void run_sampler(void* p) {
  Sampler& s = *static_cast<Sampler*>(p);
  s.job.ratio = s.ratios[s.next];
  s.next = (s.next + 1) & (kTimes - 1);
  if (!s.job.Run()) std::abort();
}

void run_blend3(void* p) {
  if (!static_cast<State*>(p)->blend.Run()) std::abort();
}

void run_local_to_model(void* p) {
  if (!static_cast<State*>(p)->to_model.Run()) std::abort();
}

void run_frame(void* p) {
  State& s = *static_cast<State*>(p);
  for (auto& job : s.samplers) {
    job.ratio = s.phase[s.frame_next];
    if (!job.Run()) std::abort();
  }
  s.frame_next = (s.frame_next + 1) & (kTimes - 1);
  if (!s.frame_blend.Run() || !s.frame_to_model.Run()) std::abort();
  const ozz::sample::Mesh& mesh = s.arnaud[0];
  for (size_t k = 0; k < mesh.joint_remaps.size(); ++k)
    s.frame_palette[k] = s.frame_model[mesh.joint_remaps[k]] * mesh.inverse_bind_poses[k];
}

void run_skin(void* p) {
  for (const auto& job : static_cast<Skin*>(p)->jobs)
    if (!job.Run()) std::abort();
}

void make_skin(State& s, bool normals, Skin& skin) {
  size_t offset = 0;
  for (const ozz::sample::Mesh& mesh : s.arnaud) {
    for (const auto& part : mesh.parts) {
      const size_t n = size_t(part.vertex_count());
      if (n == 0) continue;
      ozz::geometry::SkinningJob job;
      job.vertex_count = int(n);
      const int influences = part.influences_count();
      job.influences_count = influences;
      job.joint_matrices = ozz::make_span(s.skin_palette);
      job.joint_indices = ozz::make_span(part.joint_indices);
      job.joint_indices_stride = sizeof(uint16_t) * size_t(influences);
      if (influences > 1) {
        job.joint_weights = ozz::make_span(part.joint_weights);
        job.joint_weights_stride = sizeof(float) * size_t(influences - 1);
      }
      job.in_positions = ozz::make_span(part.positions);
      job.in_positions_stride = sizeof(float) * 3;
      job.out_positions = {s.positions.data() + 3 * offset, s.positions.data() + 3 * (offset + n)};
      job.out_positions_stride = sizeof(float) * 3;
      if (normals && part.normals.size() == 3 * n) {
        job.in_normals = ozz::make_span(part.normals);
        job.in_normals_stride = sizeof(float) * 3;
        job.out_normals = {s.normals.data() + 3 * offset, s.normals.data() + 3 * (offset + n)};
        job.out_normals_stride = sizeof(float) * 3;
      }
      skin.jobs.push_back(job);
      offset += n;
    }
    break;  // the first mesh: ossa's arnaud has one
  }
}

}  // namespace

bool OSSA_OZZ_SIDE(const char* media, AnchorSide* side) {
  State* s = new State;  // lives as long as the process: the calls point into it
  if (!load(media, "pab_skeleton.ozz", s->skeleton, side) || !load(media, "pab_walk.ozz", s->walk, side) ||
      !load(media, "pab_jog.ozz", s->jog, side) || !load(media, "pab_run.ozz", s->run, side) ||
      !load_meshes(media, "arnaud_mesh.ozz", s->arnaud, side))
    return false;
  const Skeleton& sk = s->skeleton;
  const int joints = sk.num_joints();
  const size_t soa = size_t(sk.num_soa_joints());
  side->joints = uint32_t(joints);

  // Sampling: forward 60 Hz playback (ratios of advance_time-like looping times), random seek.
  for (Sampler* sampler : {&s->forward, &s->seek}) {
    sampler->context.Resize(joints);
    sampler->locals.resize(soa);
    sampler->job.animation = &s->walk;
    sampler->job.context = &sampler->context;
    sampler->job.output = ozz::make_span(sampler->locals);
    sampler->ratios.resize(kTimes);
  }
  const double duration = s->walk.duration();
  double t = 0.0;
  for (float& r : s->forward.ratios) {
    r = float(t / duration);
    t += 1.0 / 60.0;
    t -= std::floor(t / duration) * duration;
  }
  for (size_t i = 0; i < kTimes; ++i) s->seek.ratios[i] = seek_fraction(uint32_t(i));
  if (!s->forward.job.Validate()) return failed("sampling", side);

  // Blend of three nudged rest poses, and local-to-model of one.
  const float weights[3] = {0.5f, 0.3f, 0.2f};
  for (int i = 0; i < 3; ++i) {
    s->inputs[i] = nudged_rest_pose(sk, 17 + uint32_t(i), true);
    s->layers[i].weight = weights[i];
    s->layers[i].transform = ozz::make_span(s->inputs[i]);
  }
  s->blended.resize(soa);
  s->blend.layers = s->layers;
  s->blend.rest_pose = sk.joint_rest_poses();
  s->blend.output = ozz::make_span(s->blended);
  if (!s->blend.Validate()) return failed("blending", side);
  s->nudged = nudged_rest_pose(sk, 17, true);
  s->model.resize(size_t(joints));
  s->to_model.skeleton = &sk;
  s->to_model.input = ozz::make_span(s->nudged);
  s->to_model.output = ozz::make_span(s->model);
  if (!s->to_model.Validate()) return failed("local-to-model", side);

  // Frame: the three locomotion clips at the walk's phase, blended, to model space, palette.
  const Animation* clips[3] = {&s->walk, &s->jog, &s->run};
  const float frame_weights[3] = {0.2f, 0.5f, 0.3f};
  for (int c = 0; c < 3; ++c) {
    s->contexts[c].Resize(joints);
    s->locals[c].resize(soa);
    s->samplers[c].animation = clips[c];
    s->samplers[c].context = &s->contexts[c];
    s->samplers[c].output = ozz::make_span(s->locals[c]);
    s->frame_layers[c].weight = frame_weights[c];
    s->frame_layers[c].transform = ozz::make_span(s->locals[c]);
  }
  s->frame_blended.resize(soa);
  s->frame_blend.layers = s->frame_layers;
  s->frame_blend.rest_pose = sk.joint_rest_poses();
  s->frame_blend.output = ozz::make_span(s->frame_blended);
  s->frame_model.resize(size_t(joints));
  s->frame_to_model.skeleton = &sk;
  s->frame_to_model.input = ozz::make_span(s->frame_blended);
  s->frame_to_model.output = ozz::make_span(s->frame_model);
  s->frame_palette.resize(s->arnaud[0].joint_remaps.size());
  side->palette = uint32_t(s->frame_palette.size());
  s->phase.resize(kTimes);
  for (size_t i = 0; i < kTimes; ++i) {
    const float p = float(i) / 60.0f / s->walk.duration();
    s->phase[i] = p - float(int(p));
  }

  // Skinning: a palette from the rest pose with every rotation nudged.
  {
    const ozz::vector<SoaTransform> pose = nudged_rest_pose(sk, 29, false);
    ozz::vector<Float4x4> model(static_cast<size_t>(joints));
    ozz::animation::LocalToModelJob job;
    job.skeleton = &sk;
    job.input = ozz::make_span(pose);
    job.output = ozz::make_span(model);
    if (!job.Run()) return failed("local-to-model", side);
    const ozz::sample::Mesh& mesh = s->arnaud[0];
    s->skin_palette.resize(mesh.joint_remaps.size());
    for (size_t i = 0; i < mesh.joint_remaps.size(); ++i)
      s->skin_palette[i] = model[mesh.joint_remaps[i]] * mesh.inverse_bind_poses[i];
    side->vertices = uint32_t(mesh.vertex_count());
    s->positions.resize(3 * size_t(side->vertices));
    s->normals.resize(3 * size_t(side->vertices));
  }
  make_skin(*s, false, s->skin_positions);
  make_skin(*s, true, s->skin_normals);
  for (const auto& job : s->skin_normals.jobs)
    if (!job.Validate()) return failed("skinning", side);

  side->run[kSampleForward] = {run_sampler, &s->forward};
  side->run[kSampleSeek] = {run_sampler, &s->seek};
  side->run[kBlend3] = {run_blend3, s};
  side->run[kLocalToModel] = {run_local_to_model, s};
  side->run[kFrame] = {run_frame, s};
  side->run[kSkinPositions] = {run_skin, &s->skin_positions};
  side->run[kSkinNormals] = {run_skin, &s->skin_normals};
  return true;
}

}  // namespace ossa::bench
