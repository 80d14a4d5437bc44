from os import PathLike
from typing import Any, Iterable, List, Mapping, Sequence, Tuple, Union

_Path = Union[str, PathLike[str]]

class PrecomputeReport:
    computed: List[str]
    cached: List[str]
    failed: List[Tuple[str, str]]
    seconds: float
    @property
    def ok(self) -> bool: ...

def mesh_files(folder: _Path) -> List[str]: ...
def precompute(
    paths: Union[_Path, Iterable[_Path]],
    client: Any,
    cache_dir: _Path,
    *,
    ship: str = ...,
    retries: int = ...,
    eigenpairs: int = ...,
    hks: int = ...,
    wks: int = ...,
    curvature: int = ...,
    bands: int = ...,
    area_bands: bool = ...,
    families: Union[str, Sequence[str]] = ...,
    up: str = ...,
    directions: int = ...,
    normals: int = ...,
    family_weights: Union[None, str, Mapping[str, float]] = ...,
) -> PrecomputeReport: ...
