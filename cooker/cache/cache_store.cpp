// cache_store.cpp — the folder back end of the shared cook cache and the choice of back end by
// location (see cache_store.h); the HTTP back end is cache_http.cpp, built only with libcurl.
#include "cooker/cache/cache_store.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <filesystem>

#include "cooker/write/atomic_file.h"

namespace ossa::cook {
namespace fs = std::filesystem;

namespace {

class FolderStore final : public CacheStore {
 public:
  explicit FolderStore(std::string dir) : dir_(std::move(dir)) {}

  CacheGet get(std::string_view kind, std::string_view key) override {
    CacheGet result;
    const fs::path path = entry(kind, key);
    const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NOFOLLOW);
    if (fd < 0) {
      if (errno != ENOENT) result.trouble = trouble(kind, key, std::strerror(errno));
      return result;  // ENOENT: a clean miss
    }
    struct stat st {};
    if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || static_cast<uint64_t>(st.st_size) > kMaxCacheEntryBytes) {
      ::close(fd);
      result.trouble = trouble(kind, key, "not a regular file of at most 4 GiB");
      return result;
    }
    std::vector<uint8_t> bytes(static_cast<size_t>(st.st_size));
    size_t done = 0;
    while (done < bytes.size()) {
      const ssize_t n = ::read(fd, bytes.data() + done, bytes.size() - done);
      if (n < 0 && errno == EINTR) continue;
      if (n <= 0) break;
      done += static_cast<size_t>(n);
    }
    ::close(fd);
    bytes.resize(done);  // a file cut short while read is caught by the verification of its bytes
    result.bytes = std::move(bytes);
    return result;
  }

  std::optional<CacheTrouble> put(std::string_view kind, std::string_view key,
                                  std::span<const uint8_t> bytes) override {
    if (Status st = write_file_atomic(entry(kind, key), bytes); !st)
      return CacheTrouble{dir_ + ": storing " + std::string(kind) + "/" + std::string(key) + ": " + st.message(),
                          false};
    return std::nullopt;
  }

  std::string name() const override { return dir_; }

 private:
  fs::path entry(std::string_view kind, std::string_view key) const {
    return fs::path(dir_) / std::string(kind) / std::string(key);
  }
  CacheTrouble trouble(std::string_view kind, std::string_view key, const std::string& why) const {
    return CacheTrouble{dir_ + ": " + std::string(kind) + "/" + std::string(key) + ": " + why, false};
  }

  std::string dir_;
};

}  // namespace

std::unique_ptr<CacheStore> folder_cache_store(const std::string& dir) { return std::make_unique<FolderStore>(dir); }

#if !defined(OSSA_COOK_CACHE_HTTP)
bool http_cache_available() { return false; }

Result<std::unique_ptr<CacheStore>> http_cache_store(const std::string& url, unsigned) {
  return Error{"--cache " + url +
               ": this ossa-cook was built without the HTTP cache (libcurl was not found); "
               "use a folder, or build with libcurl4-openssl-dev installed"};
}
#endif

Result<std::unique_ptr<CacheStore>> open_cache_store(const std::string& location, unsigned timeout_seconds) {
  if (location.rfind("http://", 0) == 0 || location.rfind("https://", 0) == 0)
    return http_cache_store(location, timeout_seconds);
  if (location.empty()) return Error{"--cache: an empty location"};
  return folder_cache_store(location);
}

}  // namespace ossa::cook
