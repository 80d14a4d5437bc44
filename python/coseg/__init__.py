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
- ``families`` (default ``"spectral"``): the feature families, a list or a comma-separated
  string as the CLI's ``--features``: ``"spectral"`` (HKS + WKS + curvature; or any of
  ``"hks"``, ``"wks"``, ``"curv"`` alone), ``"extrinsic"`` (heights along directions and
  distances, in the frame ``up``), ``"sdf"`` (shape diameter), ``"user:DIR"`` (``DIR`` holds
  ``<stem>.npy`` or ``.csv`` per shape; arrays are matched by their name). docs/FEATURES.md.
- ``up`` (default ``"y"``): frame of the extrinsic family, the collection's up axis
  (``"x"``, ``"-z"``, ...) or ``"pca"``; ``directions`` (default 100): its height directions;
  ``normals`` (default 0): its normal columns ``|n . u|``, banded by value and weighted as a
  family of their own (``normals=16`` with ``families="spectral,extrinsic"`` is the
  recommended configuration for aligned collections, docs/FEATURES.md).
- ``family_weights`` (default 1 each): a family's total share of the affinity, a dict
  ``{"extrinsic": 2}`` or a string ``"extrinsic=2,sdf=0.5"``; used by :func:`pair`,
  :func:`segment` and :func:`propagate` as by the CLI's commands.
