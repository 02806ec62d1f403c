// main.cpp — ossa-inspect: print what a cooked .ossa file holds, as text or as JSON.
//
//   ossa-inspect FILE.ossa [--json]
//
// The tool is the runtime's loader plus describe.h: it opens the file exactly as a game would
// (mmap, verify, validate), so "ossa-inspect says it is fine" means "the runtime will load it".
// A file that fails prints the loader's message on stderr and exits 1. The JSON form is what the
// golden regression tests compare; it names the file without its directory so goldens do not
// depend on where a tree is checked out.
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>

#include <CLI/CLI.hpp>

#include "runtime/asset.h"
#include "runtime/inspect/describe.h"

int main(int argc, char** argv) {
  CLI::App app{"ossa-inspect: print what a cooked .ossa file holds (skeleton, meshes, clips, materials)"};
  std::string path;
  bool json = false;
  app.add_option("file", path, "the .ossa file to inspect")->required();
  app.add_flag("--json", json, "print JSON with a stable key order (what the golden tests compare)");
  CLI11_PARSE(app, argc, argv);

  auto asset = ossa::Asset::open(path);
  if (!asset) {
    std::fprintf(stderr, "ossa-inspect: %s\n", asset.error().message.c_str());
    return 1;
  }
  const std::string file_name = std::filesystem::path(path).filename().string();
  const auto description = ossa::inspect::describe(*asset, file_name);
  if (json) {
    // File text is not guaranteed to be UTF-8: replace bad bytes rather than throw.
    std::cout << description.dump(2, ' ', false, nlohmann::ordered_json::error_handler_t::replace) << '\n';
  } else {
    std::cout << ossa::inspect::describe_text(description);
  }
  std::cout.flush();
  return std::cout.good() ? 0 : 1;
}
