#!/usr/bin/env python3
"""Writes the example meshes of examples/*.json (the native format, docs/format.md).

Each example shows one thing the paper shows; the figure numbers refer to Lieng et al. 2017.
Run from the repository root: python3 examples/generate.py, then write each file in the
canonical layout (tests/integration/formats.rs checks that reading and writing an example changes no byte):
for f in examples/*.json; do cargo run -q -p gradmesh-cli -- convert --force "$f" -o "$f"; done
"""
import json
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))


def write(name, layers, note):
    doc = {"format": "gradmesh", "version": 1, "layers": layers}
    with open(os.path.join(HERE, name + ".json"), "w") as f:
        json.dump(doc, f, indent=2)
        f.write("\n")
    print(f"{name}.json: {note}")


def layer(points, faces, name=None, edges=None, wedges=None, **extra):
    out = {}
    if name:
        out["name"] = name
    out.update(extra)
    out["points"] = points
    out["faces"] = faces
    if edges:
        out["edges"] = edges
    if wedges:
        out["wedges"] = wedges
    return out


def pt(x, y, colour, handles=None, **extra):
    p = {"position": [round(x, 6), round(y, 6)], "colour": colour}
    p.update(extra)
    if handles:
        p["handles"] = [[to, round(dx, 6), round(dy, 6)] for to, dx, dy in handles]
    return p


def grid(nx, ny, x0, y0, w, h, colour, warp=lambda x, y: (x, y)):
    """A rectangular gradient mesh of nx x ny points, as in Illustrator."""
    points = []
    for j in range(ny):
        for i in range(nx):
            x, y = warp(x0 + w * i / (nx - 1), y0 + h * j / (ny - 1))
            points.append(pt(x, y, colour(i, j)))
    faces = []
    for j in range(ny - 1):
        for i in range(nx - 1):
            v = j * nx + i
            faces.append([v, v + 1, v + nx + 1, v + nx])
    return points, faces


PALETTE = ["#e63946", "#f1c453", "#2a9d8f", "#264653", "#8ecae6", "#ffb703", "#fb8500",
           "#6a4c93", "#ffffff", "#1d3557"]


def rectangle():
    cols = [["#1d3557", "#457b9d", "#a8dadc", "#f1faee"],
            ["#e63946", "#ffb703", "#8ecae6", "#457b9d"],
            ["#f1c453", "#fb8500", "#e63946", "#1d3557"],
            ["#2a9d8f", "#f1faee", "#ffb703", "#6a4c93"]]
    warp = lambda x, y: (x + 18 * math.sin(y / 60), y + 14 * math.sin(x / 70))
    points, faces = grid(4, 4, 20, 20, 360, 260, lambda i, j: cols[j][i], warp)
    write("rectangle", [layer(points, faces, "rectangle")],
          "a rectangular 4x4-point mesh with curved edges, as Illustrator makes")


def annulus():
    n, rings = 16, 3
    points, faces = [], []
    for r in range(rings):
        radius = 70 + 55 * r
        for k in range(n):
            a = 2 * math.pi * k / n
            colour = ["#ffffff", "#f1c453", "#e63946"][r] if k % 4 else ["#8ecae6", "#2a9d8f", "#264653"][r]
            points.append(pt(200 + radius * math.cos(a), 200 + radius * math.sin(a), colour))
    for r in range(rings - 1):
        for k in range(n):
            a, b = r * n + k, r * n + (k + 1) % n
            faces.append([a, b, b + n, a + n])
    write("annulus", [layer(points, faces, "annulus")],
          "an annulus: a rectangle looped round, the other shape Illustrator allows")