"""

from __future__ import annotations

import functools
import inspect
import os
from collections import namedtuple
from pathlib import Path
from typing import Any, Callable, Dict, List, Optional, Sequence, Tuple, Union

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
    "propagate",
    "read_mesh",
    "segment",
    "shape_entry",
    "shape_key",
    "spectrum",
    "store_entry",
]

__version__ = "0.1.0"

#: The library's default of every keyword option, by command (``"segment"``, ``"pair"``,
#: ``"propagate"``, ...) and keyword, the per-shape options under ``"pipeline"``
#: (``coseg::jobs::defaults``; ``None``: unset, the library chooses).
DEFAULTS: Dict[str, Dict[str, Any]] = _coseg.defaults()
#: Version of the cache entry format (entries of another version are recomputed).
FORMAT_VERSION: int = _coseg.FORMAT_VERSION

_D = DEFAULTS
_P = DEFAULTS["pipeline"]
#: The spectral family's parts, selectable alone in ``families``.
SPECTRAL = ("hks", "wks", "curv")
#: The feature families (besides ``"user:DIR"``), as the CLI's ``--features``.
FAMILIES = ("spectral", "extrinsic", "sdf")
#: The per-shape options: every function that computes per-shape data takes them (and they
#: are part of the cache key).
PIPELINE_OPTIONS = (
    "eigenpairs",
    "hks",
    "wks",
    "curvature",
    "bands",
    "area_bands",
    "families",
    "up",
    "directions",
    "normals",
    "family_weights",
)
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


def _shape(shape: Any, what: str) -> Tuple[np.ndarray, np.ndarray, Optional[str], Optional[str]]:
    """``(V, F, name, file)`` of a ``(V, F)`` pair, a trimesh-like object or a mesh file path
    (``name`` and ``file`` only for a path)."""
    if isinstance(shape, (str, os.PathLike)):
        V, F = read_mesh(shape)
        return V, F, Path(shape).stem, os.fspath(shape)
    if hasattr(shape, "vertices") and hasattr(shape, "faces"):
        V, F = _as_mesh(shape.vertices, shape.faces, what)
        return V, F, None, None
    try:
        V, F = shape
    except (TypeError, ValueError):
        raise InputError(
            f"{what}: expected (V, F) arrays, a mesh with .vertices/.faces or a file path, "
            f"got {type(shape).__name__}"
        ) from None
    V, F = _as_mesh(V, F, what)
    return V, F, None, None


def _shapes(shapes: Any, names: Optional[Sequence[str]]) -> Tuple[list, List[str], List[Optional[str]]]:
    """The arrays, names and source files of a list of shapes."""
    arrays, found, files = [], [], []
    for i, s in enumerate(shapes):
        V, F, name, file = _shape(s, f"shape {i}")
        arrays.append((V, F))
        found.append(name or f"shape{i:03d}")
        files.append(file)
    if names is None:
        names = found
    names = [str(n) for n in names]
    if len(names) != len(arrays):
        raise InputError(f"names: {len(names)} names for {len(arrays)} shapes")
    return arrays, names, files


def _family_list(families: Union[str, Sequence[str]]) -> List[str]:
    if isinstance(families, str):
        families = families.split(",")
    out = [str(f).strip() for f in families if str(f).strip()]
    unknown = [f for f in out if f not in SPECTRAL + FAMILIES and not (f.startswith("user:") and len(f) > 5)]
    if unknown:
        raise InputError(
            f"unknown feature families {unknown} (expected spectral, hks, wks, curv, extrinsic, sdf or user:DIR)"
        )
    if not out:
        raise InputError("families: no feature family selected")
    return out


def _weights(family_weights: Any) -> str:
    if family_weights is None:
        return ""
    if isinstance(family_weights, str):
        return family_weights
    try:
        items = dict(family_weights).items()
    except (TypeError, ValueError):
        raise InputError(
            f"family_weights: expected a dict {{family: weight}} or a string, got {type(family_weights).__name__}"
        ) from None
    return ",".join(f"{k}={float(w)!r}" for k, w in items)


def _pipeline(
    families: Union[str, Sequence[str]] = _P["features"],
    up: str = _P["up"],
    directions: int = _P["directions"],
    family_weights: Any = None,
    normals: int = _P["normals"],
    **counts: Any,
) -> Dict[str, Any]:
    """The native module's per-shape options from the public keywords: ``families`` becomes
    the CLI's ``--features`` list (``hks``/``wks``/``curv`` alone zero the other spectral
    counts)."""
    fams = _family_list(families)
    parts = [f for f in fams if f in SPECTRAL]
    spectral = "spectral" in fams or bool(parts)
    if parts and "spectral" not in fams:
        for fam, key in zip(SPECTRAL, ("hks", "wks", "curvature")):
            if fam not in parts:
                counts[key] = 0
    rest = [f for f in fams if f not in SPECTRAL and f != "spectral"]
    counts["features"] = ",".join((["spectral"] if spectral else []) + rest)
    counts["up"] = str(up)
    counts["directions"] = directions
    counts["normals"] = normals
    counts["family_weights"] = _weights(family_weights)
    return counts


def _per_shape_keywords(*names: str) -> Callable[[Callable[..., Any]], Callable[..., Any]]:
    """Gives the decorated function (which takes them as ``**per_shape``) the per-shape keywords
    ``names`` (default: all of :data:`PIPELINE_OPTIONS`) in its signature, each with the
    library's default (``help`` and :func:`inspect.signature` show them), and rejects any other
    keyword as Python does. A keyword the function declares itself (``segment``'s
    ``families``) keeps its own default."""

    def decorate(fn: Callable[..., Any]) -> Callable[..., Any]:
        sig = inspect.signature(fn)
        own = [p for p in sig.parameters.values() if p.kind is not inspect.Parameter.VAR_KEYWORD]
        declared = {p.name for p in own}
        added = [
            inspect.Parameter(name, inspect.Parameter.KEYWORD_ONLY, default=default, annotation=annotation)
            for name, (default, annotation) in _PER_SHAPE_KEYWORDS.items()
            if name not in declared and (not names or name in names)
        ]
        allowed = declared | {p.name for p in added}

        @functools.wraps(fn)
        def wrapper(*args: Any, **kwargs: Any) -> Any:
            unknown = sorted(k for k in kwargs if k not in allowed)
            if unknown:
                raise TypeError(f"{fn.__name__}() got an unexpected keyword argument {unknown[0]!r}")
            return fn(*args, **kwargs)

        wrapper.__signature__ = sig.replace(parameters=own + added)  # type: ignore[attr-defined]
        return wrapper

    return decorate


#: Default and annotation of each per-shape keyword (:data:`PIPELINE_OPTIONS`), the defaults the
#: library's (``coseg::jobs::defaults``).
_PER_SHAPE_KEYWORDS: Dict[str, Tuple[Any, Any]] = {
    "eigenpairs": (_P["eigenpairs"], int),
    "hks": (_P["hks"], int),
    "wks": (_P["wks"], int),
    "curvature": (_P["curvature"], int),
    "bands": (_P["bands"], int),
    "area_bands": (_P["area_bands"], bool),
    "families": (_P["features"], Union[str, Sequence[str]]),
    "up": (_P["up"], str),
    "directions": (_P["directions"], int),
    "family_weights": (None, Any),
    "normals": (_P["normals"], int),
}


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


def spectrum(V: Any, F: Any, k: int = _P["eigenpairs"]) -> Tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The ``k`` smallest Laplace-Beltrami eigenpairs of the mesh scaled to unit area:
    ``(eigenvalues (k,), eigenvectors (n, k), vertex_areas (n,))`` with eigenvectors
    orthonormal under the lumped mass ``vertex_areas``. Default ``k``: 200."""
    V, F = _as_mesh(V, F)
    return _coseg.spectrum(V, F, int(k))


