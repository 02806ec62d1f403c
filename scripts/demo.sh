#!/usr/bin/env bash
# demo.sh — the main job on the bundled samples: install, build, cook assets/ into cooked/, and
# print what was cooked. The Pab clips are clip-only files: they are cooked against the cooked Pab
# skeleton, which is how a game's build would cook a clip library for one rig. The Pab animation
# graph (assets/Pab/pab.graph.json) cooks into one self-contained character, cooked/Pab/pab.ossa.
set -euo pipefail
cd "$(dirname "$0")/.."
scripts/install-deps.sh
scripts/build.sh build
bin=build/bin
out=cooked
rm -rf "$out"

echo "== cooking characters"
"$bin/ossa-cook" assets/Pab/skeleton.fbx assets/CesiumMan assets/Fox assets/RiggedSimple \
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
