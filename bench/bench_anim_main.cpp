// bench_anim_main.cpp — the main of ossa-bench-anim and ossa-bench-cloth: Google Benchmark's,
// after --clone (machine.h).
//
// The machine line goes into Google Benchmark's context (printed in its header, console or JSON)
// after --clone is applied, so it names the copy that actually ran.
#include <cstdio>
#include <string>

#include <benchmark/benchmark.h>

#include "bench/machine.h"

int main(int argc, char** argv) {
  std::string error;
  if (!ossa::bench::apply_clone(argc, argv, &error)) {
    std::fprintf(stderr, "%s: %s\n", argc > 0 ? argv[0] : "ossa-bench", error.c_str());
    return 2;
  }
  benchmark::AddCustomContext("machine", ossa::bench::machine_line());
  benchmark::Initialize(&argc, argv);
  if (benchmark::ReportUnrecognizedArguments(argc, argv)) return 1;
  benchmark::RunSpecifiedBenchmarks();
  benchmark::Shutdown();
  return 0;
}