@_per_shape_keywords("families", "eigenpairs", "hks", "wks", "curvature", "up", "directions", "normals")
def features(V: Any, F: Any, **per_shape: Any) -> Tuple[List[str], np.ndarray]:
    """Per-vertex descriptors: ``(names, matrix)`` with ``matrix`` ``n x N`` float64 and
    ``names[j]`` naming column ``j`` (``hks_000``, ..., ``wks_...``, ``curv_...``, then
    ``ext_...``, ``sdf_...``, ``user_...`` of the other families). ``families``: see the
    module's docstring (default ``"spectral"``; ``("wks",)`` alone, ``"spectral,extrinsic"``,
    ...); the spectral counts are per part (defaults 100 each, from 200 eigenpairs); ``up``,
    ``directions`` and ``normals`` set the extrinsic family (as ``coseg features --up
    --directions --normals``)."""
    V, F = _as_mesh(V, F)
    return _coseg.features(V, F, _pipeline_opts(per_shape))


@_per_shape_keywords(
    "families", "eigenpairs", "hks", "wks", "curvature", "bands", "area_bands", "up", "directions", "normals"
)
def band_table(V: Any, F: Any, **per_shape: Any) -> np.ndarray:
    """The band table: ``n x N`` uint8, entry ``(v, j)`` the band (``0..bands``) of vertex
    ``v`` in feature ``j`` (columns as :func:`features`, same ``families``, ``up``,
    ``directions``, ``normals``). Default 20 bands of equal vertex count (``area_bands=True``:
    equal area); the normal columns are cut by value into equal intervals of [0, 1]."""
    V, F = _as_mesh(V, F)
    return _coseg.band_table(V, F, _pipeline_opts(per_shape))


_PIPELINE_DOC = """Per-shape options (part of the cache key; defaults as the CLI's): ``eigenpairs`` (200),
    ``hks``, ``wks``, ``curvature`` (100 each), ``bands`` (20), ``area_bands`` (False),
    ``families`` (``"spectral"``), ``up`` (``"y"``), ``directions`` (100), ``normals`` (0),
    ``family_weights`` (1 each); see the module's docstring."""


def _path(p: Optional[Union[str, os.PathLike]]) -> Optional[str]:
    return None if p is None else os.fspath(p)


def _native_options(arguments: Dict[str, Any], *own: str) -> Dict[str, Any]:
    """The native module's options from a job function's arguments (its ``locals()`` on
    entry): every keyword under its own name, so that a keyword and its option cannot drift
    apart, except ``names``, the ``own`` arguments the function converts itself and the
    per-shape keywords (:func:`_pipeline_opts` converts those); paths as strings."""
    skip = {"names", "per_shape", *own}
    opts = {k: v for k, v in arguments.items() if k not in skip}
    opts["cache_dir"] = _path(opts["cache_dir"])
    opts["out"] = _path(opts["out"])
    return opts


