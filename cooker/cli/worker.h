// worker.h — each input of a batch cooked in its own worker process, bounded in memory and time.
//
// Why processes and not threads: a source can make the importer abort (Debian builds Assimp with
// assertions, and some malformed FBX files trip them), crash, hang or allocate without bound (a
// 309-byte file in Assimp's test set asks for ~16 GB). In a thread any of these ends or starves the
// whole batch: no report, the later inputs never cooked, a message that names no file. A process
// per input confines each to that input: the kernel reclaims whatever it held, the parent sees how
// it ended (waitpid) and turns that into a failed record naming the input and the cause, and the
// batch goes on.
//
// Shape:
// - The parent (cook_in_workers) is one thread, a scheduler that keeps up to `jobs` children
//   running. It must stay single-threaded: it fork()s, and after fork only the forking thread
//   exists in the child, so a lock another thread held (malloc's, stdio's) would stay locked
//   forever. With one thread there is no such lock, and the child may run ordinary C++ (cook_file).
// - fork, not fork+exec: the child already has the parsed options and the --skeleton rig in memory
//   (copy-on-write, nothing to pass), and no second program or argument format is needed.
// - The child bounds itself before cooking: setrlimit(RLIMIT_AS) caps its address space (an
//   allocation past it fails at once, before the machine swaps; RSS cannot be capped that way), and
//   a std::new_handler turns that failure into a marker and a dedicated exit status, so the parent
//   reports "exceeded the memory limit" rather than a crash or a bad_alloc deep inside Assimp.
//   Sanitizer builds (ASan, TSan, MSan) reserve terabytes of address space for their shadow
//   memory, so there RLIMIT_AS is not set: --max-memory is recorded but not enforced.
// - The child sends its CookRecord back over a pipe as CBOR (record_to_json / record_from_json,
//   through nlohmann): CBOR carries strings as raw bytes, so a joint name or path that is not
//   UTF-8 comes back unchanged, where JSON text would throw. The parent poll(2)s every pipe, so a
//   record larger than the pipe buffer cannot dead-lock a child.
// - The time limit is kept by the parent: a child past --timeout is sent SIGKILL. Children stay in
//   the parent's process group so that Ctrl-C in a terminal reaches them too; and on Linux each
//   asks for SIGKILL when the parent dies (PR_SET_PDEATHSIG), so none outlives a killed batch.
// - After an abnormal end the parent removes what the child may have left: its temporary file
//   (write/atomic_file.h's temporary_name: `.<output name>.tmp-<pid>-<n>` beside the output) and
//   an output it renamed into place before dying (told apart from a previous output, which a failed
//   input must leave untouched, by its inode).
//
// Test hook: OSSA_COOK_TEST_FAULT=<substring>:<fault>[,<substring>:<fault>...] makes the worker
// whose input path contains <substring> misbehave, so that tests can check how the batch handles
// each way a worker ends without depending on a particular Assimp bug. Faults, before cooking:
// `abort`, `segv` (SIGSEGV), `hang` (sleep forever), `alloc` (allocate address space without
// bound), `abort-writing` (leave a temporary file named as write_file_atomic names them, then
// abort), `garble` (send a truncated record and exit 0); after cooking: `abort-after` (abort with
// the output renamed into place). Honoured only in workers (never by cook_file itself).
#pragma once
#include <cstddef>
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cooker/cli/batch.h"
#include "cooker/cook.h"

namespace ossa::cook {

/// A CookRecord as JSON, every field (optionals as null). record_from_json(record_to_json(r))
/// gives r back exactly; both must be extended together with CookRecord / ClipRecord (worker.cpp
/// checks their sizes at compile time to catch a field added without them).
nlohmann::json record_to_json(const CookRecord& record);
/// The inverse of record_to_json; nullopt when a field is missing or of another type.
std::optional<CookRecord> record_from_json(const nlohmann::json& json);

/// True when built with a sanitizer whose shadow memory rules out RLIMIT_AS (see above).
bool memory_limit_enforced();

/// Exit status of a worker whose allocation failed (the memory limit, or the machine out of
/// memory); it writes kWorkerMemoryMarker to its pipe first.
inline constexpr int kWorkerExitMemory = 86;
inline constexpr const char* kWorkerMemoryMarker = "ossa-cook: memory limit\n";

/// "9.0 GiB", "512 MiB", "100 KiB", "12 B": how the limit is named in messages.
std::string format_size(uint64_t bytes);

/// Cooks every item in a worker process of its own, up to `jobs` (>= 1) at once, and calls
/// `finished(index, record)` once per item, in the order they finish, from this thread. A worker
/// that crashes, aborts, runs past limits.timeout_seconds or out of limits.max_memory_bytes gives
/// a failed record: `<input>: <what ended it>`, with nothing left at or beside its output. The
/// caller must have no other threads running (see above).
void cook_in_workers(const std::vector<BatchItem>& items, const CookOptions& options, const BatchLimits& limits,
                     unsigned jobs, const std::function<void(size_t index, CookRecord record)>& finished);

}  // namespace ossa::cook
