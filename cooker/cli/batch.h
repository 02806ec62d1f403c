// batch.h — many inputs to many outputs: plan the output paths, cook in parallel, report.
//
// Planning happens before any cooking so that a batch with two inputs mapping to one output is
// refused whole (nothing is written), while a batch whose inputs merely fail goes on to the end:
// each failure is a record, the others are cooked. Each input is cooked in a worker process of its
// own (cooker/cli/worker.h), bounded by BatchLimits, so that an input that crashes the importer,
// hangs or allocates without bound fails alone. Records come back in input order whatever the
// number of workers, so reports are stable and outputs are identical for any --jobs.
#pragma once
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <optional>
#include <functional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cooker/cook.h"
#include <ossa/format/result.h>

namespace ossa::cook {

struct BatchItem {
  std::filesystem::path input;
  std::filesystem::path output;
  /// The folder tree this input's cook may read without --root: the directory argument it was
  /// found in, or for an input named as a file, its own folder (input_log.h's read sandbox).
  std::filesystem::path tree;
  /// The output of this input's folder rig (assign_folder_rigs), cooked earlier in the batch; empty
  /// when it has none or is one.
  std::filesystem::path rig;
};

/// True for a model source that is its folder's rig by convention (has_folder_rig_name).
bool is_folder_rig(const std::filesystem::path& input);

/// The folder-rig convention (docs/COOKING.md): every other model source of a folder that holds
/// a folder rig in `items` gets that rig's output as BatchItem::rig, the rig of its own extension
/// first (walk.fbx -> skeleton.fbx beside skeleton.dae), else the first by path. The cook uses it
/// only if the source turns out to hold clips and no mesh. Call it when no --skeleton or
/// --retarget-to applies to the whole batch. O(items log items).
void assign_folder_rigs(std::vector<BatchItem>& items);

/// File extensions ossa-cook picks up when an input is a directory (lower case, with the dot).
bool is_source_extension(const std::filesystem::path& path);

/// The output name of an input without ".ossa": its stem, or for a graph file `X.graph.json`, X.
std::string output_stem(const std::filesystem::path& input);

/// Expands directory inputs (recursively, sorted; source extensions and graph files `*.graph.json`
/// only, so event sidecars and other JSON stay out) and maps each input to OUTDIR/<output_stem>.ossa,
/// or with `root` to OUTDIR/<path relative to root>/<output_stem>.ossa. Model sources of the batch
/// that share a stem in one folder (walk.dae, walk.fbx) keep their file name: walk.dae.ossa,
/// walk.fbx.ossa; a source alone with its stem keeps the short name. Errors: an
/// input outside `root`, or two inputs mapping to one output (both named). Missing inputs are not
/// errors here: they fail at cook time as their own record. O(inputs log inputs).
Result<std::vector<BatchItem>> plan_batch(const std::vector<std::filesystem::path>& inputs,
                                          const std::filesystem::path& out_dir, const std::filesystem::path& root);

/// What one input may take (--max-memory, --timeout). Not part of CookOptions: limits do not change
/// the bytes of an output that cooks, so they stay out of options.canonical() and provenance.
struct BatchLimits {
  uint64_t max_memory_bytes = 0;  // address space of one worker (bytes); 0: no limit
  unsigned timeout_seconds = 0;   // wall-clock time of one worker (seconds); 0: no limit
};

/// --max-memory's default: 0.8 x the memory this process may use (physical memory, or a smaller
/// cgroup limit) / `workers`, rounded down to a MiB and at least 1 GiB.
uint64_t default_max_memory(unsigned workers);

/// "512M", "4G", "1.5GiB", "100k", "1048576": a byte count. K, M, G and T (optionally followed by
/// "B" or "iB", any case) are powers of 1024; no suffix means bytes. nullopt for anything else.
std::optional<uint64_t> parse_size(const std::string& text);

/// Called after each item finishes, in the calling thread, once per item in the order they finish.
using BatchProgress = std::function<void(size_t done, size_t total, const CookRecord& record)>;

/// Cooks every item, each in a worker process of its own, up to `jobs` (>= 1) at once, within
/// `limits`. Returns one record per item, in item order. The caller must not have started other
/// threads (workers are forked; worker.h says why).
std::vector<CookRecord> run_batch(const std::vector<BatchItem>& items, const CookOptions& options,
                                  const BatchLimits& limits, unsigned jobs, const BatchProgress& progress);

/// Writes a depfile (atomically) that GNU Make and Ninja read alike: one rule per output written or
/// up to date, `OUTPUT: INPUT...`, naming every file its cook read. A file looked for and absent
/// cannot be a prerequisite (Make would fail, Ninja would re-cook every time), so its folder is
/// named instead: creating the file changes the folder's mtime, the build tool re-runs the cook,
/// and a cook that finds nothing changed leaves its output alone. Absolute paths, spelled by
/// depfile_spelling. Failed inputs have no rule. A name no spelling gives to both tools fails the
/// whole depfile (the error names the input and the name) and removes an older one: a depfile that
/// means something else makes the build tool miss a change, or run a command.
Status write_depfile(const std::filesystem::path& path, const std::vector<CookRecord>& records);

/// `path` as a depfile must spell it for GNU Make and Ninja to read it back as `path` (a space as
/// "\ ", '#' as "\#", ':' as "\:", '$' as "$$"), or nullopt with `why` set when no spelling means
/// the same to both (';', quotes, '*', '?', '=', control bytes, a line break; the full list is in
/// docs/COOKING-SECURITY.md). `target`: the name is a rule's target (where '%' makes a pattern).
std::optional<std::string> depfile_spelling(const std::string& path, bool target, std::string& why);

/// The --report document's "schema" and "schema_version": docs/schemas/ossa-cook-report.schema.json
/// describes it (docs/JSON.md). The version moves only on an incompatible change (a field removed,
/// renamed or given another meaning or type); an added optional field keeps it.
inline constexpr const char* kReportSchema = "ossa-cook-report";
inline constexpr int kReportSchemaVersion = 1;

/// What the shared cook cache did for a batch (--cache): hits, misses (inputs neither up to date
/// nor hits: cooked, or failed), bytes moved, and its trouble, said once (the first, and how many
/// inputs met any).
struct CacheTotals {
  size_t hits = 0, misses = 0;
  uint64_t bytes_fetched = 0, bytes_stored = 0;
  size_t troubled = 0;
  std::string first_trouble;
};
CacheTotals cache_totals(const std::vector<CookRecord>& records);

/// The --report document (every string made valid UTF-8: invalid bytes read as Latin-1): schema name and version,
/// cooker version, options, the limits each input ran under, totals and one record per input. A failed record carries
/// its error and the counts known before the failure, and no "output" or "cooked_bytes": nothing was written for it.
nlohmann::ordered_json report_json(const std::vector<CookRecord>& records, const CookOptions& options,
                                   const BatchLimits& limits);

}  // namespace ossa::cook
