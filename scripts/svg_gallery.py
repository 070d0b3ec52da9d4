#!/usr/bin/env python3
"""Regenerates docs/gallery/svg/*.png: for each SVG mesh-gradient test file (the 7 W3C tests
and the 6 Inkscape samples in ../shared/realdata/meshgradient), Inkscape 1.2.2's render,
gradmesh's classic render and gradmesh's scheme render side by side, on white, scaled to
fit 240 x 240 pixels each.

Run from anywhere: scripts/svg_gallery.py (needs python3 with PIL). It builds the command
line (debug is fast enough for these sizes); set GRADMESH to use another binary.
"""

import os
import subprocess
import sys
import tempfile
from pathlib import Path

from PIL import Image, ImageDraw

ROOT = Path(__file__).resolve().parent.parent
DATA = ROOT.parent / "shared" / "realdata" / "meshgradient"
OUT = ROOT / "docs" / "gallery" / "svg"
PANEL = 240
FILES = [DATA / "wpt" / f"meshgradient-{n}.svg" for n in
         ["basic-001", "basic-002", "basic-003", "basic-004", "basic-005", "bicubic-001",
          "complex-001"]]
FILES += [DATA / "zectorio-mesh-gradient-js" / f"sample{k}.svg" for k in range(1, 7)]


def on_white(path):
    image = Image.open(path).convert("RGBA")
    white = Image.new("RGBA", image.size, (255, 255, 255, 255))
    image = Image.alpha_composite(white, image).convert("RGB")
    image.thumbnail((PANEL, PANEL), Image.LANCZOS)
    return image


def main():
    binary = os.environ.get("GRADMESH")
    if binary is None:
        subprocess.run(["cargo", "build", "--quiet", "-p", "gradmesh-cli"], cwd=ROOT, check=True)
        binary = str(ROOT / "target" / "debug" / "gradmesh")
    OUT.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        for svg in FILES:
            name = svg.stem
            panels = [on_white(DATA / "inkscape-1.2.2-renders" / f"{name}.png")]
            for mode in ["classic", "scheme"]:
                png = Path(tmp) / f"{name}-{mode}.png"
                subprocess.run([binary, "render", str(svg), "-o", str(png), "--svg-mesh", mode],
                               check=True, stderr=subprocess.DEVNULL)
                panels.append(on_white(png))
            width = sum(p.width for p in panels) + 2 * 8
            height = max(p.height for p in panels) + 18
            montage = Image.new("RGB", (width, height), (255, 255, 255))
            draw = ImageDraw.Draw(montage)
            x = 0
            for label, panel in zip(["Inkscape 1.2.2", "gradmesh classic", "gradmesh scheme"],
                                    panels):
                montage.paste(panel, (x, 18))
                draw.text((x + 2, 2), label, fill=(0, 0, 0))
                x += panel.width + 8
            target = OUT / f"{name}.png"
            montage.save(target, optimize=True)
            print(target)


if __name__ == "__main__":
    sys.exit(main())