def non_rectangular():
    """Figure 1 (top right): a triangle fan and a pentagon, impossible as rectangular grids."""
    pts, faces = [], []
    # Triangle split into three quads around a centre point (valence-3 centre).
    cx, cy = 110, 170
    corners = [(cx + 95 * math.cos(a), cy + 95 * math.sin(a)) for a in
               [-math.pi / 2, math.pi / 6, 5 * math.pi / 6]]
    mids = [((corners[i][0] + corners[(i + 1) % 3][0]) / 2, (corners[i][1] + corners[(i + 1) % 3][1]) / 2)
            for i in range(3)]
    pts.append(pt(cx, cy, "#ffffff"))
    for i in range(3):
        pts.append(pt(*corners[i], ["#e63946", "#2a9d8f", "#ffb703"][i]))
        pts.append(pt(*mids[i], ["#6a4c93", "#8ecae6", "#fb8500"][i]))
    # Points: 0 centre, 1 c0, 2 m0, 3 c1, 4 m1, 5 c2, 6 m2
    faces = [[0, 6, 1, 2], [0, 2, 3, 4], [0, 4, 5, 6]]
    tri = layer(pts, faces, "triangle")
    # A pentagon: one five-sided face surrounded by five quads.
    pts, faces = [], []
    px, py = 330, 170
    for k in range(5):
        a = -math.pi / 2 + 2 * math.pi * k / 5
        pts.append(pt(px + 40 * math.cos(a), py + 40 * math.sin(a), PALETTE[k]))
    for k in range(5):
        a = -math.pi / 2 + 2 * math.pi * k / 5
        pts.append(pt(px + 100 * math.cos(a), py + 100 * math.sin(a), "#1d3557" if k % 2 else "#f1faee"))
    faces.append([0, 1, 2, 3, 4])
    for k in range(5):
        faces.append([k, k + 5, (k + 1) % 5 + 5, (k + 1) % 5])
    pent = layer(pts, faces, "pentagon")
    write("non-rectangular", [tri, pent],
          "Figure 1: layouts that a rectangular grid cannot make (a three-quad triangle, a pentagon)")


def sparse_irregular():
    """Figure 2: a sparse mesh with n-gons and vertices of valence 3 and 5."""
    P = [(60, 60), (200, 30), (340, 70), (380, 200), (320, 330), (190, 370), (60, 320), (30, 190),
         (150, 150), (260, 160), (210, 260), (120, 250)]
    C = ["#264653", "#2a9d8f", "#8ecae6", "#264653", "#6a4c93", "#e63946", "#fb8500", "#f1c453",
         "#ffffff", "#ffb703", "#e63946", "#2a9d8f"]
    pts = [pt(x, y, c) for (x, y), c in zip(P, C)]
    faces = [[0, 1, 9, 8], [1, 2, 3, 9], [9, 3, 4, 10], [10, 4, 5], [11, 10, 5, 6],
             [7, 8, 9, 10, 11], [0, 8, 7], [7, 11, 6]]
    write("sparse-irregular", [layer(pts, faces, "sparse")],
          "Figure 2: a sparse, topologically unrestricted mesh (a pentagon, triangles, valence 3 and 5)")


def edge_kinds():
    """Figure 3: smooth, crease (C0) and discontinuous (C-1) edges in one mesh."""
    cols = lambda i, j: ["#264653", "#2a9d8f", "#e9c46a", "#f4a261", "#e76f51"][i] if j != 1 else \
        ["#e63946", "#f1faee", "#a8dadc", "#457b9d", "#1d3557"][i]
    points, faces = grid(5, 3, 20, 20, 400, 240, cols)
    nx = 5
    edges = []
    # A crease along the vertical line i = 1.
    for j in range(2):
        edges.append({"points": [j * nx + 1, (j + 1) * nx + 1], "kind": "crease"})
    # A discontinuity along the vertical line i = 3, with other colours on its right side.
    wedges = []
    for j in range(2):
        edges.append({"points": [j * nx + 3, (j + 1) * nx + 3], "kind": "discontinuous"})
    for j in range(3):
        face = min(j, 1) * (nx - 1) + 3
        wedges.append({"point": j * nx + 3, "face": face, "colour": ["#ffb703", "#6a4c93", "#ffb703"][j]})
    write("edge-kinds", [layer(points, faces, "edges", edges=edges, wedges=wedges)],
          "Figure 3: smooth edges, a crease (i = 1) and a discontinuity with two colours (i = 3)")


def handles(name, scale, note):
    """Figures 4 and 6: the same mesh with short or long handles."""
    pts = [pt(40, 200, "#1d3557"), pt(200, 40, "#e63946"), pt(360, 200, "#1d3557"),
           pt(200, 360, "#f1c453"), pt(200, 200, "#ffffff")]
    faces = [[0, 1, 4], [1, 2, 4], [2, 3, 4], [3, 0, 4]]
    for i, p in enumerate(pts):
        hs = []
        for f in faces:
            k = f.index(i) if i in f else None
            if k is None:
                continue
            for nb in (f[(k + 1) % 3], f[(k - 1) % 3]):
                if any(h[0] == nb for h in hs):
                    continue
                q = pts[nb]["position"]
                d = (q[0] - p["position"][0], q[1] - p["position"][1])
                hs.append((nb, d[0] * scale, d[1] * scale))
        p["handles"] = [[to, round(dx, 6), round(dy, 6)] for to, dx, dy in hs]
    write(name, [layer(pts, faces, name)], note)


