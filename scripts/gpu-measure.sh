#!/usr/bin/env bash
# gpu-measure.sh — the viewer's figures on one machine, from the folder scripts/gpu-bundle.sh made
# (run as DIR/gpu-measure.sh from the repository root, whose assets/ the first-frame bench cooks).
# Unpacks the bundle under /tmp, starts the carried Xvfb, then prints the GL renderer, the
# first-frame bench, GPU against CPU skinning for crowds, cloth on and off, and screenshots.
# Every step has its own timeout and the script goes on after a failed one: on a leased machine a
# half-run is still worth its log. Output: $OUT/log.txt and $OUT/*.png (OUT defaults to /tmp/ossa-gpu-out).
#
# Environment: OSSA_GLX_VENDOR (nvidia where nvidia-smi exists, else mesa: the client GL vendor that
# libglvnd loads), OSSA_GL_DEBS (a folder of libglvnd .debs to unpack into / first: for a bare
# image only), OSSA_SKIN_NS (crowd sizes, default "1 100 1000 4096"), OSSA_FRAMES (300),
# OSSA_BIG_FRAMES (frames of GPU-skinned crowds of 1000 and more, default OSSA_FRAMES),
# OSSA_CPU_BIG_FRAMES (frames of CPU-skinned crowds of 1000 and more, default 60), OSSA_VIEW_TIMEOUT
# (seconds per viewer run, 90), OSSA_EXTRA=1 (the 4096-crowd runs without MSAA and at 320x180),
# OSSA_FF_RUNS (first-frame runs, 5), OSSA_FF_TIMEOUT (its seconds, 120), OSSA_TAG (screenshot name
# suffix, the vendor by default).
set -u
export PATH=$PATH:/usr/sbin:/sbin
here=$(cd "$(dirname "$0")" && pwd)
repo=$(pwd)
OUT=${OUT:-/tmp/ossa-gpu-out}
mkdir -p "$OUT"
log=$OUT/log.txt
: >"$log"
b=/tmp/ossa-gpu
vendor=${OSSA_GLX_VENDOR:-$(command -v nvidia-smi >/dev/null && echo nvidia || echo mesa)}
tag=${OSSA_TAG:-$vendor}
frames=${OSSA_FRAMES:-300}
big_frames=${OSSA_BIG_FRAMES:-$frames}
big_cpu_frames=${OSSA_CPU_BIG_FRAMES:-60}
say() { echo "$*" | tee -a "$log"; }
# step NAME SECONDS CMD...: runs CMD under timeout, output to the log, wall time after it.
step() {
  local name=$1 t=$2
  shift 2
  say "== $name: $*"
  local s e rc
  s=$(date +%s%N)
  timeout -k 5 "$t" "$@" 2>&1 | tee -a "$log"
  rc=${PIPESTATUS[0]}
  e=$(date +%s%N)
  say "-- $name rc=$rc wall_ms=$(((e - s) / 1000000))"
}

say "# gpu-measure.sh $(date -u +%FT%TZ) vendor=$vendor host=$(uname -m) $(uname -r)"
step gpu 20 nvidia-smi
step gpu-query 20 nvidia-smi --query-gpu=name,driver_version,memory.total,clocks.max.sm --format=csv
step cpu 5 sh -c "grep -m1 'model name' /proc/cpuinfo; nproc"