@_per_shape_keywords()
def pair(
    shape_a: Any,
    shape_b: Any,
    *,
    names: Optional[Tuple[str, str]] = None,
    cache_dir: Optional[Union[str, os.PathLike]] = None,
    out: Optional[Union[str, os.PathLike]] = None,
    algorithm: str = _D["pair"]["algorithm"],
    pairs: int = _D["pair"]["pairs"],
    alpha: float = _D["pair"]["alpha"],
    alpha_of_remaining: bool = _D["pair"]["alpha_of_remaining"],
    delta_t: float = _D["pair"]["delta_t"],
    t_max: float = _D["pair"]["t_max"],
    linear_t: bool = _D["pair"]["linear_t"],
    init: str = _D["pair"]["init"],
    seed: int = _D["pair"]["seed"],
    max_iterations: int = _D["pair"]["max_iterations"],
    refine_rounds: int = _D["pair"]["refine_rounds"],
    smoothing_time: float = _D["pair"]["smoothing_time"],
    map_weight: Optional[float] = None,
    map_preset: str = _D["pair"]["map_preset"],
    map_size: Optional[int] = _D["pair"]["map_size"],
    map_smoothing_time: Optional[float] = _D["pair"]["map_smoothing_time"],
    **per_shape: Any,
) -> Dict[str, Any]:
    """Stable region correspondences between two shapes (``coseg pair``).

    Each shape is ``(V, F)``, a trimesh-like object or a mesh file path. Returns a dict:
    ``labels_a`` (``n_a`` int32, region id per vertex of A; the last region is the
    leftovers), ``labels_b``, ``summary`` (the content of ``coseg pair``'s summary.json) and
    ``written`` (files written to ``out``, if given: ``<name>.regions.txt``,
    ``<name>.regions.ply``, ``summary.json``, the same files as the CLI's) and ``warnings``
    (the messages ``coseg pair`` prints, each naming its shape: the meshes', the cache's, the
    stages that fell back). Runs the library's pair job (``coseg::jobs::run_pair``), as the CLI.

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

    {pipeline}
    """
    opts = _native_options(locals(), "shape_a", "shape_b")
    va, fa, na, xa = _shape(shape_a, "shape a")
    vb, fb, nb, xb = _shape(shape_b, "shape b")
    if names is None:
        names = (na or "shape000", nb or "shape001")
    opts.update(_pipeline_opts(per_shape))
    return _coseg.pair([(va, fa), (vb, fb)], list(names), opts, [xa, xb])


