// cli.h — what every ossa command-line tool shares: the exit statuses, --version, -q / -v, and
// how a usage error is reported (CLI11's message, "did you mean" for a mistyped option, a hint to
// run --help).
//
// Why one helper: ossa-cook, ossa-inspect and ossa-view (and ossa-diff) are driven by scripts and
// build systems, which rely on the same flag meaning the same thing and on exit statuses they can
// branch on. CLI11 on its own exits with 105-109 (and others) for parse errors and prints them in
// its own words; each tool wrapping that by hand drifted. Here CLI11's ParseError is caught once
// and every usage error becomes status 2.
//
// Exit statuses (documented in each tool's --help footer and in docs/CLI.md):
//   0  success
//   1  the tool ran and its job failed, in the tool's own sense (an input did not cook, the file
//      is not a valid .ossa, the scene could not be shown, the files differ)
//   2  usage error, or the tool cannot run at all (nothing was done)
//
// The library links CLI11 only (no Assimp, no GL, no FlatBuffers), so any tool can take it. The
// version comes from the generated <ossa/version.h> (the CMake project version) in cli.cpp's
// version_line and nowhere else.
#pragma once
#include <optional>
#include <string>
#include <string_view>
#include <vector>

#include <CLI/CLI.hpp>

#include "common/edit_distance.h"

namespace ossa::cli {

inline constexpr int kExitOk = 0;
inline constexpr int kExitFailed = 1;
inline constexpr int kExitUsage = 2;

enum class Verbosity { quiet, normal, verbose };

/// "<tool> 0.6.1 (format 14)": what --version prints.
std::string version_line(std::string_view tool);

/// Levenshtein distance (insertions, deletions, substitutions each cost 1; common/edit_distance.h).
using ossa::edit_distance;

/// The name in `known` closest to `unknown` by edit distance, or "" when even the closest needs
/// more than max(2, |unknown| / 3) edits (a guess that far off would mislead). Ties go to the
/// first in `known`. Text after '=' in `unknown` (`--skeletn=x`) is ignored.
std::string closest_name(std::string_view unknown, const std::vector<std::string>& known);

/// A tool's command line: a CLI::App with --help, --version, -q/--quiet and -v/--verbose already
/// added, and a footer stating the exit statuses. The tool adds its own options through app().
class Command {
 public:
  /// `failure_meaning` completes "1 when ..." in the --help footer.
  Command(std::string tool, const std::string& description, const std::string& failure_meaning);
  Command(const Command&) = delete;
  Command& operator=(const Command&) = delete;

  CLI::App& app() { return app_; }
  const std::string& tool() const { return tool_; }

  /// Parses argv. nullopt: go on and run. Otherwise the status to exit with now: 0 after --help or
  /// --version (printed on stdout), 2 after a usage error (printed on stderr: CLI11's message, a
  /// "did you mean" line for each unknown option with a close match, and a hint to run --help).
  std::optional<int> parse(int argc, const char* const* argv);

  Verbosity verbosity() const;
  bool quiet() const { return quiet_; }
  bool verbose() const { return verbose_; }

  /// For a usage error found after parsing (a value CLI11 cannot check): prints
  /// "<tool>: <message>" and the --help hint on stderr; returns kExitUsage.
  int usage_error(const std::string& message) const;

  /// Every option name the tool accepts ("--skeleton", "-o", "--help" ...), for did-you-mean.
  std::vector<std::string> option_names() const;

 private:
  std::string tool_;
  CLI::App app_;
  bool quiet_ = false;
  bool verbose_ = false;
};

}  // namespace ossa::cli
