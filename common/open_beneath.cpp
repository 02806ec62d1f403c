// open_beneath.cpp — resolve-and-open beneath a set of folders, race-free (see open_beneath.h).
#include "common/open_beneath.h"

#include <fcntl.h>
#include <sys/syscall.h>
#include <unistd.h>
#if __has_include(<linux/openat2.h>)
#include <linux/openat2.h>
#endif

#include <atomic>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <deque>
#include <string>

#if !defined(RESOLVE_BENEATH)
// Debian 12's kernel headers have <linux/openat2.h>; older ones get the same ABI spelled here.
struct open_how {
  uint64_t flags, mode, resolve;
};
#define RESOLVE_NO_MAGICLINKS 0x02
#define RESOLVE_BENEATH 0x08
#endif
#if !defined(SYS_openat2)
#define SYS_openat2 437  // the same number on every architecture (the unified syscall table)
#endif

namespace ossa::cook {
namespace fs = std::filesystem;

namespace {

constexpr int kMaxLinks = 40;   // what the kernel allows (MAXSYMLINKS) for one resolution
constexpr int kMaxRetries = 8;  // a file swapped between the two opens of one resolution: try again
constexpr uint64_t kResolve = RESOLVE_BENEATH | RESOLVE_NO_MAGICLINKS;

fs::path normal_absolute(const fs::path& path) {
  std::error_code ec;
  const fs::path abs = fs::absolute(path, ec);
  fs::path normal = (ec ? path : abs).lexically_normal();
  if (normal.has_relative_path() && normal.filename().empty()) normal = normal.parent_path();  // "a/b/" -> "a/b"
  return normal;
}

int sys_openat2(int dirfd, const char* path, uint64_t flags) {
  open_how how{};
  how.flags = flags;
  how.resolve = kResolve;
  return static_cast<int>(::syscall(SYS_openat2, dirfd, path, &how, sizeof how));
}

std::atomic<int> g_openat2{-1};  // -1 not probed, 0 absent, 1 present

/// Errors that mean "there is no such file": a name too long for the file system cannot exist.
bool absent_errno(int e) { return e == ENOENT || e == ENOTDIR || e == ENAMETOOLONG; }

bool same_file(const struct stat& a, const struct stat& b) { return a.st_dev == b.st_dev && a.st_ino == b.st_ino; }

OpenedFile failed(OpenOutcome outcome, int error = 0) {
  OpenedFile f;
  f.outcome = outcome;
  f.error = error;
  return f;
}

OpenedFile not_regular(const struct stat& st) {
  OpenedFile f;
  f.outcome = OpenOutcome::kNotRegular;
  f.st = st;
  return f;
}

// Sentinel: the file changed between the O_PATH look and the open for reading; resolve again.
constexpr int kRetry = -2;

/// `abs` relative to the first root it lies beneath (as named, then with the root's symlinks
/// resolved, then with `abs`'s own symlinks resolved: the last only chooses the root, the open is
/// still resolved beneath it). -1 when none.
int find_root(const ReadRoots& roots, const fs::path& abs, fs::path& rel) {
  const auto match = [&](const fs::path& p) {
    for (size_t i = 0; i < roots.roots().size(); ++i) {
      const ReadRoots::Root& r = roots.roots()[i];
      for (const fs::path* base : {&r.given, &r.canonical}) {
        const fs::path candidate = p.lexically_relative(*base);
        if (!candidate.empty() && *candidate.begin() != "..") {
          rel = candidate;
          return static_cast<int>(i);
        }
      }
    }
    return -1;
  };
  if (const int i = match(abs); i >= 0) return i;
  std::error_code ec;
  const fs::path canon = fs::weakly_canonical(abs, ec);
  return ec ? -1 : match(canon);
}

/// The last step of both resolutions: `opath` (an O_PATH descriptor, owned) is what the name
/// resolved to; `reopen` opens the same name for reading. Non-regular files are never reopened.
template <class Reopen>
OpenedFile finish(int opath, bool for_reading, Reopen reopen) {
  struct stat st {};
  const int stat_rc = ::fstat(opath, &st);
  const int stat_errno = errno;
  ::close(opath);
  if (stat_rc != 0) return failed(OpenOutcome::kError, stat_errno);
  if (!S_ISREG(st.st_mode)) return not_regular(st);
  OpenedFile f;
  f.outcome = OpenOutcome::kOpened;
  f.st = st;
  if (!for_reading) return f;
  const int fd = reopen();
  if (fd < 0) return failed(OpenOutcome::kError, errno == ELOOP || errno == EXDEV ? kRetry : errno);
  struct stat opened {};
  if (::fstat(fd, &opened) != 0 || !same_file(st, opened)) {
    ::close(fd);
    return failed(OpenOutcome::kError, kRetry);
  }
  f.fd = fd;
  f.st = opened;
  return f;
}

/// openat2 from the root's descriptor. `fallback` is set when the walk must decide (the kernel
/// refused a step the sandbox may still allow, or has no openat2 after all).
OpenedFile via_openat2(const ReadRoots& roots, const fs::path& abs, bool for_reading, bool& fallback) {
  fs::path rel;
  const int index = find_root(roots, abs, rel);
  if (index < 0) return failed(OpenOutcome::kOutside);
  const int dirfd = roots.roots()[static_cast<size_t>(index)].fd;
  if (dirfd < 0) return failed(OpenOutcome::kAbsent, ENOENT);
  const int opath = sys_openat2(dirfd, rel.c_str(), O_PATH | O_CLOEXEC);
  if (opath < 0) {
    const int e = errno;
    if (absent_errno(e)) return failed(OpenOutcome::kAbsent, e);
    if (e == ENOSYS || e == EPERM) g_openat2.store(0);
    if (e == EXDEV || e == ELOOP || e == EAGAIN || e == ENOSYS || e == EPERM) fallback = true;
    return failed(OpenOutcome::kError, e);
  }
  return finish(opath, for_reading,
                [&] { return sys_openat2(dirfd, rel.c_str(), O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC); });
}

std::string read_link(int link_fd) {
  std::string target(256, '\0');
  for (;;) {
    const ssize_t n = ::readlinkat(link_fd, "", target.data(), target.size());
    if (n < 0) return {};
    if (static_cast<size_t>(n) < target.size()) {
      target.resize(static_cast<size_t>(n));
      return target;
    }
    target.resize(target.size() * 2);
  }
}

/// The walk: one component at a time, O_NOFOLLOW, from descriptors this function opened itself.
OpenedFile via_walk(const ReadRoots& roots, fs::path abs, bool for_reading) {
  int links = 0;
  for (;;) {  // one pass per start from a root (the path, or an absolute link's target)
    fs::path rel;
    const int index = find_root(roots, abs, rel);
    if (index < 0) return failed(OpenOutcome::kOutside);
    const ReadRoots::Root& root = roots.roots()[static_cast<size_t>(index)];
    if (root.fd < 0) return failed(OpenOutcome::kAbsent, ENOENT);
    std::vector<int> stack;  // descriptors of the folders below the root, owned
    const auto current = [&] { return stack.empty() ? root.fd : stack.back(); };
    const auto close_all = [&] {
      for (int fd : stack) ::close(fd);
      stack.clear();
    };
    std::deque<std::string> queue;
    for (const fs::path& c : rel) queue.push_back(c.string());
    bool restart = false;
    while (!queue.empty()) {
      const std::string name = queue.front();
      queue.pop_front();
      if (name.empty() || name == ".") continue;
      if (name == "..") {
        if (!stack.empty()) {
          ::close(stack.back());
          stack.pop_back();
          continue;
        }
        // Above the root: what is left, from the root's parent, must lie beneath a root again.
        fs::path next = root.canonical.parent_path();
        for (const std::string& q : queue) next /= q;
        abs = next.lexically_normal();
        restart = true;
        break;
      }
      const int fd = ::openat(current(), name.c_str(), O_PATH | O_NOFOLLOW | O_CLOEXEC);
      if (fd < 0) {
        const int e = errno;
        close_all();
        return failed(absent_errno(e) ? OpenOutcome::kAbsent : OpenOutcome::kError, e);
      }
      struct stat st {};
      if (::fstat(fd, &st) != 0) {
        const int e = errno;
        ::close(fd);
        close_all();
        return failed(OpenOutcome::kError, e);
      }
      if (S_ISLNK(st.st_mode)) {
        const std::string target = read_link(fd);
        ::close(fd);
        if (++links > kMaxLinks || target.empty()) {
          close_all();
          return failed(OpenOutcome::kError, target.empty() ? ENOENT : ELOOP);
        }
        if (target.front() == '/') {
          fs::path next(target);
          for (const std::string& q : queue) next /= q;
          abs = next.lexically_normal();
          restart = true;
          break;
        }
        // A relative link is read from the folder that holds it: its components come next.
        std::vector<std::string> parts;
        for (const fs::path& c : fs::path(target)) parts.push_back(c.string());
        queue.insert(queue.begin(), parts.begin(), parts.end());
        continue;
      }
      if (!queue.empty()) {
        if (!S_ISDIR(st.st_mode)) {
          ::close(fd);
          close_all();
          return failed(OpenOutcome::kAbsent, ENOTDIR);
        }
        stack.push_back(fd);
        continue;
      }
      const int parent = current();
      OpenedFile f = finish(fd, for_reading, [&] {
        return ::openat(parent, name.c_str(), O_RDONLY | O_NOFOLLOW | O_NONBLOCK | O_NOCTTY | O_CLOEXEC);
      });
      close_all();
      return f;
    }
    if (restart) {
      close_all();
      if (++links > kMaxLinks) return failed(OpenOutcome::kError, ELOOP);
      continue;
    }
    // The path ends at a folder (the root, or one reached by `..` or `.`).
    struct stat st {};
    const int rc = ::fstat(current(), &st);
    close_all();
    return rc == 0 ? not_regular(st) : failed(OpenOutcome::kError, errno);
  }
}

OpenedFile via_system(const fs::path& path, bool for_reading) {
  const int opath = ::open(path.c_str(), O_PATH | O_CLOEXEC);
  if (opath < 0) return failed(absent_errno(errno) ? OpenOutcome::kAbsent : OpenOutcome::kError, errno);
  return finish(opath, for_reading, [&] { return ::open(path.c_str(), O_RDONLY | O_NONBLOCK | O_NOCTTY | O_CLOEXEC); });
}

/// For the hard-link rule: true when the name `fd` was opened by has been unlinked since (the
/// kernel marks the descriptor's path " (deleted)"). A file seen with one link whose name is still
/// linked after that look had no other name at the look; without this, a link made into the tree,
/// opened, then removed again would show one link: the outside name's. Unknown (no /proc) counts
/// as not unlinked: the link count is then the only check.
/// The path the kernel shows for `fd` (/proc/self/fd), or "" when it cannot tell.
std::string fd_path(int fd) {
  char proc[32];
  std::snprintf(proc, sizeof proc, "/proc/self/fd/%d", fd);
  char target[4096];
  const ssize_t n = ::readlink(proc, target, sizeof target);
  if (n <= 0 || static_cast<size_t>(n) >= sizeof target) return {};
  return std::string(target, static_cast<size_t>(n));
}

bool name_unlinked(int fd) {
  constexpr std::string_view kDeleted = " (deleted)";
  const std::string link = fd_path(fd);
  return link.size() >= kDeleted.size() && std::string_view(link).substr(link.size() - kDeleted.size()) == kDeleted;
}

}  // namespace

ReadRoots::ReadRoots(const std::vector<fs::path>& dirs) {
  for (const fs::path& d : dirs) {
    Root r;
    r.given = normal_absolute(d.empty() ? fs::path(".") : d);
    std::error_code ec;
    r.canonical = fs::weakly_canonical(r.given, ec);
    if (ec) r.canonical = r.given;
    if (r.canonical.has_relative_path() && r.canonical.filename().empty()) r.canonical = r.canonical.parent_path();
    r.fd = ::open(r.given.c_str(), O_PATH | O_DIRECTORY | O_CLOEXEC);
    roots_.push_back(std::move(r));
  }
}

ReadRoots::~ReadRoots() {
  for (const Root& r : roots_)
    if (r.fd >= 0) ::close(r.fd);
}

bool have_openat2() {
  int known = g_openat2.load();
  if (known < 0) {
    const char* off = std::getenv("OSSA_TEST_NO_OPENAT2");
    known = 0;
    if (off == nullptr || *off == '\0' || std::string_view(off) == "0") {
      const int fd = sys_openat2(AT_FDCWD, ".", O_PATH | O_CLOEXEC);
      if (fd >= 0) {
        ::close(fd);
        known = 1;
      }
    }
    g_openat2.store(known);
  }
  return known == 1;
}

void force_walk_for_testing(bool walk) { g_openat2.store(walk ? 0 : -1); }

OpenedFile open_beneath(const ReadRoots* roots, const fs::path& path, bool for_reading, bool allow_hard_links) {
  OpenedFile f;
  if (path.native().find('\0') != std::string::npos)
    return failed(OpenOutcome::kError, EINVAL);  // another file for the OS
  for (int attempt = 0; attempt < kMaxRetries; ++attempt) {
    if (roots == nullptr) {
      f = via_system(path, for_reading);
    } else {
      const fs::path abs = normal_absolute(path);
      bool fallback = !have_openat2();
      if (!fallback) f = via_openat2(*roots, abs, for_reading, fallback);
      if (fallback) f = via_walk(*roots, abs, for_reading);
    }
    if (f.outcome == OpenOutcome::kError && f.error == kRetry) continue;
    if (f.outcome == OpenOutcome::kOpened && roots != nullptr && !allow_hard_links) {
      if (f.st.st_nlink > 1) {
        if (f.fd >= 0) ::close(f.fd);
        f.fd = -1;
        f.outcome = OpenOutcome::kHardLinked;
        break;
      }
      // One link at the fstat above; the name must still be linked now (see name_unlinked).
      if (f.fd >= 0 && name_unlinked(f.fd)) {
        ::close(f.fd);
        f = failed(OpenOutcome::kError, kRetry);
        continue;
      }
    }
    break;
  }
  if (f.outcome == OpenOutcome::kError && f.error == kRetry) f.error = EAGAIN;  // kept changing: give up
  return f;
}

bool sole_name_now(int fd) {
  // First wait out a rename in progress in the name's folder: looking up a name nobody has used
  // takes the folder's lock (shared), which a rename holds (exclusive) until it has unlinked the
  // name it replaced. The lookup's answer (none) is not used.
  const std::string path = fd_path(fd);
  const size_t slash = path.rfind('/');
  if (slash != std::string::npos) {
    static std::atomic<uint64_t> probes{0};
    const std::string probe = path.substr(0, slash) + "/.ossa-lock-probe-" + std::to_string(::getpid()) + "-" +
                              std::to_string(probes.fetch_add(1, std::memory_order_relaxed));
    struct stat ignored {};
    (void)::stat(probe.c_str(), &ignored);
  }
  struct stat st {};
  return ::fstat(fd, &st) == 0 && st.st_nlink <= 1 && !name_unlinked(fd);
}

const char* file_kind(const struct stat& st) {
  if (S_ISDIR(st.st_mode)) return "a directory";
  if (S_ISFIFO(st.st_mode)) return "a FIFO";
  if (S_ISCHR(st.st_mode) || S_ISBLK(st.st_mode)) return "a device";
  if (S_ISSOCK(st.st_mode)) return "a socket";
  return "not a regular file";
}

}  // namespace ossa::cook
