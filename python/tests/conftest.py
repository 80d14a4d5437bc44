"""Shared fixtures: the repository's shipped collections, the CLI binary, small options."""

import os
import shutil
from pathlib import Path

import numpy as np
import pytest

REPO = Path(__file__).resolve().parents[2]
COLLECTIONS = REPO / "collections"

#: Per-shape options small enough for CI (the CLI gets the same as flags).
SMALL = dict(eigenpairs=30, hks=12, wks=12, curvature=12, bands=10)


def cli_flags(opts=SMALL):
    flags = []
    for k, v in opts.items():
        flags += [f"--{k.replace('_', '-')}", str(v)]
    return flags


@pytest.fixture(scope="session")
def coseg_bin():
    """The `coseg` CLI: $COSEG_BIN, else the workspace's target/{debug,release}/coseg."""
    cands = [os.environ.get("COSEG_BIN")] + [str(REPO / "target" / p / "coseg") for p in ("debug", "release")]
    for c in cands:
        if c and os.path.isfile(c) and os.access(c, os.X_OK):
            return c
    pytest.skip("no coseg CLI binary (set COSEG_BIN or run `cargo build` first): CLI comparison skipped")


@pytest.fixture()
def chairs(tmp_path):
    """A copy of the shipped chairs collection (meshes only) in a fresh folder."""
    dst = tmp_path / "chairs"
    dst.mkdir()
    for f in sorted((COLLECTIONS / "chairs").glob("*.obj")):
        shutil.copy(f, dst / f.name)
    return dst


def octahedron_sphere(levels=2):
    """A closed genus-0 mesh: an octahedron subdivided `levels` times, projected to the
    unit sphere (vertices in a fixed order)."""
    V = [[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]]
    F = [[0, 2, 4], [2, 1, 4], [1, 3, 4], [3, 0, 4], [2, 0, 5], [1, 2, 5], [3, 1, 5], [0, 3, 5]]
    V = [np.array(v, float) for v in V]
    for _ in range(levels):
        mid = {}
        nf = []

        def m(a, b):
            k = (min(a, b), max(a, b))
            if k not in mid:
                V.append((V[a] + V[b]) / 2)
                mid[k] = len(V) - 1
            return mid[k]

        for a, b, c in F:
            ab, bc, ca = m(a, b), m(b, c), m(c, a)
            nf += [[a, ab, ca], [ab, b, bc], [ca, bc, c], [ab, bc, ca]]
        F = nf
    V = np.array([v / np.linalg.norm(v) for v in V])
    return V, np.array(F, dtype=np.int64)
