"""Gradient meshes of arbitrary topology (Lieng, Kosinka, Shen & Dodgson, CGF 2017).

The Rust library gradmesh, with meshes and pictures as numpy arrays:

>>> import gradmesh
>>> doc = gradmesh.read("picture.json")          # .json, .off, .obj, .svg
>>> pixels = gradmesh.render(doc, width=1024)    # (H, W, 4) uint8, straight alpha, sRGB
>>> mesh = doc.layers[0]
>>> A = gradmesh.limit_matrix(mesh, 3)           # limit colours = A @ mesh.colours

Errors raise ``gradmesh.Error`` (a ``ValueError``) with the place they lie; warnings come as
``gradmesh.MeshWarning`` through the ``warnings`` module. See docs/python.md.
"""

from ._gradmesh import (
    Document,
    Error,
    Mesh,
    MeshWarning,
    __version__,
    export,
    limit_matrix_arrays,
    read,
    refine,
    render,
)

__all__ = [
    "Document",
    "Error",
    "Mesh",
    "MeshWarning",
    "__version__",
    "export",
    "limit_matrix",
    "limit_matrix_arrays",
    "read",
    "refine",
    "render",
]


def limit_matrix(mesh, level):
    """The limit colours of level ``level``'s vertices as a sparse matrix of the points' colours.

    Row ``i`` is vertex ``i`` of the level (the order of ``refine(mesh, level, limit=True)``),
    column ``j`` is point ``j`` of the mesh; ``A @ mesh.colours`` gives the limit colours and
    ``A @ mesh.opacity`` the limit opacity. Colours are linear in the control colours
    (positions are not), so least-squares fitting of colours is one sparse solve.

    Returns a ``scipy.sparse.csr_matrix`` when scipy is installed, else the tuple
    ``(data, indices, indptr, shape)`` of ``limit_matrix_arrays``. Raises ``gradmesh.Error`` for
    a mesh with colour or opacity edits, or with a wedge of a discontinuous edge that has its
    own colour: their limit is not a linear map of the points' colours.
    """
    arrays = limit_matrix_arrays(mesh, level)
    try:
        import scipy.sparse
    except ImportError:
        return arrays
    data, indices, indptr, shape = arrays
    return scipy.sparse.csr_matrix((data, indices, indptr), shape=shape)
