// input_log.h — every file one cook read, with its content hash: the cook key, the up-to-date
// check and the depfile all come from this one list.
//
// Why a log and not a list each stage returns: files are read deep inside Assimp (a glTF's .bin,
// an OBJ's .mtl), by the material stage (textures), by the sidecar and graph stages and by the
// CLI (--skeleton). Every one of those reads goes through read_input / probe_input here (Assimp's
// through the IOSystem of import_io.h), which records into the log of the cook running on this
// thread (InputLogScope, set by cook_file). A read that bypasses this file is a cache-key bug, so
// the cooker has no other file-reading function.
//
// Files that were looked for and not found are recorded too (absent): creating a sidecar
// `walk.events.json` later must make the output out of date, so its absence is part of the key.
//
// The same door is the read sandbox (ReadSandboxScope): while a cook runs, a file outside the
// folders it may read (the input's own tree, or --root, and --allow-dir) is refused by name and
// never opened, and so is anything that is not a regular file (a device, a FIFO, a directory) and
// a file with other hard links. Each path is resolved and opened in one step from a descriptor of
// an allowed folder (open_beneath.h) and checked on the opened descriptor, so a symlink swapped in
// while the cook runs cannot lead it out. Each refusal is kept in the log with the reference that
// named the file, and fails the cook: a source cannot pull /etc/passwd or a neighbour's files into
// an output, whichever importer reads them.
//
// The hash is XXH3-64 (Debian's libxxhash): ~30 GB/s against FNV-1a's ~1 GB/s, so keying a cook
// costs nothing next to importing it (ossa-bench-cook measures both).
#pragma once
#include <algorithm>
#include <cstdint>
#include <filesystem>
#include <memory>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <ossa/format/result.h>

namespace ossa::cook {

/// One file a cook read (or looked for).
struct InputFile {
  std::string path;      // absolute and lexically normal while cooking; relative in provenance
  uint64_t hash = 0;     // input_hash of its bytes; 0 when absent
  uint64_t size = 0;     // bytes; 0 when absent
  bool present = false;  // false: looked for, not there
};

/// XXH3-64 of `bytes`.
uint64_t input_hash(std::span<const uint8_t> bytes);

/// The files one cook read. Not thread-safe: one log per cook, used by the thread running it.
class InputLog {
 public:
  /// Records a file read whole. A path recorded twice keeps its first record.
  void add(const std::filesystem::path& path, std::span<const uint8_t> bytes);
  /// Records a file hashed without being kept (hash_input).
  void add_hashed(const std::filesystem::path& path, uint64_t hash, uint64_t size);
  /// Records a file looked for and not found.
  void add_absent(const std::filesystem::path& path);
  /// Every record, sorted by path, one per path.
  std::vector<InputFile> files() const;
  /// Reads refused by the sandbox (or of files that are not regular files): one message each.
  void add_refusal(std::string message) {
    if (std::find(refusals_.begin(), refusals_.end(), message) == refusals_.end())
      refusals_.push_back(std::move(message));
  }
  const std::vector<std::string>& refusals() const { return refusals_; }

 private:
  std::vector<InputFile> files_;
  std::vector<std::string> refusals_;
};

/// The log reads on this thread record into, or null. Set for a scope by InputLogScope.
InputLog* current_input_log();

/// Makes `log` the current log of this thread until destroyed (scopes nest; the previous is restored).
class InputLogScope {
 public:
  explicit InputLogScope(InputLog* log);
  ~InputLogScope();
  InputLogScope(const InputLogScope&) = delete;
  InputLogScope& operator=(const InputLogScope&) = delete;

 private:
  InputLog* previous_;
};

struct ReadSandbox;

/// Limits this thread's reads to regular files beneath `allowed_dirs` until destroyed (scopes
/// nest; the previous limit is restored). The folders are opened here and every read is resolved
/// from their descriptors (open_beneath.h), so no change to the tree while a cook runs can lead a
/// read outside. Unless `allow_hard_links`, a regular file with more than one link is refused.
class ReadSandboxScope {
 public:
  explicit ReadSandboxScope(const std::vector<std::filesystem::path>& allowed_dirs, bool allow_hard_links = false);
  ~ReadSandboxScope();
  ReadSandboxScope(const ReadSandboxScope&) = delete;
  ReadSandboxScope& operator=(const ReadSandboxScope&) = delete;

 private:
  const ReadSandbox* previous_;
  std::unique_ptr<ReadSandbox> sandbox_;
};

/// Reads the whole of `path` and records it in the current log (a missing file is recorded absent).
/// Refused without reading: a path outside the sandbox, anything not a regular file, a file with
/// other hard links, a file over `max_bytes`; a refusal is also kept in the log. `reference` says
/// what named the file (e.g. "a texture of material 'skin'") for the messages. Errors name the
/// file. O(file size).
Result<std::vector<uint8_t>> read_input(const std::filesystem::path& path, uint64_t max_bytes = UINT64_MAX,
                                        std::string_view reference = {});

/// read_input's checks and record, without keeping the bytes: the file is streamed through the
/// hash in 256 KiB pieces (the up-to-date check needs the hash only). O(file size), no allocation
/// of the file's size.
Status hash_input(const std::filesystem::path& path, std::string_view reference = {});

/// True when `path` is a regular file inside the sandbox; a missing file (or a folder) is recorded
/// absent; one outside the sandbox, a FIFO, device or socket (one named like a sidecar),
/// has other hard links or cannot be opened is recorded as a refusal (the cook must fail, not
/// carry on as if it were absent). Opens nothing for reading.
bool probe_input(const std::filesystem::path& path, std::string_view reference = {});

/// `files` (absolute paths) with each path made relative to `base` (the input's directory) and
/// written with '/' separators, so the same tree cooked elsewhere records the same text. Sorted.
std::vector<InputFile> relative_inputs(std::span<const InputFile> files, const std::filesystem::path& base);

/// The cook key: XXH3-64 over the format version, the cooker version, the canonical options and
/// every relative input (path, presence, size, hash) in path order. Equal keys mean equal outputs.
uint64_t cook_key(std::span<const InputFile> relative, std::string_view options);

/// A key or hash as the 16 lower-case hex digits the report and ossa-inspect print.
std::string hex64(uint64_t value);

}  // namespace ossa::cook
