// platform_file.h — the loader's only contact with the operating system: open a file for reading,
// refuse what is not a regular file, read it into memory or map it read-only.
//
// Why it is shaped so: Asset::open (asset.cpp) keeps every decision (size limits, read or map,
// verification, error wording) and asks this interface for exactly four things, so a port is one
// small file per OS (platform_posix.cpp: open/fstat/read/mmap; platform_win32.cpp: CreateFileW/
// GetFileType/ReadFile/CreateFileMappingW), picked by runtime/CMakeLists.txt with if(WIN32). No
// virtual calls and no portability library: the calls are few and the loader is hot in tools that
// open thousands of files. Errors come back as the "what" part of a message ("cannot open: No such
// file or directory"); the caller prefixes the path. Internal to runtime/.
#pragma once
#include <cstddef>
#include <cstdint>
#include <string>

namespace ossa::detail {

/// An open, readable regular file. Move-only; closes on destruction. A mapping made from it
/// outlives it (unmap_file frees the mapping).
class PlatformFile {
 public:
  PlatformFile() = default;
  PlatformFile(PlatformFile&& other) noexcept;
  PlatformFile& operator=(PlatformFile&& other) noexcept;
  PlatformFile(const PlatformFile&) = delete;
  PlatformFile& operator=(const PlatformFile&) = delete;
  ~PlatformFile();

  /// Opens `path` (UTF-8) for reading without blocking on FIFOs or devices, and refuses anything
  /// that is not a regular file ("not a regular file"). False with *error set on failure.
  bool open(const std::string& path, std::string* error);
  /// Size in bytes, as seen when the file was opened.
  uint64_t size() const { return size_; }
  /// Reads exactly `size` bytes from the start into `dst`; a file that shrank is an error.
  bool read_all(void* dst, size_t size, std::string* error);
  /// Maps the first `size` bytes read-only; nullptr with *error set on failure.
  void* map(size_t size, std::string* error);
  void close();

 private:
  intptr_t handle_ = -1;  // POSIX: a descriptor; Windows: a HANDLE (-1 = INVALID_HANDLE_VALUE)
  uint64_t size_ = 0;
};

/// Frees a mapping made by PlatformFile::map (the same `size`).
void unmap_file(void* base, size_t size);

}  // namespace ossa::detail
