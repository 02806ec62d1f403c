// cook_job.h — what the window does that takes longer than a frame: cooking a dropped source
// file (FBX, glTF, ...) in the background, and opening files behind the loading indicator.
//
// The viewer does not link the cooker: it runs the `ossa-cook` executable as a child process, the
// same program a build runs, so a cook from the viewer is a cook like any other (its settings
// files, its read sandbox, its worker isolation around Assimp, its up-to-date check) and the
// viewer keeps only the runtime's dependencies. The child is started and waited for on a thread
// of its own, so the window keeps drawing (a spinner, the elapsed time) while it runs; the main
// loop polls CookJob::finished() once a frame and takes the result.
//
// Where things go: the cooker is $OSSA_COOK when set, else looked for next to the running
// ossa-view (/proc/self/exe's folder: the build's bin/ and an install's bin/ hold both), then on
// PATH. The cook runs with the cooker's own limits (its --timeout default, settings files). Outputs go to a cache
// folder, $XDG_CACHE_HOME/ossa-view (else ~/.cache/ossa-view), one sub-folder per source path
// (a hash of it), so two sources of one name never share an output and a second cook of an
// unchanged source is answered by the cooker's own cook-key check without cooking again.
//
// Opens are synchronous (load_scene maps and verifies, upload_scene fills buffers), so a large
// file stalls a frame or more. To show that something is happening, an open is a request first
// (PendingWork): the frame that takes it draws "loading NAME...", and the open runs at the start
// of the next frame, after that frame was presented. Sources are cooked one at a time in the order
// asked; each finished cook becomes an open request for its output, and a failed one puts the
// cooker's message in the panel's status. interactive.cpp calls step_pending_work once a frame,
// before building the UI, and note_indicator_drawn after presenting. One file for both because
// the queue is the cook's only user and the indicator reports both.
//
// POSIX only (posix_spawn, pipes): the viewer is not built for Windows (the MinGW check builds the
// runtime alone); on other systems start() reports that cooking from the viewer is unsupported.
#pragma once
#include <atomic>
#include <chrono>
#include <deque>
#include <filesystem>
#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include <ossa/format/result.h>
#include "viewer/app.h"

namespace ossa::view {

/// True for the source formats ossa-cook accepts (.fbx .gltf .glb .dae .bvh .obj), any case.
bool is_cook_source(const std::filesystem::path& path);

/// The ossa-cook to run: `exe_dir`/ossa-cook when it is an executable file, else the first
/// executable ossa-cook on `path_env` (a PATH value, ':'-separated), else nullopt.
std::optional<std::filesystem::path> find_cooker(const std::filesystem::path& exe_dir, const std::string& path_env);

/// The folder holding the running executable (/proc/self/exe), or empty when unknown.
std::filesystem::path executable_dir();

/// The cook cache root: `xdg_cache_home`/ossa-view when that is an absolute path, else
/// `home`/.cache/ossa-view, else the system temporary folder's ossa-view-cache. Either argument
/// may be null (the environment variable is unset).
std::filesystem::path cook_cache_root(const char* xdg_cache_home, const char* home);

/// Where `source` cooks to under `cache_root`: a sub-folder named by a hash of the source's
/// absolute path, and in it the cooker's output name (the source's stem + ".ossa").
std::filesystem::path cook_output_for(const std::filesystem::path& cache_root, const std::filesystem::path& source);

struct CookResult {
  bool ok = false;
  std::filesystem::path output;  // the cooked file (ok)
  std::string error;             // what the cooker printed on stderr, or why it could not run
  double seconds = 0.0;
};

/// One background cook at a time. Not copyable; the destructor stops a running child (SIGTERM)
/// and joins the thread.
class CookJob {
 public:
  CookJob() = default;
  CookJob(const CookJob&) = delete;
  CookJob& operator=(const CookJob&) = delete;
  ~CookJob();

  /// Starts cooking `source` with `cooker` into `output`'s folder (created). False, with
  /// `error` set, when a cook is already running, or the folder cannot be made.
  bool start(const std::filesystem::path& cooker, const std::filesystem::path& source,
             const std::filesystem::path& output, std::string& error);
  bool running() const { return started_ && !done_.load(); }
  /// True once when a started cook has ended; then result() holds what happened.
  bool finished();
  const CookResult& result() const { return result_; }
  const std::filesystem::path& source() const { return source_; }
  double elapsed_seconds() const;

 private:
  void run(std::filesystem::path cooker, std::filesystem::path output);
  std::thread thread_;
  std::atomic<bool> done_{false};
  std::atomic<int> child_{-1};
  bool started_ = false;
  std::filesystem::path source_;
  std::chrono::steady_clock::time_point start_time_{};
  CookResult result_;  // written by the thread before done_, read after
};

// ---- opens and cooks in progress

struct PendingWork {
  std::vector<std::string> open;  // .ossa files to open next (open_or_add)
  bool open_announced = false;    // a frame saying "loading" was presented
  std::deque<std::filesystem::path> cook_queue;
  CookJob cook;
  std::filesystem::path cooker;      // empty: not found yet (looked for on the first cook)
  std::filesystem::path cache_root;  // cook_cache_root from the environment
  int frames_while_cooking = 0;      // frames drawn while the current cook ran (-v reports it)
  int progress_logged = 0;           // whole seconds of the current cook already reported in `log`
  std::vector<std::string> log;      // lines for -v: what was cooked / opened, and how long it took
};

/// Splits `paths` into sources to cook (is_cook_source) and files to open, and queues them.
/// Sources are cooked first; the files to open are opened together (a character and its clips).
void request_paths(PendingWork& work, const std::vector<std::string>& paths);

/// True while an open or a cook is waiting or running.
bool busy(const PendingWork& work);

/// One frame's step: opens the requested files once the loading indicator has been presented
/// (the result into `status`: empty on success, the error otherwise), starts the next queued
/// cook, and turns a finished cook into an open request (or its error into `status`).
void step_pending_work(PendingWork& work, App& app, float aspect, std::string& status);

/// Call after presenting a frame that showed the indicator.
void note_indicator_drawn(PendingWork& work);

/// What the loading indicator says now ("loading Fox.ossa", "cooking Fox.glb  1.2 s"), or
/// nullopt when nothing is pending.
std::optional<std::string> indicator_text(const PendingWork& work);

}  // namespace ossa::view
