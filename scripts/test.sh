#!/usr/bin/env bash
# test.sh — install, build (warnings as errors), and run every test through CTest: the main suite,
# the bad-input suite again under AddressSanitizer + UBSan, and the loader fuzzer for a bounded time
# (when clang is present). The main suite runs last so its CTest summary is the closing line.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
jobs="$(nproc)"

echo "== sanitizer build: bad-input suite under ASan + UBSan"
cmake -S . -B build-asan -G Ninja -DOSSA_SANITIZE=ON -DOSSA_WERROR=ON -DOSSA_BUILD_BENCH=OFF >/dev/null
cmake --build build-asan -j "$jobs" --target bad_input_test
ctest --test-dir build-asan -L bad_input --output-on-failure -j "$jobs"

if command -v clang++ >/dev/null; then
  echo "== fuzz build: libFuzzer over the loader"
  CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DOSSA_FUZZ=ON -DOSSA_WERROR=ON -DOSSA_BUILD_BENCH=OFF >/dev/null
  cmake --build build-fuzz -j "$jobs" --target fuzz_load fuzz_make_corpus
  ctest --test-dir build-fuzz -R fuzz_load_bounded --output-on-failure
else
  echo "== fuzz build skipped: clang++ not found"
fi

echo "== main build and suite"
cmake -S . -B build -G Ninja -DOSSA_WERROR=ON >/dev/null
cmake --build build -j "$jobs"
ctest --test-dir build --output-on-failure -j "$jobs"
