// atomic_file.cpp — temporaries, the atomic write and the sweep of stale temporaries (see atomic_file.h).
#include "cooker/write/atomic_file.h"

#include <fcntl.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/stat.h>
#include <unistd.h>
#include <xxhash.h>

#include <atomic>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <map>
#include <set>

namespace ossa::cook {
namespace fs = std::filesystem;

namespace {

// '.' + name + ".tmp-" + pid (<= 10 digits) + '-' + counter (<= 10 digits) <= 255.
constexpr size_t kLongestKeptName = 255 - 1 - 5 - 10 - 1 - 10;  // 228
constexpr size_t kCutName = kLongestKeptName - 9;               // 219, then '~' and 8 hex digits
constexpr time_t kOldSeconds = 3600;

}  // namespace

std::string temporary_prefix(const std::string& output_name) {
  if (output_name.size() <= kLongestKeptName) return "." + output_name + ".tmp-";
  char hash[12];
  std::snprintf(hash, sizeof hash, "~%08x",
                static_cast<unsigned>(XXH3_64bits(output_name.data(), output_name.size()) & 0xFFFFFFFFu));
  std::string prefix = ".";  // appended: "." + std::string&& trips GCC 12's false -Wrestrict at -O3
  prefix += output_name.substr(0, kCutName);
  prefix += hash;
  prefix += ".tmp-";
  return prefix;
}

std::string temporary_name(const std::string& output_name, long pid, unsigned n) {
  return temporary_prefix(output_name) + std::to_string(pid) + "-" + std::to_string(n);
}

Status write_file_atomic(const fs::path& path, std::span<const uint8_t> bytes) {
  static std::atomic<unsigned> counter{0};
  std::error_code ec;
  const fs::path dir = path.parent_path().empty() ? fs::path(".") : path.parent_path();
  // A read-only file is the user's way of saying "do not replace": rename(2) would, so it is
  // refused here (by its mode bits, which also hold for root, whom access(2) lets write anything).
  struct stat existing {};
  if (::stat(path.c_str(), &existing) == 0 && S_ISREG(existing.st_mode) &&
      (existing.st_mode & (S_IWUSR | S_IWGRP | S_IWOTH)) == 0)
    return Error{path.string() + ": is read-only, not replaced (make it writable or remove it)"};
  fs::create_directories(dir, ec);
  if (ec) return Error{path.string() + ": cannot create its folder " + dir.string() + ": " + ec.message()};
  const fs::path tmp =
      dir / temporary_name(path.filename().string(), static_cast<long>(::getpid()), counter.fetch_add(1));
  const int fd = ::open(tmp.c_str(), O_WRONLY | O_CREAT | O_EXCL | O_CLOEXEC, 0644);
  if (fd < 0) return Error{path.string() + ": cannot create its temporary file: " + std::strerror(errno)};
  ::flock(fd, LOCK_EX);  // held until this process closes it or dies (see the header)
  size_t done = 0;
  bool ok = true;
  std::string why;
  while (done < bytes.size()) {
    const ssize_t n = ::write(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0) {
      if (errno == EINTR) continue;
      ok = false;
      why = std::strerror(errno);
      break;
    }
    done += static_cast<size_t>(n);
  }
  if (ok && ::fsync(fd) != 0) {
    ok = false;
    why = std::strerror(errno);
  }
  // Renamed while still open and locked: a sweep in another process never sees it unlocked.
  if (ok && std::rename(tmp.c_str(), path.c_str()) != 0) {
    ok = false;
    why = std::strerror(errno);
  }
  if (!ok) ::unlink(tmp.c_str());
  if (::close(fd) != 0 && ok) {
    ok = false;
    why = std::strerror(errno);
  }
  if (!ok) return Error{path.string() + ": write failed: " + why};
  return {};
}

size_t remove_stale_temporaries(const std::vector<fs::path>& outputs) {
  std::map<fs::path, std::set<std::string>> prefixes;  // folder -> temporary prefixes of its outputs
  for (const fs::path& out : outputs)
    prefixes[out.parent_path().empty() ? fs::path(".") : out.parent_path()].insert(
        temporary_prefix(out.filename().string()));
  size_t removed = 0;
  const time_t now = std::time(nullptr);
  for (const auto& [dir, wanted] : prefixes) {
    std::error_code ec;
    for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
      const std::string entry = it->path().filename().string();
      const size_t tmp = entry.rfind(".tmp-");
      if (entry.empty() || entry[0] != '.' || tmp == std::string::npos || !wanted.count(entry.substr(0, tmp + 5)))
        continue;
      char* end_of_pid = nullptr;
      const long pid = std::strtol(entry.c_str() + tmp + 5, &end_of_pid, 10);
      if (pid <= 0 || end_of_pid == nullptr || *end_of_pid != '-') continue;
      const int fd = ::open(it->path().c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_CLOEXEC);
      if (fd < 0) continue;
      struct stat st {};
      // A lock held means a writer is alive, wherever it runs; an unlocked file is stale when its
      // pid is gone here or it is old.
      const bool stale =
          ::fstat(fd, &st) == 0 && S_ISREG(st.st_mode) && ::flock(fd, LOCK_EX | LOCK_NB) == 0 &&
          pid != static_cast<long>(::getpid()) &&
          ((::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH) || now - st.st_mtime > kOldSeconds);
      struct stat named {};
      if (stale && ::lstat(it->path().c_str(), &named) == 0 && named.st_dev == st.st_dev && named.st_ino == st.st_ino &&
          ::unlink(it->path().c_str()) == 0)
        ++removed;
      ::close(fd);
    }
  }
  return removed;
}

}  // namespace ossa::cook