if [ -n "${OSSA_GL_DEBS:-}" ]; then
  for f in "$OSSA_GL_DEBS"/*.deb; do dpkg -x "$f" /; done
  ldconfig
fi
rm -rf "$b" && mkdir -p "$b"
step unpack 120 tar -xJf "$here/payload.tar.xz" -C "$b"

# Libraries: the bundle's first, then the NVIDIA driver's folder (where libGLX_nvidia lives) when
# the loader's cache does not know it; libstdc++ from the bundle only where the image's is older.
libs=$b/lib
sys_cxx=$(ldconfig -p | awk '/libstdc\+\+\.so\.6 .*x86-64/{print $NF; exit}')
if [ -z "$sys_cxx" ] || ! grep -qa GLIBCXX_3.4.30 "$sys_cxx"; then libs=$libs:$b/lib/fallback; fi
if [ "$vendor" = nvidia ] && ! ldconfig -p | grep -q libGLX_nvidia.so.0; then
  glx=$(find /usr/local/nvidia /usr/lib /usr/lib64 /usr/lib/x86_64-linux-gnu -name 'libGLX_nvidia.so.0' 2>/dev/null |
    head -1)
  [ -n "$glx" ] && libs=$libs:$(dirname "$glx")
fi
export LD_LIBRARY_PATH=$libs LIBGL_DRIVERS_PATH=$b/dri
say "LD_LIBRARY_PATH=$LD_LIBRARY_PATH"
# Xvfb runs xkbcomp from /usr/bin and reads /usr/share/X11/xkb (paths built into it): supply both
# where the image lacks them (a bare image as root; elsewhere they are installed).
[ -x /usr/bin/xkbcomp ] || cp "$b/bin/xkbcomp" /usr/bin/xkbcomp
[ -d /usr/share/X11/xkb ] || { mkdir -p /usr/share/X11 && ln -s "$b/xkb" /usr/share/X11/xkb; }

display=:${OSSA_DISPLAY:-97}
"$b/bin/Xvfb" "$display" -screen 0 1280x1024x24 -nolisten tcp +extension GLX >"$OUT/xvfb.txt" 2>&1 &
xvfb=$!
for _ in $(seq 50); do [ -e "/tmp/.X11-unix/X${display#:}" ] && break; sleep 0.1; done
export DISPLAY=$display __GLX_VENDOR_LIBRARY_NAME=$vendor
say "Xvfb pid $xvfb on $DISPLAY"
step glxinfo 20 "$b/bin/glxinfo" -B
view=$b/bin/ossa-view
c=$b/cooked
step renderer 30 "$view" "$c/CesiumMan/CesiumMan.ossa" --frames 1 -v
# Asked for NVIDIA and got something else: say what the loader saw, and stop (the figures would be
# another renderer's) unless OSSA_ANY_RENDERER=1.
if [ "$vendor" = nvidia ] && ! grep -q 'ossa-view: OpenGL .*NVIDIA' "$log"; then
  step diag 30 sh -c 'cat /etc/os-release | head -2; ldconfig -p | grep -iE "nvidia|libGLX|libstdc"; \
    ls -la /usr/local/nvidia/lib64 /usr/local/nvidia/lib 2>&1 | head -40; \
    ls /usr/share/glvnd/egl_vendor.d /usr/local/nvidia/share/glvnd 2>&1'
  LIBGL_DEBUG=verbose step glxinfo-debug 20 "$b/bin/glxinfo" -B
  cat "$OUT/xvfb.txt" >>"$log"
  if [ "${OSSA_ANY_RENDERER:-0}" != 1 ]; then say "# not NVIDIA: stopping"; kill "$xvfb"; exit 1; fi
fi

# 1. First frame, cooked against Assimp (the repository's samples plus the shared AnimeBoy).
step first-frame "${OSSA_FF_TIMEOUT:-120}" "$b/bin/ossa-bench-first-frame" --runs "${OSSA_FF_RUNS:-5}" \
  --assets "$repo/assets" --shared "$b/shared"

# view LABEL FRAMES ARGS...: one headless run with --stats and --first-frame-time; prints a RESULT
# line: per-frame wall time over frames 2..N (process wall minus first-frame-ms, over N-1: so it
# also holds the teardown), then --stats' averages (CPU ms per stage; gpu: GL_TIME_ELAPSED).
view() {
  local label=$1 n=$2
  shift 2
  local s e rc out
  s=$(date +%s%N)
  out=$(timeout -k 5 "${OSSA_VIEW_TIMEOUT:-90}" "$view" "$@" --frames "$n" --stats --first-frame-time 2>&1)
  rc=$?
  e=$(date +%s%N)
  echo "$out" >>"$log"
  local ff stats
  ff=$(echo "$out" | awk '/^first-frame-ms/{print $2}')
  stats=$(echo "$out" | grep '^frames ' || true)
  awk -v l="$label" -v n="$n" -v rc="$rc" -v w=$(((e - s) / 1000000)) -v ff="${ff:-0}" -v st="$stats" 'BEGIN {
    split(st, a, " ");  # frames N sample X ms blend X ms graph X ms skin X ms draw X ms gpu X ms
    printf "RESULT %-34s rc=%s frames=%d wall=%dms first=%.0fms per_frame=%.3fms sample=%s skin=%s draw=%s gpu=%s\n",
      l, rc, n, w, ff, (w - ff) / (n - 1), a[4], a[13], a[16], a[19] }' | tee -a "$log"
}

# 2. GPU skinning against CPU skinning, crowds.
for n in ${OSSA_SKIN_NS:-1 100 1000 4096}; do
  for who in cesium pab; do
    files=("$c/CesiumMan/CesiumMan.ossa")
    [ $who = pab ] && files=("$c/Pab/arnaud.ossa" "$c/Pab/walk.ossa")
    gf=$frames cf=$frames
    [ "$n" -ge 1000 ] && gf=$big_frames cf=$big_cpu_frames
    view "$who crowd $n gpu-skin" "$gf" "${files[@]}" --crowd "$n"
    view "$who crowd $n cpu-skin" "$cf" "${files[@]}" --crowd "$n" --cpu-skinning
  done
done

# 3. Cloth (CapedMan's cape: simulated on the CPU, or drawn skinned).
for n in 1 100; do
  for cl in on off; do
    view "caped crowd $n cloth $cl" "$frames" "$c/CapedMan/CapedMan.ossa" --crowd "$n" --cloth "$cl"
  done
done

# 3b. Where a large GPU-skinned crowd's frame goes: the same crowd with no multisampling, then at a
# small size (fewer fragments), with OSSA_EXTRA=1.
if [ "${OSSA_EXTRA:-0}" = 1 ]; then
  for who in cesium pab; do
    files=("$c/CesiumMan/CesiumMan.ossa")
    [ $who = pab ] && files=("$c/Pab/arnaud.ossa" "$c/Pab/walk.ossa")
    view "$who crowd 4096 gpu-skin msaa1" "$big_frames" "${files[@]}" --crowd 4096 --msaa 1
    view "$who crowd 4096 gpu-skin 320x180 msaa1" "$big_frames" "${files[@]}" --crowd 4096 --msaa 1 --size 320x180
    view "$who crowd 4096 cpu-skin 320x180 msaa1" "$big_cpu_frames" "${files[@]}" --crowd 4096 --msaa 1 --size 320x180 \
      --cpu-skinning
  done
fi

# 4. Screenshots, to compare with another vendor's (scripts/png-diff.py).
step shot-cesium 30 "$view" "$c/CesiumMan/CesiumMan.ossa" --time 0.5 --size 960x540 --screenshot "$OUT/cesium-$tag.png"
step shot-caped 30 "$view" "$c/CapedMan/CapedMan.ossa" --time 1.5 --yaw 150 --size 960x540 \
  --screenshot "$OUT/caped-$tag.png"
step shot-crowd 30 "$view" "$c/Pab/arnaud.ossa" "$c/Pab/walk.ossa" --crowd 100 --time 0.6 --size 960x540 \
  --screenshot "$OUT/pab-crowd-$tag.png"

kill "$xvfb" 2>/dev/null
wait "$xvfb" 2>/dev/null
say "# done $(date -u +%FT%TZ)"
