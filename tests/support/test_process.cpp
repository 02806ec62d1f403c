// test_process.cpp — run_command (test_files.h): a shell command with its output captured.
//
// Kept out of test_files.cpp because it is POSIX process code (posix_spawn, waitpid) that only the
// suites driving command-line tools need; the runtime suites, which also build for Windows
// (MinGW-w64, run under Wine), link test_files.cpp without it. On Windows run_command reports that
// it could not start anything (exit_code -1): no Windows suite runs tools.
#include "test_files.h"

#if defined(_WIN32)

namespace ossa::test {

CommandResult run_command(const std::string& command) {
  CommandResult result;
  result.err = "run_command is not available on Windows: " + command;
  return result;
}

}  // namespace ossa::test

#else

#include <fcntl.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <cerrno>
#include <system_error>

extern char** environ;

namespace ossa::test {

CommandResult run_command(const std::string& command) {
  CommandResult result;
  const std::filesystem::path dir = make_temp_dir("cmd");
  if (dir.empty()) return result;
  const std::string out_path = (dir / "stdout").string(), err_path = (dir / "stderr").string();

  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, STDIN_FILENO, "/dev/null", O_RDONLY, 0);
  posix_spawn_file_actions_addopen(&actions, STDOUT_FILENO, out_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&actions, STDERR_FILENO, err_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  std::string sh = "/bin/sh", dash_c = "-c", cmd = command;
  char* argv[] = {sh.data(), dash_c.data(), cmd.data(), nullptr};
  pid_t pid = 0;
  const int spawned = posix_spawn(&pid, "/bin/sh", &actions, nullptr, argv, environ);
  posix_spawn_file_actions_destroy(&actions);
  if (spawned == 0) {
    int status = 0;
    while (waitpid(pid, &status, 0) < 0 && errno == EINTR) {
    }
    result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : WIFSIGNALED(status) ? 128 + WTERMSIG(status) : -1;
  }
  result.out = read_text(out_path).value_or("");
  result.err = read_text(err_path).value_or("");
  std::error_code ignored;
  std::filesystem::remove_all(dir, ignored);
  return result;
}

}  // namespace ossa::test

#endif
