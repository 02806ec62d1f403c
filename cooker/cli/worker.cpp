// worker.cpp — the worker processes of a batch: the record's wire form, the child's limits and test
// hook, and the parent's scheduler (see worker.h for why it is shaped so).
#include "cooker/cli/worker.h"

#include "cooker/cache/cook_cache.h"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>
#if defined(__linux__)
#include <sys/prctl.h>
#endif

#include <algorithm>
#include <cerrno>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <new>
#include <stdexcept>
#include <string_view>
#include <type_traits>

// Sanitizers whose shadow memory is reserved address space (terabytes): RLIMIT_AS would starve them.
#if defined(__SANITIZE_ADDRESS__) || defined(__SANITIZE_THREAD__)
#define OSSA_SANITIZER_SHADOW 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer) || __has_feature(thread_sanitizer) || __has_feature(memory_sanitizer)
#define OSSA_SANITIZER_SHADOW 1
#endif
#endif

namespace ossa::cook {
namespace fs = std::filesystem;
using json = nlohmann::json;
using Clock = std::chrono::steady_clock;

// ---------------------------------------------------------------------------------------------
// The record on the wire: every field of the records' field lists (cooker/model/cook_record.h),
// under its own key, optionals as null. A field added to a record and to its list crosses the pipe
// with no edit here; tests/cooker/cook_isolation_test.cpp checks that every listed field survives.

namespace {

template <class T>
struct is_optional : std::false_type {};
template <class T>
struct is_optional<std::optional<T>> : std::true_type {};

/// Records that have a field list (and are sent as objects), as opposed to plain values.
template <class T>
constexpr bool kIsRecord =
    std::is_same_v<T, ClipRecord> || std::is_same_v<T, TextureRecord> || std::is_same_v<T, MorphRecord> ||
    std::is_same_v<T, InputFile> || std::is_same_v<T, RetargetRecord> || std::is_same_v<T, RetargetContactRecord>;

template <class T>
struct record_vector : std::false_type {};
template <class T>
struct record_vector<std::vector<T>> : std::bool_constant<kIsRecord<T>> {};

template <class Record>
json to_wire(const Record& r);

template <class T>
json value_to_wire(const T& value) {
  if constexpr (is_optional<T>::value) {
    return value ? json(*value) : json(nullptr);
  } else if constexpr (record_vector<T>::value) {
    json list = json::array();
    for (const auto& r : value) list.push_back(to_wire(r));
    return list;
  } else {
    return json(value);
  }
}

template <class Record>
json to_wire(const Record& r) {
  json j = json::object();
  record_fields([&j](const char* key, const auto& value) { j[key] = value_to_wire(value); }, r);
  return j;
}

template <class Record>
void from_wire(const json& j, Record& r);

/// Throws (std::invalid_argument, or nlohmann's type_error / out_of_range) when `j` is not a `T`.
template <class T>
void value_from_wire(const json& j, T& out) {
  if constexpr (is_optional<T>::value) {
    if (j.is_null()) out.reset();
    else if (j.is_number_unsigned()) out = j.get<typename T::value_type>();
    else throw std::invalid_argument("not a count");
  } else if constexpr (record_vector<T>::value) {
    if (!j.is_array()) throw std::invalid_argument("not a list");
    out.clear();
    for (const json& item : j) from_wire(item, out.emplace_back());
  } else {
    out = j.get<T>();
  }
}

template <class Record>
void from_wire(const json& j, Record& r) {
  if (!j.is_object()) throw std::invalid_argument("not an object");
  record_fields([&j](const char* key, auto& value) { value_from_wire(j.at(key), value); }, r);
}

}  // namespace

json record_to_json(const CookRecord& r) { return to_wire(r); }

std::optional<CookRecord> record_from_json(const json& j) {
  try {
    CookRecord r;
    from_wire(j, r);
    return r;
  } catch (const std::exception&) {  // a missing key or a value of another type
    return std::nullopt;
  }
}

bool memory_limit_enforced() {
#if defined(OSSA_SANITIZER_SHADOW)
  return false;
#else
  return true;
#endif
}

std::string format_size(uint64_t bytes) {
  char buf[32];
  const double b = static_cast<double>(bytes);
  if (bytes >= (uint64_t{1} << 30)) std::snprintf(buf, sizeof buf, "%.1f GiB", b / (1 << 30));
  else if (bytes >= (uint64_t{1} << 20)) std::snprintf(buf, sizeof buf, "%.0f MiB", b / (1 << 20));
  else if (bytes >= (uint64_t{1} << 10)) std::snprintf(buf, sizeof buf, "%.0f KiB", b / (1 << 10));
  else std::snprintf(buf, sizeof buf, "%llu B", static_cast<unsigned long long>(bytes));
  return buf;
}

// ---------------------------------------------------------------------------------------------
// The child

namespace {

int g_record_fd = -1;  // the child's write end, for the new-handler

/// The new-handler of a worker: an allocation failed, which under RLIMIT_AS means the limit. No
/// allocation here (there is no memory to be had), only write(2) and _exit(2).
void on_memory_exhausted() {
  const size_t length = std::strlen(kWorkerMemoryMarker);
  [[maybe_unused]] const ssize_t written = ::write(g_record_fd, kWorkerMemoryMarker, length);
  ::_exit(kWorkerExitMemory);
}

bool write_all(int fd, const uint8_t* data, size_t size) {
  while (size > 0) {
    const ssize_t n = ::write(fd, data, size);
    if (n < 0) {
      if (errno == EINTR) continue;
      return false;
    }
    data += n;
    size -= static_cast<size_t>(n);
  }
  return true;
}

/// OSSA_COOK_TEST_FAULT (worker.h): the fault asked for this input, or "" (no allocation when unset).
std::string_view test_fault(const std::string& input) {
  const char* spec = std::getenv("OSSA_COOK_TEST_FAULT");
  if (spec == nullptr) return {};
  std::string_view rest(spec);
  while (!rest.empty()) {
    const size_t comma = rest.find(',');
    const std::string_view entry = rest.substr(0, comma);
    rest = comma == std::string_view::npos ? std::string_view() : rest.substr(comma + 1);
    const size_t colon = entry.rfind(':');
    if (colon == std::string_view::npos || colon == 0) continue;
    if (input.find(entry.substr(0, colon)) != std::string::npos) return entry.substr(colon + 1);
  }
  return {};
}

/// The faults that happen before cooking.
void inject_fault_before(std::string_view fault, const BatchItem& item, int record_fd) {
  if (fault == "abort") std::abort();
  if (fault == "segv") {
    ::raise(SIGSEGV);
    std::abort();  // not reached: SIGSEGV's default action ends the process
  }
  if (fault == "hang")
    for (;;) ::pause();
  if (fault == "alloc") {
    // Leaked on purpose until the address-space limit (RLIMIT_AS) refuses one. Only the first page
    // of each chunk is touched: the limit counts address space, not resident pages, and touching
    // every page made the time to reach it depend on how fast the machine faults in fresh memory
    // (over 2 s on a new VM under a parallel test load, which the test's time limit then caught).
    constexpr size_t kChunk = size_t{64} << 20;
    for (;;) {
      volatile char* chunk = new char[kChunk];
      chunk[0] = 1;
    }
  }
  if (fault == "abort-writing") {  // die as if in the middle of write_file_atomic (cook.cpp)
    std::error_code ignored;
    fs::create_directories(item.output.parent_path(), ignored);
    const fs::path tmp = item.output.parent_path() / temporary_name(item.output.filename().string(), ::getpid(), 0);
    if (FILE* f = std::fopen(tmp.c_str(), "wb")) {
      std::fputs("half a file", f);
      std::fclose(f);
    }
    std::abort();
  }
  if (fault == "garble") {  // a record cut short, then a normal exit
    const uint8_t truncated[] = {0xb2, 0x65, 'i', 'n'};
    write_all(record_fd, truncated, sizeof truncated);
    ::_exit(0);
  }
}

[[noreturn]] void run_worker(const BatchItem& item, const CookOptions& options, const BatchLimits& limits,
                             int record_fd, pid_t parent) {
#if defined(__linux__)
  // Die with the batch: a killed ossa-cook must not leave workers cooking (or hanging) on.
  ::prctl(PR_SET_PDEATHSIG, SIGKILL);
  if (::getppid() != parent) ::_exit(1);  // the parent died before prctl took effect
#else
  (void)parent;
#endif
  g_record_fd = record_fd;
  if (limits.max_memory_bytes > 0 && memory_limit_enforced()) {
    rlimit limit{};
    ::getrlimit(RLIMIT_AS, &limit);
    const rlim_t wanted = static_cast<rlim_t>(limits.max_memory_bytes);
    if (limit.rlim_max == RLIM_INFINITY || wanted < limit.rlim_max) limit.rlim_max = wanted;
    limit.rlim_cur = limit.rlim_max;
    ::setrlimit(RLIMIT_AS, &limit);
  }
  std::set_new_handler(on_memory_exhausted);
  const std::string_view fault = test_fault(item.input.string());
  if (!fault.empty()) inject_fault_before(fault, item, record_fd);

  CookOptions item_options = options;
  if (item_options.root.empty()) item_options.root = item.tree;  // the read sandbox's default
  item_options.folder_rig = item.rig;
  const CookRecord record = cook_file(item.input, item.output, item_options);
  if (fault == "abort-after") std::abort();  // the output is in place: the parent must remove it
  std::vector<uint8_t> bytes;
  try {
    bytes = json::to_cbor(record_to_json(record));
  } catch (const std::exception&) {
    ::_exit(1);  // reported by the parent as an exit without a record
  }
  // _exit, not exit: no static destructors or atexit handlers of the parent's state run twice.
  ::_exit(write_all(record_fd, bytes.data(), bytes.size()) ? 0 : 1);
}

// ---------------------------------------------------------------------------------------------
// The parent

struct Worker {
  size_t index = 0;
  pid_t pid = -1;
  int fd = -1;  // read end of the record pipe; -1 once the child closed it
  std::vector<uint8_t> received;
  Clock::time_point started;
  bool killed_for_time = false;
  // The file at the output path before the worker started (a failed input must leave it alone).
  bool had_output = false;
  dev_t output_dev = 0;
  ino_t output_ino = 0;
  // The batch's own cache lookup for this input, a miss (cook_cache.h): its fields join the record.
  bool looked_up = false;
  CookRecord cache_miss;
};

std::string signal_name(int sig) {
  switch (sig) {
    case SIGABRT: return "SIGABRT; Assimp may have aborted";
    case SIGSEGV: return "SIGSEGV; an invalid memory access";
    case SIGBUS: return "SIGBUS; an invalid memory access";
    case SIGFPE: return "SIGFPE; an arithmetic fault";
    case SIGILL: return "SIGILL; an illegal instruction";
    case SIGKILL: return "SIGKILL; the system may have run out of memory";
    case SIGTERM: return "SIGTERM";
    case SIGINT: return "SIGINT";
    case SIGHUP: return "SIGHUP";
    case SIGQUIT: return "SIGQUIT";
    case SIGPIPE: return "SIGPIPE";
    case SIGTRAP: return "SIGTRAP";
    case SIGXCPU: return "SIGXCPU; CPU time limit";
    case SIGXFSZ: return "SIGXFSZ; file size limit";
    default: return "";
  }
}

/// Removes what a worker that ended abnormally may have left for this output: its temporary files,
/// and an output it renamed into place (not a previous file, which has another inode).
void remove_leftovers(const fs::path& output, const Worker& w) {
  std::error_code ec;
  const fs::path dir = output.parent_path().empty() ? fs::path(".") : output.parent_path();
  const std::string prefix = temporary_prefix(output.filename().string()) + std::to_string(w.pid) + "-";
  for (fs::directory_iterator it(dir, ec), end; !ec && it != end; it.increment(ec)) {
    if (it->path().filename().string().rfind(prefix, 0) != 0) continue;
    std::error_code ignored;
    fs::remove(it->path(), ignored);
  }
  struct stat st {};
  if (::stat(output.c_str(), &st) == 0 && (!w.had_output || st.st_dev != w.output_dev || st.st_ino != w.output_ino))
    ::unlink(output.c_str());
}

}  // namespace

void cook_in_workers(const std::vector<BatchItem>& items, const CookOptions& options, const BatchLimits& limits,
                     unsigned jobs, const std::function<void(size_t, CookRecord)>& finished) {
  const size_t max_running = std::max<size_t>(1, std::min<size_t>(jobs, items.size()));
  const pid_t self = ::getpid();
  // An inherited SIGCHLD = SIG_IGN would make the kernel reap workers itself, and waitpid fail.
  ::signal(SIGCHLD, SIG_DFL);
  std::vector<Worker> running;
  size_t next = 0;

  const auto failed_record = [&](size_t index, const std::string& why, double seconds) {
    CookRecord r;
    r.input = items[index].input.string();
    r.output = items[index].output.string();
    r.error = r.input + ": " + why;
    r.seconds = seconds;
    return r;
  };

  // Starts items[next]; false when no process could be made (errno set).
  const auto start = [&]() -> bool {
    const BatchItem& item = items[next];
    // An up-to-date output needs no worker: the check runs no importer (cook.h), and a process per
    // input was most of an all-up-to-date run's time. Inputs a test fault names still go to a worker.
    // So does a cache hit (cooker/cache/cook_cache.h); a miss's trouble is kept for the worker's record.
    Worker w;
    w.index = next;
    if (!options.force && test_fault(item.input.string()).empty()) {
      CookOptions item_options = options;
      if (item_options.root.empty()) item_options.root = item.tree;
      item_options.folder_rig = item.rig;
      if (std::optional<CookRecord> fresh = up_to_date_record(item.input, item.output, item_options, &w.cache_miss)) {
        finished(next, std::move(*fresh));
        ++next;
        return true;
      }
      w.looked_up = options.cache != nullptr;
      if (w.cache_miss.cache_down && options.cache != nullptr && !options.cache->down) {
        options.cache->down = true;  // this worker and those after it do not ask again
        options.cache->down_reason = w.cache_miss.cache_note;
      }
    }
    struct stat st {};
    if (::stat(item.output.c_str(), &st) == 0) {
      w.had_output = true;
      w.output_dev = st.st_dev;
      w.output_ino = st.st_ino;
    }
    int fds[2];
    if (::pipe2(fds, O_CLOEXEC) != 0) return false;
    // Whatever is buffered would otherwise be written again by the child if it flushed.
    std::fflush(stdout);
    std::fflush(stderr);
    w.started = Clock::now();
    const pid_t pid = ::fork();
    if (pid < 0) {
      const int saved = errno;
      ::close(fds[0]);
      ::close(fds[1]);
      errno = saved;
      return false;
    }
    if (pid == 0) {
      ::close(fds[0]);
      for (const Worker& other : running) ::close(other.fd);  // other workers' read ends (may be -1)
      if (w.looked_up) {
        CookOptions stores_only = options;
        stores_only.cache_looked_up = true;
        run_worker(item, stores_only, limits, fds[1], self);
      }
      run_worker(item, options, limits, fds[1], self);
    }
    ::close(fds[1]);
    w.pid = pid;
    w.fd = fds[0];
    running.push_back(std::move(w));
    ++next;
    return true;
  };

  const auto finish = [&](Worker& w, int status) {
    const BatchItem& item = items[w.index];
    const double seconds = std::chrono::duration<double>(Clock::now() - w.started).count();
    std::string why;
    std::optional<CookRecord> record;
    if (w.killed_for_time) {
      why = "exceeded the time limit (--timeout " + std::to_string(limits.timeout_seconds) + " s)";
    } else if (WIFSIGNALED(status)) {
      const int sig = WTERMSIG(status);
      const std::string name = signal_name(sig);
      why = "worker killed by signal " + std::to_string(sig) + (name.empty() ? "" : " (" + name + ")");
    } else if (WIFEXITED(status) && WEXITSTATUS(status) == kWorkerExitMemory &&
               std::string_view(reinterpret_cast<const char*>(w.received.data()), w.received.size()) ==
                   kWorkerMemoryMarker) {
      why = limits.max_memory_bytes > 0 && memory_limit_enforced()
                ? "exceeded the memory limit (--max-memory " + format_size(limits.max_memory_bytes) + ")"
                : "ran out of memory";
    } else if (WIFEXITED(status) && WEXITSTATUS(status) == 0) {
      const json parsed = json::from_cbor(w.received, /*strict=*/true, /*allow_exceptions=*/false);
      if (!parsed.is_discarded()) record = record_from_json(parsed);
      if (!record || record->input != item.input.string() || record->output != item.output.string()) {
        record.reset();
        why = "worker sent an unreadable record (" + std::to_string(w.received.size()) + " bytes)";
      }
    } else {
      why = "worker exited with status " + std::to_string(WIFEXITED(status) ? WEXITSTATUS(status) : -1) +
            " without a record";
    }
    if (!record) {
      remove_leftovers(item.output, w);
      record = failed_record(w.index, why, seconds);
    }
    if (record->cache_note.empty()) record->cache_note = w.cache_miss.cache_note;
    record->cache_down = record->cache_down || w.cache_miss.cache_down;
    record->cache_bytes_fetched += w.cache_miss.cache_bytes_fetched;
    finished(w.index, std::move(*record));
  };

  std::vector<pollfd> polled;
  while (next < items.size() || !running.empty()) {
    while (running.size() < max_running && next < items.size()) {
      if (start()) continue;
      if (!running.empty()) break;  // try again when a worker has finished
      const std::string why = std::string("cannot start a worker process: ") + std::strerror(errno);
      finished(next, failed_record(next, why, 0.0));
      ++next;
    }
    if (running.empty()) continue;

    // Wait for a record's bytes, a child's end, or the nearest deadline.
    polled.clear();
    int wait_ms = -1;
    const auto now = Clock::now();
    for (const Worker& w : running) {
      if (w.fd >= 0) polled.push_back({w.fd, POLLIN, 0});
      else wait_ms = 1;  // its pipe is closed but it has not exited yet: look again soon
      if (limits.timeout_seconds > 0 && !w.killed_for_time) {
        const auto left = w.started + std::chrono::seconds(limits.timeout_seconds) - now;
        const auto ms = std::max<int64_t>(0, std::chrono::ceil<std::chrono::milliseconds>(left).count());
        if (wait_ms < 0 || ms < wait_ms) wait_ms = static_cast<int>(std::min<int64_t>(ms, 1 << 30));
      }
    }
    if (::poll(polled.data(), polled.size(), wait_ms) < 0 && errno != EINTR) {
      std::fprintf(stderr, "ossa-cook: poll: %s\n", std::strerror(errno));
      std::abort();  // cannot happen with valid descriptors; nothing sensible to go on with
    }

    for (Worker& w : running) {
      if (w.fd < 0) continue;
      const auto it = std::find_if(polled.begin(), polled.end(), [&](const pollfd& p) { return p.fd == w.fd; });
      if (it == polled.end() || it->revents == 0) continue;
      uint8_t buffer[65536];
      const ssize_t n = ::read(w.fd, buffer, sizeof buffer);
      if (n > 0) {
        w.received.insert(w.received.end(), buffer, buffer + n);
      } else if (n == 0 || (errno != EINTR && errno != EAGAIN)) {
        ::close(w.fd);
        w.fd = -1;
      }
    }

    const auto after = Clock::now();
    for (Worker& w : running) {
      if (limits.timeout_seconds == 0 || w.killed_for_time) continue;
      if (after - w.started >= std::chrono::seconds(limits.timeout_seconds)) {
        ::kill(w.pid, SIGKILL);
        w.killed_for_time = true;
      }
    }

    // Reap the children whose pipes are closed; keep the others.
    for (size_t i = 0; i < running.size();) {
      Worker& w = running[i];
      int status = 0;
      pid_t reaped = 0;
      if (w.fd < 0) {
        do reaped = ::waitpid(w.pid, &status, WNOHANG);
        while (reaped < 0 && errno == EINTR);
        if (reaped < 0) {  // not our child any more (cannot happen with SIGCHLD at SIG_DFL): judge by the record
          reaped = w.pid;
          status = 0;
        }
      }
      if (reaped != w.pid) {
        ++i;
        continue;
      }
      Worker done = std::move(w);
      running.erase(running.begin() + static_cast<ptrdiff_t>(i));
      finish(done, status);
    }
  }
}

}  // namespace ossa::cook
