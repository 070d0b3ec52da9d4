"""Fit the control colours of a gradient mesh to a photograph by least squares.

The limit colours of a refined level are a linear map of the control colours
(``gradmesh.limit_matrix``), so the colours that best match a picture at the limit surface's
points are one sparse least-squares solve: the first step of vectorising a photograph.

    python examples/python/fit_photo.py PHOTO [--grid 12] [--level 4] [--out fitted.png]

Prints the RMS error (in 8-bit sRGB levels) of the rendered mesh against the photograph, for
the fitted colours and for the photograph's colours sampled at the control points.
"""

import argparse

import numpy as np
from scipy.optimize import lsq_linear
from PIL import Image

import gradmesh


def grid_mesh(width, height, n):
    """An n x n grid of quads over the picture (pixel units, y down), colours in sRGB."""
    xs, ys = np.linspace(0, width, n + 1), np.linspace(0, height, n + 1)
    points = np.array([(x, y) for y in ys for x in xs])
    faces = [[j * (n + 1) + i, j * (n + 1) + i + 1, (j + 1) * (n + 1) + i + 1, (j + 1) * (n + 1) + i]
             for j in range(n) for i in range(n)]
    return gradmesh.Mesh(points, faces, np.full((len(points), 3), 0.5), colour_space="srgb")


def sample(photo, xy):
    """The photograph's colour at each point (nearest pixel)."""
    h, w, _ = photo.shape
    i = np.clip(np.floor(xy[:, 1]).astype(int), 0, h - 1)
    j = np.clip(np.floor(xy[:, 0]).astype(int), 0, w - 1)
    return photo[i, j]


def fit(mesh, photo, level):
    """Control colours whose limit colours at level `level` best match the photograph."""
    matrix = gradmesh.limit_matrix(mesh, level)           # limit colours = matrix @ control
    target = sample(photo, gradmesh.refine(mesh, level, limit=True)["points"])
    # One bounded least-squares problem per channel: sRGB values stay within 0..1.
    colours = np.column_stack([lsq_linear(matrix, target[:, c], bounds=(0, 1), lsmr_tol="auto").x
                               for c in range(3)])
    return mesh.with_colours(colours)


def rms(mesh, photo):
    """RMS difference, in 8-bit levels, between the rendered mesh and the photograph."""
    h, w, _ = photo.shape
    pixels = gradmesh.render(mesh, w, h, (0, 0, w, h), dither=False)
    return float(np.sqrt(np.mean((pixels[..., :3] / 255.0 - photo) ** 2)) * 255.0)


def main(argv=None):
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("photo")
    parser.add_argument("--grid", type=int, default=12, help="quads along each side")
    parser.add_argument("--level", type=int, default=4, help="level whose limit points are fitted")
    parser.add_argument("--width", type=int, default=256, help="width the photograph is scaled to")
    parser.add_argument("--out", help="write the fitted mesh's render here (.png, .pdf, .svg)")
    args = parser.parse_args(argv)

    with Image.open(args.photo) as image:
        image = image.convert("RGB")
        height = round(image.height * args.width / image.width)
        photo = np.asarray(image.resize((args.width, height), Image.LANCZOS)) / 255.0
    mesh = grid_mesh(args.width, height, args.grid)
    sampled = mesh.with_colours(sample(photo, mesh.points))
    fitted = fit(mesh, photo, args.level)
    errors = {"sampled at the control points": rms(sampled, photo), "least squares": rms(fitted, photo)}
    for name, error in errors.items():
        print(f"{name}: RMS error {error:.2f} (8-bit levels), {len(mesh)} control points")
    if args.out:
        gradmesh.export(fitted, args.out, args.width, height, (0, 0, args.width, height))
    return errors


if __name__ == "__main__":
    main()
