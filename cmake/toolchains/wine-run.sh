#!/bin/sh
# CMAKE_CROSSCOMPILING_EMULATOR for MinGW-built executables: wine-run.sh prog.exe [args...]
# Runs the program under Wine headless (no DISPLAY, no stdin) and exits with its exit code.
#
# The program's output goes to a temp file that `tail` streams back, instead of straight into the
# caller's pipe: the first Wine process of a wineserver session starts Wine's background processes
# (services.exe, winedevice.exe, plugplay.exe, ...), which inherit stdout/stderr. CTest, ninja and
# execute_process (gtest_discover_tests) read until EOF, so with a plain `wine64 prog.exe` every
# test waits ~1.5-2 s for the wineserver to shut down, and forever if a persistent wineserver
# (wineserver -p) is running. Streaming (not cat-at-the-end) keeps the output of a test that CTest
# kills on TIMEOUT.
unset DISPLAY WAYLAND_DISPLAY
# -all silences Wine's fixme/err chatter; err+module still reports a missing DLL (exit code 53).
export WINEDEBUG="${WINEDEBUG:--all,err+module}"
# No Mono/Gecko install attempts, no desktop menu entries.
export WINEDLLOVERRIDES="${WINEDLLOVERRIDES:-mscoree,mshtml,winemenubuilder.exe=}"
: "${WINEPREFIX:?wine-run.sh: set WINEPREFIX (an absolute path owned by the current user)}"
export WINEPREFIX
wine="${WINE:-}"
if [ -z "$wine" ]; then
  for c in /usr/lib/wine/wine64 wine64 wine; do
    if command -v "$c" >/dev/null 2>&1; then wine=$c; break; fi
  done
fi
[ -n "$wine" ] || { echo "wine-run.sh: no wine64/wine found (apt-get install wine64)" >&2; exit 127; }
# One wineserver for the whole test run: by default it exits 3 s after its last client, and a test
# starting just then loses the race ("wine client error:0: recvmsg: Connection reset by peer",
# seen with ctest -j2). -p30 keeps it 30 s past the last client; when one is already running for
# this prefix the new one just exits. Its output goes nowhere, so it holds no caller's pipe.
server="${WINESERVER:-$(dirname "$(command -v "$wine")")/wineserver}"
[ -x "$server" ] && "$server" -p30 </dev/null >/dev/null 2>&1
out=$(mktemp "${TMPDIR:-/tmp}/wine-run.XXXXXX") || exit 125
trap 'rm -f "$out"' EXIT
run() {
  : >"$out"
  "$wine" "$@" </dev/null >"$out" 2>&1 &
  pid=$!
  tail -n +1 -s 0.02 -f --pid=$pid "$out"
  wait $pid
}
run "$@"
rc=$?
# If Wine itself failed (the server went away under the program, or Wine's loader could not start
# it), run it once more. Only Wine's own messages count, or a run that printed nothing at all (seen
# under load: exit code non-zero after 0.2 s with no output, not even GoogleTest's first line): a
# test that fails prints why and fails again, so a retry never hides a test's own failure, and a
# second Wine failure is reported as it is.
if [ $rc -ne 0 ] && { [ ! -s "$out" ] || head -n 5 "$out" | grep -q -e '^wine client error' -e '^wine: ' -e '^wineserver: '; }; then
  echo "wine-run.sh: Wine failed before or while starting the program; running it again" >&2
  run "$@"
  rc=$?
fi
exit $rc
