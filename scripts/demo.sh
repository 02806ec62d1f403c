#!/usr/bin/env bash
# demo.sh — the main job on the bundled samples: install, build, cook assets/ into cooked/, print
# what was cooked, and show it. The Pab clips are clip-only files: they are cooked against the
# cooked Pab skeleton, which is how a game's build would cook a clip library for one rig. The Pab
# animation graph (assets/Pab/pab.graph.json) cooks into one self-contained character,
# cooked/Pab/pab.ossa. With a display (DISPLAY set, not CI) ossa-view opens on it, driven by its
# graph; otherwise headless screenshots are written to cooked/screenshots/ (under xvfb-run when
# there is no display).
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh build
bin=build/bin
out=cooked
rm -rf "$out"

echo "== cooking characters"
"$bin/ossa-cook" assets/Pab/skeleton.fbx assets/CesiumMan assets/CapedMan assets/Fox assets/RiggedSimple \
  --root assets -o "$out" --report "$out/report-characters.json"
echo "== cooking Pab clips and mesh against the Pab skeleton"
"$bin/ossa-cook" assets/Pab/arnaud.fbx assets/Pab/walk.fbx assets/Pab/jog.fbx assets/Pab/run.fbx \
  assets/Pab/crossarms.fbx --skeleton "$out/Pab/skeleton.ossa" --root assets -o "$out" \
  --report "$out/report-pab-clips.json"

echo "== cooking the Pab character from its animation graph (docs/GRAPH.md)"
"$bin/ossa-cook" assets/Pab/pab.graph.json --root assets -o "$out" --report "$out/report-pab-graph.json"

echo "== what was cooked"
for f in "$out"/Pab/skeleton.ossa "$out"/Pab/pab.ossa "$out"/Fox/Fox.ossa; do
  "$bin/ossa-inspect" "$f"
  echo
done
echo "demo: cooked files are in $out/ (inspect any with $bin/ossa-inspect FILE.ossa [--json])"

pab=("$out/Pab/arnaud.ossa" "$out/Pab/walk.ossa" "$out/Pab/jog.ossa" "$out/Pab/run.ossa" "$out/Pab/crossarms.ossa")
if [ -n "${DISPLAY:-}" ] && [ -z "${CI:-}" ]; then
  echo "== ossa-view on Pab's graph: W walk, Shift+W run, C cross arms (close the window to finish)"
  "$bin/ossa-view" "$out/Pab/pab.ossa" --graph pab
else
  echo "== headless screenshots (no display, or CI)"
  shots="$out/screenshots"
  mkdir -p "$shots"
  xvfb=()
  [ -n "${DISPLAY:-}" ] || xvfb=(xvfb-run -a -s "-screen 0 1280x1024x24")
  "${xvfb[@]}" "$bin/ossa-view" "${pab[@]}" --clip walk --time 0.6 --size 960x540 --screenshot "$shots/pab-walk.png"
  "${xvfb[@]}" "$bin/ossa-view" "$out/Pab/pab.ossa" --graph pab --set speed=3.13 --set crossed_arms=true --time 2 \
    --size 960x540 --screenshot "$shots/pab-graph-jog-crossed-arms.png"
  "${xvfb[@]}" "$bin/ossa-view" "$out/Pab/pab.ossa" --graph pab --param look_weight=1 --param look_target=55,165,60 \
    --param ground_left=15 --time 2 --size 960x540 --show-procedural --screenshot "$shots/pab-graph-look-and-ground.png"
  "${xvfb[@]}" "$bin/ossa-view" "$out/Fox/fox_tail.ossa" --graph fox --time 1.5 --size 960x540 --show-procedural \
    --screenshot "$shots/fox-tail-spring.png"
  "${xvfb[@]}" "$bin/ossa-view" "$out/Fox/Fox.ossa" --clip Walk --crowd 9 --time 0.3 --size 960x540 --screenshot "$shots/fox-crowd.png"
  "${xvfb[@]}" "$bin/ossa-view" "$out/CesiumMan/CesiumMan.ossa" --time 0.5 --skeleton --size 960x540 --screenshot "$shots/cesium-man.png"
  "${xvfb[@]}" "$bin/ossa-view" "$out/CapedMan/CapedMan.ossa" --time 1.5 --yaw 150 --size 960x540 --screenshot "$shots/caped-man-cloth.png"
  echo "demo: screenshots in $shots/ (with a display, scripts/demo.sh opens the viewer instead)"
fi
