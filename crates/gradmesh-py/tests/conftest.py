"""Paths the tests read: the repository's examples and test corpus, and the real artwork in
../shared beside the repository (a test that needs it fails, naming the path, when it is
missing)."""

import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[3]
EXAMPLES = ROOT / "examples"
CORPUS = ROOT / "crates" / "gradmesh" / "tests" / "corpus"
REALDATA = ROOT.parent / "shared" / "realdata" / "gradientmeshimproved-off"


def require(path: pathlib.Path) -> pathlib.Path:
    assert path.exists(), (
        f"{path} is missing: the tests need ../shared beside the repository "
        "(see the README, Test data)"
    )
    return path


@pytest.fixture
def tucan_paths():
    """The six layers of the Tucan, bottom first (as the README's render command takes them)."""
    return [require(REALDATA / f"Tucan_Tucan_Layer{k}.off") for k in (5, 4, 3, 2, 1, 0)]


def example(name: str) -> pathlib.Path:
    return require(EXAMPLES / name)
