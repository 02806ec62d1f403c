// cli.cpp — see cli.h. CLI11's exceptions are caught here and never leave parse().
#include "tools/cli/cli.h"

#include <algorithm>
#include <cstdio>
#include <iostream>

#include <ossa/version.h>

namespace ossa::cli {

std::string version_line(std::string_view tool) {
  // The one use of the version number (cli.h says why).
  return std::string(tool) + " " + OSSA_VERSION_STRING + " (format " + std::to_string(kFormatVersion) + ")";
}

std::string closest_name(std::string_view unknown, const std::vector<std::string>& known) {
  unknown = unknown.substr(0, unknown.find('='));
  std::string best;
  size_t best_distance = std::max<size_t>(2, unknown.size() / 3) + 1;
  for (const std::string& name : known) {
    const size_t d = edit_distance(unknown, name);
    if (d < best_distance) {
      best_distance = d;
      best = name;
    }
  }
  return best;
}

Command::Command(std::string tool, const std::string& description, const std::string& failure_meaning)
    : tool_(std::move(tool)), app_(description, tool_) {
  app_.set_version_flag("--version", version_line(tool_), "print \"" + tool_ + " VERSION (format N)\" and exit");
  CLI::Option* quiet = app_.add_flag("-q,--quiet", quiet_, "print only errors");
  app_.add_flag("-v,--verbose", verbose_, "print more detail")->excludes(quiet);
  app_.footer("Exit status: 0 success; 1 " + failure_meaning + "; 2 usage error or cannot run.");
}

std::vector<std::string> Command::option_names() const {
  std::vector<std::string> names;
  for (const CLI::Option* o : app_.get_options()) {
    for (const std::string& l : o->get_lnames()) names.push_back("--" + l);
    for (const std::string& s : o->get_snames()) names.push_back("-" + s);
  }
  return names;
}

std::optional<int> Command::parse(int argc, const char* const* argv) {
  try {
    app_.parse(argc, argv);
    return std::nullopt;
  } catch (const CLI::Success& e) {
    // --help or --version: CLI11 prints them on stdout.
    app_.exit(e);
    return kExitOk;
  } catch (const CLI::ParseError& e) {
    std::fprintf(stderr, "%s: %s\n", tool_.c_str(), e.what());
    // Options CLI11 did not recognise are left over, whichever error it stopped at (a mistyped
    // --output also makes "--output is required"); each gets its closest match.
    const std::vector<std::string> known = option_names();
    for (const std::string& arg : app_.remaining()) {
      if (arg.size() < 2 || arg[0] != '-') continue;
      const std::string guess = closest_name(arg, known);
      if (!guess.empty())
        std::fprintf(stderr, "%s: unknown option %s: did you mean %s?\n", tool_.c_str(),
                     arg.substr(0, arg.find('=')).c_str(), guess.c_str());
    }
    std::fprintf(stderr, "run '%s --help' for the options\n", tool_.c_str());
    return kExitUsage;
  }
}

Verbosity Command::verbosity() const {
  return quiet_ ? Verbosity::quiet : verbose_ ? Verbosity::verbose : Verbosity::normal;
}

int Command::usage_error(const std::string& message) const {
  std::fprintf(stderr, "%s: %s\nrun '%s --help' for the options\n", tool_.c_str(), message.c_str(), tool_.c_str());
  return kExitUsage;
}

}  // namespace ossa::cli
