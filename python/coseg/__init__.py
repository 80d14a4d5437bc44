"""coseg: stable region correspondences between shapes, and consistent co-segmentation of
shape collections (Python bindings of the Rust library ``coseg``).

Meshes are ``(V, F)`` numpy arrays: ``V`` is ``n x 3`` float64 positions, ``F`` is ``m x 3``
integer vertex indices (0-based), the convention of trimesh, libigl and potpourri3d. Every
function that computes releases the GIL; every library error is raised as a
:class:`coseg.errors.InputError` (a ``ValueError``) or :class:`coseg.errors.FileError` (an
``OSError``) with the library's message.

Options are keyword arguments; their defaults are the library's (``coseg.DEFAULTS``).

Per-shape options (every function that computes per-shape data takes them):

- ``eigenpairs`` (default 200): Laplace-Beltrami eigenpairs.
- ``hks`` (default 100), ``wks`` (default 100), ``curvature`` (default 100): number of heat
  kernel signature, wave kernel signature and multiscale mean-curvature features.
- ``bands`` (default 20): bands K per feature.
- ``area_bands`` (default False): cut bands by equal area instead of equal vertex count.
"""

from __future__ import annotations

import os
from collections import namedtuple
from pathlib import Path
from typing import Any, Dict, List, Optional, Sequence, Tuple, Union

import numpy as np

from . import _coseg
from .errors import CosegError, FileError, InputError

__all__ = [
    "DEFAULTS",
    "FORMAT_VERSION",
    "CosegError",
    "FileError",
    "InputError",
    "ShapeEntry",
    "band_table",
    "entry_is_valid",
    "features",
    "mesh_format",
    "pair",
    "read_mesh",
    "segment",
    "shape_entry",
    "shape_key",
    "spectrum",
    "store_entry",
]

__version__ = "0.1.0"

#: The library's default of every keyword option (``pair_*``/``segment_*`` where the two
#: stages differ).
DEFAULTS: Dict[str, Any] = dict(_coseg.defaults())
#: Version of the cache entry format (entries of another version are recomputed).
FORMAT_VERSION: int = _coseg.FORMAT_VERSION

_D = DEFAULTS
FAMILIES = ("hks", "wks", "curv")
MESH_SUFFIXES = (".obj", ".off", ".ply")

#: The per-shape task's result: content key (64 hex digits), vertex count, and the bytes of
#: the full and the compact cache entries.
ShapeEntry = namedtuple("ShapeEntry", ["key", "vertices", "entry", "bands_entry"])


def _as_mesh(V: Any, F: Any, what: str = "mesh") -> Tuple[np.ndarray, np.ndarray]:
    """Checks and converts ``(V, F)`` to C-contiguous float64 / int64 arrays."""
    V = np.asarray(V)
    F = np.asarray(F)
    if V.dtype.kind not in "fiu":
        raise InputError(f"{what}: V must hold real numbers, got dtype {V.dtype}")
    if F.dtype.kind not in "iu":
        raise InputError(f"{what}: F must hold integers, got dtype {F.dtype}")
    if V.ndim != 2 or V.shape[1] != 3:
        raise InputError(f"{what}: V must be n x 3, got shape {V.shape}")
    if F.ndim != 2 or F.shape[1] != 3:
        raise InputError(f"{what}: F must be m x 3, got shape {F.shape}")
    if F.size and (F.min() < 0 or F.max() >= len(V)):
        bad = F.min() if F.min() < 0 else F.max()
        raise InputError(f"{what}: F refers to vertex {bad}, but the mesh has {len(V)} vertices")
    return (
        np.ascontiguousarray(V, dtype=np.float64),
        np.ascontiguousarray(F, dtype=np.int64),
    )


def _shape(shape: Any, what: str) -> Tuple[np.ndarray, np.ndarray, Optional[str]]:
    """``(V, F, name)`` of a ``(V, F)`` pair, a trimesh-like object or a mesh file path."""
    if isinstance(shape, (str, os.PathLike)):
        V, F = read_mesh(shape)
        return V, F, Path(shape).stem
    if hasattr(shape, "vertices") and hasattr(shape, "faces"):
        V, F = _as_mesh(shape.vertices, shape.faces, what)
        return V, F, None
    try:
        V, F = shape
    except (TypeError, ValueError):
        raise InputError(
            f"{what}: expected (V, F) arrays, a mesh with .vertices/.faces or a file path, "
            f"got {type(shape).__name__}"
        ) from None
    V, F = _as_mesh(V, F, what)
    return V, F, None


