// clip_reference.h — a source clip sampled on its frame grid: the raw keys every clip is cooked
// from and measured against.
//
// The compressor (clip_compress.h) fits its keys to these samples and bounds its error against
// them; ossa-bench-acl hands the same floats to ACL, so both codecs start from one set of raw keys.
// Kept apart from the compressor so that whatever measures a cooked clip can rebuild exactly what
// it was cooked from.
#pragma once
#include "cooker/clip/clip_error.h"
#include "cooker/model/clip_grid.h"
#include "cooker/model/source_scene.h"

namespace ossa::cook {

/// Every channel of every joint of `skeleton` at every frame of `grid`, from the source keys:
/// linear for translation and scale, slerp on the shortest arc for rotation (what Assimp's own
/// evaluator does), ends clamped; a grid time within 1/1000 of a frame of a source key takes that
/// key's value exactly, so a source keyed on the grid survives bit for bit. Channels without keys
/// hold the joint's bind value. Tracks must address joints of `skeleton`. O(joints * frames + keys).
ClipSamples reference_samples(const SourceClip& clip, const SourceSkeleton& skeleton, const FrameGrid& grid);

}  // namespace ossa::cook
