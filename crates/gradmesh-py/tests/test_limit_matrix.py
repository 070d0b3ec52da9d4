"""limit_matrix: applied to the points' colours and opacity it gives refine(limit=True)'s to
1e-12, as a scipy matrix or as plain arrays; meshes it cannot express are refused."""

import numpy as np
import pytest
import scipy.sparse

import gradmesh
from conftest import REALDATA, example, require


def assert_maps_to_the_limit(mesh, level):
    matrix = gradmesh.limit_matrix(mesh, level)
    assert scipy.sparse.issparse(matrix) and matrix.format == "csr"
    limit = gradmesh.refine(mesh, level, limit=True)
    assert matrix.shape == (len(limit["points"]), len(mesh))
    assert np.abs(matrix @ mesh.colours - limit["colours"]).max() <= 1e-12
    assert np.abs(matrix @ mesh.opacity - limit["opacity"]).max() <= 1e-12
    assert np.allclose(matrix.sum(axis=1), 1.0, atol=1e-12)


@pytest.mark.parametrize("level", [0, 1, 2, 3])
@pytest.mark.parametrize("name", ["sparse-irregular.json", "fold.json", "annulus.json"])
def test_examples(name, level):
    assert_maps_to_the_limit(gradmesh.read(example(name)).layers[0], level)


@pytest.mark.parametrize("layer", range(6))
def test_tucan_layers(layer):
    mesh = gradmesh.read(require(REALDATA / f"Tucan_Tucan_Layer{layer}.off")).layers[0]
    assert_maps_to_the_limit(mesh, 3)


def test_arrays_form_is_the_same_matrix():
    mesh = gradmesh.read(example("non-rectangular.json")).layers[0]
    data, indices, indptr, shape = gradmesh.limit_matrix_arrays(mesh, 2)
    assert indptr.shape == (shape[0] + 1,) and indptr[-1] == len(data) == len(indices)
    dense = np.zeros(shape)
    for r in range(shape[0]):
        dense[r, indices[indptr[r] : indptr[r + 1]]] = data[indptr[r] : indptr[r + 1]]
    assert np.array_equal(dense, gradmesh.limit_matrix(mesh, 2).toarray())


def test_colour_edits_are_refused():
    mesh = gradmesh.read(example("multires.json")).layers[0]
    with pytest.raises(gradmesh.Error, match="edit 0: it changes colour"):
        gradmesh.limit_matrix(mesh, 2)


def test_wedges_with_their_own_colours_are_refused():
    mesh = gradmesh.read(example("edge-kinds.json")).layers[0]
    assert mesh.wedge_count > 0
    with pytest.raises(gradmesh.Error, match="wedge of point"):
        gradmesh.limit_matrix(mesh, 2)