def fold(name, inner, note):
    """Figure 9: a concave mesh folds; making it more convex fixes it."""
    pts = [pt(40, 40, "#264653"), pt(360, 40, "#2a9d8f"), pt(360, 360, "#e9c46a"),
           pt(40, 360, "#e76f51"), pt(inner, 200, "#ffffff")]
    faces = [[0, 1, 2, 4], [2, 3, 0, 4]]
    long = [[1, 200.0, 0.0], [3, 0.0, 200.0]]
    pts[0]["handles"] = long
    write(name, [layer(pts, faces, name)], note)


def irregular_vertex(name, spread, note):
    """Figure 13 (bottom): the colour of a valence-5 vertex spreads as its handles say."""
    pts = [pt(200, 200, "#e63946")]
    for k in range(5):
        a = -math.pi / 2 + 2 * math.pi * k / 5
        pts.append(pt(200 + 110 * math.cos(a), 200 + 110 * math.sin(a), "#1d3557"))
    for k in range(5):
        a = -math.pi / 2 + 2 * math.pi * (k + 0.5) / 5
        pts.append(pt(200 + 180 * math.cos(a), 200 + 180 * math.sin(a), "#a8dadc"))
    faces = [[0, 1 + k, 6 + k, 1 + (k + 1) % 5] for k in range(5)]
    hs = []
    for k in range(5):
        q = pts[1 + k]["position"]
        s = spread[k]
        hs.append((1 + k, (q[0] - 200) * s, (q[1] - 200) * s))
    pts[0]["handles"] = [[to, round(dx, 6), round(dy, 6)] for to, dx, dy in hs]
    write(name, [layer(pts, faces, name)], note)


def multires():
    """Figure 10: detail added to the sparse mesh of Figure 2 by a few colour edits after two
    steps (level 2) and one after three, geometry edited on the control mesh only."""
    P = [(60, 60), (200, 30), (340, 70), (380, 200), (320, 330), (190, 370), (60, 320), (30, 190),
         (150, 150), (260, 160), (210, 260), (120, 250)]
    C = ["#264653", "#2a9d8f", "#8ecae6", "#264653", "#6a4c93", "#e63946", "#fb8500", "#f1c453",
         "#ffffff", "#ffb703", "#e63946", "#2a9d8f"]
    pts = [pt(x, y, c) for (x, y), c in zip(P, C)]
    faces = [[0, 1, 9, 8], [1, 2, 3, 9], [9, 3, 4, 10], [10, 4, 5], [11, 10, 5, 6],
             [7, 8, 9, 10, 11], [0, 8, 7], [7, 11, 6]]
    edits = [
        # A dark eye in the pentagon, pinned outright, with a white glint one level down.
        {"level": 2, "face": 5, "point": 8, "at": [3, 3], "colour": "#1d3557"},
        {"level": 3, "face": 5, "point": 8, "at": [5, 5], "colour": "#ffffff"},
        # A band of shade across the upper right quad, relative to what the coarse mesh gives.
        {"level": 2, "face": 1, "point": 2, "at": [1, 2], "colour_offset": [-30, 0, 0]},
        {"level": 2, "face": 1, "point": 2, "at": [2, 2], "colour_offset": [-30, 0, 0]},
        {"level": 2, "face": 1, "point": 2, "at": [3, 2], "colour_offset": [-30, 0, 0]},
        # A warm spot in the lower left quad and a faded one in the triangle at the bottom.
        {"level": 2, "face": 4, "point": 6, "at": [2, 2], "colour": "#ffd166"},
        {"level": 2, "face": 3, "point": 5, "at": [2, 2], "opacity": 0.2},
    ]
    write("multires", [layer(pts, faces, "multires", fine_edits="colour-only", edits=edits)],
          "Figure 10: a few colour edits after two subdivision steps add detail to a sparse mesh")


if __name__ == "__main__":
    rectangle()
    annulus()
    non_rectangular()
    sparse_irregular()
    edge_kinds()
    handles("handles-short", 0.12, "Figures 4 and 6: short handles keep each colour close to its point")
    handles("handles-long", 0.45, "Figures 4 and 6: long handles spread each colour further")
    fold("fold", 300, "Figure 9 (left): a concave mesh with long handles folds over itself")
    fold("fold-fixed", 170, "Figure 9 (right): the same mesh made more convex: no fold")
    irregular_vertex("irregular-vertex", [0.33, 0.33, 0.33, 0.33, 0.33],
                     "Figure 13: a valence-5 vertex with default handles")
    multires()
    irregular_vertex("irregular-vertex-spread", [0.45, 0.1, 0.45, 0.1, 0.45],
                     "Figure 13: the same vertex, long handles on three edges spread its red there")
