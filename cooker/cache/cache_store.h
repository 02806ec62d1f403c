// cache_store.h — where a shared cook cache keeps its entries: a folder or an HTTP server, behind
// one get/put interface keyed as Bazel's remote cache is (`ac/<key>`, `cas/<key>`).
//
// Why Bazel's layout: a studio already runs a server for it (nginx with WebDAV, bazel-remote in
// its plain HTTP mode), and the same two names give the folder back end its shape: DIR/ac/<key>
// and DIR/cas/<key>, so a folder can be served over HTTP as it is, or an HTTP cache's files copied
// into a folder. `ac` holds small manifests (cook_cache.h), `cas` holds cooked outputs.
//
// Why trouble is a value, not a failure: the cache is an optimisation. A server that is down,
// slow, refuses writes or answers garbage, a folder that is read-only or full, must cost a miss
// and be said, never fail a cook. get() tells "absent" (a clean miss) from trouble (an Error whose
// message names the cache, the entry and the cause); `unreachable` marks trouble that will not go
// away within the batch (no connection, a timeout) so the batch stops asking (cook_cache.h).
//
// Concurrency: several processes (a batch's workers, other machines) read and write at once. The
// folder back end writes each entry to a temporary beside it and renames it into place
// (write/atomic_file.h), so a reader sees a whole entry or none; two writers of one key write the
// same bytes, and the last rename wins. Entries are never trusted anyway: cook_cache.h verifies
// every one it reads.
#pragma once
#include <cstdint>
#include <memory>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

#include <ossa/format/result.h>

namespace ossa::cook {

/// What a get or put met: nothing (ok), or trouble said in `message`.
struct CacheTrouble {
  std::string message;       // "<cache>: <entry>: <cause>"
  bool unreachable = false;  // no connection or a timeout: asking again in this batch is pointless
};

/// The answer to a get: the entry's bytes, absent (nullopt, no trouble), or trouble.
struct CacheGet {
  std::optional<std::vector<uint8_t>> bytes;
  std::optional<CacheTrouble> trouble;
};

/// The largest entry a get accepts (bytes): a server answering without end costs a miss, not the
/// machine's memory.
inline constexpr uint64_t kMaxCacheEntryBytes = uint64_t{4} << 30;

class CacheStore {
 public:
  virtual ~CacheStore() = default;
  /// Fetches `kind` ("ac" or "cas") / `key`. O(entry size) plus the round trip.
  virtual CacheGet get(std::string_view kind, std::string_view key) = 0;
  /// Stores `bytes` under `kind` / `key`, replacing an older entry whole; nullopt when stored.
  virtual std::optional<CacheTrouble> put(std::string_view kind, std::string_view key,
                                          std::span<const uint8_t> bytes) = 0;
  /// How messages name this cache: the folder or the URL.
  virtual std::string name() const = 0;
};

/// A folder back end over `dir` (created on the first put).
std::unique_ptr<CacheStore> folder_cache_store(const std::string& dir);

/// True when this build has the HTTP back end (libcurl was found at configure time).
bool http_cache_available();

/// An HTTP back end speaking Bazel's remote-cache protocol: GET / PUT of `<url>/ac/<key>` and
/// `<url>/cas/<key>` (200 is a hit, 404 a miss, anything else trouble). Each request is bounded:
/// `timeout_seconds` in all (connecting within min(timeout, 3 s)). An Error when the build has
/// no HTTP back end.
Result<std::unique_ptr<CacheStore>> http_cache_store(const std::string& url, unsigned timeout_seconds);

/// `location` as a store: "http://..." or "https://..." is an HTTP cache, anything else a folder.
Result<std::unique_ptr<CacheStore>> open_cache_store(const std::string& location, unsigned timeout_seconds);

}  // namespace ossa::cook
