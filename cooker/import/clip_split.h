// clip_split.h — a clip longer than one clip can hold, cooked as consecutive parts.
//
// Compressed clips address keys by 16-bit frame index (format/ossa.fbs, Clip; clip_grid.h
// kMaxFrames), which two bytes per key buys on every clip. A legitimate long capture (a 100,000-frame
// BVH at 120 fps is 14 minutes) must not be refused for it, nor resampled coarser (that would lose
// motion the capture holds), so such a clip is cut on its frame grid into parts of at most
// kMaxFrames frames that share their boundary frame: played one after another they are the clip,
// with no key lost. Each channel's value at a cut is interpolated from its source keys the way the
// compressor resamples (linear, normalized lerp for rotations), so both parts agree there exactly.
#pragma once
#include <string>
#include <vector>

#include "cooker/model/source_scene.h"

namespace ossa::cook {

/// Appends `clip` to *out as it is when its frame grid fits in kMaxFrames frames; otherwise
/// appends its parts, named "<name>.part1", "<name>.part2", ... (source_name keeps the clip's own
/// source name), each starting at time 0, and returns a one-line description for the warnings
/// (empty when not split). Runs at import, before events and root motion exist. O(keys).
std::string split_long_clip(SourceClip clip, std::vector<SourceClip>* out);

}  // namespace ossa::cook
