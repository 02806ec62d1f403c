#!/usr/bin/env bash
# test.sh — install, build (warnings as errors), and run every test through CTest: the main suite,
# the bad-input suite again under AddressSanitizer + UBSan, and the loader fuzzer for a bounded time
# (when clang is present), the runtime alone with only FlatBuffers and GLM, the runtime and its suites
# cross-built for Windows and run under Wine, and the main suite (which includes the install +
# out-of-tree consumer test). The main build comes first and its suite last.
#
# Time: every stage prints how long it took, and a table of all of them closes the run. Every
# build goes through ccache (installed by install-deps.sh) with CCACHE_BASEDIR set to this clone,
# so the five builds share what they compile alike (the runtime-only build reuses the main
# build's runtime objects) and a later run, from any clone on this machine, recompiles only what
# changed.
set -euo pipefail
cd "$(dirname "$0")/.."
started=$SECONDS
stage_name="" stage_start=$SECONDS
timings=()
end_stage() {
  if [ -n "$stage_name" ]; then
    local took=$((SECONDS - stage_start))
    timings+=("$(printf '%5d s  %s' "$took" "$stage_name")")
    echo "== $stage_name: $took s"
  fi
  stage_name=""
}
stage() {
  end_stage
  stage_name=$1 stage_start=$SECONDS
  echo "== $stage_name"
}
report_times() {
  end_stage
  echo "== stage times"
  printf '%s\n' "${timings[@]}"
  printf '%5d s  total\n' $((SECONDS - started))
}
trap report_times EXIT

stage "packages"
scripts/install-deps.sh
jobs="$(nproc)"
launcher=()
if command -v ccache >/dev/null; then
  export CCACHE_BASEDIR="$PWD" CCACHE_NOHASHDIR=1
  launcher=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
fi

stage "main build"
cmake -S . -B build -G Ninja -DOSSA_WERROR=ON "${launcher[@]}" >/dev/null
cmake --build build -j "$jobs"

stage "sanitizer build: bad-input suite under ASan + UBSan"
cmake -S . -B build-asan -G Ninja -DOSSA_SANITIZE=ON -DOSSA_WERROR=ON -DOSSA_BUILD_BENCH=OFF "${launcher[@]}" >/dev/null
cmake --build build-asan -j "$jobs" --target bad_input_test
ctest --test-dir build-asan -L bad_input --output-on-failure -j "$jobs"

if command -v clang++ >/dev/null; then
  stage "fuzz build: libFuzzer over the loader"
  CC=clang CXX=clang++ cmake -S . -B build-fuzz -G Ninja -DOSSA_FUZZ=ON -DOSSA_WERROR=ON -DOSSA_BUILD_BENCH=OFF \
    "${launcher[@]}" >/dev/null
  cmake --build build-fuzz -j "$jobs" --target fuzz_load fuzz_make_corpus
  ctest --test-dir build-fuzz -R fuzz_load_bounded --output-on-failure
else
  echo "== fuzz build skipped: clang++ not found"
fi

stage "runtime-only build: FlatBuffers and GLM (GoogleTest for its suites), every other package hidden"
# CMAKE_DISABLE_FIND_PACKAGE_X makes find_package(X) fail as if X were not installed, so this proves
# -DOSSA_RUNTIME_ONLY=ON needs nothing else without uninstalling anything.
hidden=()
for p in assimp OpenMesh meshoptimizer CLI11 nlohmann_json PkgConfig benchmark glfw3; do
  hidden+=("-DCMAKE_DISABLE_FIND_PACKAGE_$p=ON")
done
cmake -S . -B build-runtime -G Ninja --no-warn-unused-cli -DOSSA_RUNTIME_ONLY=ON -DOSSA_WERROR=ON "${hidden[@]}" \
  "${launcher[@]}" >/dev/null
cmake --build build-runtime -j "$jobs"
ctest --test-dir build-runtime --output-on-failure -j "$jobs"

stage "Windows: runtime + its suites cross-built with MinGW-w64, run under Wine"
# The runtime's portability check: the same runtime-only build for x86_64 Windows (PE, no ifunc, no
# POSIX), every runtime suite run under a headless Wine (one WINEPREFIX in build-win, created on the
# first run; cmake/toolchains/wine-run.sh). Each test has a CTest TIMEOUT, and the stage is bounded
# as a whole so a stuck Wine cannot hold CI.
# Wine's own start-up is made serial and happens once: the prefix is created by one wineboot before
# anything runs in it (the build runs test discovery under Wine, two at a time with -j2, and two
# first runs racing to create a prefix is how a CI run once lost a test), and one persistent
# wineserver serves the whole stage (a server that exits between two tests can drop a client that
# connects just then). Both are undone on the way out.
export WINEPREFIX="$PWD/build-win/wineprefix"
wine_server=/usr/lib/wine/wineserver
if [ -x /usr/lib/wine/wine64 ] && [ -x "$wine_server" ]; then
  mkdir -p build-win
  WINEDEBUG=-all WINEDLLOVERRIDES="mscoree,mshtml,winemenubuilder.exe=" DISPLAY='' \
    timeout 300 /usr/lib/wine/wine64 wineboot -i </dev/null >build-win/wineboot.log 2>&1 ||
    { echo "wineboot failed:"; cat build-win/wineboot.log; }
  "$wine_server" -w </dev/null >/dev/null 2>&1 || true
  "$wine_server" -p </dev/null >/dev/null 2>&1
  trap '"$wine_server" -k >/dev/null 2>&1 || true; report_times' EXIT
fi
cmake -S . -B build-win -G Ninja -DCMAKE_TOOLCHAIN_FILE=cmake/toolchains/mingw-w64-x86_64.cmake \
  -DOSSA_RUNTIME_ONLY=ON -DOSSA_WERROR=ON -DOSSA_BUILD_BENCH=OFF "${launcher[@]}" >/dev/null
timeout 900 cmake --build build-win -j "$jobs"
timeout 300 ctest --test-dir build-win --output-on-failure -j "$jobs" --timeout 60
if [ -x "$wine_server" ]; then "$wine_server" -k >/dev/null 2>&1 || true; fi
trap report_times EXIT
unset WINEPREFIX

stage "main suite"
ctest --test-dir build --output-on-failure -j "$jobs" --timeout 900
