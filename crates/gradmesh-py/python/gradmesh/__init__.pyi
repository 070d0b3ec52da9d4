"""Type stubs of gradmesh (the extension module `gradmesh._gradmesh` and its wrappers)."""

import os
from typing import Any, Dict, List, Optional, Sequence, Tuple, TypedDict, Union

import numpy as np
import numpy.typing as npt

__version__: str

class Error(ValueError):
    """An input gradmesh refuses, with the place it lies."""

class MeshWarning(UserWarning):
    """Legal but suspicious input."""

EdgeTag = Tuple[str, Optional[float]]
Edit = Dict[str, Any]
View = Tuple[float, float, float, float]

class Mesh:
    def __init__(
        self,
        points: npt.ArrayLike,
        faces: Union[Sequence[Sequence[int]], npt.ArrayLike],
        colours: npt.ArrayLike,
        opacity: Optional[npt.ArrayLike] = None,
        *,
        colour_space: str = "lab",
        name: Optional[str] = None,
        corners: Optional[Sequence[int]] = None,
        handles: Optional[Dict[Tuple[int, int], Tuple[float, float]]] = None,
        edges: Optional[Dict[Tuple[int, int], Union[str, EdgeTag]]] = None,
        first_step: str = "ternary",
        interpolate_positions: bool = False,
    ) -> None: ...
    @property
    def points(self) -> npt.NDArray[np.float64]: ...
    @property
    def colours(self) -> npt.NDArray[np.float64]: ...
    @property
    def opacity(self) -> npt.NDArray[np.float64]: ...
    @property
    def corners(self) -> npt.NDArray[np.bool_]: ...
    @property
    def faces(self) -> List[npt.NDArray[np.int64]]: ...
    @property
    def face_offsets(self) -> npt.NDArray[np.int64]: ...
    @property
    def face_points(self) -> npt.NDArray[np.int64]: ...
    @property
    def colour_space(self) -> str: ...
    @property
    def name(self) -> Optional[str]: ...
    @property
    def first_step(self) -> str: ...
    @property
    def interpolate_positions(self) -> bool: ...
    @property
    def edges(self) -> Dict[Tuple[int, int], EdgeTag]: ...
    @property
    def handles(self) -> Dict[Tuple[int, int], Tuple[float, float]]: ...
    @property
    def edits(self) -> List[Edit]: ...
    @property
    def wedge_count(self) -> int: ...
    def with_colours(
        self, colours: npt.ArrayLike, opacity: Optional[npt.ArrayLike] = None
    ) -> "Mesh": ...
    def with_points(self, points: npt.ArrayLike) -> "Mesh": ...
    def warnings(self) -> List[str]: ...
    def __len__(self) -> int: ...

class Document:
    def __init__(self, layers: Sequence[Mesh]) -> None: ...
    @staticmethod
    def from_json(text: str) -> "Document": ...
    def to_json(self) -> str: ...
    def write(self, path: Union[str, os.PathLike]) -> None: ...
    @property
    def layers(self) -> List[Mesh]: ...
    def __len__(self) -> int: ...

class Refined(TypedDict):
    points: npt.NDArray[np.float64]
    colours: npt.NDArray[np.float64]
    opacity: npt.NDArray[np.float64]
    face_offsets: npt.NDArray[np.int64]
    face_points: npt.NDArray[np.int64]

def read(path: Union[str, os.PathLike]) -> Document: ...
def refine(
    mesh: Mesh,
    levels: int,
    limit: bool = False,
    *,
    interpolate_positions: Optional[bool] = None,
    first_step: Optional[str] = None,
) -> Refined: ...
def limit_matrix_arrays(
    mesh: Mesh, level: int
) -> Tuple[
    npt.NDArray[np.float64], npt.NDArray[np.int64], npt.NDArray[np.int64], Tuple[int, int]
]: ...
def limit_matrix(mesh: Mesh, level: int) -> Any:
    """A scipy.sparse.csr_matrix if scipy is installed, else limit_matrix_arrays' tuple."""
def render(
    doc: Union[Document, Mesh],
    width: Optional[int] = None,
    height: Optional[int] = None,
    view: Optional[View] = None,
    *,
    bits: int = 8,
    background: Union[None, str, Sequence[float]] = None,
    dither: bool = True,
    out: Optional[np.ndarray] = None,
) -> np.ndarray: ...
def export(
    doc: Union[Document, Mesh],
    path: Union[str, os.PathLike],
    width: Optional[int] = None,
    height: Optional[int] = None,
    view: Optional[View] = None,
    *,
    bits: int = 8,
    background: Union[None, str, Sequence[float]] = None,
    dither: bool = True,
    tolerance: float = 0.5,
    pdf_colour: str = "srgb",
    fallback: bool = True,
) -> None: ...
