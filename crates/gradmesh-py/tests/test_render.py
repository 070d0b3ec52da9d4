"""Rendering into numpy arrays: equal to the command line's PNG pixel for pixel, into a given
array, at every depth, on two threads at once; and exporting PNG, PDF and SVG files."""

import os
import subprocess
import threading

import numpy as np
import pytest
from PIL import Image

import gradmesh
from conftest import ROOT, example


def tucan(paths):
    layers = [layer for p in paths for layer in gradmesh.read(p).layers]
    return gradmesh.Document(layers)


def cli_render(args, tmp_path):
    """Runs `gradmesh render ARGS -o out.png` (GRADMESH_CLI, or the CLI built by cargo) and
    returns the PNG's RGBA pixels."""
    out = tmp_path / "cli.png"
    cli = os.environ.get("GRADMESH_CLI")
    command = [cli] if cli else ["cargo", "run", "--release", "--locked", "-q", "-p", "gradmesh-cli", "--"]
    subprocess.run(command + ["render", *map(str, args), "-o", str(out)], cwd=ROOT, check=True)
    with Image.open(out) as image:
        assert image.mode == "RGBA", image.mode
        return np.asarray(image)


def test_tucan_equals_the_command_lines_png(tucan_paths, tmp_path):
    pixels = gradmesh.render(tucan(tucan_paths), width=1024)
    expected = cli_render([*tucan_paths, "--width", "1024"], tmp_path)
    assert pixels.dtype == np.uint8 and pixels.shape == expected.shape
    assert pixels.shape[1] == 1024
    assert (pixels[..., 3] > 0).mean() > 0.3, "the Tucan covers much of the picture"
    assert np.array_equal(pixels, expected)


def test_background_and_view_equal_the_command_line(tmp_path):
    path = example("edge-kinds.json")
    doc = gradmesh.read(path)
    view = (10.0, 5.0, 180.5, 120.0)
    pixels = gradmesh.render(doc, width=300, view=view, background="#336699")
    args = [path, "--width", "300", "--view", *map(str, view), "--background", "#336699"]
    expected = cli_render(args, tmp_path)
    assert np.array_equal(pixels, expected)
    assert (pixels[..., 3] == 255).all()


def test_sixteen_bits_agree_with_floats():
    doc = gradmesh.read(example("edge-kinds.json"))
    wide = gradmesh.render(doc, width=200, bits=16)
    floats = gradmesh.render(doc, width=200, bits=32)
    assert wide.dtype == np.uint16
    assert np.abs(floats * 65535 - wide.astype(np.float64)).max() <= 1.0


def test_float_and_byte_renders_agree():
    doc = gradmesh.read(example("sparse-irregular.json"))
    floats = gradmesh.render(doc, width=200, bits=32)
    bytes_ = gradmesh.render(doc, width=200, dither=False)
    assert floats.dtype == np.float32 and floats.shape == bytes_.shape
    assert np.abs(floats * 255 - bytes_.astype(np.float32)).max() <= 1.0


def test_render_into_a_given_array():
    mesh = gradmesh.read(example("annulus.json")).layers[0]
    fresh = gradmesh.render(mesh, 120, 90)
    out = np.full((90, 120, 4), 7, dtype=np.uint8)
    returned = gradmesh.render(mesh, 120, 90, out=out)
    assert returned is out
    assert np.array_equal(out, fresh)


@pytest.mark.parametrize(
    "out, message",
    [
        (np.zeros((90, 120, 4), dtype=np.float32), "dtype"),
        (np.zeros((90, 121, 4), dtype=np.uint8), "shape"),
        (np.zeros((120, 90, 4), dtype=np.uint8).transpose(1, 0, 2), "contiguous"),
        ([[0] * 4] * 10, "numpy array"),
    ],
)
def test_a_bad_out_array_is_refused(out, message):
    mesh = gradmesh.read(example("annulus.json")).layers[0]
    with pytest.raises(gradmesh.Error, match=message):
        gradmesh.render(mesh, 120, 90, out=out)


def test_a_read_only_out_array_is_refused():
    mesh = gradmesh.read(example("annulus.json")).layers[0]
    out = np.zeros((90, 120, 4), dtype=np.uint8)
    out.flags.writeable = False
    with pytest.raises(gradmesh.Error, match="writeable"):
        gradmesh.render(mesh, 120, 90, out=out)


@pytest.mark.parametrize(
    "kwargs, message",
    [
        (dict(width=0, height=10), "no pixels"),
        (dict(width=100000, height=100000), "pixel count"),
        (dict(view=(0, 0, 0, 10)), "view"),
        (dict(view=(0, 0, float("nan"), 10)), "view"),
        (dict(bits=12), "bits"),
        (dict(background="not a colour"), "background"),
        (dict(background=(1, 2)), "background"),
    ],
)
def test_bad_render_options_raise(kwargs, message):
    mesh = gradmesh.read(example("annulus.json")).layers[0]
    with pytest.raises(gradmesh.Error, match=message):
        gradmesh.render(mesh, **kwargs)


def test_renders_on_two_threads_at_once_equal_one_at_a_time(tucan_paths):
    doc = tucan(tucan_paths)
    alone = gradmesh.render(doc, width=512)
    results = [None, None]

    def work(i):
        results[i] = gradmesh.render(doc, width=512)

    threads = [threading.Thread(target=work, args=(i,)) for i in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for r in results:
        assert np.array_equal(r, alone)


def test_export_writes_png_pdf_and_svg(tmp_path):
    doc = gradmesh.read(example("non-rectangular.json"))
    gradmesh.export(doc, tmp_path / "a.png", width=160)
    with Image.open(tmp_path / "a.png") as image:
        assert np.array_equal(np.asarray(image), gradmesh.render(doc, width=160))
    gradmesh.export(doc, tmp_path / "a.pdf", width=160)
    assert (tmp_path / "a.pdf").read_bytes().startswith(b"%PDF-")
    gradmesh.export(doc, tmp_path / "a.svg", width=160)
    svg = (tmp_path / "a.svg").read_text()
    assert "<svg" in svg and "meshgradient" in svg
    with pytest.raises(gradmesh.Error, match=r"\.png, \.pdf or \.svg"):
        gradmesh.export(doc, tmp_path / "a.gif")
    assert not (tmp_path / "a.gif").exists()
