// plain_read.h — the physical limit a loader is measured against: open + read + close of a file's
// bytes into a buffer allocated beforehand (ossa-bench-load's read_ms, ossa-bench-guard's load row).
#pragma once
#include <fcntl.h>
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

}  // namespace ossa::bench
