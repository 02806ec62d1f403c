// platform_posix.cpp — platform_file.h on POSIX systems: open/fstat/read/mmap.
//
// What asset.cpp did directly before the Windows port: O_NONBLOCK so that opening a FIFO or a
// device for reading cannot wait for a writer before fstat says it is not a regular file (it
// changes nothing for regular files or mmap); read() loops over EINTR and short reads; the mapping
// is MAP_PRIVATE and read-only, and the descriptor is closed right after mapping (the mapping
// keeps the file alive).
#include "internal/platform_file.h"

#include <fcntl.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>

#include <cerrno>
#include <cstring>
#include <utility>

namespace ossa::detail {
namespace {

std::string os_error(const char* what, int err) { return std::string(what) + ": " + std::strerror(err); }

}  // namespace

PlatformFile::PlatformFile(PlatformFile&& other) noexcept
    : handle_(std::exchange(other.handle_, -1)), size_(std::exchange(other.size_, 0)) {}

PlatformFile& PlatformFile::operator=(PlatformFile&& other) noexcept {
  if (this != &other) {
    close();
    handle_ = std::exchange(other.handle_, -1);
    size_ = std::exchange(other.size_, 0);
  }
  return *this;
}

PlatformFile::~PlatformFile() { close(); }

void PlatformFile::close() {
  if (handle_ >= 0) ::close(static_cast<int>(handle_));
  handle_ = -1;
}

bool PlatformFile::open(const std::string& path, std::string* error) {
  close();
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC | O_NONBLOCK | O_NOCTTY);
  if (fd < 0) {
    *error = os_error("cannot open", errno);
    return false;
  }
  struct stat st;
  if (::fstat(fd, &st) != 0) {
    *error = os_error("cannot stat", errno);
    ::close(fd);
    return false;
  }
  if (!S_ISREG(st.st_mode)) {
    *error = "not a regular file";
    ::close(fd);
    return false;
  }
  handle_ = fd;
  size_ = static_cast<uint64_t>(st.st_size);
  return true;
}

bool PlatformFile::read_all(void* dst, size_t size, std::string* error) {
  size_t done = 0;
  while (done < size) {
    const ssize_t n = ::read(static_cast<int>(handle_), static_cast<uint8_t*>(dst) + done, size - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) {
      *error = n < 0 ? os_error("cannot read", errno) : std::string("file shrank while being read");
      return false;
    }
    done += static_cast<size_t>(n);
  }
  return true;
}

void* PlatformFile::map(size_t size, std::string* error) {
  void* mapping = ::mmap(nullptr, size, PROT_READ, MAP_PRIVATE, static_cast<int>(handle_), 0);
  if (mapping == MAP_FAILED) {
    *error = os_error("cannot map", errno);
    return nullptr;
  }
  return mapping;
}

void unmap_file(void* base, size_t size) { ::munmap(base, size); }

}  // namespace ossa::detail
