"""Meshes and documents: arrays out and back in exactly, JSON and file round trips, refinement,
and bad input raising gradmesh.Error with its place."""

import warnings

import numpy as np
import pytest

import gradmesh
from conftest import example

SQUARE = dict(
    points=np.array([[0.0, 0.0], [100.0, 0.0], [100.0, 80.0], [0.0, 80.0], [50.0, 140.0]]),
    faces=[[0, 1, 2, 3], [3, 2, 4]],
    colours=np.array(
        [[50.0, 60.0, 40.0], [90.0, -10.0, 80.0], [40.0, 10.0, -50.0], [70.0, 0.0, 0.0], [30.0, 5.0, 5.0]]
    ),
)


def test_arrays_round_trip_exactly():
    rng = np.random.default_rng(7)
    points = SQUARE["points"] + rng.normal(scale=1e-3, size=(5, 2))
    colours = rng.uniform(0.0, 1.0, size=(5, 3))
    opacity = rng.uniform(0.2, 1.0, size=5)
    mesh = gradmesh.Mesh(points, SQUARE["faces"], colours, opacity, colour_space="srgb", name="m")
    assert np.array_equal(mesh.points, points) and mesh.points.dtype == np.float64
    assert np.array_equal(mesh.colours, colours)
    assert np.array_equal(mesh.opacity, opacity)
    assert [f.tolist() for f in mesh.faces] == SQUARE["faces"]
    assert mesh.face_offsets.tolist() == [0, 4, 7]
    assert mesh.face_points.tolist() == [0, 1, 2, 3, 3, 2, 4]
    assert (mesh.colour_space, mesh.name, len(mesh)) == ("srgb", "m", 5)
    again = gradmesh.Mesh(mesh.points, mesh.faces, mesh.colours, mesh.opacity, colour_space="srgb", name="m")
    assert again == mesh


def test_json_and_file_round_trips(tmp_path):
    mesh = gradmesh.Mesh(
        **SQUARE,
        edges={(1, 2): ("crease", 1.5), (2, 3): "discontinuous"},
        handles={(0, 1): (20.0, 5.0)},
        corners=[4],
        first_step="binary",
    )
    assert mesh.edges == {(1, 2): ("crease", 1.5), (2, 3): ("discontinuous", None)}
    assert mesh.handles == {(0, 1): (20.0, 5.0)}
    assert mesh.corners.tolist() == [False, False, False, False, True]
    doc = gradmesh.Document([mesh, mesh.with_colours(SQUARE["colours"] * 0.5)])
    back = gradmesh.Document.from_json(doc.to_json())
    assert back == doc
    for a, b in zip(back.layers, doc.layers):
        assert np.array_equal(a.points, b.points) and np.array_equal(a.colours, b.colours)
    doc.write(tmp_path / "doc.json")
    assert gradmesh.read(tmp_path / "doc.json") == doc
    with pytest.raises(gradmesh.Error, match=r"\.json"):
        doc.write(tmp_path / "doc.off")


def test_files_of_every_format_read():
    assert len(gradmesh.read(example("multires.json")).layers[0].edits) == 7
    for name in ["rectangle.json", "annulus.json"]:
        doc = gradmesh.read(example(name))
        assert len(doc) >= 1 and len(doc.layers[0]) > 0


def test_with_colours_keeps_everything_else():
    mesh = gradmesh.read(example("edge-kinds.json")).layers[0]
    grey = np.full((len(mesh), 3), [50.0, 0.0, 0.0])
    recoloured = mesh.with_colours(grey, opacity=np.full(len(mesh), 0.5))
    assert np.array_equal(recoloured.colours, grey)
    assert np.array_equal(recoloured.opacity, np.full(len(mesh), 0.5))
    assert np.array_equal(recoloured.points, mesh.points)
    assert recoloured.edges == mesh.edges and recoloured.handles == mesh.handles
    moved = mesh.with_points(mesh.points + 3.0)
    assert np.array_equal(moved.points, mesh.points + 3.0)


