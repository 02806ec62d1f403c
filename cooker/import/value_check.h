// value_check.h — the numbers of an imported scene checked against what the format can hold,
// at import, so that a bad source value is named where it came from.
//
// The loader (ossa/loader/validate.h) refuses a file whose bind transforms or clip keys are not
// finite or lie beyond +-1e7, so that every sum, difference and ratio a runtime forms stays
// finite. A source can carry such values (a corrupt FBX, a hand-edited glTF with 1e20 in a
// translation); without this check the cooker would build the file and only its own verification
// would object, as "internal error, cooked bytes fail verification". Here the same bounds are
// checked on the SourceScene with the joint, clip and key named. O(joints + keys + vertices).
#pragma once
#include "cooker/model/source_scene.h"
#include <ossa/format/result.h>

namespace ossa::cook {

/// The loader's bound on translations and scales (runtime/internal/validator.h's kMaxPoseValue), source units.
inline constexpr float kMaxSourceValue = 1e7f;

/// Checks bind poses, inverse binds, mesh attributes and bind matrices (finite), clip keys and
/// root motion. The error names the joint / mesh / clip and the value.
Status check_scene_values(const SourceScene& scene);

}  // namespace ossa::cook
