"""The per-shape stage of a collection on a Dask cluster (``dask.distributed``).

The per-shape stage (spectrum, descriptors, band table) is independent for every shape and
dominates the cost of a large collection; the collection stage needs only its results. So:

    from dask.distributed import Client, LocalCluster
    import coseg, coseg.dask
    client = Client(LocalCluster(n_workers=2, threads_per_worker=1))
    report = coseg.dask.precompute("shapes/", client, "shapes/.cache")
    result = coseg.segment("shapes/", cache_dir="shapes/.cache")   # warm: reads the entries
    # or: coseg.propagate("shapes/", "shapes/labels/", cache_dir="shapes/.cache")

Each task is :func:`coseg.shape_entry` (mesh bytes and options in, cache entry bytes out);
the client verifies every returned entry against the content key it computed itself and
writes it atomically as soon as it arrives, so finished entries survive a failure or an
interrupt. Shapes whose entries already verify are not submitted again: a rerun resumes.
A shape that fails (unreadable file, invalid mesh, spectrum failure, a lost worker after
``retries``) is reported in the result and skipped; the others go on.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Dict, Iterable, List, Tuple, Union

from . import MESH_SUFFIXES, InputError, _pipeline_opts, entry_is_valid, mesh_format, shape_entry, shape_key, store_entry

PathLike = Union[str, "os.PathLike[str]"]

__all__ = ["PrecomputeReport", "mesh_files", "precompute"]


@dataclass
class PrecomputeReport:
    """What :func:`precompute` did, per input file."""

    #: Files whose entries were computed on the cluster and written.
    computed: List[str] = field(default_factory=list)
    #: Files whose entries were already valid in the cache (not submitted).
    cached: List[str] = field(default_factory=list)
    #: ``(file, message)`` of every file that failed; its entry was not written.
    failed: List[Tuple[str, str]] = field(default_factory=list)
    #: Wall time of the whole call, in seconds.
    seconds: float = 0.0

    @property
    def ok(self) -> bool:
        """True when no file failed."""
        return not self.failed


def mesh_files(folder: PathLike) -> List[str]:
    """The mesh files (.obj, .off, .ply, any case) directly in ``folder``, sorted by name:
    the files ``coseg segment FOLDER`` reads."""
    out = [
        os.path.join(os.fspath(folder), name)
        for name in os.listdir(folder)
        if Path(name).suffix.lower() in MESH_SUFFIXES and os.path.isfile(os.path.join(folder, name))
    ]
    return sorted(out)


def _naming(path: str, error: BaseException) -> str:
    """The error's message, naming the file (the library names in-memory meshes `<memory>`)."""
    msg = str(error)
    if "<memory>" in msg:
        return msg.replace("<memory>", path)
    return msg if path in msg else f"{path}: {msg}"


def _entry_task(payload: Union[bytes, str], fmt: str, options: Dict[str, Any]) -> Tuple[Any, ...]:
    """Runs on a worker: the per-shape task on mesh bytes (or on a path the worker can read)."""
    if isinstance(payload, str):
        with open(payload, "rb") as f:
            payload = f.read()
    return tuple(shape_entry(payload, fmt, **options))


def precompute(
    paths: Union[PathLike, Iterable[PathLike]],
    client: Any,
    cache_dir: PathLike,
    *,
    ship: str = "bytes",
    retries: int = 1,
    **options: Any,
) -> PrecomputeReport:
    """Computes the per-shape cache entries of ``paths`` on the Dask cluster behind
    ``client`` and writes them into ``cache_dir``, where ``coseg segment`` (CLI or
    :func:`coseg.segment`) finds them: same content key, same bytes as a serial run.

    ``paths``: a folder (its mesh files, as :func:`mesh_files`) or an iterable of mesh
    files. ``options``: the per-shape options (``eigenpairs``, ``hks``, ``wks``,
    ``curvature``, ``bands``, ``area_bands``, ``families``, ``up``, ``directions``,
    ``normals``, ``family_weights``; library defaults), which must match those of the later ``segment``
    or ``propagate`` call, since they are part of the key. (``families`` with ``user:DIR``
    cannot run as a pure task: the task sees bytes, not the file name its features are
    matched by.) ``ship="bytes"`` sends each
    file's bytes with its task (no shared file system needed); ``ship="path"`` sends only
    the path, for clusters whose workers see the same files. ``retries``: how often Dask
    reruns a task whose worker died. Entries come back to the client, which verifies and
    writes them, so ``cache_dir`` need only be visible to the client.

    Returns a :class:`PrecomputeReport`; a failed shape never stops the others.
    """
    if ship not in ("bytes", "path"):
        raise InputError(f"ship: {ship!r} is not one of 'bytes', 'path'")
    t0 = time.perf_counter()
    opts = _pipeline_opts(options)
    if isinstance(paths, (str, os.PathLike)):
        files = mesh_files(paths)
    else:
        files = [os.fspath(p) for p in paths]
    cache_dir = os.fspath(cache_dir)
    report = PrecomputeReport()
    pending = {}
    from dask.distributed import as_completed

    for path in files:
        try:
            fmt = mesh_format(path)
            with open(path, "rb") as f:
                data = f.read()
            key, vertices = shape_key(data, fmt, **opts)
        except (OSError, ValueError) as e:
            report.failed.append((path, _naming(path, e)))
            continue
        if entry_is_valid(cache_dir, key, vertices):
            report.cached.append(path)
            continue
        payload = data if ship == "bytes" else os.path.abspath(path)
        # The task name carries the content key, so the dashboard shows which shape runs.
        fut = client.submit(
            _entry_task, payload, fmt, opts, key=f"coseg-shape-{key}-{len(pending)}", retries=retries, pure=False
        )
        pending[fut] = (path, key, vertices)
    for fut in as_completed(list(pending)):
        path, key, vertices = pending.pop(fut)
        try:
            got_key, got_vertices, entry, bands_entry = fut.result()
            if got_key != key or got_vertices != vertices:
                raise InputError(f"{path}: the worker computed key {got_key}, expected {key}")
            store_entry(cache_dir, key, vertices, entry, bands_entry)
            report.computed.append(path)
        except Exception as e:  # a failed shape is reported, never fatal for the others
            report.failed.append((path, _naming(path, e)))
        finally:
            fut.release()
    order = {p: i for i, p in enumerate(files)}
    report.computed.sort(key=order.__getitem__)
    report.failed.sort(key=lambda x: order[x[0]])
    report.seconds = time.perf_counter() - t0
    return report
