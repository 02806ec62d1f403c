// cook_settings.h — per-asset cook settings without a command line per file.
//
// Two files may sit beside a source (docs/SETTINGS.md has examples):
//   - `ossa.cook.json` in its folder: `"defaults"` for every input of that folder, and `"files"`,
//     a list of `{"match": "<glob on the file name>", ...settings}` applied in order to the inputs
//     whose file name matches;
//   - `<stem>.cook.json` (for `X.graph.json`: `X.cook.json`): settings for that one input.
// Later layers win: command line, folder defaults, each matching folder entry, the stem file. A
// setting is one of: "float_vertices", "clip_compression" (booleans), "clip_tolerance_mm"
// (number), "root_motion" (boolean), "up_axis" ("x" | "y" | "z"), "skeleton" (a cooked .ossa rig,
// relative to the settings file), "clip_names" ({"source clip": "new name"}), "texture_format"
// ("bc" | "rgba8" | "source"), "cloth" (an object: docs/CLOTH.md, cooker/model/cloth_settings.h).
//
// Both files are read through the cook's input log (looked for on every cook, absent or not), so
// they are inputs of the cook key and the depfile like any source: editing, adding or removing one
// re-cooks exactly the outputs it applies to. Mistakes are reported as `file:line:col: what` with a
// "did you mean" for misspelt keys, and fail the input they apply to.
#pragma once
#include <filesystem>
#include <map>
#include <memory>
#include <string>

#include "cooker/model/cook_options.h"
#include "cooker/model/source_scene.h"
#include <ossa/format/result.h>

namespace ossa::cook {

/// What the settings files gave one input, beyond CookOptions.
struct AppliedSettings {
  std::map<std::string, std::string> clip_names;  // source clip name -> cooked clip name
  std::unique_ptr<SourceSkeleton> reference;      // a "skeleton" setting's rig (options points at it)
};

/// Reads the settings files that apply to `input` and layers them over `options` (which then
/// may point into `applied`). Errors name the settings file, line and column. O(settings size).
Status apply_cook_settings(const std::filesystem::path& input, CookOptions& options, AppliedSettings& applied);

/// Renames clips per "clip_names"; an error when a name is not a clip of the source or two clips
/// would end up with one name.
Status rename_clips(const std::map<std::string, std::string>& names, std::vector<SourceClip>& clips,
                    const std::string& label);

}  // namespace ossa::cook
