// clip_side_by_side.h — ossa's half of ossa-bench-acl: a source's clips cooked in-process with
// ossa-cook's defaults, the raw keys they were cooked from, and the one error measure both codecs
// are judged by.
//
// cook_side_by_side imports a source as ossa-cook does, samples each clip on its frame grid
// (cooker/clip/clip_reference.h: the raw keys), compresses it (compress_clip, default options) and
// writes and loads the result as a file, so playback is the runtime's own on verified bytes. The
// raw keys are also handed over as RawClipData, the form acl_codec.h gives ACL.
//
// measure_clip plays the raw keys as the runtime plays a clip (between consecutive frames ossa's
// interpolation, cooker/clip/clip_error.h's interpolate_keys) against a candidate sampled at the
// same times: every frame, and three points between each pair of frames. Both poses go to model
// space in double (<ossa/anim/pose_error.h>) and every joint is compared with ossa::probe_error, the
// measure ossa-cook bounds and reports.
#pragma once
#include <cstdint>
#include <functional>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "bench/acl_codec.h"
#include "cooker/clip/clip_error.h"
#include "cooker/import/import_scene.h"
#include <ossa/anim/pose.h>
#include <ossa/anim/pose_error.h>
#include <ossa/anim/sample.h>
#include <ossa/loader/asset.h>

namespace ossa::bench {

/// ossa-cook's default bound: 0.1 mm at probe points 10 cm from each joint.
inline constexpr double kToleranceMetres = 0.0001;
inline constexpr double kProbeMetres = 0.1;
/// Points measured between two frames (at 1/4, 2/4, 3/4 of the way), as the cooker measures.
inline constexpr uint32_t kPointsBetweenFrames = kClipErrorSubdivisions - 1;

struct SideBySideClip {
  ClipView clip;  // ossa's cooked clip (in SideBySideFile::asset)
  SkeletonView rig;
  SamplingCache cache;                        // for measuring
  SamplingCache forward_cache, random_cache;  // for timing
  Pose pose;
  cook::ClipSamples reference;  // the raw keys on the grid
  std::vector<int16_t> parents;
  RawClipData raw;            // the same keys for ACL
  std::vector<double> shell;  // per joint: where the probe points sit, in the joint's local units
  double metres_per_unit = 1.0;
  double probe = 0.1;       // kProbeMetres in the clip's units
  uint32_t ossa_bytes = 0;  // CompressedClip::cooked_bytes
};

struct SideBySideFile {
  std::vector<uint8_t> bytes;
  std::unique_ptr<Asset> asset;
  std::vector<SideBySideClip> clips;
};

/// Imports `path` with `options`, cooks each clip and loads the cooked file. Errors name the file.
Result<SideBySideFile> cook_side_by_side(const std::string& path, const cook::ImportOptions& options);

struct ClipMeasure {
  double at_frames = 0.0;  // largest probe error at the frames, clip units
  double between = 0.0;    // ... between frames
  uint32_t worst_joint = 0;
  float worst_frame = 0.0f;  // frame position of the largest error
  double max() const { return at_frames > between ? at_frames : between; }
};

/// Largest probe error of `candidate` (local pose at a time in seconds) against the raw keys.
/// O(frames * joints * (1 + kPointsBetweenFrames)).
ClipMeasure measure_clip(const SideBySideClip& c, const std::function<void(float, PoseSpan)>& candidate);

/// ossa::sample of the cooked clip, no looping.
void sample_ossa(SideBySideClip& c, float time, PoseSpan out);

/// ns per pose of ossa::sample (looping) with `cache` over `times` in order, into c.pose.
double time_ossa(SideBySideClip& c, SamplingCache& cache, std::span<const float> times);

}  // namespace ossa::bench
