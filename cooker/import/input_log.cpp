// input_log.cpp — the per-cook record of files read, and the cook key (see input_log.h).
#include "cooker/import/input_log.h"

#include <xxhash.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <fstream>

#include <ossa/version.h>

namespace ossa::cook {
namespace fs = std::filesystem;

namespace {

thread_local InputLog* t_current = nullptr;

fs::path normal_absolute(const fs::path& path) {
  std::error_code ec;
  fs::path abs = fs::absolute(path, ec);
  return (ec ? path : abs).lexically_normal();
}

}  // namespace

uint64_t input_hash(std::span<const uint8_t> bytes) { return XXH3_64bits(bytes.data(), bytes.size()); }

void InputLog::add(const fs::path& path, std::span<const uint8_t> bytes) {
  files_.push_back({normal_absolute(path).string(), input_hash(bytes), bytes.size(), true});
}

void InputLog::add_absent(const fs::path& path) { files_.push_back({normal_absolute(path).string(), 0, 0, false}); }

std::vector<InputFile> InputLog::files() const {
  std::vector<InputFile> out = files_;
  // Stable: of two records of one path, the first read is kept.
  std::stable_sort(out.begin(), out.end(), [](const InputFile& a, const InputFile& b) { return a.path < b.path; });
  out.erase(std::unique(out.begin(), out.end(), [](const InputFile& a, const InputFile& b) { return a.path == b.path; }),
            out.end());
  return out;
}

InputLog* current_input_log() { return t_current; }

InputLogScope::InputLogScope(InputLog* log) : previous_(t_current) { t_current = log; }
InputLogScope::~InputLogScope() { t_current = previous_; }

Result<std::vector<uint8_t>> read_input(const fs::path& path, uint64_t max_bytes) {
  std::error_code ec;
  if (!fs::is_regular_file(path, ec)) {
    if (InputLog* log = current_input_log()) log->add_absent(path);
    if (fs::exists(path, ec)) return Error{path.string() + ": is not a regular file"};
    return Error{path.string() + ": cannot open: " + std::strerror(ENOENT)};
  }
  const uintmax_t size = fs::file_size(path, ec);
  if (ec) return Error{path.string() + ": cannot read its size: " + ec.message()};
  if (size > max_bytes)
    return Error{path.string() + ": is " + std::to_string(size) + " bytes, over the limit of " +
                 std::to_string(max_bytes)};
  std::ifstream in(path, std::ios::binary);
  if (!in) return Error{path.string() + ": cannot open: " + std::strerror(errno)};
  std::vector<uint8_t> bytes(static_cast<size_t>(size));
  in.read(reinterpret_cast<char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
  if (static_cast<uintmax_t>(in.gcount()) != size || in.bad()) return Error{path.string() + ": read error"};
  if (in.peek() != std::char_traits<char>::eof()) return Error{path.string() + ": changed while being read"};
  if (InputLog* log = current_input_log()) log->add(path, bytes);
  return bytes;
}

bool probe_input(const fs::path& path) {
  std::error_code ec;
  if (fs::is_regular_file(path, ec)) return true;
  if (InputLog* log = current_input_log()) log->add_absent(path);
  return false;
}

std::vector<InputFile> relative_inputs(std::span<const InputFile> files, const fs::path& base) {
  const fs::path abs_base = normal_absolute(base);
  std::vector<InputFile> out;
  out.reserve(files.size());
  for (const InputFile& f : files) {
    InputFile r = f;
    const fs::path rel = fs::path(f.path).lexically_relative(abs_base);
    r.path = rel.empty() ? fs::path(f.path).generic_string() : rel.generic_string();
    out.push_back(std::move(r));
  }
  std::sort(out.begin(), out.end(), [](const InputFile& a, const InputFile& b) { return a.path < b.path; });
  return out;
}

uint64_t cook_key(std::span<const InputFile> relative, std::string_view options) {
  // A canonical text, hashed: unambiguous (every field ends in a separator no path or option
  // contains), independent of the machine's endianness, and easy to reproduce in a test.
  std::string text = "ossa-cook-key 1\nformat " + std::to_string(kFormatVersion) + "\ncooker " + kCookerVersion +
                     "\noptions " + std::string(options) + "\n";
  for (const InputFile& f : relative) {
    text += f.path;
    text += '\0';
    text += f.present ? hex64(f.hash) + " " + std::to_string(f.size) : std::string("absent");
    text += '\n';
  }
  return XXH3_64bits(text.data(), text.size());
}

std::string hex64(uint64_t value) {
  char buf[17];
  std::snprintf(buf, sizeof buf, "%016llx", static_cast<unsigned long long>(value));
  return buf;
}

}  // namespace ossa::cook
