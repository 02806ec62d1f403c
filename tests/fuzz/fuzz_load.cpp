// fuzz_load.cpp — libFuzzer target over the loader: any bytes in, never a crash or UB out.
//
// Each input goes through both entry points (verify_buffer over a 16-byte aligned copy, which is
// what its contract asks for, and Asset::from_bytes); they must agree. An accepted input is then
// walked by tests/support/asset_walk.h, which reads every byte the views expose and re-checks the
// invariants of ossa/loader/validate.h, so the fuzzer finds not only out-of-bounds reads (ASan) and
// UB (UBSan) but also files the validator wrongly lets through (abort with the broken promise).
//
// Build: CC=clang CXX=clang++ cmake -DOSSA_FUZZ=ON ...; seeds: tests/fuzz/make_corpus.cpp.
// Run:   build-fuzz/bin/fuzz_load -max_total_time=60 CORPUS_DIR SEED_DIR  (ctest -R fuzz_load_bounded)
#include <cstdint>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <span>
#include <string>

#include <ossa/loader/asset.h>
#include "tests/support/asset_walk.h"

namespace {

[[noreturn]] void die(const char* what, const std::string& detail) {
  std::fprintf(stderr, "fuzz_load: %s: %s\n", what, detail.c_str());
  std::abort();
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  // Exactly `size` bytes (posix_memalign takes any size), so ASan flags a read one past the end.
  void* copy = nullptr;
  if (posix_memalign(&copy, 16, size == 0 ? 1 : size) != 0) return 0;
  if (size != 0) std::memcpy(copy, data, size);
  const std::span<const uint8_t> bytes(static_cast<const uint8_t*>(copy), size);

  const ossa::Status verified = ossa::verify_buffer(bytes, "fuzz.ossa");
  ossa::Result<ossa::Asset> loaded = ossa::Asset::from_bytes(bytes, "fuzz.ossa");
  if (verified.ok() != loaded.ok())
    die("verify_buffer and Asset::from_bytes disagree", verified.ok() ? loaded.error().message : verified.message());

  if (!loaded.ok()) {
    if (loaded.error().message.find("fuzz.ossa") == std::string::npos)
      die("error message does not name the input", loaded.error().message);
  } else {
    const ossa::Asset asset = std::move(*loaded);  // views must survive a move
    uint64_t checksum = 0;
    const std::string problem = ossa::test::walk_asset(asset, &checksum);
    if (!problem.empty()) die("accepted a file that breaks a promise", problem);
    volatile uint64_t sink = checksum;
    (void)sink;
  }
  std::free(copy);
  return 0;
}
