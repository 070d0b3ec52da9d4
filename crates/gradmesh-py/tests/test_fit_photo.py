"""examples/python/fit_photo.py: least-squares colours through limit_matrix match a photograph
better than the photograph's colours sampled at the control points."""

import importlib.util

from conftest import EXAMPLES, ROOT, require


def test_least_squares_beats_sampling(tmp_path, capsys):
    path = require(EXAMPLES / "python" / "fit_photo.py")
    spec = importlib.util.spec_from_file_location("fit_photo", path)
    fit_photo = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(fit_photo)
    photo = require(ROOT.parent / "shared" / "realdata" / "images" / "chelsea.png")
    out = tmp_path / "fitted.png"
    errors = fit_photo.main([str(photo), "--grid", "8", "--level", "3", "--width", "160", "--out", str(out)])
    print(capsys.readouterr().out)
    assert errors["least squares"] < 0.9 * errors["sampled at the control points"], errors
    assert out.stat().st_size > 0
