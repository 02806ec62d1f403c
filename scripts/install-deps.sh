#!/usr/bin/env bash
# install-deps.sh — installs everything ossa builds, tests and demos with, from Debian 12 packages.
# Idempotent: apt runs only when a package is missing. Uses sudo when not root.
set -euo pipefail

PACKAGES=(
  cmake ninja-build g++ pkg-config git ccache
  libassimp-dev libglm-dev libglfw3-dev flatbuffers-compiler libflatbuffers-dev libstb-dev
  libopenmesh-dev libmeshoptimizer-dev libcli11-dev nlohmann-json3-dev libxxhash-dev
  libgtest-dev libgmock-dev libbenchmark-dev libimgui-dev libepoxy-dev
  xvfb xauth libgl1-mesa-dri libglx-mesa0 mesa-utils
  clang libclang-rt-14-dev clang-format
  python3 python3-jsonschema
  libcurl4-openssl-dev nginx-light
  g++-mingw-w64-x86-64-posix wine64
)
# libcurl4-openssl-dev: ossa-cook --cache over HTTP (optional: without it only folders); nginx-light:
# its tests serve a cache over WebDAV on loopback (they skip, saying so, without nginx).
# clang-format (14 on Debian 12): CTest's format_check holds every C++ file to .clang-format.
# ccache: scripts/test.sh compiles its five builds through it, so they share what they compile alike.
# g++-mingw-w64-x86-64-posix + wine64: the Windows stage of scripts/test.sh cross-builds the runtime
# and its suites with MinGW-w64 (cmake/toolchains/mingw-w64-x86_64.cmake) and runs them under Wine;
# GoogleTest's sources for that build come with libgtest-dev (/usr/src/googletest).

missing=()
for p in "${PACKAGES[@]}"; do
  dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q "install ok installed" || missing+=("$p")
done
if ((${#missing[@]} == 0)); then
  echo "install-deps: all ${#PACKAGES[@]} packages present"
  exit 0
fi
SUDO=""
[ "$(id -u)" -eq 0 ] || SUDO="sudo"
echo "install-deps: installing ${missing[*]}"
$SUDO apt-get update -q
DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q --no-install-recommends "${missing[@]}"
