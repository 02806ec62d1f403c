// cook_job.cpp — see cook_job.h.
//
// The child's stdout goes to /dev/null (the cooker's table) and its stderr into a pipe the thread
// reads to the end before it waits for the child, so a chatty cooker cannot block on a full pipe.
// The folder hash is FNV-1a 64 of the absolute path: a name, not a security measure.
#include "viewer/cook_job.h"

#include <algorithm>
#include <cctype>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <system_error>
#include <vector>

#ifndef _WIN32
#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>
extern char** environ;
#endif

namespace fs = std::filesystem;

namespace ossa::view {
namespace {

std::string lower_extension(const fs::path& p) {
  std::string e = p.extension().string();
  std::transform(e.begin(), e.end(), e.begin(), [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return e;
}

bool executable_file(const fs::path& p) {
  std::error_code ec;
  if (!fs::is_regular_file(p, ec)) return false;
#ifdef _WIN32
  return true;
#else
  return access(p.c_str(), X_OK) == 0;
#endif
}

uint64_t fnv1a(const std::string& s) {
  uint64_t h = 1469598103934665603ull;
  for (unsigned char c : s) {
    h ^= c;
    h *= 1099511628211ull;
  }
  return h;
}

/// The cooker's stderr, trimmed, without its "[1/1, 1 failed]" progress lines.
std::string tidy_errors(const std::string& text) {
  std::string out;
  size_t start = 0;
  while (start < text.size()) {
    size_t end = text.find('\n', start);
    if (end == std::string::npos) end = text.size();
    std::string line = text.substr(start, end - start);
    start = end + 1;
    if (line.empty() || line.front() == '[') continue;
    out += (out.empty() ? "" : "\n") + line;
  }
  return out;
}

}  // namespace

bool is_cook_source(const fs::path& path) {
  static const char* const kExtensions[] = {".fbx", ".gltf", ".glb", ".dae", ".bvh", ".obj"};
  const std::string e = lower_extension(path);
  return std::any_of(std::begin(kExtensions), std::end(kExtensions), [&](const char* k) { return e == k; });
}

std::optional<fs::path> find_cooker(const fs::path& exe_dir, const std::string& path_env) {
#ifdef _WIN32
  const char* name = "ossa-cook.exe";
  const char separator = ';';
#else
  const char* name = "ossa-cook";
  const char separator = ':';
#endif
  if (!exe_dir.empty() && executable_file(exe_dir / name)) return exe_dir / name;
  size_t start = 0;
  while (start < path_env.size()) {
    size_t end = path_env.find(separator, start);
    if (end == std::string::npos) end = path_env.size();
    const std::string folder = path_env.substr(start, end - start);
    start = end + 1;
    if (!folder.empty() && executable_file(fs::path(folder) / name)) return fs::path(folder) / name;
  }
  return std::nullopt;
}

fs::path executable_dir() {
  std::error_code ec;
  const fs::path self = fs::read_symlink("/proc/self/exe", ec);
  return ec ? fs::path() : self.parent_path();
}

fs::path cook_cache_root(const char* xdg_cache_home, const char* home) {
  if (xdg_cache_home != nullptr && fs::path(xdg_cache_home).is_absolute())
    return fs::path(xdg_cache_home) / "ossa-view";
  if (home != nullptr && fs::path(home).is_absolute()) return fs::path(home) / ".cache" / "ossa-view";
  std::error_code ec;
  const fs::path tmp = fs::temp_directory_path(ec);
  return (ec ? fs::path("/tmp") : tmp) / "ossa-view-cache";
}

fs::path cook_output_for(const fs::path& cache_root, const fs::path& source) {
  std::error_code ec;
  const fs::path absolute = fs::absolute(source, ec).lexically_normal();
  char folder[17];
  std::snprintf(folder, sizeof folder, "%016llx",
                static_cast<unsigned long long>(fnv1a((ec ? source : absolute).string())));
  return cache_root / folder / (source.stem().string() + ".ossa");
}

CookJob::~CookJob() {
#ifndef _WIN32
  if (const int pid = child_.load(); pid > 0 && !done_.load()) kill(pid, SIGTERM);
#endif
  if (thread_.joinable()) thread_.join();
}

bool CookJob::start(const fs::path& cooker, const fs::path& source, const fs::path& output, std::string& error) {
  if (running()) {
    error = "a cook is already running (" + source_.filename().string() + ")";
    return false;
  }
  if (thread_.joinable()) thread_.join();
  std::error_code ec;
  fs::create_directories(output.parent_path(), ec);
  if (ec) {
    error = output.parent_path().string() + ": cannot create the cook cache folder: " + ec.message();
    return false;
  }
  source_ = source;
  result_ = CookResult{};
  done_ = false;
  started_ = true;
  start_time_ = std::chrono::steady_clock::now();
  thread_ = std::thread(&CookJob::run, this, cooker, output);
  return true;
}

bool CookJob::finished() {
  if (!started_ || !done_.load()) return false;
  if (thread_.joinable()) thread_.join();
  started_ = false;
  return true;
}

double CookJob::elapsed_seconds() const {
  return std::chrono::duration<double>(std::chrono::steady_clock::now() - start_time_).count();
}

void CookJob::run(fs::path cooker, fs::path output) {
  CookResult r;
  r.output = output;
#ifdef _WIN32
  (void)cooker;
  r.error = "cooking from the viewer needs a POSIX system; run ossa-cook and open its output";
#else
  // --root: the source's own folder, so the output is OUT/<stem>.ossa and the cook may read the
  // files beside the source (a .gltf's buffers and textures) and nothing else.
  const std::vector<std::string> args = {cooker.string(),
                                         "--quiet",
                                         source_.string(),
                                         "--root",
                                         fs::absolute(source_).parent_path().string(),
                                         "-o",
                                         output.parent_path().string()};
  std::vector<char*> argv;
  for (const std::string& a : args) argv.push_back(const_cast<char*>(a.c_str()));
  argv.push_back(nullptr);
  int fds[2];
  if (pipe(fds) != 0) {
    r.error = "cannot run " + cooker.string() + ": pipe() failed";
  } else {
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
    posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
    posix_spawn_file_actions_addclose(&actions, fds[0]);
    posix_spawn_file_actions_adddup2(&actions, fds[1], STDERR_FILENO);
    pid_t pid = -1;
    const int rc = posix_spawn(&pid, argv[0], &actions, nullptr, argv.data(), environ);
    posix_spawn_file_actions_destroy(&actions);
    close(fds[1]);
    if (rc != 0) {
      r.error = "cannot run " + cooker.string() + ": " + std::error_code(rc, std::generic_category()).message();
    } else {
      child_ = pid;
      std::string err;
      char buffer[4096];
      for (;;) {
        const ssize_t n = read(fds[0], buffer, sizeof buffer);
        if (n > 0) err.append(buffer, static_cast<size_t>(n));
        else if (n == 0 || errno != EINTR) break;
      }
      int status = 0;
      while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
      }
      child_ = -1;
      std::error_code ec;
      if (WIFEXITED(status) && WEXITSTATUS(status) == 0 && fs::is_regular_file(output, ec)) {
        r.ok = true;
      } else {
        r.error = tidy_errors(err);
        if (r.error.empty())
          r.error =
              source_.string() + ": the cooker " +
              (WIFSIGNALED(status) ? "was killed by signal " + std::to_string(WTERMSIG(status))
                                   : "exited with status " + std::to_string(WEXITSTATUS(status))) +
              (WIFEXITED(status) && WEXITSTATUS(status) == 0 ? " but wrote no " + output.filename().string() : "");
      }
    }
    close(fds[0]);
  }
#endif
  r.seconds = elapsed_seconds();
  result_ = std::move(r);
  done_ = true;
}

// ---- PendingWork

void request_paths(PendingWork& work, const std::vector<std::string>& paths) {
  std::vector<std::string> open;
  for (const std::string& p : paths) {
    if (is_cook_source(p)) work.cook_queue.emplace_back(p);
    else open.push_back(p);
  }
  if (!open.empty()) {
    work.open = std::move(open);
    work.open_announced = false;
  }
}

bool busy(const PendingWork& work) { return !work.open.empty() || !work.cook_queue.empty() || work.cook.running(); }

void note_indicator_drawn(PendingWork& work) {
  if (!work.open.empty()) work.open_announced = true;
  if (!work.cook.running()) return;
  ++work.frames_while_cooking;
  // Once a second of cooking, a progress line for -v: what a script (and the tests) read to know
  // the window keeps drawing while the cooker runs, without assuming how fast either is.
  const int seconds = static_cast<int>(work.cook.elapsed_seconds());
  if (seconds > work.progress_logged) {
    work.progress_logged = seconds;
    work.log.push_back("cooking " + work.cook.source().string() + ": " + std::to_string(seconds) + " s, " +
                       std::to_string(work.frames_while_cooking) + " frames drawn");
  }
}

void step_pending_work(PendingWork& work, App& app, float aspect, std::string& status) {
  if (!work.open.empty() && work.open_announced) {
    const std::vector<std::string> paths = std::move(work.open);
    work.open.clear();
    work.open_announced = false;
    const auto t0 = std::chrono::steady_clock::now();
    const Status s = open_or_add(app, paths, aspect);
    status = s ? std::string() : s.message();
    const double ms = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    char line[64];
    std::snprintf(line, sizeof line, " in %.1f ms", ms);
    work.log.push_back((s ? "opened " : "could not open ") + paths.front() + line);
  }
  if (work.cook.finished()) {
    const CookResult& r = work.cook.result();
    char line[96];
    std::snprintf(line, sizeof line, " in %.2f s (%d frames drawn meanwhile)", r.seconds, work.frames_while_cooking);
    work.log.push_back((r.ok ? "cooked " : "could not cook ") + work.cook.source().string() + " -> " +
                       r.output.string() + line);
    if (r.ok) request_paths(work, {r.output.string()});
    else status = r.error;
  }
  if (!work.cook.running() && !work.cook_queue.empty()) {
    const fs::path source = work.cook_queue.front();
    work.cook_queue.pop_front();
    if (work.cooker.empty()) {
      const char* chosen = std::getenv("OSSA_COOK");
      const char* path = std::getenv("PATH");
      if (chosen != nullptr && *chosen != '\0') work.cooker = chosen;
      else if (const auto found = find_cooker(executable_dir(), path ? path : "")) work.cooker = *found;
    }
    if (work.cache_root.empty()) work.cache_root = cook_cache_root(std::getenv("XDG_CACHE_HOME"), std::getenv("HOME"));
    std::string error;
    if (work.cooker.empty()) {
      status = source.string() +
               ": cannot cook it: ossa-cook was found neither beside ossa-view nor on PATH (OSSA_COOK names one)";
    } else if (!work.cook.start(work.cooker, source, cook_output_for(work.cache_root, source), error)) {
      status = source.string() + ": " + error;
    } else {
      work.frames_while_cooking = 0;
      work.progress_logged = 0;
    }
  }
}

std::optional<std::string> indicator_text(const PendingWork& work) {
  if (work.cook.running()) {
    char seconds[32];
    std::snprintf(seconds, sizeof seconds, "  %.1f s", work.cook.elapsed_seconds());
    std::string text = "cooking " + work.cook.source().filename().string() + seconds;
    if (!work.cook_queue.empty()) text += "  (" + std::to_string(work.cook_queue.size()) + " more queued)";
    return text;
  }
  if (!work.open.empty()) {
    std::string text = "loading " + fs::path(work.open.front()).filename().string();
    if (work.open.size() > 1) text += " and " + std::to_string(work.open.size() - 1) + " more";
    return text + "...";
  }
  if (!work.cook_queue.empty()) return "cooking " + work.cook_queue.front().filename().string();
  return std::nullopt;
}

}  // namespace ossa::view
