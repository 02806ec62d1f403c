// atomic_file.h — writing an output so that no reader ever sees half of it, and cleaning up after
// writers that died: the temporary file beside the target, its name, and the sweep of the
// temporaries a killed batch left.
//
// Why a lock on each temporary: a writer's temporary must survive every other cooker (a second
// ossa-cook on the same tree, a build farm's other job) and vanish once its writer is gone. The
// pid in its name says who made it, but pids are reused and mean nothing across PID namespaces
// (containers sharing a volume). The writer holds an flock on the temporary from its creation to
// its rename, and the kernel drops that lock when the process dies however it dies; so a temporary
// is stale when its lock can be taken and either its pid names no process here or it is over an
// hour old (a pid reused by an unrelated process). The microseconds between a writer's creating
// its file and locking it are covered by the pid (alive) and the age (fresh).
//
// Why the name may be shortened: `.<name>.tmp-<pid>-<n>` is 27 bytes longer than the output's name,
// so a legal output name of 229-255 bytes would fail with "File name too long" on the temporary
// alone. Such names are cut to 219 bytes plus '~' and 8 hex digits of the name's hash, which keeps
// every temporary name within NAME_MAX (255) whatever the pid's digits.
#pragma once
#include <cstdint>
#include <filesystem>
#include <span>
#include <string>
#include <vector>

#include <ossa/format/result.h>

namespace ossa::cook {

/// `.<output name, or its shortened form>.tmp-`: what every temporary of `output_name` starts with.
std::string temporary_prefix(const std::string& output_name);

/// The temporary file name `pid` uses for its `n`-th write of `output_name` (at most 255 bytes).
std::string temporary_name(const std::string& output_name, long pid, unsigned n);

/// Writes bytes to a temporary file in path's directory (created if needed), locked, flushed,
/// then renamed onto path. On any failure the temporary is removed and path is untouched; the
/// error names path and the cause (errno's text: "No space left on device", "File name too
/// long", ...). A read-only file at path is refused, not replaced.
Status write_file_atomic(const std::filesystem::path& path, std::span<const uint8_t> bytes);

/// Removes the stale temporaries (see above) of `outputs` left by writers that died, reading each
/// folder once. Returns how many were removed. O(outputs + entries of their folders).
size_t remove_stale_temporaries(const std::vector<std::filesystem::path>& outputs);

}  // namespace ossa::cook
