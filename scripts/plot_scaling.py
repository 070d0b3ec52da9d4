#!/usr/bin/env python3
"""Plots the CSV of `cargo run --release -p gradmesh --example scaling` as an SVG.

Two log-log panels: render time against pixel count (one mesh), and render time against face
count (at 1024 px). Standard library only.

Usage: python3 scripts/plot_scaling.py scaling.csv [scaling.svg]   (CSV from stdin with "-")
"""

import csv
import math
import sys

W, H = 460, 360  # one panel
MARGIN = dict(left=70, right=20, top=40, bottom=55)


def read(path):
    f = sys.stdin if path == "-" else open(path, newline="")
    with f:
        return list(csv.DictReader(f))


def ticks(lo, hi):
    """Powers of ten (and 2, 5 between them when the range is short) spanning lo..hi."""
    a, b = math.floor(math.log10(lo)), math.ceil(math.log10(hi))
    steps = (1,) if b - a > 3 else (1, 2, 5)
    out = [m * 10**e for e in range(a, b + 1) for m in steps]
    return [t for t in out if lo <= t <= hi] or [lo, hi]


def label(v):
    for div, suffix in ((1e6, "M"), (1e3, "k")):
        if v >= div:
            return f"{v / div:g}{suffix}"
    return f"{v:g}"


def panel(x0, title, xlabel, xs, ys):
    """SVG elements of one log-log panel at horizontal offset x0."""
    lx = [math.log10(x) for x in xs]
    ly = [math.log10(y) for y in ys]
    xlo, xhi = min(lx) - 0.1, max(lx) + 0.1
    ylo, yhi = min(ly) - 0.2, max(ly) + 0.2
    pw = W - MARGIN["left"] - MARGIN["right"]
    ph = H - MARGIN["top"] - MARGIN["bottom"]
    left, top = x0 + MARGIN["left"], MARGIN["top"]

    def px(v):
        return left + (math.log10(v) - xlo) / (xhi - xlo) * pw

    def py(v):
        return top + ph - (math.log10(v) - ylo) / (yhi - ylo) * ph

    out = [
        f'<text x="{left + pw / 2}" y="22" text-anchor="middle" font-weight="bold">{title}</text>',
        f'<rect x="{left}" y="{top}" width="{pw}" height="{ph}" fill="none" stroke="#444"/>',
    ]
    for t in ticks(10**xlo, 10**xhi):
        x = px(t)
        out.append(f'<line x1="{x:.1f}" y1="{top}" x2="{x:.1f}" y2="{top + ph}" stroke="#ddd"/>')
        out.append(f'<text x="{x:.1f}" y="{top + ph + 16}" text-anchor="middle">{label(t)}</text>')
    for t in ticks(10**ylo, 10**yhi):
        y = py(t)
        out.append(f'<line x1="{left}" y1="{y:.1f}" x2="{left + pw}" y2="{y:.1f}" stroke="#ddd"/>')
        out.append(f'<text x="{left - 6}" y="{y + 4:.1f}" text-anchor="end">{label(t)}</text>')
    out.append(
        f'<text x="{left + pw / 2}" y="{H - 12}" text-anchor="middle">{xlabel}</text>'
    )
    out.append(
        f'<text transform="translate({x0 + 18},{top + ph / 2}) rotate(-90)" '
        f'text-anchor="middle">time (ms)</text>'
    )
    # A reference line of slope 1 (time proportional to x) through the first point, clipped
    # to the panel.
    lx_end = min(lx[-1], lx[0] + (yhi - ly[0]))
    out.append(
        f'<line x1="{px(xs[0]):.1f}" y1="{py(ys[0]):.1f}" x2="{px(10**lx_end):.1f}" '
        f'y2="{py(10 ** (ly[0] + lx_end - lx[0])):.1f}" stroke="#999" stroke-dasharray="4 3">'
        f"<title>proportional</title></line>"
    )
    out.append(
        f'<text x="{left + pw - 4}" y="{top + 14}" text-anchor="end" fill="#999">'
        f"dashed: time proportional to {xlabel}</text>"
    )
    pts = " ".join(f"{px(x):.1f},{py(y):.1f}" for x, y in zip(xs, ys))
    out.append(f'<polyline points="{pts}" fill="none" stroke="#1f77b4" stroke-width="2"/>')
    for x, y in zip(xs, ys):
        out.append(
            f'<circle cx="{px(x):.1f}" cy="{py(y):.1f}" r="3.5" fill="#1f77b4">'
            f"<title>{label(x)}: {y:.3g} ms</title></circle>"
        )
    return out


def main():
    if len(sys.argv) < 2:
        sys.exit(__doc__)
    rows = read(sys.argv[1])
    dest = sys.argv[2] if len(sys.argv) > 2 else "scaling.svg"
    series = {"pixels": [], "faces": []}
    for r in rows:
        series[r["series"]].append(r)
    body = []
    pix = sorted(series["pixels"], key=lambda r: int(r["pixels"]))
    if pix:
        body += panel(
            0,
            f"One mesh ({pix[0]['faces']} faces)",
            "pixels",
            [int(r["pixels"]) for r in pix],
            [float(r["ms"]) for r in pix],
        )
    fac = sorted(series["faces"], key=lambda r: int(r["faces"]))
    if fac:
        body += panel(
            W,
            f"Generated meshes at {fac[0]['width']}x{fac[0]['height']}",
            "faces",
            [int(r["faces"]) for r in fac],
            [float(r["ms"]) for r in fac],
        )
    svg = (
        f'<svg xmlns="http://www.w3.org/2000/svg" width="{2 * W}" height="{H}" '
        f'font-family="sans-serif" font-size="12">\n'
        f'<rect width="100%" height="100%" fill="white"/>\n' + "\n".join(body) + "\n</svg>\n"
    )
    with open(dest, "w") as f:
        f.write(svg)
    print(f"wrote {dest}")


if __name__ == "__main__":
    main()
