#!/usr/bin/env bash
# measure-anchors.sh — the performance tables of one machine in one go, each a ratio taken in the
# same minutes: ossa against ozz-animation (ossa-bench-vs-ozz) and ACL (ossa-bench-acl), the guard
# (ossa-bench-guard), this checkout's ossa-bench-anim against an earlier commit's, run turn about,
# and the guard of this checkout with the denormal regression put back (it must fail). It exists so that a session that lands on a CPU not measured yet (an Intel machine, an
# older AMD) spends its time reading tables, not assembling them.
#
# Usage (from the repository root):
#   scripts/measure-anchors.sh [--ozz DIR] [--acl DIR [--rtm DIR]] [--ref COMMIT] [--rounds N]
#                              [--out DIR] [--jobs N] [--no-regressed]
#   --ozz     an ozz-animation 0.16.0 checkout with its media/bin (docs/MEASURING.md says how)
#   --acl     an ACL v2.1.0 checkout; --rtm its RTM (default: <acl>/external/rtm)
#   --ref     the earlier commit built for the turn-about rows (default 613d7e9, the landing before
#             the 2x sampling regression on Intel; "none" skips it)
#   --rounds  turn-about rounds of the two ossa-bench-anim builds (default 3)
#   --out     where the outputs go (default /tmp/ossa-anchors): cpu.txt, vs-ozz.txt, vs-ozz-avx2.txt, acl.txt,
#             guard.txt, guard-avx2.txt, guard-regressed.txt, guard-regressed-avx2.txt (the guard
#             with --clone avx2 too), anim.txt (one line per build and round), summary.txt
#   --no-regressed  skip the guard of the build with the regression put back: a worktree of this
#             checkout's HEAD in which runtime/internal/float_env.h's FlushDenormals sets no bits and
#             cooker/import/tiny_values.cpp flushes nothing (the two defences against the 2x
#             sampling regression on Intel, issue 27), built for ossa-bench-guard alone
# The anchors are built into build-anchors/ (configured with the checkouts given; never fetched),
# the reference in a git worktree under the output folder. A step that cannot run (no checkout
# given, a reference that does not build) is reported in summary.txt and the others go on.
# Cost: a first run builds the project three times (this checkout with the anchors, the reference,
# the regressed worktree's guard: ~20-35 minutes on 2 cores, less with ccache), then ~10 minutes of
# benches. Run it on a quiet machine: every table here is a ratio, but a neighbour's
# load still widens the spread between rounds.
set -u
repo=$(pwd)
ozz="" acl="" rtm="" ref=613d7e9 rounds=3 out=/tmp/ossa-anchors jobs=$(nproc) regressed=1
while [ $# -gt 0 ]; do
  case "$1" in
    --ozz) ozz=$2; shift 2 ;;
    --acl) acl=$2; shift 2 ;;
    --rtm) rtm=$2; shift 2 ;;
    --ref) ref=$2; shift 2 ;;
    --rounds) rounds=$2; shift 2 ;;
    --out) out=$2; shift 2 ;;
    --jobs) jobs=$2; shift 2 ;;
    --no-regressed) regressed=0; shift ;;
    *) echo "measure-anchors.sh: unknown argument '$1' (see the header of $0)" >&2; exit 2 ;;
  esac
done
if [ ! -f "$repo/CMakeLists.txt" ] || [ ! -d "$repo/bench" ]; then
  echo "measure-anchors.sh: run it from the repository root" >&2
  exit 2
fi
case "$rounds" in '' | *[!0-9]*) echo "measure-anchors.sh: --rounds takes a number" >&2; exit 2 ;; esac
mkdir -p "$out"
summary=$out/summary.txt
: >"$summary"
say() { echo "$*" | tee -a "$summary"; }

# The CPU line every table is read against (and /proc/cpuinfo's first processor, whole).
cpu_field() { awk -F': ' -v k="$1" '$1 ~ "^" k "[ \t]*$" {print $2; exit}' /proc/cpuinfo; }
sed '/^$/q' /proc/cpuinfo >"$out/cpu.txt"
isa=$(grep -m1 '^flags' /proc/cpuinfo | grep -o -w -E 'avx512f|avx2' | tr '\n' ' ' | sed 's/ $//')
say "# cpu: $(cpu_field 'model name') (family $(cpu_field 'cpu family'), model $(cpu_field model), $(nproc) logical cpus; ${isa:-no avx2})"
say "# checkout $(git -C "$repo" rev-parse --short HEAD)$(git -C "$repo" diff --quiet HEAD || echo ' (with local changes)'), reference $ref"

