// main.cpp — ossa-view: parse the command line, then run headless or in a window.
#include "viewer/headless.h"
#include "viewer/interactive.h"
#include "viewer/options.h"

int main(int argc, char** argv) {
  const ossa::view::ParsedOptions parsed = ossa::view::parse_options(argc, argv);
  if (!parsed.options) return parsed.exit_code;
  const ossa::view::ViewerOptions& o = *parsed.options;
  return o.headless() ? ossa::view::run_headless(o) : ossa::view::run_interactive(o);
}
