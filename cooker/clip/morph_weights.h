// morph_weights.h — a clip's morph weight tracks compressed onto its frame grid (format v5
// MorphTrack).
//
// A weight is one float per frame, so the scheme is the clip channels' in one dimension: sample
// the source (linear between its keys; the importer already resampled STEP and CUBICSPLINE curves)
// at every frame, quantize to 16 bits in the track's own range, then keep only the keys needed for
// linear interpolation between them to stay within the tolerance at every frame, measured against
// the source, quantization included. A track whose range fits in twice the tolerance is one key
// (a constant track stored once). Greedy segment growth, each segment capped at kMaxSegment frames,
// keeps the cost O(frames * kMaxSegment) even for 65,536-frame clips.
#pragma once
#include <cstdint>
#include <string>
#include <vector>

#include "cooker/model/clip_grid.h"
#include "cooker/model/source_scene.h"

namespace ossa::cook {

struct CompressedMorphTrack {
  std::string name;
  std::vector<uint16_t> key_frames;  // first 0, last frame_count - 1 (or only 0: constant)
  std::vector<uint16_t> values;      // range_min + range_extent * q / 65535
  float range_min = 0.0f, range_extent = 0.0f;
  float max_error = 0.0f;  // largest |cooked - source| over every frame
};

/// Compresses one track. tolerance 0 keeps a key at every frame (quantization error only).
/// O(frames * kMaxSegment).
CompressedMorphTrack compress_morph_track(const SourceMorphTrack& track, const FrameGrid& grid, float tolerance);

/// The source track's value at `time`: linear between keys, held outside them.
float source_morph_weight(const SourceMorphTrack& track, float time);

}  // namespace ossa::cook
