#!/usr/bin/env bash
# Regenerates docs/gallery/*.png: every example in examples/ and the paper authors' real
# artwork from ../shared/realdata (their Tucan and Paprika pictures are several meshes; the
# authors number layers from the top, so they are listed bottom first here).
# Run from anywhere: scripts/gallery.sh
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --quiet -p gradmesh-cli
bin=target/release/gradmesh
out=docs/gallery
mkdir -p "$out"

for f in examples/*.json; do
  name=$(basename "$f" .json)
  "$bin" render "$f" -o "$out/$name.png" --width 400 --background white --boundary
  echo "$out/$name.png"
done

real=../shared/realdata/gradientmeshimproved-off
"$bin" render "$real"/Tucan_Tucan_Layer{5,4,3,2,1,0}.off -o "$out/tucan.png" --width 800
"$bin" render "$real"/Paprika_Paprika_layer{2,1,0}.off -o "$out/paprika.png" --width 400 --background white
"$bin" render "$real/paprikaOneMesh.off" -o "$out/paprika-one-mesh.png" --width 400 --background white
"$bin" render "$real/Glasses.off" -o "$out/glasses.png" --width 600 --background white
echo "$out/tucan.png $out/paprika.png $out/paprika-one-mesh.png $out/glasses.png"