def _pipeline(families: Sequence[str], **counts: Any) -> Dict[str, Any]:
    unknown = set(families) - set(FAMILIES)
    if unknown:
        raise InputError(f"unknown feature families {sorted(unknown)} (expected {FAMILIES})")
    for fam, key in zip(FAMILIES, ("hks", "wks", "curvature")):
        if fam not in families:
            counts[key] = 0
    return counts


def mesh_format(path: Union[str, os.PathLike]) -> str:
    """``"obj"``, ``"off"`` or ``"ply"`` from a file name (case-insensitive)."""
    suffix = Path(path).suffix.lower()
    if suffix not in MESH_SUFFIXES:
        raise InputError(f"{path}: unsupported mesh format (expected .obj, .off or .ply)")
    return suffix[1:]


def read_mesh(path: Union[str, os.PathLike]) -> Tuple[np.ndarray, np.ndarray]:
    """Reads a mesh file (.obj, .off, .ply) as ``(V, F)``: ``V`` ``n x 3`` float64, ``F``
    ``m x 3`` int64, in file order (vertices are never merged or reordered; polygons are
    fan-triangulated). Mesh warnings (boundary, degenerate triangles, ...) go to
    :mod:`warnings`."""
    V, F, warns = _coseg.read_mesh(os.fspath(path))
    if warns:
        import warnings

        for w in warns:
            warnings.warn(w, stacklevel=2)
    return V, F


