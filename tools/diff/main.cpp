// main.cpp — ossa-diff: compare two cooks of the same asset by what a player would see.
//
//   ossa-diff OLD.ossa NEW.ossa [--tolerance-mm MM] [--json] [-q] [-v] [--skeleton REF.ossa]
//
// Exit status is the interface a CI job uses, so it is kept to three values whatever happens:
// 0 the cooks are the same within the tolerance, 1 they differ (every difference named on stdout),
// 2 they cannot be compared (a file the loader refuses, with its message naming the file, on
// stderr) or the command line is wrong. The shared command line (tools/cli/cli.h) gives
// --help, --version, -q / -v, the mapping of every CLI11 parse error to 2 and "did you mean".
// -q prints nothing on stdout (an error that makes comparing impossible still goes to stderr, as
// cmp -s does).
#include <cstdio>
#include <iostream>
#include <string>

#include "tools/cli/cli.h"
#include "tools/diff/diff.h"
#include "tools/diff/report.h"

int main(int argc, char** argv) {
  using ossa::cli::kExitFailed, ossa::cli::kExitOk, ossa::cli::kExitUsage;
  ossa::cli::Command command("ossa-diff",
                             "ossa-diff: compare two cooked .ossa files by what a player would see (skeleton, "
                             "meshes, clips, materials, graphs)",
                             "when the files differ beyond the tolerance (each difference on stdout)");
  CLI::App& app = command.app();
  std::string old_path, new_path, skeleton, old_skeleton, new_skeleton;
  ossa::diff::Options options;
  bool json = false;
  app.add_option("old", old_path, "the previous cook (.ossa)")->required();
  app.add_option("new", new_path, "the new cook of the same asset (.ossa)")->required();
  app.add_option("--tolerance-mm", options.tolerance_mm,
                 "a joint, vertex or clip differs when its error exceeds this many millimetres (default 0.1)")
      ->check(CLI::NonNegativeNumber);
  app.add_option("--skeleton", skeleton, "cooked rig for clip-only files on both sides (ossa-cook --skeleton)");
  app.add_option("--old-skeleton", old_skeleton, "cooked rig for a clip-only OLD file (overrides --skeleton)");
  app.add_option("--new-skeleton", new_skeleton, "cooked rig for a clip-only NEW file (overrides --skeleton)");
  app.add_flag("--json", json, "print the report as JSON (docs/schemas/ossa-diff.schema.json)");
  if (const auto exit_now = command.parse(argc, argv)) return *exit_now;
  options.old_skeleton = old_skeleton.empty() ? skeleton : old_skeleton;
  options.new_skeleton = new_skeleton.empty() ? skeleton : new_skeleton;

  const auto report = ossa::diff::diff_files(old_path, new_path, options);
  if (!report) {
    std::fprintf(stderr, "ossa-diff: %s\n", report.error().message.c_str());
    return kExitUsage;
  }
  if (!command.quiet()) {
    if (json) {
      // File text is not guaranteed to be UTF-8: replace bad bytes rather than throw.
      std::cout << ossa::diff::to_json(*report).dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace)
                << '\n';
    } else {
      std::cout << ossa::diff::to_text(*report, command.verbose());
    }
    std::cout.flush();
    if (!std::cout.good()) return kExitUsage;
  }
  return report->same() ? kExitOk : kExitFailed;
}
