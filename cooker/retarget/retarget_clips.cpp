// retarget_clips.cpp — the cook-time retarget (retarget_clips.h).
//
// The source clip is sampled on its frame grid exactly as the compressor samples it
// (clip_compress.cpp: a grid time within 1e-3 frames of a key takes the key, otherwise linear /
// shortest-arc slerp in double), so the poses fed to the retarget job are the ones a lossless cook
// of the source would play: that is what lets a test hold the live job to the cooked clip.
#include "cooker/retarget/retarget_clips.h"

#include <algorithm>
#include <cmath>
#include <string_view>

#include <glm/gtc/quaternion.hpp>

#include "cooker/model/clip_grid.h"
#include <ossa/anim/pose.h>
#include <ossa/retarget/foot_contacts.h>
#include <ossa/retarget/retarget.h>
#include <ossa/retarget/retarget_measure.h>

namespace ossa::cook {
namespace {

constexpr double kSnapFrames = 1e-3;  // as the compressor (clip_compress.cpp)

glm::vec3 blend(const glm::vec3& a, const glm::vec3& b, double f) {
  return glm::vec3(glm::mix(glm::dvec3(a), glm::dvec3(b), f));
}
glm::quat blend(const glm::quat& a, const glm::quat& b, double f) {
  glm::dquat qa(a), qb(b);
  if (glm::dot(qa, qb) < 0.0) qb = -qb;
  return glm::quat(glm::normalize(glm::slerp(qa, qb, f)));
}

/// A channel's value at grid time t (keys sorted); `fallback` when it has none.
template <class V>
V at_time(const std::vector<float>& times, const std::vector<V>& values, double t, double rate, const V& fallback) {
  const size_t n = std::min(times.size(), values.size());
  if (n == 0) return fallback;
  const size_t i =
      static_cast<size_t>(std::upper_bound(times.begin(), times.begin() + static_cast<std::ptrdiff_t>(n), t,
                                           [](double x, float k) { return x < static_cast<double>(k); }) -
                          times.begin());
  const size_t near =
      (i < n && (i == 0 || static_cast<double>(times[i]) - t < t - static_cast<double>(times[i - 1]))) ? i : i - 1;
  if (std::abs(static_cast<double>(times[near]) - t) * rate <= kSnapFrames) return values[near];
  if (i == 0) return values[0];
  if (i == n) return values[n - 1];
  const double t0 = times[i - 1], t1 = times[i];
  return blend(values[i - 1], values[i], (t - t0) / (t1 - t0));
}

/// Every frame of a clip on its grid, as local poses of its skeleton.
std::vector<Pose> sample_clip(const SourceClip& clip, const SourceSkeleton& skeleton, const FrameGrid& grid) {
  const auto joints = static_cast<uint32_t>(skeleton.joints.size());
  std::vector<const SourceTrack*> track(joints, nullptr);
  for (const SourceTrack& t : clip.tracks)
    if (t.joint < joints) track[t.joint] = &t;
  std::vector<Pose> frames;
  frames.reserve(grid.frame_count);
  for (uint32_t f = 0; f < grid.frame_count; ++f) {
    Pose pose(joints);
    const double t = static_cast<double>(f) / grid.sample_rate;
    for (uint32_t j = 0; j < joints; ++j) {
      const SourceJoint& b = skeleton.joints[j];
      Transform x{b.translation, b.rotation, b.scale};
      if (const SourceTrack* k = track[j]) {
        x.translation = at_time(k->translation_times, k->translations, t, grid.sample_rate, b.translation);
        x.rotation = at_time(k->rotation_times, k->rotations, t, grid.sample_rate, b.rotation);
        x.scale = at_time(k->scale_times, k->scales, t, grid.sample_rate, b.scale);
      }
      set_transform(pose, j, x);
    }
    frames.push_back(std::move(pose));
  }
  return frames;
}

/// A rig as the retarget job reads it, with its names and bind pose kept alive.
struct Rig {
  std::string name;
  std::vector<std::string_view> names;
  std::vector<int16_t> parents;
  std::vector<Transform> bind;
  std::vector<RestRotation> rest_rotations;
  RetargetRig rig;
};

Result<Rig> make_rig(const SourceSkeleton& skeleton, const std::string& name, const RetargetTarget& target,
                     const char* role) {
  Rig r;
  for (const SourceJoint& j : skeleton.joints) {
    r.names.emplace_back(j.name);
    r.parents.push_back(static_cast<int16_t>(j.parent));
    r.bind.push_back(Transform{j.translation, j.rotation, j.scale});
  }
  const tools::RigMapSpec* spec = target.map != nullptr ? tools::section_for(*target.map, role, r.names) : nullptr;
  const std::string label = spec != nullptr ? target.map_name + " (" + role + ")" : name;
  auto applied = tools::apply_rig_map(spec, r.names, r.parents, label);
  if (!applied) return applied.error();
  r.rest_rotations = std::move(applied->rest_rotations);
  r.name = name;
  r.rig.parents = r.parents;
  r.rig.bind = r.bind;
  r.rig.names = r.names;
  r.rig.humanoid = applied->humanoid;
  r.rig.rest = applied->rest;
  r.rig.rest_rotations = r.rest_rotations;
  return r;
}

float distance_mm(const glm::vec3& a, const glm::vec3& b, float metres_per_unit) {
  return glm::length(a - b) * metres_per_unit * 1000.0f;
}

}  // namespace

Status retarget_scene(SourceScene& scene, const RetargetTarget& target, const std::string& label,
                      std::vector<RetargetRecord>* records) {
  if (target.skeleton == nullptr || target.skeleton->joints.empty())
    return Error{label + ": no target rig to retarget to"};
  if (scene.skeleton.joints.empty()) return Error{label + ": has no skeleton to retarget from"};
  if (scene.clips.empty()) return Error{label + ": has no clips to retarget"};
  auto source = make_rig(scene.skeleton, label + " (source rig)", target, "source");
  if (!source) return source.error();
  auto dest = make_rig(*target.skeleton, target.name + " (target rig)", target, "target");
  if (!dest) return dest.error();
  source->rig.name = source->name;  // the names live in the Rigs, which stay where they are from here
  dest->rig.name = dest->name;
  auto built = make_retarget_map(source->rig, dest->rig);
  if (!built) return Error{"retarget: " + built.error().message};
  const RetargetMap& map = *built;
  RetargetScratch scratch = make_retarget_scratch(map);
  const float source_mpu = scene.metres_per_unit > 0.0f ? scene.metres_per_unit : 1.0f;
  const float target_mpu = target.skeleton->metres_per_unit > 0.0f ? target.skeleton->metres_per_unit : 1.0f;
  const auto target_joints = static_cast<uint32_t>(target.skeleton->joints.size());

  std::vector<SourceClip> out_clips;
  for (const SourceClip& clip : scene.clips) {
    const FrameGrid grid = frame_grid(clip);
    if (grid.frame_count > kMaxFrames)
      return Error{label + ": clip '" + clip.name + "' has more frames than a retarget cooks in one clip"};
    const std::vector<Pose> frames = sample_clip(clip, scene.skeleton, grid);
    // 1: the source's feet (its floor); 2: where the transfer puts the target's ankles.
    std::vector<ContactFrame> feet(frames.size());
    for (size_t f = 0; f < frames.size(); ++f) {
      pose_source(map, frames[f], scratch);
      feet[f] = contact_frame(map, scratch);
    }
    const float floor = clip_floor(map, feet);
    Pose pose(target_joints);
    RetargetInput in;
    in.source_floor = floor;
    for (size_t f = 0; f < frames.size(); ++f) {
      in.source = frames[f];
      if (!retarget(map, in, scratch, pose)) return Error{label + ": retarget: internal error (pose sizes)"};
      feet[f].target_ankle = contact_frame(map, scratch).target_ankle;
    }
    const std::vector<ContactSpan> contacts = find_foot_contacts(map, feet, grid.sample_rate, floor);

    // 3: the clip, with its feet held; measured as it goes.
    SourceClip result;
    result.name = clip.name;
    result.source_name = clip.source_name;
    result.duration = grid.duration();
    result.sample_rate = grid.sample_rate;
    result.events = clip.events;
    result.morph_weights = clip.morph_weights;
    result.tracks.resize(target_joints);
    for (uint32_t j = 0; j < target_joints; ++j) result.tracks[j].joint = static_cast<uint16_t>(j);
    RetargetRecord record;
    record.clip = clip.name;
    record.frames = grid.frame_count;
    record.hips_ratio = (map.target_pose.hips_height * target_mpu) / (map.source_pose.hips_height * source_mpu);
    record.floor_mm = floor * source_mpu * 1000.0f;
    for (const ContactSpan& c : contacts) {
      RetargetContactRecord cr;
      cr.foot = c.foot;
      cr.start = grid.time(c.first);
      cr.end = grid.time(c.last);
      glm::dvec3 mean(0.0);
      for (uint32_t f = c.first; f <= c.last; ++f) mean += glm::dvec3(feet[f].source_ankle[c.foot]);
      mean /= static_cast<double>(c.last - c.first + 1);
      for (uint32_t f = c.first; f <= c.last; ++f)
        cr.source_slide_mm =
            std::max(cr.source_slide_mm, distance_mm(feet[f].source_ankle[c.foot], glm::vec3(mean), source_mpu));
      record.contacts.push_back(cr);
    }
    std::vector<glm::dvec3> held_sum(contacts.size(), glm::dvec3(0.0));
    std::vector<std::vector<glm::vec3>> held_path(contacts.size());
    std::array<FootContact, 2> held{};
    in.contacts = held;
    for (size_t f = 0; f < frames.size(); ++f) {
      foot_contacts_at(contacts, static_cast<float>(f), grid.sample_rate, ContactSettings{}.blend_time, held);
      in.source = frames[f];
      if (!retarget(map, in, scratch, pose)) return Error{label + ": retarget: internal error (pose sizes)"};
      const float time = grid.time(static_cast<uint32_t>(f));
      for (uint32_t j = 0; j < target_joints; ++j) {
        const Transform x = get_transform(pose, j);
        SourceTrack& track = result.tracks[j];
        track.translation_times.push_back(time);
        track.translations.push_back(x.translation);
        track.rotation_times.push_back(time);
        glm::quat q = x.rotation;
        if (!track.rotations.empty() && glm::dot(track.rotations.back(), q) < 0.0f)
          q = -q;  // neighbours on one hemisphere
        track.rotations.push_back(q);
        track.scale_times.push_back(time);
        track.scales.push_back(x.scale);
      }
      RetargetMeasure m;
      measure_retarget(map, scratch, &m);
      for (size_t i = 0; i < kRetargetLimbCount; ++i) {
        // Limb i belongs to the left arm, left leg, right arm, right leg: guard bits 1, 4, 2, 8.
        static constexpr uint8_t kGuardBit[kRetargetLimbCount] = {1, 1, 4, 4, 2, 2, 8, 8};
        float& worst = (scratch.adjusted & kGuardBit[i]) != 0 ? record.guard_max_deg : record.limb_max_deg;
        worst = std::max(worst, m.limb_degrees[i]);
      }
      for (float d : m.hand_degrees) record.hand_max_deg = std::max(record.hand_max_deg, d);
      for (float d : m.foot_degrees) record.foot_max_deg = std::max(record.foot_max_deg, d);
      bool crossing = false;
      for (int p : {kLeftHandPoint, kRightHandPoint, kLeftFootPoint, kRightFootPoint}) {
        const float side = p % 2 == 0 ? 1.0f : -1.0f;
        crossing |=
            side * m.source_side[static_cast<size_t>(p)] > 0.05f && side * m.target_side[static_cast<size_t>(p)] < 0.0f;
      }
      record.crossing_frames += crossing ? 1 : 0;
      record.guarded_frames += (scratch.adjusted & 0x0F) != 0 ? 1 : 0;
      for (size_t k = 0; k < contacts.size(); ++k) {
        const ContactSpan& c = contacts[k];
        if (f < c.first || f > c.last) continue;
        const glm::vec3 goal = held_ankle(map, scratch, c.foot, held[c.foot], floor);
        record.contacts[k].held_mm =
            std::max(record.contacts[k].held_mm, distance_mm(m.target_ankle[c.foot], goal, target_mpu));
        held_path[k].push_back(m.target_ankle[c.foot]);
        held_sum[k] += glm::dvec3(m.target_ankle[c.foot]);
      }
    }
    for (size_t k = 0; k < contacts.size(); ++k) {
      const glm::vec3 mean(held_sum[k] / static_cast<double>(std::max<size_t>(1, held_path[k].size())));
      for (const glm::vec3& p : held_path[k])
        record.contacts[k].slide_mm = std::max(record.contacts[k].slide_mm, distance_mm(p, mean, target_mpu));
    }
    out_clips.push_back(std::move(result));
    if (records != nullptr) records->push_back(std::move(record));
  }
  scene.clips = std::move(out_clips);
  scene.skeleton = *target.skeleton;
  scene.metres_per_unit = target_mpu;
  scene.meshes.clear();
  scene.materials.clear();
  scene.vertices_over_4_influences = 0;
  return {};
}

}  // namespace ossa::cook
