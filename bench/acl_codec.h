// acl_codec.h — ACL (Nicholas Frechette's Animation Compression Library) behind a plain interface,
// for ossa-bench-acl: compress the raw keys ossa cooks from, play the result back, time it.
//
// Only acl_codec.cpp includes ACL's headers (found through -DOSSA_ACL_SOURCE_DIR, never fetched),
// so the side-by-side program and its measure see plain spans and ossa poses. ACL gets:
//   - every joint as one qvvf track (its parent, the raw sample at every frame of the clip's grid),
//     the rig's bind pose as each track's default value (what ossa leaves out of a clip, and what a
//     runtime hands back for it: the decompression writer returns it for default sub-tracks);
//   - ossa's error measure inside its optimizer: six points at +-shell along each local axis
//     (ACL's own metric uses three, +shell), carried into object space through the parent chain,
//     scale included, with the shell distance given per joint;
//   - get_default_compression_settings() otherwise (v2.1: level automatic, variable bit rates,
//     segments of ~16 frames, trivial key frames stripped).
// Playback is ACL's own: a decompression_context seeks to a time and decompresses a whole pose into
// an rtm::qvvf array, with ACL's benchmark settings (default transform formats, no safety checks).
#pragma once
#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include <ossa/anim/pose.h>

namespace ossa::bench {

/// One joint's raw sample: translation xyz, rotation xyzw (unit), scale xyz.
struct RawTransform {
  float t[3];
  float q[4];
  float s[3];
};

/// A clip's raw samples, frame-major: frames[f * joints + j].
struct RawClipData {
  uint32_t joints = 0, frames = 0;
  float sample_rate = 30.0f;
  std::vector<int> parents;           // parents[j] < j, -1 for a root
  std::vector<RawTransform> bind;     // per joint
  std::vector<RawTransform> samples;  // frames * joints
};

class AclClip {
 public:
  /// Compresses `raw` with every joint's precision (ACL's error threshold) and shell distance
  /// (where its six probe points sit, in the joint's local units) given in the clip's units.
  static std::unique_ptr<AclClip> compress(const RawClipData& raw, double precision, std::span<const double> shell,
                                           std::string* error);
  ~AclClip();
  AclClip(const AclClip&) = delete;
  AclClip& operator=(const AclClip&) = delete;

  /// compressed_tracks::get_size(): everything ACL needs to play the clip, headers included.
  uint32_t bytes() const;
  /// Segments ACL split the clip into.
  uint32_t segments() const;
  /// Seeks to `time` (seconds, no rounding: interpolated) and decompresses the whole pose into `out`
  /// (bind values for default sub-tracks).
  void sample(float time, PoseSpan out);
  /// ns per pose of seek + decompress_tracks into ACL's own rtm::qvvf output, over `times` in order.
  double time_poses(std::span<const float> times);

 private:
  struct Impl;
  explicit AclClip(std::unique_ptr<Impl> impl);
  std::unique_ptr<Impl> impl_;
};

/// "ACL 2.1.0" from ACL's version header.
std::string acl_version();

}  // namespace ossa::bench