# This checkout, with the anchors it was given.
args=(-S "$repo" -B "$repo/build-anchors" -G Ninja)
[ -n "$ozz" ] && args+=(-DOSSA_OZZ_SOURCE_DIR="$ozz")
[ -n "$acl" ] && args+=(-DOSSA_ACL_SOURCE_DIR="$acl")
[ -n "$rtm" ] && args+=(-DOSSA_RTM_SOURCE_DIR="$rtm")
command -v ccache >/dev/null && args+=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
targets=(ossa-bench-anim ossa-bench-guard)
[ -n "$ozz" ] && targets+=(ossa-bench-vs-ozz)
[ -n "$acl" ] && targets+=(ossa-bench-acl)
if ! cmake "${args[@]}" >"$out/build.log" 2>&1 || ! cmake --build "$repo/build-anchors" -j"$jobs" --target "${targets[@]}" >>"$out/build.log" 2>&1; then
  say "build of this checkout failed: see $out/build.log"
  exit 1
fi
bin=$repo/build-anchors/bin

# The earlier commit, in a worktree of its own (its build directory inside it).
ref_bin=""
if [ "$ref" != none ]; then
  wt=$out/ref-$ref
  if [ ! -d "$wt" ]; then
    git -C "$repo" worktree add --force --detach "$wt" "$ref" >>"$out/build.log" 2>&1 || say "reference $ref: no worktree (see $out/build.log)"
  fi
  if [ -d "$wt" ]; then
    rargs=(-S "$wt" -B "$wt/build" -G Ninja)
    command -v ccache >/dev/null && rargs+=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
    if cmake "${rargs[@]}" >>"$out/build.log" 2>&1 &&
      CCACHE_BASEDIR=$wt CCACHE_NOHASHDIR=1 cmake --build "$wt/build" -j"$jobs" --target ossa-bench-anim \
        >>"$out/build.log" 2>&1; then
      ref_bin=$wt/build/bin
    else
      say "reference $ref: ossa-bench-anim did not build (see $out/build.log); its rows are skipped"
    fi
  fi
fi

# ossa-bench-anim of both builds, turn about: the rows the 2x regression moved. The two builds cook
# the same Pab fixture, and each round runs both in the same minutes.
filter='^(BM_Sample|BM_SampleSeek|BM_Frame|BM_SkinPositions|BM_SkinFull)$'
: >"$out/anim.txt"
anim_row() {  # $1 name, $2 binary: one line "name BM_x ns BM_y ns ..."
  local line
  line=$("$2" --benchmark_filter="$filter" --benchmark_min_time=0.5 2>/dev/null | awk '/^BM_/ {printf " %s %s", $1, $2}')
  echo "$1$line" | tee -a "$out/anim.txt"
}
for _ in $(seq "$rounds"); do
  anim_row now "$bin/ossa-bench-anim"
  [ -n "$ref_bin" ] && anim_row "$ref" "$ref_bin/ossa-bench-anim"
done
# Per row, the range over rounds of each build, and the ratio of the medians.
awk -v ref="$ref" '
  { for (i = 2; i < NF; i += 2) { v[$1, $i, ++n[$1, $i]] = $(i + 1); rows[$i] = 1 } builds[$1] = 1 }
  function median(b, r,   k, m, a, i, j, t) {
    m = n[b, r]; for (i = 1; i <= m; ++i) a[i] = v[b, r, i]
    for (i = 1; i <= m; ++i) for (j = i + 1; j <= m; ++j) if (a[j] < a[i]) { t = a[i]; a[i] = a[j]; a[j] = t }
    return m % 2 ? a[(m + 1) / 2] : (a[m / 2] + a[m / 2 + 1]) / 2
  }
  END {
    printf "# ossa-bench-anim, ns per call, median of the rounds: now against %s\n", ref
    for (r in rows) {
      if (n["now", r] == 0) continue
      if (n[ref, r] > 0) printf "%-18s now %10.0f  %s %10.0f  now/%s %.2f\n", r, median("now", r), ref, median(ref, r), ref, median("now", r) / median(ref, r)
      else printf "%-18s now %10.0f\n", r, median("now", r)
    }
  }' "$out/anim.txt" | tee -a "$summary"