@_per_shape_keywords()
def segment(
    shapes: Any,
    *,
    names: Optional[Sequence[str]] = None,
    cache_dir: Optional[Union[str, os.PathLike]] = None,
    out: Optional[Union[str, os.PathLike]] = None,
    regions: Optional[int] = None,
    parts: Optional[Union[str, int]] = None,
    starts: int = _D["segment"]["starts"],
    refine_sizes: str = _D["segment"]["refine_sizes"],
    parts_from: Optional[str] = None,
    snap_band: Optional[float] = None,
    area_fraction: Optional[float] = _D["segment"]["area_fraction"],
    seed: Optional[int] = _D["segment"]["seed"],
    complete_limit: int = _D["segment"]["complete_limit"],
    neighbours: int = _D["segment"]["neighbours"],
    refine_rounds: int = _D["segment"]["refine_rounds"],
    smoothing_time: float = _D["segment"]["smoothing_time"],
    families: Optional[Union[str, Sequence[str]]] = None,
    **per_shape: Any,
) -> Dict[str, Any]:
    """Consistent co-segmentation of a collection (``coseg segment``).

    ``shapes`` is a folder (every .obj/.off/.ply directly in it, read exactly as
    ``coseg segment FOLDER`` does, unreadable files skipped and reported), or a list whose
    items are ``(V, F)`` pairs, trimesh-like objects or file paths. Returns a dict:
    ``names``, ``labels`` (one int32 array per shape, region id per vertex; the last region
    is the leftovers), ``summary`` (the content of summary.json), ``skipped``, ``warnings``,
    ``outcomes`` (per shape ``"hit"``, ``"miss"``, ``"recomputed"`` from the cache, or
    ``"computed"`` without one) and ``written`` (files written to ``out``, if given: the
    CLI's region files).

    Options (defaults as ``coseg segment``; by default the result is parts, their number and
    the feature families chosen from the data, docs/PARTS.md, and ``summary["part_count"]``
    and ``summary["features"]`` say what was chosen and why): ``regions`` alone: that many
    equal-area regions per shape instead, the last the leftovers (the paper's stable regions);
    ``parts`` (None: ``"auto"``): an integer N cuts the tree of parts at N, ``"auto"`` lets
    the tree's cut criterion choose; ``parts_from`` (None: ``"geometry"``): ``"geometry"``
    takes ``regions`` (default 12) refined equal-area regions and groups touching ones (and
    left/right copies) of one thickness across convex boundaries (``--parts-from geometry``,
    docs/PARTS.md; a region made of separate pieces of different parts is split first, and
    pieces split from one region that face the same way are grouped as copies of one part:
    ``summary["parts"]["leaf_origin"]``, ``["leaf_copies"]``), then moves each part boundary
    onto a concave crease within ``snap_band`` (None: 0.1) × √(shape area) (``--snap-band``;
    0 keeps the regions' boundaries); ``"adaptive"``: parts of their own size (Algorithm 3
    across the collection), ``regions`` then being the upper bound (default 8);
    ``summary["parts"]`` holds the tree, mirror candidates (regions holding both sides) and
    mirror pairs (regions that are left/right copies, ``mirror_pairs``); ``families`` (None:
    ``"spectral"`` or ``"spectral,extrinsic"`` in the collection frame, chosen from the data;
    given, the families as given); ``starts`` (1): co-segment from this many starts and keep
    the one of highest mean confidence (equal-area mode only: with parts it raises
    :class:`InputError`); ``refine_sizes`` (``"free"``): ``"keep"`` or ``"keep:TOL"`` keeps
    each part's area within a factor 1 + TOL (default 0.5) of its area before refinement;
    ``area_fraction`` (None: 1 / regions) of
    each region; ``seed`` (None: start from the most distinctive vertex); ``complete_limit``
    (12): collections up to this size use a complete shape graph, larger ones ``neighbours``
    (6) nearest neighbours; ``refine_rounds`` (boundary refinement sweeps, 0 = none) and
    ``smoothing_time``.
    ``cache_dir``: per-shape cache (for a folder, default ``<out>/.cache``, as the CLI, or
    ``<folder>/.cache`` without ``out``; for a list, none unless given). Fill it on a
    cluster with :func:`coseg.dask.precompute`.

    {pipeline}
    """
    opts = _native_options(locals(), "shapes", "families")
    opts["parts"] = None if parts is None else str(parts)
    opts.update(_pipeline_opts(dict(per_shape, families=_P["features"] if families is None else families)))
    if families is None:
        # As `coseg segment` without --features: the library chooses the families.
        opts["features"] = None
    if isinstance(shapes, (str, os.PathLike)):
        if names is not None:
            raise InputError("names: a folder's shapes are named by file stem")
        return _coseg.segment(os.fspath(shapes), None, opts)
    arrays, names, files = _shapes(shapes, names)
    return _coseg.segment(arrays, names, opts, files)


def _label_array(labels: Any, what: str) -> Union[None, str, np.ndarray]:
    """One shape's annotation for the native module: None, a label file path, or int64."""
    if labels is None:
        return None
    if isinstance(labels, (str, os.PathLike)):
        return os.fspath(labels)
    a = np.asarray(labels)
    if a.dtype.kind not in "iu":
        raise InputError(f"{what}: labels must be integers (-1 = unlabelled), got dtype {a.dtype}")
    if a.ndim != 1:
        raise InputError(f"{what}: labels must be one per vertex (1-D), got shape {a.shape}")
    if a.size and (a.min() < -(2**31) or a.max() > 2**31 - 1):
        bad = a.min() if a.min() < -(2**31) else a.max()
        raise InputError(f"{what}: label {bad} is outside the 32-bit label range")
    return np.ascontiguousarray(a, dtype=np.int64)


