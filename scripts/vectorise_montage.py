"""Side-by-side picture of one photograph and its fits, with the benchmark's figures under each.

usage: python vectorise_montage.py PHOTO BENCH_DIR POINTS OUT.png

Reads BENCH_DIR/table.md and the renders scripts/vectorise-bench.sh left there
(STEM-POINTS-mesh.png, STEM-POINTS-grid.png, STEM-vtracer-photo.png) and writes a 2 x 2
montage at half size: the photograph, the quadtree mesh, the regular grid, vtracer's photo
preset. Needs Pillow.
"""

import pathlib
import sys

from PIL import Image, ImageDraw


def table_rows(path, stem):
    """The table's rows for one photograph: method -> (points, psnr, delta_e, bytes, seconds)."""
    rows = {}
    for line in pathlib.Path(path).read_text().splitlines():
        cells = [c.strip() for c in line.strip().strip("|").split("|")]
        if len(cells) == 7 and cells[0] == stem:
            rows[cells[1]] = cells[2:]
    return rows


def caption(title, row):
    points, psnr, delta_e, size, seconds = row
    pts = "" if points == "–" else f"{points} pts, "
    return f"{title}: {pts}{psnr} dB, dE00 {delta_e}, {int(size) / 1000:.1f} KB, {seconds} s"


def main():
    photo, bench, points, out = sys.argv[1:5]
    photo, bench = pathlib.Path(photo), pathlib.Path(bench)
    stem = photo.stem
    rows = table_rows(bench / "table.md", stem)
    panels = [
        (photo, f"{stem} ({photo.name})"),
        (bench / f"{stem}-{points}-mesh.png",
         caption("quadtree mesh", rows[f"quadtree mesh, {points}"])),
        (bench / f"{stem}-{points}-grid.png",
         caption("regular grid", rows[f"regular grid, {points}"])),
        (bench / f"{stem}-vtracer-photo.png", caption("vtracer photo", rows["vtracer photo"])),
    ]
    first = Image.open(panels[0][0])
    w, h = first.width // 2, first.height // 2
    bar = 16
    sheet = Image.new("RGB", (2 * w, 2 * (h + bar)), "white")
    draw = ImageDraw.Draw(sheet)
    for k, (path, text) in enumerate(panels):
        x, y = (k % 2) * w, (k // 2) * (h + bar)
        picture = Image.open(path).convert("RGB").resize((w, h), Image.LANCZOS)
        sheet.paste(picture, (x, y))
        draw.text((x + 4, y + h + 2), text, fill="black")
    sheet.save(out, optimize=True)
    print(out)


if __name__ == "__main__":
    main()