def spectrum(V: Any, F: Any, k: int = _D["eigenpairs"]) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The ``k`` smallest Laplace-Beltrami eigenpairs of the mesh scaled to unit area:
    ``(eigenvalues (k,), eigenvectors (n, k), vertex_areas (n,))`` with eigenvectors
    orthonormal under the lumped mass ``vertex_areas``. Default ``k``: 200."""
    V, F = _as_mesh(V, F)
    return _coseg.spectrum(V, F, int(k))


def features(
    V: Any,
    F: Any,
    *,
    families: Sequence[str] = FAMILIES,
    eigenpairs: int = _D["eigenpairs"],
    hks: int = _D["hks"],
    wks: int = _D["wks"],
    curvature: int = _D["curvature"],
) -> Tuple[List[str], np.ndarray]:
    """Per-vertex descriptors: ``(names, matrix)`` with ``matrix`` ``n x N`` float64 and
    ``names[j]`` naming column ``j`` (``hks_000``, ..., ``wks_...``, ``curv_...``).
    ``families`` selects among ``"hks"``, ``"wks"``, ``"curv"``; the counts are per family
    (defaults 100 each, from 200 eigenpairs)."""
    V, F = _as_mesh(V, F)
    opts = _pipeline(families, eigenpairs=eigenpairs, hks=hks, wks=wks, curvature=curvature)
    return _coseg.features(V, F, opts)


def band_table(
    V: Any,
    F: Any,
    *,
    families: Sequence[str] = FAMILIES,
    eigenpairs: int = _D["eigenpairs"],
    hks: int = _D["hks"],
    wks: int = _D["wks"],
    curvature: int = _D["curvature"],
    bands: int = _D["bands"],
    area_bands: bool = _D["area_bands"],
) -> np.ndarray:
    """The band table: ``n x N`` uint8, entry ``(v, j)`` the band (``0..bands``) of vertex
    ``v`` in feature ``j`` (columns as :func:`features`). Default 20 bands of equal vertex
    count (``area_bands=True``: equal area)."""
    V, F = _as_mesh(V, F)
    opts = _pipeline(
        families,
        eigenpairs=eigenpairs,
        hks=hks,
        wks=wks,
        curvature=curvature,
        bands=bands,
        area_bands=area_bands,
    )
    return _coseg.band_table(V, F, opts)


def pair(
    shape_a: Any,
    shape_b: Any,
    *,
    names: Optional[Tuple[str, str]] = None,
    cache_dir: Optional[Union[str, os.PathLike]] = None,
    out: Optional[Union[str, os.PathLike]] = None,
    algorithm: str = _D["algorithm"],
    pairs: int = _D["pairs"],
    alpha: float = _D["alpha"],
    alpha_of_remaining: bool = _D["alpha_of_remaining"],
    delta_t: float = _D["delta_t"],
    t_max: float = _D["t_max"],
    linear_t: bool = _D["linear_t"],
    init: str = _D["init"],
    seed: int = _D["pair_seed"],
    max_iterations: int = _D["max_iterations"],
    refine_rounds: int = _D["pair_refine_rounds"],
    smoothing_time: float = _D["pair_smoothing_time"],
    map_weight: Optional[float] = None,
    map_preset: str = _D["map_preset"],
    map_size: int = _D["map_size"],
    map_smoothing_time: float = _D["map_smoothing_time"],
    eigenpairs: int = _D["eigenpairs"],
    hks: int = _D["hks"],
    wks: int = _D["wks"],
    curvature: int = _D["curvature"],
    bands: int = _D["bands"],
    area_bands: bool = _D["area_bands"],
) -> Dict[str, Any]:
    """Stable region correspondences between two shapes (``coseg pair``).

    Each shape is ``(V, F)``, a trimesh-like object or a mesh file path. Returns a dict:
    ``labels_a`` (``n_a`` int32, region id per vertex of A; the last region is the
    leftovers), ``labels_b``, ``summary`` (the content of ``coseg pair``'s summary.json) and
    ``written`` (files written to ``out``, if given: ``<name>.regions.txt``,
    ``<name>.regions.ply``, ``summary.json``, the same files as the CLI's).

    Options (defaults as ``coseg pair``): ``algorithm`` ``"fixed"`` (Algorithm 2) or
    ``"auto"`` (Algorithm 3); ``pairs`` (10) region pairs; ``alpha`` (0.1) area cutoff per
    pair as a fraction of each shape's area (of the remaining area with
    ``alpha_of_remaining``); ``delta_t`` (0.1) and ``t_max`` (20) of Algorithm 3, which
    bisects unless ``linear_t``; ``init`` ``"random"`` (seeded by ``seed``, 0) or
    ``"extreme"``; ``max_iterations`` (100) of Algorithm 1; ``refine_rounds`` (10, 0 = none)
    and ``smoothing_time`` (3e-3, unit-area surface) of the boundary refinement;
    ``map_weight`` (None: the preset's, 0.5 or 2; 0 skips the map step), ``map_preset``
    (``"auto"``, ``"general"``, ``"near-isometric"``), ``map_size`` and
    ``map_smoothing_time`` of the map-guided last step. ``cache_dir``: per-shape cache
    (read if valid, written otherwise). ``names``: names of the two shapes (default: file
    stems, or ``shape000``/``shape001``).
    """
    va, fa, na = _shape(shape_a, "shape a")
    vb, fb, nb = _shape(shape_b, "shape b")
    if names is None:
        names = (na or "shape000", nb or "shape001")
    opts = dict(
        algorithm=algorithm,
        pairs=pairs,
        alpha=alpha,
        alpha_of_remaining=alpha_of_remaining,
        delta_t=delta_t,
        t_max=t_max,
        linear_t=linear_t,
        init=init,
        seed=seed,
        max_iterations=max_iterations,
        refine_rounds=refine_rounds,
        smoothing_time=smoothing_time,
        map_weight=map_weight,
        map_preset=map_preset,
        map_size=map_size,
        map_smoothing_time=map_smoothing_time,
        eigenpairs=eigenpairs,
        hks=hks,
        wks=wks,
        curvature=curvature,
        bands=bands,
        area_bands=area_bands,
        cache_dir=None if cache_dir is None else os.fspath(cache_dir),
        out=None if out is None else os.fspath(out),
    )
    return _coseg.pair([(va, fa), (vb, fb)], list(names), opts)


def segment(
    shapes: Any,
    *,
    names: Optional[Sequence[str]] = None,
    cache_dir: Optional[Union[str, os.PathLike]] = None,
    out: Optional[Union[str, os.PathLike]] = None,
    regions: int = _D["regions"],
    area_fraction: Optional[float] = _D["area_fraction"],
    seed: Optional[int] = _D["segment_seed"],
    complete_limit: int = _D["complete_limit"],
    neighbours: int = _D["neighbours"],
    refine_rounds: int = _D["segment_refine_rounds"],
    smoothing_time: float = _D["segment_smoothing_time"],
    eigenpairs: int = _D["eigenpairs"],
    hks: int = _D["hks"],
    wks: int = _D["wks"],
    curvature: int = _D["curvature"],
    bands: int = _D["bands"],
    area_bands: bool = _D["area_bands"],
) -> Dict[str, Any]:
    """Consistent co-segmentation of a collection (``coseg segment``).

    ``shapes`` is a folder (every .obj/.off/.ply directly in it, read exactly as
    ``coseg segment FOLDER`` does, unreadable files skipped and reported), or a list whose
    items are ``(V, F)`` pairs, trimesh-like objects or file paths. Returns a dict:
    ``names``, ``labels`` (one int32 array per shape, region id per vertex; the last region
    is the leftovers), ``summary`` (the content of summary.json), ``skipped``, ``warnings``
    and ``written`` (files written to ``out``, if given: the CLI's region files).

    Options (defaults as ``coseg segment``): ``regions`` (6) regions per shape, the last the
    leftovers; ``area_fraction`` (None: 1 / regions) of each region; ``seed`` (None: start
    from the most distinctive vertex); ``complete_limit`` (12): collections up to this size
    use a complete shape graph, larger ones ``neighbours`` (6) nearest neighbours;
    ``refine_rounds`` (boundary refinement sweeps, 0 = none) and ``smoothing_time``.
    ``cache_dir``: per-shape cache (for a folder, default ``<out>/.cache``, as the CLI, or
    ``<folder>/.cache`` without ``out``; for a list, none unless given). Fill it on a
    cluster with :func:`coseg.dask.precompute`.
    """
    opts = dict(
        regions=regions,
        area_fraction=area_fraction,
        seed=seed,
        complete_limit=complete_limit,
        neighbours=neighbours,
        refine_rounds=refine_rounds,
        smoothing_time=smoothing_time,
        eigenpairs=eigenpairs,
        hks=hks,
        wks=wks,
        curvature=curvature,
        bands=bands,
        area_bands=area_bands,
        cache_dir=None if cache_dir is None else os.fspath(cache_dir),
        out=None if out is None else os.fspath(out),
    )
    if isinstance(shapes, (str, os.PathLike)):
        if names is not None:
            raise InputError("names: a folder's shapes are named by file stem")
        return _coseg.segment(os.fspath(shapes), None, opts)
    arrays = []
    found = []
    for i, s in enumerate(shapes):
        V, F, name = _shape(s, f"shape {i}")
        arrays.append((V, F))
        found.append(name or f"shape{i:03d}")
    if names is None:
        names = found
    names = [str(n) for n in names]
    if len(names) != len(arrays):
        raise InputError(f"names: {len(names)} names for {len(arrays)} shapes")
    return _coseg.segment(arrays, names, opts)


def _pipeline_opts(options: Dict[str, Any]) -> Dict[str, Any]:
    allowed = {"eigenpairs", "hks", "wks", "curvature", "bands", "area_bands"}
    unknown = set(options) - allowed
    if unknown:
        raise TypeError(f"unknown per-shape option(s): {', '.join(sorted(unknown))}")
    return dict(options)


def shape_key(mesh_bytes: bytes, format: str, **options: Any) -> Tuple[str, int]:
    """``(key, vertices)``: the content key (64 hex digits, as the Rust cache names its files)
    of a whole mesh file's bytes in ``format`` (``"obj"``, ``"off"``, ``"ply"``) under the
    per-shape options, and the mesh's vertex count. Parses the mesh, computes nothing else."""
    return _coseg.shape_key(bytes(mesh_bytes), format, _pipeline_opts(options))


def shape_entry(mesh_bytes: bytes, format: str, **options: Any) -> ShapeEntry:
    """The per-shape stage as a pure task: mesh file bytes and per-shape options in, the
    bytes of the two cache entries out (exactly what ``coseg segment`` writes into its
    cache), touching no file. Deterministic. Run it anywhere; store the result with
    :func:`store_entry`."""
    return ShapeEntry(*_coseg.shape_entry(bytes(mesh_bytes), format, _pipeline_opts(options)))


def store_entry(
    cache_dir: Union[str, os.PathLike], key: str, vertices: int, entry: bytes, bands_entry: bytes
) -> Tuple[str, str]:
    """Verifies both entry byte strings against ``key`` and ``vertices`` (magic, version, key,
    length, checksum, sizes) and writes them atomically into ``cache_dir``; returns the two
    paths. Raises :class:`InputError` and writes nothing if either fails verification."""
    a, b = _coseg.store_entry(os.fspath(cache_dir), key, int(vertices), bytes(entry), bytes(bands_entry))
    return os.fspath(a), os.fspath(b)


def entry_is_valid(cache_dir: Union[str, os.PathLike], key: str, vertices: int) -> bool:
    """True when ``cache_dir`` holds both entries of ``key`` and both verify."""
    return _coseg.entry_is_valid(os.fspath(cache_dir), key, int(vertices))
