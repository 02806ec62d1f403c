#!/usr/bin/env bash
# cook_cmake_test.sh BUILD_DIR SOURCE_DIR WORK_DIR [SHARED_ASSETS]
#
# ossa_cook() as a game uses it, for real: install the build into a fresh prefix, configure a small
# project (examples/cook_project) against it with Ninja over a private copy of sample assets, build,
# then change one input of each class — an event sidecar, a graph file, a glTF's external buffer, a
# texture, the rig a clip is cooked against — and check after each rebuild that exactly the outputs
# whose cooks read it were re-cooked (their mtime moved, every other output's did not). A touch
# that changes no bytes re-cooks nothing, and a build with nothing changed runs nothing.
set -euo pipefail
build=$1 src=$2 work=$3 shared=${4:-}
prefix=$work/prefix project=$work/project bin=$work/project-build
rm -rf "$work"
mkdir -p "$work"
fail() { echo "cook_cmake_test: FAIL: $*" >&2; exit 1; }

cmake --install "$build" --prefix "$prefix" >"$work/install.log"
[ -f "$prefix/lib/cmake/ossa/ossaCook.cmake" ] || fail "ossaCook.cmake was not installed"

# The project and its assets: a private copy, edited below.
cp -r "$src/examples/cook_project" "$project"
mkdir -p "$project/assets"
cp -r "$src/assets/Pab" "$src/assets/RiggedSimple" "$project/assets/"
gltf=0
if [ -n "$shared" ] && [ -f "$shared/Khronos_embedded/interpolation_test.gltf" ]; then
  mkdir -p "$project/assets/gltf"
  cp "$shared/Khronos_embedded/interpolation_test.gltf" "$shared/Khronos_embedded/interpolation_test.bin" "$project/assets/gltf/"
  # The texture it names: a real 1x1 PNG (the cooker decodes every texture it embeds).
  python3 -c 'import sys,zlib,struct
def chunk(t, d): return struct.pack(">I", len(d)) + t + d + struct.pack(">I", zlib.crc32(t + d))
sys.stdout.buffer.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", 1, 1, 8, 2, 0, 0, 0))
  + chunk(b"IDAT", zlib.compress(b"\x00\xff\x00\x00")) + chunk(b"IEND", b""))' >"$project/assets/gltf/l.jpg"
  gltf=1
fi
chmod -R u+w "$project"

cmake -S "$project" -B "$bin" -G Ninja -DCMAKE_PREFIX_PATH="$prefix" -DCOOK_GLTF=$gltf >"$work/configure.log" \
  || { cat "$work/configure.log"; fail "the project did not configure against the prefix"; }
cmake --build "$bin" >"$work/build-1.log" || { cat "$work/build-1.log"; fail "the first build failed"; }

cooked=$bin/cooked
outputs=(Pab/skeleton Pab/pab Pab/walk Pab/run Pab/jog RiggedSimple/RiggedSimple)
[ "$gltf" = 1 ] && outputs+=(gltf/interpolation_test)
for o in "${outputs[@]}"; do [ -f "$cooked/$o.ossa" ] || fail "the build did not write $o.ossa"; done

# mtimes of every output, one "name mtime" line each.
stamp_ns() { for o in "${outputs[@]}"; do echo "$o $(stat -c %.9Y "$cooked/$o.ossa")"; done; }
n=1
# rebuild WHAT EXPECTED...: rebuilds and checks that exactly EXPECTED outputs changed mtime.
rebuild() {
  local what=$1
  shift
  local before after changed expected
  before=$(stamp_ns)
  sleep 0.05
  n=$((n + 1))
  cmake --build "$bin" >"$work/build-$n.log" || { cat "$work/build-$n.log"; fail "rebuild after $what failed"; }
  after=$(stamp_ns)
  changed=$({ diff <(echo "$before") <(echo "$after") || true; } | sed -n 's/^> \([^ ]*\) .*/\1/p' | sort | tr '\n' ' ')
  expected=$(printf '%s\n' "$@" | sed '/^$/d' | sort | tr '\n' ' ')
  [ "$changed" = "$expected" ] || fail "after $what: re-cooked [$changed], expected [$expected] (log: $work/build-$n.log)"
  echo "ok: $what -> re-cooked [${changed% }]"
}

rebuild "nothing changed"
grep -q "no work to do" "$work/build-$n.log" || fail "a build with nothing changed ran commands: $(cat "$work/build-$n.log")"

echo " " >>"$project/assets/Pab/walk.events.json"
rebuild "editing walk.events.json (read by walk and by the graph)" Pab/walk Pab/pab

echo " " >>"$project/assets/Pab/pab.graph.json"
rebuild "editing the graph file" Pab/pab

touch "$project/assets/Pab/run.fbx" "$project/assets/Pab/skeleton.fbx"
rebuild "touching run.fbx and skeleton.fbx without changing them"

printf '{"ossa_events": 1, "clips": {}}\n' >"$project/assets/RiggedSimple/RiggedSimple.events.json"
rebuild "creating a sidecar that did not exist (the depfile names its folder)" RiggedSimple/RiggedSimple

if [ "$gltf" = 1 ]; then
  printf '\0' >>"$project/assets/gltf/interpolation_test.bin"
  rebuild "editing a glTF's external buffer" gltf/interpolation_test
  printf '\0' >>"$project/assets/gltf/l.jpg"
  rebuild "editing a texture" gltf/interpolation_test
else
  echo "skip: ../shared/assets not present, no .gltf with an external buffer and texture"
fi

# The rig: its own output, the graph that uses it, and the clips cooked against its output.
printf '\0' >>"$project/assets/Pab/skeleton.fbx"
rebuild "editing the rig source" Pab/skeleton Pab/pab Pab/walk Pab/run Pab/jog

rebuild "nothing changed, again"
echo "cook_cmake_test: every rebuild re-cooked exactly what changed"
