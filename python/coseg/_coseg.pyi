"""Type stubs of the native module ``coseg._coseg`` (the Rust half). Use the wrappers in
``coseg`` instead: they coerce dtypes, check arrays and document the options. Here ``V`` must
be float64 ``n x 3`` and ``F`` int64 ``m x 3`` exactly; ``options`` is a dict of the keyword
options of the matching ``coseg`` function (unknown keys raise ``TypeError``), with the
feature families as the CLI spells them (``features="spectral,extrinsic"``,
``family_weights="extrinsic=2"``); ``files`` names the mesh file each shape was read from
(``None`` for arrays). For a folder, ``propagate``'s ``labels`` are label file or folder
paths (the CLI's ``--labels``); for a list, one entry per shape (int64 labels, a label
file, or ``None``)."""

from os import PathLike
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np
import numpy.typing as npt

_V = npt.NDArray[np.float64]
_F = npt.NDArray[np.int64]
_Path = Union[str, PathLike[str]]

FORMAT_VERSION: int

def defaults() -> Dict[str, Dict[str, Any]]: ...
def read_mesh(path: _Path) -> Tuple[_V, _F, List[str]]: ...
def spectrum(v: _V, f: _F, k: int) -> Tuple[npt.NDArray[np.float64], npt.NDArray[np.float64], npt.NDArray[np.float64]]: ...
def features(v: _V, f: _F, options: Optional[Dict[str, Any]] = None) -> Tuple[List[str], npt.NDArray[np.float64]]: ...
def band_table(v: _V, f: _F, options: Optional[Dict[str, Any]] = None) -> npt.NDArray[np.uint8]: ...
def shape_key(mesh_bytes: bytes, format: str, options: Optional[Dict[str, Any]] = None) -> Tuple[str, int]: ...
def shape_entry(mesh_bytes: bytes, format: str, options: Optional[Dict[str, Any]] = None) -> Tuple[str, int, bytes, bytes]: ...
def store_entry(cache_dir: _Path, key: str, vertices: int, entry: bytes, bands_entry: bytes) -> Tuple[str, str]: ...
def entry_is_valid(cache_dir: _Path, key: str, vertices: int) -> bool: ...
def pair(
    shapes: List[Tuple[_V, _F]],
    names: Optional[Sequence[str]] = None,
    options: Optional[Dict[str, Any]] = None,
    files: Optional[Sequence[Optional[str]]] = None,
) -> Dict[str, Any]: ...
def segment(
    shapes: Union[_Path, List[Tuple[_V, _F]]],
    names: Optional[Sequence[str]] = None,
    options: Optional[Dict[str, Any]] = None,
    files: Optional[Sequence[Optional[str]]] = None,
) -> Dict[str, Any]: ...
def propagate(
    shapes: Union[_Path, List[Tuple[_V, _F]]],
    labels: List[Union[None, str, npt.NDArray[np.int64]]],
    names: Optional[Sequence[str]] = None,
    options: Optional[Dict[str, Any]] = None,
    files: Optional[Sequence[Optional[str]]] = None,
) -> Dict[str, Any]: ...