def test_refine_gives_levels_and_limits():
    mesh = gradmesh.Mesh(**SQUARE)
    level0 = gradmesh.refine(mesh, 0)
    assert np.array_equal(level0["points"], SQUARE["points"])
    level2 = gradmesh.refine(mesh, 2)
    faces = np.diff(level2["face_offsets"])
    assert (faces == 4).all(), "level 2 is all quads"
    assert level2["points"].shape == (len(level2["opacity"]), 2)
    assert level2["face_points"].max() < len(level2["points"])
    limit = gradmesh.refine(mesh, 1, limit=True)
    # Condition 1: control points keep their colour in the limit (at level 1, point v is
    # vertex v).
    assert np.allclose(limit["colours"][:5], SQUARE["colours"], atol=1e-9)
    binary = gradmesh.refine(mesh, 1, first_step="binary")
    assert len(binary["points"]) != len(gradmesh.refine(mesh, 1)["points"])
    interpolated = gradmesh.refine(mesh, 1, limit=True, interpolate_positions=True)
    assert np.allclose(interpolated["points"][:5], SQUARE["points"], atol=1e-9)


def bad(**changes):
    args = dict(SQUARE)
    args.update(changes)
    return args


@pytest.mark.parametrize(
    "args, message",
    [
        (bad(points=np.zeros((5, 3))), r"points: shape \[5, 3\], expected \(N, 2\)"),
        (bad(colours=np.zeros((4, 3))), r"colours: shape \[4, 3\], expected \(5, 3\)"),
        (bad(points=SQUARE["points"] * [1, np.nan]), r"points\[0, 1\] is NaN"),
        (bad(colours=np.where(np.eye(5, 3) > 0, np.inf, 1.0)), r"colours\[0, 0\] is inf"),
        (bad(points=[["a", "b"]] * 5), "points: cannot be read as an array of numbers"),
        (bad(faces=[[0, 1, 2, 3], [3, 2, 9]]), "face 1: corner 2 refers to point 9"),
        (bad(faces=[[0, 1, 2, 3], [3, 2, -4]]), r"faces\[1\]\[2\] is -4"),
        (bad(faces=[[0, 1, 2, 3], [3, 2.5, 4]]), r"faces\[1\]: not a sequence of integers"),
        (bad(faces=7), "faces: expected a sequence"),
        (bad(faces=[[0, 1, 2, 3], [2, 3, 4]]), "wound inconsistently"),
        (bad(faces=[[0, 1]]), "face 0"),
        (dict(SQUARE, opacity=np.full(5, 2.0)), "opacity"),
        (dict(SQUARE, colour_space="cmyk"), "colour_space"),
        (dict(SQUARE, edges={(0, 2): "crease"}), "edge tag names edge 0-2"),
        (dict(SQUARE, edges={(0, 1): "wobbly"}), "wobbly"),
        (dict(SQUARE, handles={(0, 1): (1e300, 0.0)}), "handle 0->1 x: 1e300 is beyond"),
        (dict(SQUARE, handles={(0, 2): (1.0, 0.0)}), "handle of point 0 names edge 0-2"),
        (dict(SQUARE, corners=[9]), "corners: point 9"),
        (dict(SQUARE, first_step="quaternary"), "first_step"),
    ],
)
def test_bad_meshes_raise_errors_naming_the_place(args, message):
    with pytest.raises(gradmesh.Error, match=message):
        gradmesh.Mesh(**args)


def test_errors_are_value_errors_and_files_are_located(tmp_path):
    assert issubclass(gradmesh.Error, ValueError)
    path = tmp_path / "broken.json"
    path.write_text('{"format": "gradmesh", "version": 1, "layers": [{"points": [')
    with pytest.raises(gradmesh.Error, match="broken.json:1"):
        gradmesh.read(path)
    with pytest.raises(gradmesh.Error, match="missing.off"):
        gradmesh.read(tmp_path / "missing.off")
    with pytest.raises(gradmesh.Error, match="extension"):
        gradmesh.read(tmp_path / "picture.png")
    with pytest.raises(gradmesh.Error):
        gradmesh.Document.from_json("[1, 2]")


def test_warnings_go_through_the_warnings_module():
    points = np.vstack([SQUARE["points"], [[500.0, 500.0]]])
    colours = np.vstack([SQUARE["colours"], [[50.0, 0.0, 0.0]]])
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        mesh = gradmesh.Mesh(points, SQUARE["faces"], colours)
    assert any(
        issubclass(w.category, gradmesh.MeshWarning) and "point 5 is not used" in str(w.message)
        for w in caught
    ), [str(w.message) for w in caught]
    assert any("point 5" in w for w in mesh.warnings())
