// platform_win32.cpp — platform_file.h on Windows: CreateFileW, GetFileType /
// GetFileInformationByHandle, ReadFile, CreateFileMappingW + MapViewOfFile.
//
// Paths are UTF-8 in the API (as on POSIX) and converted to UTF-16 for CreateFileW, so any file
// name works regardless of the process code page; invalid UTF-8 is refused rather than guessed.
// FILE_FLAG_BACKUP_SEMANTICS lets a directory open so it can be refused as "not a regular file"
// (the same message as POSIX), and GetFileType refuses pipes and character devices (CON, NUL,
// COM1). The share mode lets other readers open the file and lets it be renamed or deleted while
// it is only open for reading. The mapping object is closed right after MapViewOfFile: the view
// keeps it (and the file) alive until UnmapViewOfFile.
#include "internal/platform_file.h"

#ifndef WIN32_LEAN_AND_MEAN
#define WIN32_LEAN_AND_MEAN
#endif
#ifndef NOMINMAX
#define NOMINMAX
#endif
#include <windows.h>

#include <algorithm>
#include <string>
#include <utility>

namespace ossa::detail {
namespace {

HANDLE as_handle(intptr_t h) { return reinterpret_cast<HANDLE>(h); }

std::string win_error(const char* what, DWORD err) {
  char* text = nullptr;
  const DWORD n = FormatMessageA(
      FORMAT_MESSAGE_ALLOCATE_BUFFER | FORMAT_MESSAGE_FROM_SYSTEM | FORMAT_MESSAGE_IGNORE_INSERTS, nullptr, err,
      MAKELANGID(LANG_NEUTRAL, SUBLANG_DEFAULT), reinterpret_cast<LPSTR>(&text), 0, nullptr);
  std::string message(text != nullptr ? text : "", n);
  if (text != nullptr) LocalFree(text);
  while (!message.empty() &&
         (message.back() == '\n' || message.back() == '\r' || message.back() == ' ' || message.back() == '.'))
    message.pop_back();
  if (message.empty()) message = "error " + std::to_string(err);
  return std::string(what) + ": " + message;
}

/// UTF-8 -> UTF-16; false for invalid UTF-8.
bool widen(const std::string& utf8, std::wstring* out) {
  out->clear();
  if (utf8.empty()) return true;
  const int n =
      MultiByteToWideChar(CP_UTF8, MB_ERR_INVALID_CHARS, utf8.data(), static_cast<int>(utf8.size()), nullptr, 0);
  if (n <= 0) return false;
  out->resize(static_cast<size_t>(n));
  return MultiByteToWideChar(CP_UTF8, MB_ERR_INVALID_CHARS, utf8.data(), static_cast<int>(utf8.size()), out->data(),
                             n) == n;
}

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
  if (as_handle(handle_) != INVALID_HANDLE_VALUE) CloseHandle(as_handle(handle_));
  handle_ = -1;
}

bool PlatformFile::open(const std::string& path, std::string* error) {
  close();
  std::wstring wide;
  if (path.empty() || !widen(path, &wide)) {
    *error = path.empty() ? "cannot open: empty path" : "cannot open: the path is not valid UTF-8";
    return false;
  }
  const HANDLE h = CreateFileW(wide.c_str(), GENERIC_READ, FILE_SHARE_READ | FILE_SHARE_DELETE, nullptr, OPEN_EXISTING,
                               FILE_ATTRIBUTE_NORMAL | FILE_FLAG_BACKUP_SEMANTICS, nullptr);
  if (h == INVALID_HANDLE_VALUE) {
    *error = win_error("cannot open", GetLastError());
    return false;
  }
  BY_HANDLE_FILE_INFORMATION info;
  if (GetFileType(h) != FILE_TYPE_DISK || !GetFileInformationByHandle(h, &info) ||
      (info.dwFileAttributes & (FILE_ATTRIBUTE_DIRECTORY | FILE_ATTRIBUTE_DEVICE)) != 0) {
    *error = "not a regular file";
    CloseHandle(h);
    return false;
  }
  handle_ = reinterpret_cast<intptr_t>(h);
  size_ = (static_cast<uint64_t>(info.nFileSizeHigh) << 32) | info.nFileSizeLow;
  return true;
}

bool PlatformFile::read_all(void* dst, size_t size, std::string* error) {
  size_t done = 0;
  while (done < size) {
    const DWORD chunk = static_cast<DWORD>(std::min<size_t>(size - done, 1u << 30));
    DWORD n = 0;
    if (!ReadFile(as_handle(handle_), static_cast<uint8_t*>(dst) + done, chunk, &n, nullptr)) {
      *error = win_error("cannot read", GetLastError());
      return false;
    }
    if (n == 0) {
      *error = "file shrank while being read";
      return false;
    }
    done += n;
  }
  return true;
}

void* PlatformFile::map(size_t size, std::string* error) {
  const HANDLE mapping = CreateFileMappingW(as_handle(handle_), nullptr, PAGE_READONLY, 0, 0, nullptr);
  if (mapping == nullptr) {
    *error = win_error("cannot map", GetLastError());
    return nullptr;
  }
  void* view = MapViewOfFile(mapping, FILE_MAP_READ, 0, 0, size);
  const DWORD err = GetLastError();
  CloseHandle(mapping);  // the view keeps the mapping object alive
  if (view == nullptr) *error = win_error("cannot map", err);
  return view;
}

void unmap_file(void* base, size_t) { UnmapViewOfFile(base); }

}  // namespace ossa::detail
