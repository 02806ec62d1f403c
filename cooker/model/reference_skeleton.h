// reference_skeleton.h — a rig read back from a cooked file, to cook other files against it.
//
// Clip-only sources (--skeleton REF.ossa, the "skeleton" cook setting) and graphs bind to a rig
// that is already cooked. Its joints come back from the file through the runtime's verifying
// loader as the SourceSkeleton every stage reads (names, parents, bind pose, inverse bind, unit),
// so a clip is resampled, compressed and hashed against exactly what the runtime will play it on.
#pragma once
#include <filesystem>

#include "cooker/model/input_log.h"
#include "cooker/model/source_scene.h"
#include <ossa/format/result.h>

namespace ossa::cook {

/// Loads the skeleton of a cooked file (for --skeleton). Errors name the file. `as_read`, when
/// given, receives the file's input record (absolute path, hash, size) for the cooks' input logs.
/// O(file size) for the verification.
Result<SourceSkeleton> load_reference_skeleton(const std::filesystem::path& ossa_file, InputFile* as_read = nullptr);

}  // namespace ossa::cook
