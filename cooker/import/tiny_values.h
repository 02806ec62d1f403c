// tiny_values.h — values too small to mean anything, flushed to zero in the cooker.
//
// Rest poses rebuilt from matrices (a skin's offset matrices, Assimp's decomposition of FBX and
// Collada nodes) carry rounding noise such as 7.7e-34 or -1.97e-31 where the true value is 0: Pab
// has five in its bind rotations; resampling a clip onto its frame grid leaves ~1e-21 where a
// component crosses zero (Fox). Kept, such a value costs the runtime dearly although it changes
// nothing: interpolating or blending squares it below FLT_MIN, and every subnormal result costs
// the CPU a microcode assist (Pab's walk sampled 1.8x slower on a Zen 5 EPYC, 2-2.5x on an Intel
// Xeon). So every float the runtime computes with (bind transforms, inverse binds, clip keys, root
// motion, vertex attributes, morph deltas) is set to 0 where its magnitude is below kTinyValue:
// at import, and where the clip stage resamples keys onto the grid. The bound is 2^-60 (8.7e-19):
// the square of any value kept, and its product with any other kept value or with a weight down
// to 2^-60, stays a normal float; and no value of a real rig comes near it (a quantized key holds
// multiples of its range's step; a length of 1e-18 in any unit is nothing to draw). The runtime
// does not rely on this: its float kernels run with flush-to-zero set (runtime/internal/float_env.h)
// for files cooked elsewhere. O(values).
#pragma once
#include <cstddef>
#include <span>

#include "cooker/model/source_scene.h"

namespace ossa::cook {

/// Magnitudes below this are flushed to 0 (see the header comment).
inline constexpr float kTinyValue = 0x1p-60f;

/// Sets every bind, key, vertex and morph value of `scene` with |v| < kTinyValue to 0 (a -0 too:
/// the cooked bytes do not depend on the sign of a zero the source happened to compute).
/// Returns how many values changed.
size_t flush_tiny_values(SourceScene& scene);

/// The same on values a later stage computes (a clip resampled onto its frame grid: a component
/// interpolated across zero lands near 1e-21). Returns how many changed.
size_t flush_tiny_values(std::span<glm::vec4> values);

}  // namespace ossa::cook
