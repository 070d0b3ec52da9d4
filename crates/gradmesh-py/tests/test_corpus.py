"""The Rust test corpus of malformed and hostile inputs (crates/gradmesh/tests/corpus), through
Python: read, check each layer, refine it to the limit at level 3, and render at one pixel per
unit. Each input gives its expected outcome (the `.expected` sidecar: "ok", or text of the
error); a failure is a gradmesh.Error, never a crash."""

import math

import numpy as np
import pytest

import gradmesh
from conftest import CORPUS, require

INPUTS = sorted(p for p in require(CORPUS).iterdir() if p.suffix != ".expected")


def bounds(doc):
    """The control points and explicit handle tips of every layer (the renderer's bounds)."""
    xy = []
    for mesh in doc.layers:
        points = mesh.points
        xy.extend(points)
        xy.extend(points[a] + np.array(h) for (a, _), h in mesh.handles.items() if a < len(points))
    if not xy:
        return None
    xy = np.array(xy)
    return xy.min(axis=0), xy.max(axis=0)


def run(path):
    doc = gradmesh.read(path)
    for mesh in doc.layers:
        mesh.warnings()
        limit = gradmesh.refine(mesh, 3, limit=True)
        assert all(np.isfinite(a).all() for a in limit.values())
    box = bounds(doc)
    if box is not None:
        (x0, y0), (x1, y1) = box[0] - 0.5, box[1] + 0.5
        side = lambda x: min(max(math.ceil(x), 1), 2**32 - 1)
        image = gradmesh.render(doc, side(x1 - x0), side(y1 - y0), (x0, y0, x1, y1), bits=32)
        assert np.isfinite(image).all()


def test_the_corpus_is_there():
    assert len(INPUTS) > 50


@pytest.mark.parametrize("path", INPUTS, ids=[p.name for p in INPUTS])
def test_corpus_input_gives_its_expected_outcome(path):
    expected = path.with_name(path.name + ".expected").read_text().strip()
    if expected == "ok":
        run(path)
        return
    with pytest.raises(gradmesh.Error) as caught:
        run(path)
    message = str(caught.value)
    # Read errors carry the file (`name:line: ...`); errors of a layer name it in the sidecar
    # (`name: layer 0: ...`) but not here, where the layer is checked alone.
    assert expected in message or message in expected, f"{message!r} vs {expected!r}"