# The guard as CTest runs it, then with --clone avx2 (the copies an AVX2-only CPU runs; exit 77 and
# no rows where this CPU has no AVX2).
for clone in "" avx2; do
  f=$out/guard${clone:+-$clone}.txt
  "$bin/ossa-bench-guard" ${clone:+--clone "$clone"} >"$f" 2>&1
  say "# ossa-bench-guard${clone:+ --clone $clone}: exit $? ($(grep -c -w ok "$f") rows ok, $(grep -c -w REGRESSED "$f") regressed)"
  grep -E -w '^check|ok|REGRESSED' "$f" >>"$summary"
done

if [ -n "$ozz" ]; then
  # As is, then ossa's AVX2 copies against the same ozz builds: what an AVX2-only CPU (Zen 2/3,
  # Intel's client parts) would read, as near as this CPU can say (skipped where it has no AVX2).
  for clone in "" avx2; do
    f=$out/vs-ozz${clone:+-$clone}.txt
    "$bin/ossa-bench-vs-ozz" --rounds 31 --media "$ozz/media/bin" ${clone:+--clone "$clone"} >"$f" 2>&1
    say "# ossa-bench-vs-ozz --rounds 31${clone:+ --clone $clone}: exit $?"
    grep -E '^(workload|sample|blend|local|frame|skin)' "$f" >>"$summary"
  done
else
  say "# ossa-bench-vs-ozz: skipped (no --ozz)"
fi

if [ -n "$acl" ]; then
  "$bin/ossa-bench-acl" --runs 5 >"$out/acl.txt" 2>&1
  say "# ossa-bench-acl --runs 5: exit $?"
  grep -E '^# (clips|bytes ossa|forward ns|random access ns|mean ns)' "$out/acl.txt" | cut -c1-400 >>"$summary"
  grep -E '^(CMU_BVH|Pab/atlas|Pab/crossarms)' "$out/acl.txt" >>"$summary"
else
  say "# ossa-bench-acl: skipped (no --acl)"
fi
# The guard must catch the regression it was written for: this checkout's HEAD with both
# defences against subnormals taken out, each edit checked to have matched.
if [ "$regressed" = 1 ]; then
  wt=$out/regressed
  [ -d "$wt" ] && git -C "$repo" worktree remove --force "$wt" >>"$out/build.log" 2>&1
  if git -C "$repo" worktree add --force --detach "$wt" HEAD >>"$out/build.log" 2>&1 &&
    sed -i 's/kBits = 0x8040;/kBits = 0x0;/' "$wt/runtime/internal/float_env.h" &&
    grep -q 'kBits = 0x0;' "$wt/runtime/internal/float_env.h" &&
    sed -i 's/^  Flusher flush;$/  Flusher flush;\n  if (flush.changed == 0) return 0;/' "$wt/cooker/import/tiny_values.cpp" &&
    [ "$(grep -c 'if (flush.changed == 0) return 0;' "$wt/cooker/import/tiny_values.cpp")" = 2 ]; then
    gargs=(-S "$wt" -B "$wt/build" -G Ninja)
    command -v ccache >/dev/null && gargs+=(-DCMAKE_C_COMPILER_LAUNCHER=ccache -DCMAKE_CXX_COMPILER_LAUNCHER=ccache)
    if cmake "${gargs[@]}" >>"$out/build.log" 2>&1 &&
      CCACHE_BASEDIR=$wt CCACHE_NOHASHDIR=1 cmake --build "$wt/build" -j"$jobs" --target ossa-bench-guard \
        >>"$out/build.log" 2>&1; then
      for clone in "" avx2; do
        f=$out/guard-regressed${clone:+-$clone}.txt
        "$wt/build/bin/ossa-bench-guard" ${clone:+--clone "$clone"} >"$f" 2>&1
        status=$?
        rows=$(awk '$NF == "REGRESSED" {printf "%s%s", sep, $1; sep = ", "}' "$f")
        what="ossa-bench-guard${clone:+ --clone $clone} with the regression put back"
        if [ "$status" = 77 ]; then
          say "# $what: skipped (this CPU cannot run that copy)"
        elif [ "$status" != 0 ] && [ -n "$rows" ]; then
          say "# $what: exit $status, REGRESSED: $rows (as it must)"
        else
          say "# $what: exit $status, nothing regressed: THE GUARD MISSED IT"
        fi
        grep -E -w '^check|ok|REGRESSED' "$f" >>"$summary"
      done
    else
      say "# regression put back: ossa-bench-guard did not build (see $out/build.log)"
    fi
  else
    say "# regression put back: the worktree or its two edits failed (see $out/build.log)"
  fi
fi
echo "measure-anchors.sh: tables in $summary"
