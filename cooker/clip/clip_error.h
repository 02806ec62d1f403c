// clip_error.h — reading a compressed clip back as a runtime does, and how far it then moves a
// skeleton from its source: the one error metric the compressor bounds and reports
// (cooker/clip/clip_compress.h), and the decoding it is measured through.
//
// The metric is the one the animation-compression literature uses (ACL's "virtual vertices", ozz's
// error at a distance): for every joint six probe points sit at ±probe along each of the joint's
// three axes, `probe` from the joint in the source pose's model space (whatever scale the armature
// carries); both the source pose and the cooked pose carry them into model space (the joint's whole
// parent chain included, so errors accumulate down the hierarchy as a skinned vertex would see
// them), and the joint's error is the largest displacement among its six points. Six points rather
// than the three positive ones: with a translation error d and a rotation error r, the
// displacement of a point is |d + r·p|, which is largest on whichever side r·p points along d, so
// the negative side matters.
//
// Where: at every frame and at kErrorSubdivisions - 1 points between each pair of frames, because
// a runtime plays between frames too, and there the cooked clip interpolates its own keys while the
// source is the raw frames interpolated the same way (what a lossless cook plays). Errors that
// cancel at the frames need not cancel between them: a child fitted to undo its parent's decoded
// error at the frames (clip_compress.cpp, error compensation) leaves a residue between them that
// grows with how fast both move.
//
// The measure itself (affine_from_trs, probe_error) lives in <ossa/anim/pose_error.h>, so tools that
// judge cooked output without the cooker (ossa-diff) measure exactly what the cooker bounded.
// Poses are kept as per-channel, per-position float samples (ClipSamples, the layout the
// compressor works in); model space is built in double so the measurement reflects the data, not
// rounding in the measurement. Decoding, on the other hand, is done in float with the runtime's own
// arithmetic (ossa/format/clip_codec.h's decoding, then lerp / nlerp on the shortest arc between
// keys), because the bound is a promise about what a runtime will play.
#pragma once
#include <cstdint>
#include <span>
#include <vector>

#include <glm/glm.hpp>

#include "cooker/clip/clip_compress.h"
#include "cooker/model/source_scene.h"
#include <ossa/anim/pose_error.h>

namespace ossa::cook {

/// Channels of a joint, in fb::Channel order.
inline constexpr uint32_t kChannelsPerJoint = 3;
enum ChannelIndex : uint32_t { kTranslation = 0, kRotation = 1, kScale = 2 };

/// Every channel of every joint sampled at every frame of a clip's grid (or, for the error measure,
/// at every position of a finer grid: between_frames). Translation and scale are xyz (w = 0);
/// rotation is a unit quaternion as (x, y, z, w).
struct ClipSamples {
  uint32_t joint_count = 0;
  uint32_t frame_count = 0;
  std::vector<glm::vec4> values;  // [(joint * 3 + channel) * frame_count + frame]

  void resize(uint32_t joints, uint32_t frames) {
    joint_count = joints;
    frame_count = frames;
    values.assign(static_cast<size_t>(joints) * kChannelsPerJoint * frames, glm::vec4(0.0f));
  }
  glm::vec4* channel(uint32_t joint, uint32_t ch) {
    return values.data() + (static_cast<size_t>(joint) * kChannelsPerJoint + ch) * frame_count;
  }
  const glm::vec4* channel(uint32_t joint, uint32_t ch) const {
    return values.data() + (static_cast<size_t>(joint) * kChannelsPerJoint + ch) * frame_count;
  }
};

/// Positions measured per frame interval (<ossa/anim/pose_error.h>): the frames and the points at
/// 1/4, 2/4 and 3/4 of the way to the next frame. Position p of a clip is frame position p / kErrorSubdivisions; a clip
/// of F frames has (F - 1) * kErrorSubdivisions + 1 positions.
inline constexpr uint32_t kErrorSubdivisions = kClipErrorSubdivisions;

/// A channel's bind value as a sample (translation/scale xyz with w = 0, rotation xyzw).
glm::vec4 bind_value(const SourceJoint& joint, uint32_t channel);

/// A decoded key as a sample: translation/scale xyz; rotations x, y, z, w from the three stored
/// components and the channel's dropped index (ossa/format/clip_codec.h's rotation_from_stored).
glm::vec4 key_sample(uint32_t channel, uint32_t dropped, const float stored[3]);

/// What a runtime plays between two decoded keys at weight alpha in [0, 1], in float and in
/// runtime/anim/sample.cpp's arithmetic: a * (1 - alpha) + b * alpha for translation and scale; for
/// rotation the same with b's weight negated when dot(a, b) < 0 (shortest arc), then multiplied by
/// 1 / |q|.
glm::vec4 interpolate_keys(uint32_t channel, const glm::vec4& a, glm::vec4 b, float alpha);

/// Decodes `clip` (made for `skeleton`) at every frame of its grid, or with subdivisions = n at every
/// frame position p / n: bind values for absent channels, constants, and animated keys decoded
/// from key_values and interpolated between the key frames f0 <= x < f1 around each position x with
/// alpha = (x - f0) * (1 / (f1 - f0)), as runtime/anim/sample.cpp does.
void decode_clip(const CompressedClip& clip, const SourceSkeleton& skeleton, ClipSamples& out,
                 uint32_t subdivisions = 1);

/// A clip keyed at every frame (`frames`, e.g. the source on its grid) played at every position of
/// kErrorSubdivisions per frame, as a runtime plays it (interpolate_keys between neighbours).
ClipSamples between_frames(const ClipSamples& frames);

/// A joint's model-space transform: x -> linear * x + origin (<ossa/anim/pose_error.h>).
using Affine = ModelAffine;

/// Local TRS (float samples) -> affine in double: translate * rotate * scale, as
/// ossa::affine_from_trs (the rotation normalized first).
Affine affine_from_trs(const glm::vec4& t, const glm::vec4& r, const glm::vec4& s);

/// Model space of every joint at one frame of `samples` (parents-first skeleton). out.size() ==
/// joint count.
void model_at_frame(const SourceSkeleton& skeleton, const ClipSamples& samples, uint32_t frame, std::span<Affine> out);

/// The largest displacement of the six probe points between two model-space transforms of one
/// joint: ossa::probe_error (<ossa/anim/pose_error.h>).
using ossa::probe_error;

struct ClipError {
  double max = 0.0;               // over every joint at every position
  double max_at_frames = 0.0;     // ... at the frames only
  double mean = 0.0;              // of the per-joint, per-position error (largest of its six points)
  uint16_t worst_joint = 0;       // where max occurs (the first such joint, lowest position first)
  float worst_frame = 0.0f;       // the frame position where max occurs
  std::vector<double> joint_max;  // per joint, over positions
};

/// Measures `test` against `reference` (same joint and position counts, same skeleton) at every
/// position; positions are frame positions p / subdivisions. `reference_models`, when given, is the
/// reference's model space [joint * positions + position], computed once by a caller that measures
/// repeatedly. O(positions * joints).
ClipError measure_clip_error(const SourceSkeleton& skeleton, const ClipSamples& reference, const ClipSamples& test,
                             double probe, const std::vector<Affine>* reference_models = nullptr,
                             uint32_t subdivisions = 1);

}  // namespace ossa::cook
