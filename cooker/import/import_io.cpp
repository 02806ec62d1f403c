// import_io.cpp — Assimp's view of the file system during a cook (see import_io.h).
#include "cooker/import/import_io.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <cstring>
#include <vector>

#include <assimp/IOStream.hpp>

#include "cooker/model/input_log.h"
#include "cooker/import/source_precheck.h"

namespace ossa::cook {
namespace {

/// A read-only stream over a file's bytes, owned. Unlike Assimp's MemoryIOStream it asserts
/// nothing about its arguments (Debian's Assimp is built with assertions, and an abort is the one
/// failure a cook cannot turn into an error); a zero-sized read simply reads nothing.
class BufferStream : public Assimp::IOStream {
 public:
  explicit BufferStream(std::vector<uint8_t> bytes) : bytes_(std::move(bytes)) {}

  size_t Read(void* out, size_t size, size_t count) override {
    if (size == 0 || count == 0 || out == nullptr) return 0;
    const size_t whole = std::min(count, (bytes_.size() - pos_) / size);
    if (whole > 0) std::memcpy(out, bytes_.data() + pos_, whole * size);
    pos_ += whole * size;
    return whole;
  }
  size_t Write(const void*, size_t, size_t) override { return 0; }
  aiReturn Seek(size_t offset, aiOrigin origin) override {
    size_t target = 0;
    switch (origin) {
      case aiOrigin_SET: target = offset; break;
      case aiOrigin_CUR: target = pos_ + offset; break;
      case aiOrigin_END: target = bytes_.size() - std::min(offset, bytes_.size()); break;
      default: return aiReturn_FAILURE;
    }
    if (target > bytes_.size()) return aiReturn_FAILURE;
    pos_ = target;
    return aiReturn_SUCCESS;
  }
  size_t Tell() const override { return pos_; }
  size_t FileSize() const override { return bytes_.size(); }
  void Flush() override {}

 private:
  std::vector<uint8_t> bytes_;
  size_t pos_ = 0;
};

}  // namespace

namespace {
constexpr std::string_view kReference = "the source, read by the importer";
}

namespace {
std::string normal_absolute(const char* path) {
  std::error_code ec;
  const std::filesystem::path abs = std::filesystem::absolute(path, ec);
  return (ec ? std::filesystem::path(path) : abs).lexically_normal().string();
}
}  // namespace

LoggedIOSystem::LoggedIOSystem(std::string main)
    : main_(normal_absolute(main.c_str())), folder_(std::filesystem::path(main_).parent_path().string()) {}

std::string LoggedIOSystem::resolve(const char* path) const {
  const std::filesystem::path p(path);
  return p.is_relative() && !folder_.empty() ? (std::filesystem::path(folder_) / p).string() : std::string(path);
}

bool LoggedIOSystem::Exists(const char* path) const {
  return path != nullptr && probe_input(resolve(path), kReference);
}

Assimp::IOStream* LoggedIOSystem::Open(const char* path, const char* mode) {
  if (path == nullptr ||
      (mode != nullptr && (std::strchr(mode, 'w') || std::strchr(mode, 'a') || std::strchr(mode, '+'))))
    return nullptr;
  const std::string resolved = resolve(path);
  path = resolved.c_str();
  auto bytes = read_input(path, UINT64_MAX, kReference);
  if (!bytes) return nullptr;
  if (normal_absolute(path) == main_) {
    std::string ext = std::filesystem::path(path).extension().string();
    for (char& c : ext) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
    auto checked = precheck_source(*bytes, ext);
    if (!checked) {
      refused_ = checked.error().message;
      return nullptr;
    }
    if (*checked) return new BufferStream(std::move(**checked));  // the repaired bytes
  }
  return new BufferStream(std::move(*bytes));
}

void LoggedIOSystem::Close(Assimp::IOStream* stream) { delete stream; }

}  // namespace ossa::cook
