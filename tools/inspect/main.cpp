// main.cpp — ossa-inspect: print what a cooked .ossa file holds, as text or as JSON.
//
//   ossa-inspect FILE.ossa... [--json | --humanoid [--map MAP.json]] [-q | -v] [--version] [--help]
//
// The tool is the runtime's loader plus describe.h: it opens the file exactly as a game would
// (mmap, verify, validate), so "ossa-inspect says it is fine" means "the runtime will load it";
// -q prints nothing and answers that question with the exit status alone. -v adds every clip
// channel (joint, kind, constant or animated, keys, bits). The JSON form is what the golden
// regression tests compare and is described in docs/schemas/ossa-inspect.schema.json; it names the
// file without its directory so goldens do not depend on where a tree is checked out. --humanoid
// prints the rig's humanoid mapping for retargeting instead (describe_humanoid.h).
//
// Several files are described in turn (text: one after another, a blank line between; JSON: an
// array of the descriptions, the one object alone for a single file, so scripts and goldens that
// pass one file see what they always saw). A file that fails does not stop the others.
//
// Exit status (tools/cli/cli.h), the worst over the files: 0 every file loads; 1 one is not a
// valid .ossa file (the loader's message, naming the file, on stderr); 2 usage error, or a file
// cannot be read at all.
#include <algorithm>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <optional>
#include <string>
#include <vector>

#include <ossa/loader/asset.h>
#include "tools/cli/cli.h"
#include "tools/inspect/describe.h"
#include "tools/inspect/describe_humanoid.h"

#include <fstream>
#include <sstream>

int main(int argc, char** argv) {
  ossa::cli::Command command(
      "ossa-inspect", "ossa-inspect: print what cooked .ossa files hold (skeleton, meshes, clips, materials, graphs)",
      "when the file is not a valid .ossa file");
  std::vector<std::string> paths;
  bool json = false;
  command.app().add_option("files", paths, "the .ossa files to inspect")->required();
  command.app().add_flag("--json", json,
                         "print JSON with a stable key order (docs/JSON.md; what the golden tests compare)");
  bool humanoid = false;
  std::string map_path;
  command.app().add_flag(
      "--humanoid", humanoid,
      "print the rig's humanoid mapping for retargeting (which joint plays which bone, what is missing, "
      "its retarget pose; docs/RETARGET.md) instead of the summary");
  command.app().add_option("--map", map_path, "with --humanoid: a humanoid map file to apply (docs/RETARGET.md)");
  if (const auto exit_now = command.parse(argc, argv)) return *exit_now;
  if (humanoid && json) return command.usage_error("--humanoid prints text; it does not combine with --json");
  if (!map_path.empty() && !humanoid) return command.usage_error("--map is read with --humanoid");

  std::optional<ossa::tools::HumanoidMapFile> map;
  if (!map_path.empty()) {
    std::ifstream in(map_path, std::ios::binary);
    std::stringstream text;
    text << in.rdbuf();
    if (!in) {
      std::fprintf(stderr, "ossa-inspect: --map %s: cannot be read\n", map_path.c_str());
      return ossa::cli::kExitUsage;
    }
    auto parsed = ossa::tools::parse_humanoid_map_file(text.str(), map_path);
    if (!parsed) {
      std::fprintf(stderr, "ossa-inspect: --map %s\n", parsed.error().message.c_str());
      return ossa::cli::kExitUsage;
    }
    map = std::move(*parsed);
  }

  int status = ossa::cli::kExitOk;
  nlohmann::ordered_json all = nlohmann::ordered_json::array();
  bool printed = false;
  for (const std::string& path : paths) {
    // A file that is not there or not a regular file is a usage problem, not an invalid .ossa.
    std::error_code ec;
    if (!std::filesystem::is_regular_file(path, ec)) {
      std::fprintf(stderr, "ossa-inspect: %s: %s\n", path.c_str(),
                   std::filesystem::exists(path, ec) ? "not a regular file" : "no such file");
      status = std::max(status, ossa::cli::kExitUsage);
      continue;
    }
    auto asset = ossa::Asset::open(path);
    if (!asset) {
      std::fprintf(stderr, "ossa-inspect: %s\n", asset.error().message.c_str());
      status = std::max(status, ossa::cli::kExitFailed);
      continue;
    }
    if (command.quiet()) continue;
    if (humanoid) {
      auto text = ossa::inspect::describe_humanoid(*asset, map ? &*map : nullptr, map_path);
      if (!text) {
        std::fprintf(stderr, "ossa-inspect: %s\n", text.error().message.c_str());
        status = std::max(status, ossa::cli::kExitFailed);
        continue;
      }
      std::cout << (printed ? "\n" : "") << *text;
      printed = true;
      continue;
    }
    const std::string file_name = std::filesystem::path(path).filename().string();
    ossa::inspect::DescribeOptions options;
    options.channels = command.verbose();
    options.influences = command.verbose();
    auto description = ossa::inspect::describe(*asset, file_name, options);
    if (json) {
      all.push_back(std::move(description));
    } else {
      std::cout << (printed ? "\n" : "") << ossa::inspect::describe_text(description);
      printed = true;
    }
  }
  if (json && !command.quiet() && !all.empty()) {
    // File text is not guaranteed to be UTF-8: replace bad bytes rather than throw.
    const nlohmann::ordered_json& out = paths.size() == 1 ? all.front() : all;
    std::cout << out.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) << '\n';
  }
  std::cout.flush();
  if (!std::cout.good()) {
    std::fprintf(stderr, "ossa-inspect: cannot write to stdout\n");
    return ossa::cli::kExitUsage;
  }
  return status;
}
