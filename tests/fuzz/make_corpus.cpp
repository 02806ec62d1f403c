// make_corpus.cpp — writes the seed corpus for fuzz_load: one file per valid synthetic variant
// (tests/support/test_files.h: valid_variants), named <variant>.ossa, into the directory given.
//
// A C++ generator rather than a script because the seeds are built with the same FlatBufferBuilder
// code as the tests' synthetic file; a checked-in binary corpus would silently go stale when the
// schema moves. Valid, varied seeds let the fuzzer start deep inside the format (past the
// identifier, version and verifier) instead of rediscovering its structure byte by byte.
//
// Usage: fuzz_make_corpus DIR   (ctest runs it as the fuzz_seed_corpus fixture)
#include <cstdio>
#include <filesystem>
#include <system_error>

#include "tests/support/test_files.h"

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: %s DIR\n", argv[0]);
    return 2;
  }
  const std::filesystem::path dir = argv[1];
  std::error_code error;
  std::filesystem::create_directories(dir, error);
  if (error) {
    std::fprintf(stderr, "%s: %s\n", dir.c_str(), error.message().c_str());
    return 1;
  }
  for (const auto& [name, spec] : ossa::test::valid_variants()) {
    const std::filesystem::path path = dir / (name + ".ossa");
    if (!ossa::test::write_file(path, ossa::test::make_valid_file(spec))) {
      std::fprintf(stderr, "%s: cannot write\n", path.c_str());
      return 1;
    }
    std::printf("%s\n", path.c_str());
  }
  return 0;
}
