#!/usr/bin/env bash
# install_test.sh BUILD_DIR SOURCE_DIR WORK_DIR IN_TREE_CONSUMER COOKED.ossa
#
# What a game does with ossa, for real: install the build into a fresh prefix, check the package
# holds what docs promise (headers that compile on their own, the generated schema header without
# a pinned FlatBuffers patch version, the CMake package, the pkg-config file, no path back into the
# build tree), then build examples/consumer out of tree against the prefix twice — once with
# find_package(ossa), once with pkg-config — and check both print exactly what the same program
# built inside this tree prints for the cooked Pab character walking through its graph.
set -euo pipefail
build=$1 src=$2 work=$3 in_tree=$4 cooked=$5
prefix=$work/prefix
rm -rf "$work"
mkdir -p "$work"
fail() { echo "install_test: FAIL: $*" >&2; exit 1; }

echo "== cmake --install $build --prefix $prefix"
cmake --install "$build" --prefix "$prefix" >"$work/install.log"

libdir=lib
[ -d "$prefix/lib" ] || fail "no lib/ folder in the prefix"
for f in include/ossa/version.h include/ossa/format/ossa_generated.h include/ossa/loader/asset.h \
         include/ossa/graph/graph.h $libdir/libossa_runtime.a $libdir/libossa_format.a \
         $libdir/cmake/ossa/ossaConfig.cmake $libdir/cmake/ossa/ossaConfigVersion.cmake \
         $libdir/pkgconfig/ossa.pc share/doc/ossa/LICENSE share/ossa/ossa.fbs share/ossa/schema/mesh.fbs bin/ossa-cook bin/ossa-inspect bin/ossa-diff bin/ossa-view; do
  [ -e "$prefix/$f" ] || fail "missing $f"
done
if grep -q FLATBUFFERS_VERSION_REVISION "$prefix/include/ossa/format/ossa_generated.h"; then
  fail "the installed ossa_generated.h pins a FlatBuffers patch version"
fi
echo "== the installed schema (ossa.fbs and its parts) compiles to the installed header"
flatc --cpp --scoped-enums --gen-all -o "$work/schema" "$prefix/share/ossa/ossa.fbs" >"$work/flatc.log" 2>&1 \
  || { cat "$work/flatc.log" >&2; fail "flatc cannot compile the installed share/ossa/ossa.fbs"; }
strip_version() { grep -v -e 'FLATBUFFERS_VERSION_' -e 'flatbuffers version included' -e "needs FlatBuffers" "$1"; }
cmp -s <(strip_version "$work/schema/ossa_generated.h") <(strip_version "$prefix/include/ossa/format/ossa_generated.h") \
  || fail "the installed schema does not generate the installed ossa_generated.h"
if grep -rqF "$build" "$prefix/$libdir/cmake" "$prefix/$libdir/pkgconfig"; then
  fail "the installed package refers to the build tree $build"
fi
for internal in message.h vector_clones.h graph_internal.h; do
  [ -z "$(find "$prefix/include" -name "$internal")" ] || fail "internal header $internal was installed"
done

echo "== every public header compiles on its own"
headers=$(cd "$prefix/include" && find ossa -name '*.h' | sort)
n=0
for h in $headers; do
  echo "#include <$h>" | c++ -std=c++20 -fsyntax-only -Wall -Wextra -Werror -I"$prefix/include" -x c++ - \
    || fail "<$h> does not compile on its own against the installed prefix"
  n=$((n + 1))
done
echo "$n headers compile alone"

echo "== examples/consumer with find_package(ossa)"
cmake -S "$src/examples/consumer" -B "$work/consumer" -G Ninja -DCMAKE_PREFIX_PATH="$prefix" >"$work/consumer-configure.log" \
  || { cat "$work/consumer-configure.log"; fail "the consumer did not configure against the prefix"; }
cmake --build "$work/consumer" >"$work/consumer-build.log" || { cat "$work/consumer-build.log"; fail "the consumer did not build"; }

echo "== examples/consumer with pkg-config"
# shellcheck disable=SC2046
c++ -O2 "$src/examples/consumer/main.cpp" -o "$work/consumer-pc" \
  $(PKG_CONFIG_PATH="$prefix/$libdir/pkgconfig" pkg-config --cflags --libs ossa) \
  || fail "the consumer did not build with pkg-config's flags"

args=("$cooked" pab "RightHand" speed=3.13 crossed_arms=true --seconds 1.5)
expected=$("$in_tree" "${args[@]}")
echo "in tree:        $(echo "$expected" | tail -n 1)"
echo "$expected" | tail -n 1 | grep -Eq '^RightHand -?[0-9]+\.[0-9]{4} -?[0-9]+\.[0-9]{4} -?[0-9]+\.[0-9]{4}$' \
  || fail "the in-tree consumer printed no position: $expected"
for exe in "$work/consumer/ossa_consumer" "$work/consumer-pc"; do
  got=$("$exe" "${args[@]}") || fail "$exe failed"
  echo "$(basename "$exe"): $(echo "$got" | tail -n 1)"
  [ "$got" = "$expected" ] || fail "$exe printed '$got', the in-tree build '$expected'"
done
# The position must depend on the graph's inputs, or the comparison above proves nothing.
standing=$("$in_tree" "$cooked" pab "RightHand" --seconds 1.5 | tail -n 1)
[ "$standing" != "$(echo "$expected" | tail -n 1)" ] || fail "the joint did not move between two graph inputs"
echo "install_test: ok"
