#!/usr/bin/env bash
# The vectoriser's benchmark (docs/vectorise.md): the five photographs of
# ../shared/realdata/images at about 256 and 1024 control points, for the free-topology fit
# (`gradmesh vectorise`), the regular grid with its colours fitted by the same least squares,
# and vtracer 0.6.15 (PyPI) at its presets. Prints one Markdown table: points, PSNR over 8-bit
# sRGB, mean CIEDE2000, gzip -9 bytes (of the JSON, of vtracer's SVG), time.
#
# The meshes are rendered by gradmesh's renderer, vtracer's SVG files by resvg 0.49 (the
# version the command line links), both inside the example at the photograph's size, and all
# are measured by the same code.
#
# usage: scripts/vectorise-bench.sh [OUT_DIR] [fast|default|best]
#   OUT_DIR (default /tmp/vectorise-bench) receives the renders, vtracer's SVG files and
#   table.md; VTRACER_VENV (default /tmp/vtracer-venv) is the Python venv made for vtracer
#   and Pillow (the side-by-side picture of coffee at 256 points, docs/vectorise-coffee-256.png).
set -euo pipefail
root=$(cd "$(dirname "$0")/.." && pwd)
out=$(mkdir -p "${1:-/tmp/vectorise-bench}" && cd "${1:-/tmp/vectorise-bench}" && pwd)
quality=${2:-default}
venv=${VTRACER_VENV:-/tmp/vtracer-venv}
photos="$root/../shared/realdata/images"
[ -d "$photos" ] || { echo "no photographs at $photos" >&2; exit 1; }

if [ ! -x "$venv/bin/python" ]; then python3 -m venv "$venv"; fi
"$venv/bin/pip" install --quiet vtracer==0.6.15 pillow

cd "$root"
# vtracer at its colour presets (its command line's `photo` and `poster`, and the defaults of
# its Python binding), timed around the conversion alone.
"$venv/bin/python" - "$photos" "$out" <<'EOF'
import sys, time, pathlib, vtracer
photos, out = pathlib.Path(sys.argv[1]), pathlib.Path(sys.argv[2])
presets = {
    "photo": dict(filter_speckle=10, color_precision=8, layer_difference=48,
                  corner_threshold=180, length_threshold=4.0, max_iterations=10,
                  splice_threshold=45, path_precision=2),
    "poster": dict(filter_speckle=4, color_precision=8, layer_difference=16,
                   corner_threshold=60, length_threshold=4.0, max_iterations=10,
                   splice_threshold=45, path_precision=2),
    "default": dict(path_precision=2),
}
with open(out / "vtracer-times.tsv", "w") as times:
    for name in ["coffee.png", "chelsea.png", "rocket.jpg", "astronaut.png", "grace_hopper.jpg"]:
        stem = name.split(".")[0]
        for preset, options in presets.items():
            svg = out / f"{stem}-vtracer-{preset}.svg"
            start = time.perf_counter()
            vtracer.convert_image_to_svg_py(str(photos / name), str(svg), colormode="color",
                                            hierarchical="stacked", mode="spline", **options)
            times.write(f"{stem}\t{preset}\t{time.perf_counter() - start:.3f}\n")
EOF
uptime | tee "$out/uptime.txt"
cargo run --release --quiet -p gradmesh --example vectorise_table -- \
  --out "$out" --vtracer "$out" --quality "$quality" | tee "$out/table.md"
uptime | tee -a "$out/uptime.txt"
"$venv/bin/python" "$root/scripts/vectorise_montage.py" "$photos/coffee.png" "$out" 256 \
  "$root/docs/vectorise-coffee-256.png"
