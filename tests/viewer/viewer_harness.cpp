// viewer_harness.cpp — see viewer_harness.h.
#include "viewer_harness.h"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <array>
#include <cerrno>
#include <cstdlib>
#include <map>
#include <poll.h>

#include <stb_image.h>

extern char** environ;

#ifndef OSSA_TEST_VIEWER_COOKED_DIR
#define OSSA_TEST_VIEWER_COOKED_DIR "viewer-cooked"
#endif

namespace ossa::test {
namespace {

/// Our Xvfb, stopped when the test process exits.
struct XServer {
  pid_t pid = -1;
  std::string display;
  std::string error;
  ~XServer() {
    if (pid > 0) {
      kill(pid, SIGTERM);
      int status = 0;
      waitpid(pid, &status, 0);
    }
  }
};

bool on_path(const std::string& program) {
  const char* path = std::getenv("PATH");
  std::string p = path ? path : "/usr/bin:/bin";
  size_t start = 0;
  while (start <= p.size()) {
    const size_t end = std::min(p.find(':', start), p.size());
    const std::filesystem::path candidate = std::filesystem::path(p.substr(start, end - start)) / program;
    if (access(candidate.c_str(), X_OK) == 0) return true;
    start = end + 1;
  }
  return false;
}

/// Starts `Xvfb -displayfd` and reads the display number it chose (5 s at most).
void start_xvfb(XServer& x) {
  int fds[2];
  if (pipe(fds) != 0) {
    x.error = "pipe() failed";
    return;
  }
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, "/dev/null", O_WRONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, "/dev/null", O_WRONLY, 0);
  // Close the read end before the dup2: pipe() may have returned it as fd 3 itself.
  posix_spawn_file_actions_addclose(&actions, fds[0]);
  posix_spawn_file_actions_adddup2(&actions, fds[1], 3);
  const char* argv[] = {"Xvfb",         "-displayfd", "3",   "-screen",  "0",
                        "1920x1200x24", "-nolisten",  "tcp", "-noreset", nullptr};
  const int rc = posix_spawnp(&x.pid, "Xvfb", &actions, nullptr, const_cast<char**>(argv), environ);
  posix_spawn_file_actions_destroy(&actions);
  close(fds[1]);
  if (rc != 0) {
    x.pid = -1;
    x.error = "cannot start Xvfb";
    close(fds[0]);
    return;
  }
  std::string number;
  pollfd p{fds[0], POLLIN, 0};
  while (poll(&p, 1, 5000) > 0) {
    char c = 0;
    if (read(fds[0], &c, 1) != 1 || c == '\n') break;
    number += c;
  }
  close(fds[0]);
  if (number.empty()) x.error = "Xvfb did not report a display within 5 s";
  else x.display = ":" + number;
}

}  // namespace

std::filesystem::path viewer_cooked_dir() { return env_or("OSSA_VIEWER_COOKED", OSSA_TEST_VIEWER_COOKED_DIR); }

std::optional<std::string> test_display(std::string* why) {
  static XServer server;
  static bool tried = false;
  if (!tried) {
    tried = true;
    if (on_path("Xvfb")) start_xvfb(server);
    else server.error = "Xvfb is not installed (scripts/install-deps.sh installs it)";
  }
  if (!server.display.empty()) return server.display;
  if (const char* d = std::getenv("DISPLAY"); d != nullptr && *d != '\0') return std::string(d);
  if (why) *why = server.error + ", and DISPLAY is not set";
  return std::nullopt;
}

std::string quote(const std::string& s) {
  std::string out = "'";
  for (char c : s) out += c == '\'' ? std::string("'\\''") : std::string(1, c);
  return out + "'";
}

CommandResult run_viewer(const std::string& args) {
  std::string why;
  const auto display = test_display(&why);
  if (!display) return {-1, "", "no display: " + why};
  // Bounded, so a viewer that hangs (waiting on a FIFO, say) fails its test with exit 124 instead
  // of stalling the suite until CTest's own timeout.
  return run_command("DISPLAY=" + quote(*display) + " timeout --kill-after=10 600 " +
                     quote((bin_dir() / "ossa-view").string()) + " " + args);
}

Image load_png(const std::filesystem::path& path) {
  Image image;
  int channels = 0;
  stbi_uc* p = stbi_load(path.c_str(), &image.width, &image.height, &channels, 3);
  if (p == nullptr) return Image{};
  image.rgb.assign(p, p + static_cast<size_t>(image.width) * image.height * 3);
  stbi_image_free(p);
  return image;
}

double coverage(const Image& image) {
  if (image.empty()) return 0.0;
  const std::array<const uint8_t*, 4> corners = {image.at(0, 0), image.at(image.width - 1, 0),
                                                 image.at(0, image.height - 1),
                                                 image.at(image.width - 1, image.height - 1)};
  std::map<std::array<uint8_t, 3>, int> votes;
  for (const uint8_t* c : corners) ++votes[{c[0], c[1], c[2]}];
  const auto background =
      std::max_element(votes.begin(), votes.end(), [](auto& a, auto& b) { return a.second < b.second; })->first;
  size_t covered = 0;
  for (size_t i = 0; i < image.rgb.size(); i += 3) {
    int d = 0;
    for (int c = 0; c < 3; ++c)
      d = std::max(d, std::abs(int(image.rgb[i + c]) - int(background[static_cast<size_t>(c)])));
    covered += d > 6 ? 1 : 0;
  }
  return static_cast<double>(covered) / (static_cast<double>(image.rgb.size()) / 3.0);
}

ImageDiff compare(const Image& a, const Image& b, int threshold) {
  ImageDiff d;
  if (a.width != b.width || a.height != b.height || a.empty()) {
    d.mean_abs = 255.0;
    d.differing = 1.0;
    d.max_channel = 255;
    return d;
  }
  double sum = 0.0;
  size_t differing = 0;
  for (size_t i = 0; i < a.rgb.size(); i += 3) {
    int worst = 0;
    for (size_t c = 0; c < 3; ++c) {
      const int diff = std::abs(int(a.rgb[i + c]) - int(b.rgb[i + c]));
      sum += diff;
      worst = std::max(worst, diff);
    }
    d.max_channel = std::max(d.max_channel, worst);
    differing += worst > threshold ? 1 : 0;
  }
  d.mean_abs = sum / static_cast<double>(a.rgb.size());
  d.differing = static_cast<double>(differing) / (static_cast<double>(a.rgb.size()) / 3.0);
  return d;
}

}  // namespace ossa::test