@_per_shape_keywords()
def propagate(
    shapes: Any,
    labels: Any,
    *,
    names: Optional[Sequence[str]] = None,
    cache_dir: Optional[Union[str, os.PathLike]] = None,
    out: Optional[Union[str, os.PathLike]] = None,
    part_names: Any = None,
    complete_limit: int = _D["propagate"]["complete_limit"],
    neighbours: int = _D["propagate"]["neighbours"],
    smoothing_time: float = _D["propagate"]["smoothing_time"],
    max_sweeps: int = _D["propagate"]["max_sweeps"],
    network_weight: float = _D["propagate"]["network_weight"],
    similarity_power: float = _D["propagate"]["similarity_power"],
    size_prior: float = _D["propagate"]["size_prior"],
    area_weighted: bool = _D["propagate"]["area_weighted"],
    map_step: bool = False,
    map_agreement: float = _D["propagate"]["map_agreement"],
    **per_shape: Any,
) -> Dict[str, Any]:
    """Part labels from a few annotated shapes to a whole collection (``coseg propagate``).

    ``shapes`` and ``labels``, either:

    - a list of shapes (``(V, F)`` pairs, trimesh-like objects or mesh file paths) and a list
      with one entry per shape: an integer array of per-vertex labels (any integers, ``-1``
      = unlabelled; partial annotations allowed), a label file (``.labels.txt`` per vertex,
      ``.seg`` per face) or ``None`` for an unlabelled shape; or a dict ``{name: labels}``
      naming the annotated shapes only;
    - a folder (every mesh file directly in it, read as ``coseg propagate FOLDER``) and a
      label file or folder, or a list of them (the CLI's ``--labels``: folders are matched
      to meshes by stem).

    At least one shape must carry a label. Returns a dict: ``names``; ``labels`` (one int32
    array per shape: the part label of each vertex, the annotation's integers; ``-1`` only
    on a shape no labelled shape reaches); ``confidence`` (one float64 array per shape,
    ``(best - second) / best`` of the vertex's part scores, 1 on annotated vertices);
    ``parts`` (the labels, ascending); ``shape_confidence`` (float64, area-weighted mean per
    shape); ``sources`` (names of the annotated shapes); ``summary`` (the content of
    ``coseg propagate``'s summary.json); ``skipped``, ``warnings``, ``outcomes`` (per shape,
    as :func:`segment`'s) and ``written`` (with ``out``: ``<name>.labels.txt``,
    ``<name>.seg``, ``<name>.labels.ply``, ``summary.json``, byte for byte the CLI's; no
    pictures, as ``coseg propagate --no-pictures``).

    Options (defaults as ``coseg propagate``): ``smoothing_time`` (3e-3, unit-area surface; 0
    = none) of the part scores; ``max_sweeps`` (3) over the unlabelled shapes;
    ``network_weight`` (1; 0 = sources only) of labelled neighbours that are not sources;
    ``similarity_power`` (0 = all sources alike; 4 helps on collections that mix kinds) how
    much more a source like the target counts when several vote;
    ``size_prior`` (0.25, in [0, 1]) how strongly part sizes follow the sources' area
    shares; ``area_weighted`` (False) weighs the parts' band histograms by vertex area;
    ``map_step`` (False; a folder only, it reads the spectra from the cache) re-labels each
    unlabelled shape through a point map from its nearest source, kept where it agrees with
    the propagation on at least ``map_agreement`` (0.8) of the area (near-isometric
    collections; docs/PROPAGATION.md, "Map step"); ``complete_limit`` (12) and
    ``neighbours`` (6) of the shape graph. Recommended for aligned collections:
    ``families="spectral,extrinsic", up=..., normals=16, area_weighted=True``.
    ``part_names``: a JSON ``{label: name}`` file or a dict ``{label: name}`` (for a list of
    shapes), carried into the summary. ``cache_dir``: per-shape cache (default for a folder
    ``<out>/.cache`` as the CLI, else the library's, in the system's temporary folder; for a
    list, none unless given). ``names``: names of a list's shapes (default: file stems, or
    ``shape000``, ...).

    Bad labels (wrong length, not integers, not 1-D, out of range, a file that does not fit
    its mesh, no labelled vertex anywhere) raise :class:`InputError` before anything is
    computed; a missing label file raises :class:`FileError`.

    {pipeline}
    """
    opts = _native_options(locals(), "shapes", "labels", "part_names")
    opts.update(_pipeline_opts(per_shape))
    if isinstance(part_names, (str, os.PathLike)):
        opts["part_names"] = os.fspath(part_names)
    elif part_names is not None:
        try:
            opts["part_names_map"] = {int(k): str(v) for k, v in dict(part_names).items()}
        except (TypeError, ValueError):
            raise InputError("part_names: expected a JSON file or a dict {integer label: name}") from None
    if isinstance(shapes, (str, os.PathLike)):
        if names is not None:
            raise InputError("names: a folder's shapes are named by file stem")
        if isinstance(labels, (str, os.PathLike)):
            labels = [labels]
        try:
            files = [os.fspath(p) for p in labels]
        except TypeError:
            raise InputError(
                "labels: for a folder, give label files or folders (as coseg propagate --labels)"
            ) from None
        return _coseg.propagate(os.fspath(shapes), files, None, opts)
    arrays, names, files = _shapes(shapes, names)
    if isinstance(labels, dict):
        unknown = sorted(set(map(str, labels)) - set(names))
        if unknown:
            raise InputError(f"labels: no shape named {unknown} (shapes: {names})")
        by_name = {str(k): v for k, v in labels.items()}
        labels = [by_name.get(n) for n in names]
    else:
        labels = list(labels)
    if len(labels) != len(arrays):
        raise InputError(
            f"labels: {len(labels)} entries for {len(arrays)} shapes (give None for an unlabelled shape)"
        )
    entries = [_label_array(l, f"labels of shape {i} ({n})") for i, (l, n) in enumerate(zip(labels, names))]
    return _coseg.propagate(arrays, entries, names, opts, files)


