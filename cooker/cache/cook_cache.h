// cook_cache.h — the shared cook cache: look an output up before cooking, store it after, so that
// an asset is cooked once for a whole studio and its build farm (docs/SCALE.md).
//
// Why two levels: an output's cook key (input_log.h) covers every file its cook read, and some of
// those are known only once the importer has parsed the source (a glTF's buffers, textures, a
// graph's sources). Like compiler caches, the lookup starts from what is known without importing:
//   manifest key = XXH3-64 of (format and cooker versions, options, the source's name, size and hash)
//   ac/<manifest key>  -> manifest: the cook key and every file that cook read, with its hash
//   the listed files re-hashed here, as they are now -> the cook key of this tree
//   cas/<cook key>     -> the cooked output
// The second step is the up-to-date check's (cook.h), run over the manifest's list instead of an
// output's provenance; the key is the cook key itself, so no second hashing scheme exists.
//
// Why nothing read from the cache is trusted: an entry may be truncated (a full disk, a killed
// writer on a network folder), corrupted, written by another cooker version, or come from a server
// answering garbage. A manifest must name this source and these options; an output must have the
// size and XXH3-64 its manifest records (the loader's checks see structure, not every byte), pass
// the runtime loader's verification and carry, in its provenance, the cook key computed here from
// this tree's files, this input's name and these options. Anything else is a miss, never written.
//
// Trouble with the store (cache_store.h) is said in the record (cache_note) and costs a miss;
// unreachable trouble also sets cache_down, and the batch marks the cache down so that workers
// started after that do not ask again (each worker is forked from the batch and sees the mark).
#pragma once
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include "cooker/cache/cache_store.h"
#include "cooker/model/cook_record.h"

namespace ossa::cook {

/// --cache-mode: read (look up only: developers' machines), readwrite (also store: CI), off.
enum class CacheMode : uint8_t { Off, Read, ReadWrite };
std::optional<CacheMode> parse_cache_mode(std::string_view text);
const char* cache_mode_name(CacheMode mode);

/// A batch's cache. `down` is set in the batch's own process once a worker found the store
/// unreachable; workers forked later see it and do not ask.
struct CookCache {
  std::unique_ptr<CacheStore> store;
  CacheMode mode = CacheMode::ReadWrite;
  bool down = false;
  std::string down_reason;
};

/// The level-1 key of a source named `source_name` with these bytes (size, hash) and options.
uint64_t manifest_key(std::string_view source_name, uint64_t source_size, uint64_t source_hash,
                      std::string_view canonical);

/// Looks `input` up (unless the cache is off or down). The files are hashed through the read
/// sandbox in a log of this call's own (the running cook's log is left alone). Returns the
/// output's verified bytes on a hit, nullopt on a miss; trouble goes into record.cache_note and
/// cache_down, bytes fetched into record.cache_bytes_fetched. O(bytes of the listed inputs + the
/// output).
std::optional<std::vector<uint8_t>> cache_lookup(const CookCache& cache, CookRecord& record,
                                                 const std::filesystem::path& input, const std::string& canonical);

/// Stores the output a cook just wrote (readwrite mode, cache not down): cas/<cook key>, then the
/// manifest at ac/<manifest key>, both from the written file's provenance. Trouble goes into
/// record.cache_note; bytes stored into record.cache_bytes_stored.
void cache_store_output(const CookCache& cache, CookRecord& record, const std::filesystem::path& output,
                        const std::string& canonical);

}  // namespace ossa::cook
