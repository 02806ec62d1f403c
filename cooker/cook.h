// cook.h — cook one source file into one .ossa file: import, build meshes, write, atomically.
//
// The batch (cli/batch.h) calls cook_file once per input, each in a worker process of its own
// (cli/worker.h); a call touches nothing shared (it is also safe on several threads at once), so
// the bytes written do not depend on --jobs. The output is written
// to a temporary file beside the target and renamed over it only when complete: a failed input
// leaves no output file, and a reader never sees a half-written one.
//
// This is the orchestrator: it runs the stages (import, mesh, clip, graph, texture, write) in
// order; the options it takes and the record it returns are the cooker's model (cooker/model/),
// which the stages read, so no stage includes this header (scripts/check-layout.py).
#pragma once
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "cooker/model/cook_options.h"
#include "cooker/model/cook_record.h"
#include "cooker/model/reference_skeleton.h"
#include "cooker/write/atomic_file.h"
#include "tools/retarget/map_file.h"
#include <ossa/format/result.h>

namespace ossa::cook {

/// Cooks `input` to `output` (parent directories are created). Never throws.
///
/// Unless options.force, an existing `output` whose provenance cook key equals the key of the
/// inputs it lists as they are now (re-hashed) is up to date: it is neither cooked nor rewritten
/// (its mtime stays), and the record says so. Every file read goes into the record's inputs_read
/// and, relative to the input's directory, into the output's provenance with the cook key
/// (input_log.h).
///
/// A source file's clips get the events of its sidecar `<stem>.events.json` when there is one
/// (cooker/clip/clip_events.h; the sidecar's bytes are part of the provenance hash). A graph file
/// (is_graph_file) cooks into a self-contained character: its rig, meshes, clips and the compiled
/// graph (docs/GRAPH.md); `reference` is then not used, the graph names its own rig.
CookRecord cook_file(const std::filesystem::path& input, const std::filesystem::path& output,
                     const CookOptions& options);

/// The record cook_file would return for an output that is up to date (settings applied, the
/// output's listed inputs re-read and re-hashed inside the read sandbox, the key recomputed), or
/// nullopt when it would cook (or fail). Reads only the output and the files it lists, parses only
/// the output (through the verifying loader) and settings files (ossa's own JSON reader): no
/// importer runs, so the batch calls it in its own process before starting a worker for an input,
/// and an all-up-to-date run costs no process per input. O(bytes of the listed inputs).
///
/// With a cache (options.cache), an output that is not up to date is looked up there too, and a
/// hit is written and returned (cache_hit): a warm cache costs no process per input either. On a
/// miss, `cache_miss` (when given) receives the lookup's cache_note, cache_down and bytes fetched.
std::optional<CookRecord> up_to_date_record(const std::filesystem::path& input, const std::filesystem::path& output,
                                            const CookOptions& options, CookRecord* cache_miss = nullptr);

/// Reads and parses a humanoid map file (for --map; tools/retarget/map_file.h). Errors name the
/// file. `as_read`, when given, receives its input record (absolute path, hash, size).
Result<tools::HumanoidMapFile> load_humanoid_map_file(const std::filesystem::path& path, InputFile* as_read = nullptr);

}  // namespace ossa::cook
