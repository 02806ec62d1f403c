// input_log.cpp — the per-cook record of files read, and the cook key (see input_log.h).
#include "cooker/model/input_log.h"

#include <fcntl.h>
#include <sys/stat.h>
#include <unistd.h>
#include <xxhash.h>

#include <algorithm>
#include <cerrno>
#include <cstdio>
#include <cstring>
#include <memory>

#include "common/message.h"
#include "common/open_beneath.h"
#include <ossa/version.h>

namespace ossa::cook {
namespace fs = std::filesystem;

/// The limits of ReadSandboxScope: the folders' descriptors and the hard-link rule.
struct ReadSandbox {
  ReadRoots roots;
  bool allow_hard_links = false;
};

namespace {

thread_local InputLog* t_current = nullptr;
thread_local const ReadSandbox* t_sandbox = nullptr;  // null: no limit

/// `path` absolute, with `..` and every symlink of its existing part resolved: for messages only
/// (what a refused name led to); the sandbox itself never decides by a resolved path.
fs::path canonical_path(const fs::path& path) {
  std::error_code ec;
  fs::path abs = fs::absolute(path, ec);
  if (ec) return path.lexically_normal();
  fs::path canon = fs::weakly_canonical(abs, ec);
  return ec ? abs.lexically_normal() : canon;
}

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

void InputLog::add_hashed(const fs::path& path, uint64_t hash, uint64_t size) {
  files_.push_back({normal_absolute(path).string(), hash, size, true});
}

void InputLog::add_absent(const fs::path& path) { files_.push_back({normal_absolute(path).string(), 0, 0, false}); }

std::vector<InputFile> InputLog::files() const {
  std::vector<InputFile> out = files_;
  // Stable: of two records of one path, the first read is kept.
  std::stable_sort(out.begin(), out.end(), [](const InputFile& a, const InputFile& b) { return a.path < b.path; });
  out.erase(
      std::unique(out.begin(), out.end(), [](const InputFile& a, const InputFile& b) { return a.path == b.path; }),
      out.end());
  return out;
}

InputLog* current_input_log() { return t_current; }

InputLogScope::InputLogScope(InputLog* log) : previous_(t_current) { t_current = log; }
InputLogScope::~InputLogScope() { t_current = previous_; }

ReadSandboxScope::ReadSandboxScope(const std::vector<fs::path>& allowed_dirs, bool allow_hard_links)
    : previous_(t_sandbox), sandbox_(new ReadSandbox{ReadRoots(allowed_dirs), allow_hard_links}) {
  t_sandbox = sandbox_.get();
}
ReadSandboxScope::~ReadSandboxScope() { t_sandbox = previous_; }

namespace {

std::string allowed_list() {
  std::string s;
  for (const ReadRoots::Root& r : t_sandbox->roots.roots()) s += (s.empty() ? "" : ", ") + r.canonical.string();
  return s;
}

/// Refuses `path` (records why in the current log) and returns the message.
std::string refuse(const fs::path& path, const std::string& why, std::string_view reference) {
  // The file as resolved (`..` and symlinks followed), and as the reference wrote it when different.
  const fs::path resolved = canonical_path(path);
  std::string message = detail::printable(resolved.string(), 400) + ": refused: " + why;
  if (!reference.empty() || resolved != path) {
    message += " (named";
    if (!reference.empty()) message += " by " + std::string(reference);
    if (resolved != path) message += " as '" + detail::printable(path.string(), 400) + "'";
    message += ")";
  }
  if (InputLog* log = current_input_log()) log->add_refusal(message);
  return message;
}

/// Names the widening that would allow `path`: --root at the nearest folder holding both the file and
/// an allowed folder (the input's, usually), or --allow-dir at the file's own folder.
std::string outside_message(const fs::path& path) {
  const fs::path file = canonical_path(path);
  fs::path nearest;
  for (const ReadRoots::Root& r : t_sandbox->roots.roots()) {
    fs::path common;
    auto a = r.canonical.begin(), b = file.begin();
    for (; a != r.canonical.end() && b != file.end() && *a == *b; ++a, ++b) common /= *a;
    if (common.native().size() > nearest.native().size()) nearest = common;
  }
  const std::string dir = detail::printable(file.parent_path().string(), 400);
  return "outside the folders this cook may read (" + allowed_list() + "; --root " +
         detail::printable(nearest.empty() ? std::string("/") : nearest.string(), 400) + " or --allow-dir " + dir +
         " would allow it)";
}

std::string hard_link_message(const struct stat& st) {
  return "has " + std::to_string(st.st_nlink) +
         " hard links: another name for the same bytes may lie outside the folders this cook may read "
         "(--allow-hard-links reads such files)";
}

struct OpenedInput {
  int fd = -1;
  uint64_t size = 0;
  bool sole_name = false;  // the hard-link rule applies: look again after reading (sole_name_now)
};

/// The sandbox's one door: resolved and opened in one step beneath the allowed folders
/// (open_beneath.h), then checked on the opened descriptor (regular file, links, size).
Result<OpenedInput> open_input(const fs::path& path, uint64_t max_bytes, std::string_view reference) {
  // A NUL byte (a JSON "\u0000") would cut the path short for the operating system: another file.
  if (path.native().find('\0') != std::string::npos) return Error{refuse(path, "contains a NUL byte", reference)};
  const ReadSandbox* sandbox = t_sandbox;
  const OpenedFile f =
      open_beneath(sandbox ? &sandbox->roots : nullptr, path, true, !sandbox || sandbox->allow_hard_links);
  switch (f.outcome) {
    case OpenOutcome::kOpened: break;
    case OpenOutcome::kAbsent:
      if (InputLog* log = current_input_log()) log->add_absent(path);
      return Error{detail::printable(path.string(), 400) + ": cannot open: " + std::strerror(f.error)};
    case OpenOutcome::kOutside: return Error{refuse(path, outside_message(path), reference)};
    case OpenOutcome::kNotRegular:
      return Error{refuse(path, std::string("is ") + file_kind(f.st) + ", not a regular file", reference)};
    case OpenOutcome::kHardLinked: return Error{refuse(path, hard_link_message(f.st), reference)};
    case OpenOutcome::kError:
      return Error{detail::printable(path.string(), 400) + ": cannot open: " + std::strerror(f.error)};
  }
  if (static_cast<uint64_t>(f.st.st_size) > max_bytes) {
    ::close(f.fd);
    return Error{detail::printable(path.string(), 400) + ": is " + std::to_string(f.st.st_size) +
                 " bytes, over the limit of " + std::to_string(max_bytes)};
  }
  return OpenedInput{f.fd, static_cast<uint64_t>(f.st.st_size), sandbox && !sandbox->allow_hard_links};
}

}  // namespace

Result<std::vector<uint8_t>> read_input(const fs::path& path, uint64_t max_bytes, std::string_view reference) {
  auto opened = open_input(path, max_bytes, reference);
  if (!opened) return opened.error();
  const int fd = opened->fd;
  std::vector<uint8_t> bytes(static_cast<size_t>(opened->size));
  size_t done = 0;
  while (done < bytes.size()) {
    const ssize_t n = ::read(fd, bytes.data() + done, bytes.size() - done);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    done += static_cast<size_t>(n);
  }
  uint8_t extra = 0;
  const ssize_t more = done == bytes.size() ? ::read(fd, &extra, 1) : 0;
  const bool linked_elsewhere = opened->sole_name && !sole_name_now(fd);
  ::close(fd);
  if (done != bytes.size() || more != 0 || linked_elsewhere)
    return Error{detail::printable(path.string(), 400) + ": changed while being read"};
  if (InputLog* log = current_input_log()) log->add(path, bytes);
  return bytes;
}

Status hash_input(const fs::path& path, std::string_view reference) {
  auto opened = open_input(path, UINT64_MAX, reference);
  if (!opened) return opened.error();
  // Streamed through a fixed buffer: XXH3's streaming form gives the one-shot hash, and no
  // file-sized buffer is allocated (and page-faulted in) only to be hashed and freed.
  constexpr size_t kChunk = 256 << 10;
  static thread_local std::vector<uint8_t> buffer(kChunk);
  XXH3_state_t* state = XXH3_createState();
  if (state == nullptr) {
    ::close(opened->fd);
    return Error{detail::printable(path.string(), 400) + ": out of memory"};
  }
  XXH3_64bits_reset(state);
  uint64_t done = 0;
  for (;;) {
    const ssize_t n = ::read(opened->fd, buffer.data(), kChunk);
    if (n < 0 && errno == EINTR) continue;
    if (n <= 0) break;
    XXH3_64bits_update(state, buffer.data(), static_cast<size_t>(n));
    done += static_cast<uint64_t>(n);
  }
  const uint64_t hash = XXH3_64bits_digest(state);
  XXH3_freeState(state);
  const bool linked_elsewhere = opened->sole_name && !sole_name_now(opened->fd);
  ::close(opened->fd);
  if (done != opened->size || linked_elsewhere)
    return Error{detail::printable(path.string(), 400) + ": changed while being read"};
  if (InputLog* log = current_input_log()) log->add_hashed(path, hash, done);
  return {};
}

bool probe_input(const fs::path& path, std::string_view reference) {
  if (path.native().find('\0') != std::string::npos) {
    refuse(path, "contains a NUL byte", reference);
    return false;
  }
  // Resolved as a read would resolve it, nothing opened for reading: a name that exists but is no
  // regular file (a FIFO called walk.events.json) is refused, not taken for absent.
  const ReadSandbox* sandbox = t_sandbox;
  const OpenedFile f =
      open_beneath(sandbox ? &sandbox->roots : nullptr, path, false, !sandbox || sandbox->allow_hard_links);
  switch (f.outcome) {
    case OpenOutcome::kOpened: return true;
    case OpenOutcome::kAbsent:
      if (InputLog* log = current_input_log()) log->add_absent(path);
      return false;
    case OpenOutcome::kOutside: refuse(path, outside_message(path), reference); return false;
    case OpenOutcome::kNotRegular:
      // A folder is no file of that name (an importer probes folders, e.g. an empty "mtllib"); a
      // FIFO, device or socket is a file the cook cannot read, and must not pass for absent.
      if (S_ISDIR(f.st.st_mode)) {
        if (InputLog* log = current_input_log()) log->add_absent(path);
        return false;
      }
      refuse(path, std::string("is ") + file_kind(f.st) + ", not a regular file", reference);
      return false;
    case OpenOutcome::kHardLinked: refuse(path, hard_link_message(f.st), reference); return false;
    case OpenOutcome::kError:
      refuse(path, std::string("cannot be opened: ") + std::strerror(f.error), reference);
      return false;
  }
  return false;
}

std::vector<InputFile> relative_inputs(std::span<const InputFile> files, const fs::path& base) {
  // An input named without a folder has an empty parent: the current directory. No trailing
  // separator either ("/a/b/" would make every path relative to a phantom empty element).
  fs::path abs_base = normal_absolute(base.empty() ? fs::path(".") : base);
  if (abs_base.has_relative_path() && abs_base.filename().empty()) abs_base = abs_base.parent_path();
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