for _f in (pair, segment, propagate):
    if _f.__doc__:  # None under python -OO
        _f.__doc__ = _f.__doc__.replace("{pipeline}", _PIPELINE_DOC)


def _pipeline_opts(options: Dict[str, Any]) -> Dict[str, Any]:
    """The per-shape keywords (:data:`PIPELINE_OPTIONS`) for the native module; unknown keys
    raise ``TypeError``. Idempotent: its own output passes through unchanged."""
    if "features" in options:  # already converted
        allowed = set(PIPELINE_OPTIONS) - {"families"} | {"features"}
        unknown = set(options) - allowed
        if unknown:
            raise TypeError(f"unknown per-shape option(s): {', '.join(sorted(unknown))}")
        return dict(options)
    unknown = set(options) - set(PIPELINE_OPTIONS)
    if unknown:
        raise TypeError(f"unknown per-shape option(s): {', '.join(sorted(unknown))}")
    o = dict(options)
    fam = dict(
        families=o.pop("families", _P["features"]),
        up=o.pop("up", _P["up"]),
        directions=o.pop("directions", _P["directions"]),
        normals=o.pop("normals", _P["normals"]),
        family_weights=o.pop("family_weights", None),
    )
    return _pipeline(**fam, **o)


def shape_key(mesh_bytes: bytes, format: str, **options: Any) -> Tuple[str, int]:
    """``(key, vertices)``: the content key (64 hex digits, as the Rust cache names its files)
    of a whole mesh file's bytes in ``format`` (``"obj"``, ``"off"``, ``"ply"``) under the
    per-shape options (:data:`PIPELINE_OPTIONS`), and the mesh's vertex count. Parses the
    mesh, computes nothing else."""
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
