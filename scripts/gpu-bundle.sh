#!/usr/bin/env bash
# gpu-bundle.sh BUILD_DIR DEST — packs what scripts/gpu-measure.sh needs to run the viewer on a bare
# machine with an NVIDIA GPU and no display (docs/MEASURING.md, "On an NVIDIA GPU"): the Release
# ossa-view and ossa-bench-first-frame, Xvfb (its GLX extension needs Mesa's swrast driver, server
# side only), xkbcomp and the keyboard data, glxinfo, every shared library these load from this
# Debian 12 machine except glibc's and libglvnd's (the device gets those from the image and from
# libglvnd's .debs), and the samples cooked here. DEST gets payload.tar.xz (unpacked there under
# /tmp) and gpu-measure.sh, so DEST is one folder to carry.
#
# Two libraries are replaced by empty stubs made here: libz3 and libxml2 are linked by libLLVM
# (Mesa's llvmpipe needs LLVM to load) for features Mesa never calls, and with their ICU they are
# ~16 MB compressed of a transfer capped at 64 MiB. libLLVM is linked lazily (no BIND_NOW), so the
# functions are only looked up when called; the one data symbol (xmlFree) and libxml2's symbol
# versions are defined. Nothing is installed and nothing third-party enters the repository.
set -euo pipefail
build=${1:?usage: gpu-bundle.sh BUILD_DIR DEST}
dest=${2:?usage: gpu-bundle.sh BUILD_DIR DEST}
repo=$(cd "$(dirname "$0")/.." && pwd)
build=$(cd "$build" && pwd)
mkdir -p "$dest"
dest=$(cd "$dest" && pwd)
stage=$(mktemp -d)
trap 'rm -rf "$stage"' EXIT
mkdir -p "$stage"/{bin,lib/fallback,dri,cooked,shared}

# Programs (stripped).
for p in "$build"/bin/ossa-view "$build"/bin/ossa-bench-first-frame /usr/bin/Xvfb /usr/bin/xkbcomp /usr/bin/glxinfo; do
  strip -o "$stage/bin/$(basename "$p")" "$p"
done
multiarch=/usr/lib/x86_64-linux-gnu
strip -o "$stage/dri/swrast_dri.so" "$multiarch/dri/swrast_dri.so"
cp -L "$multiarch/libGLX_mesa.so.0" "$stage/lib/"
cp -r /usr/share/X11/xkb "$stage/xkb"

# Shared libraries: everything ldd resolves, less glibc, libglvnd (the .debs), the stubbed two,
# and libstdc++/libgcc_s, which go to lib/fallback (used only where the image's are older).
skip='^(libc|libm|libdl|libpthread|librt|libresolv|ld-linux-x86-64|linux-vdso|'
skip+='libGL|libGLX|libGLdispatch|libEGL|libOpenGL|libGLESv2|libz3|libxml2|libicuuc|libicudata)\.so'
for f in "$stage"/bin/* "$stage"/dri/swrast_dri.so "$stage"/lib/libGLX_mesa.so.0; do
  ldd "$f" | awk '/=> \//{print $1, $3}'
done | sort -u | while read -r name path; do
  if [[ $name =~ $skip ]]; then continue; fi
  if [[ $name =~ ^(libstdc\+\+|libgcc_s)\.so ]]; then cp -L "$path" "$stage/lib/fallback/$name"; continue; fi
  strip -o "$stage/lib/$name" "$path" 2>/dev/null || cp -L "$path" "$stage/lib/$name"
done

# The stubs (see the header). Mesa opens its driver with RTLD_NOW, so each stub defines every
# symbol libLLVM takes from the library (functions that abort if ever called), with its version.
llvm=$(ldd "$stage/dri/swrast_dri.so" | awk '/libLLVM/{print $3}')
z3=$(ldd "$llvm" | awk '/libz3/{print $3}')
{
  echo '#include <stdlib.h>'
  comm -12 <(nm -D --undefined-only "$llvm" | awk '{print $2}' | sort -u) \
    <(nm -D --defined-only "$z3" | awk '{print $3}' | sort -u) | sed 's/.*/void &(void) { abort(); }/'
} >"$stage/z3.c"
cc -shared -fPIC -o "$stage/lib/libz3.so.4" -Wl,-soname,libz3.so.4 "$stage/z3.c"
nm -D --undefined-only "$llvm" | awk '$2 ~ /@LIBXML2_/ {print $2}' | sort -u >"$stage/xml.syms"
{
  echo '#include <stdlib.h>'
  echo 'void *xmlFree = 0;'  # a function pointer variable in libxml2
  sed 's/@.*//' "$stage/xml.syms" | grep -vx xmlFree | sed 's/.*/void &(void) { abort(); }/'
} >"$stage/xml.c"
{
  prev=
  for v in $(sed 's/.*@//' "$stage/xml.syms" | sort -u -V); do
    echo "$v { global: $(grep "@$v\$" "$stage/xml.syms" | sed 's/@.*/;/' | tr '\n' ' ')}${prev:+ $prev};"
    prev=$v
  done
} >"$stage/xml.map"
cc -shared -fPIC -o "$stage/lib/libxml2.so.2" -Wl,-soname,libxml2.so.2 -Wl,--version-script="$stage/xml.map" \
  "$stage/xml.c"
rm "$stage"/z3.c "$stage"/xml.c "$stage"/xml.map "$stage"/xml.syms

# The samples, cooked as scripts/demo.sh cooks them.
cook=$build/bin/ossa-cook
(cd "$repo" && "$cook" assets/Pab/skeleton.fbx assets/CesiumMan assets/CapedMan --root assets -o "$stage/cooked")
(cd "$repo" && "$cook" assets/Pab/arnaud.fbx assets/Pab/walk.fbx --skeleton "$stage/cooked/Pab/skeleton.ossa" \
  --root assets -o "$stage/cooked")
# A textured character for the first-frame bench, when the shared assets are beside the checkout.
if [ -d "$repo/../shared/assets/AnimeBoy" ]; then cp -r "$repo/../shared/assets/AnimeBoy" "$stage/shared/"; fi

tar -C "$stage" -cf - . | xz -T2 -6 >"$dest/payload.tar.xz"
cp "$repo/scripts/gpu-measure.sh" "$dest/"
du -sh "$dest"
