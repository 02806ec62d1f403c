// plain_read.h — the physical limit a loader is measured against: open + read + close of a file's
// bytes into a buffer allocated beforehand (ossa-bench-load's read_ms, ossa-bench-guard's load row),
// and the same with the fstat a loader needs when it does not know the size beforehand
// (ossa-bench-load's stat_read_ms).
#pragma once
#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>

#include <filesystem>
#include <vector>

namespace ossa::bench {

/// Reads exactly buffer.size() bytes of `path` into buffer; false on any error or a shorter file.
inline bool read_whole(const std::filesystem::path& path, std::vector<char>& buffer) {
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0) return false;
  size_t got = 0;
  while (got < buffer.size()) {
    const ssize_t n = ::read(fd, buffer.data() + got, buffer.size() - got);
    if (n <= 0) break;
    got += static_cast<size_t>(n);
  }
  ::close(fd);
  return got == buffer.size();
}

/// open + fstat + read of st_size bytes + close into `buffer` (at least that large): the least a
/// loader that learns the size from the file does. False on any error or a short read.
inline bool stat_read_whole(const std::filesystem::path& path, std::vector<char>& buffer) {
  const int fd = ::open(path.c_str(), O_RDONLY);
  if (fd < 0) return false;
  struct stat st;
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode) || static_cast<size_t>(st.st_size) > buffer.size()) {
    ::close(fd);
    return false;
  }
  const auto size = static_cast<size_t>(st.st_size);
  size_t got = 0;
  while (got < size) {
    const ssize_t n = ::read(fd, buffer.data() + got, size - got);
    if (n <= 0) break;
    got += static_cast<size_t>(n);
  }
  ::close(fd);
  return got == size;
}

}  // namespace ossa::bench
