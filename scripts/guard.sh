#!/usr/bin/env bash
# Behaviour guard for restructuring: writes every output that must not change into a folder
# and prints one checksum line per file. Compare two runs with diff:
#   scripts/guard.sh target/release/gradmesh /tmp/before > /tmp/before.sums
#   (change the code, rebuild)
#   scripts/guard.sh target/release/gradmesh /tmp/after > /tmp/after.sums
#   diff <(cut -d' ' -f1 /tmp/before.sums) <(cut -d' ' -f1 /tmp/after.sums)
# Outputs: `refine` at levels 1-4 and `--limit` (level 3) of every example and every real OFF
# file; `render` at 8 and 16 bits of the gallery's examples and the real artwork.
set -euo pipefail
bin=${1:?usage: guard.sh GRADMESH_BINARY OUT_DIR}
out=${2:?usage: guard.sh GRADMESH_BINARY OUT_DIR}
cd "$(dirname "$0")/.."
real=../shared/realdata/gradientmeshimproved-off
test -d "$real" || { echo "guard.sh: $real is missing" >&2; exit 1; }
mkdir -p "$out"
inputs=(examples/*.json "$real"/*.off)
for f in "${inputs[@]}"; do
  name=$(basename "$f")
  for k in 1 2 3 4; do
    "$bin" refine "$f" -o "$out/$name.l$k.obj" --levels "$k" 2>/dev/null \
      || echo "refused" > "$out/$name.l$k.obj"
  done
  "$bin" refine "$f" -o "$out/$name.limit.obj" --levels 3 --limit 2>/dev/null \
    || echo "refused" > "$out/$name.limit.obj"
done
render() { # name, then render arguments
  local name=$1; shift
  "$bin" render "$@" -o "$out/$name.8.png" 2>/dev/null
  "$bin" render "$@" -o "$out/$name.16.png" --bits 16 2>/dev/null
}
for f in examples/*.json; do
  render "$(basename "$f" .json)" "$f" --width 400 --background white --boundary
  render "$(basename "$f" .json)-plain" "$f" --width 300
done
render tucan "$real"/Tucan_Tucan_Layer{5,4,3,2,1,0}.off --width 800
render paprika "$real"/Paprika_Paprika_layer{2,1,0}.off --width 400 --background white
render paprika-one-mesh "$real/paprikaOneMesh.off" --width 400 --background white
render glasses "$real/Glasses.off" --width 600 --background white
cd "$out" && sha256sum -- * | awk '{print $1, $2}'
