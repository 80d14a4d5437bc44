"""The Dask path: a 2-worker LocalCluster gives the serial path's cache entries and results;
failures are reported and skipped; a rerun resumes."""

import shutil
import subprocess
from pathlib import Path

import numpy as np
import pytest

import coseg
from conftest import COLLECTIONS, SMALL, cli_flags

distributed = pytest.importorskip("dask.distributed")
import coseg.dask  # noqa: E402


@pytest.fixture(scope="module")
def client():
    cluster = distributed.LocalCluster(
        n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None
    )
    c = distributed.Client(cluster)
    yield c
    c.close()
    cluster.close()


def serial_cache(folder, cache):
    for p in coseg.dask.mesh_files(folder):
        e = coseg.shape_entry(Path(p).read_bytes(), coseg.mesh_format(p), **SMALL)
        coseg.store_entry(cache, e.key, e.vertices, e.entry, e.bands_entry)


def test_dask_matches_serial_and_cli(client, chairs, tmp_path, coseg_bin):
    serial, dist = tmp_path / "serial-cache", tmp_path / "dask-cache"
    serial_cache(chairs, serial)
    rep = coseg.dask.precompute(chairs, client, dist, **SMALL)
    assert rep.ok and len(rep.computed) == 6 and rep.cached == []
    names = sorted(p.name for p in serial.iterdir())
    assert len(names) == 12 and names == sorted(p.name for p in dist.iterdir())
    for n in names:
        assert (serial / n).read_bytes() == (dist / n).read_bytes(), n
    # The collection stage is warm on the cluster's entries and equals the serial result.
    warm = coseg.segment(chairs, cache_dir=dist, out=tmp_path / "warm", regions=4, **SMALL)
    assert warm["outcomes"] == ["hit"] * 6
    cold = coseg.segment(chairs, cache_dir=tmp_path / "cold-cache", out=tmp_path / "cold", regions=4, **SMALL)
    assert cold["outcomes"] == ["miss"] * 6
    for a, b in zip(warm["labels"], cold["labels"]):
        assert np.array_equal(a, b)
    # And the CLI, reading the same cache, is warm and writes the same region files.
    cli = subprocess.run(
        [coseg_bin, "segment", str(chairs), "-o", str(tmp_path / "cli"), "--cache", str(dist),
         "--regions", "4", *cli_flags()],
        check=True, capture_output=True, text=True,
    )
    assert "(6 cached)" in cli.stdout, cli.stdout
    for n in sorted(p.name for p in (tmp_path / "warm").iterdir() if ".regions." in p.name):
        assert (tmp_path / "warm" / n).read_bytes() == (tmp_path / "cli" / n).read_bytes(), n
    # Label propagation reads the same entries warm, and equals a cold run.
    src = COLLECTIONS / "chairs" / "chairs_00.labels.txt"
    pw = coseg.propagate(chairs, src, cache_dir=dist, **SMALL)
    assert pw["outcomes"] == ["hit"] * 6 and pw["sources"] == ["chairs_00"]
    pc = coseg.propagate(chairs, src, cache_dir=tmp_path / "cold-cache", **SMALL)
    assert all(np.array_equal(a, b) for a, b in zip(pw["labels"], pc["labels"]))


def test_dask_with_feature_families(client, chairs, tmp_path):
    """The feature families are part of the key: precompute with them, and segment with the
    same families is warm and equals a serial run."""
    fam = dict(families="spectral,extrinsic", up="z", directions=6, family_weights={"extrinsic": 2})
    cache = tmp_path / "fam-cache"
    rep = coseg.dask.precompute(chairs, client, cache, **SMALL, **fam)
    assert rep.ok and len(rep.computed) == 6
    plain = coseg.shape_key(sorted(chairs.glob("*.obj"))[0].read_bytes(), "obj", **SMALL)
    with_fam = coseg.shape_key(sorted(chairs.glob("*.obj"))[0].read_bytes(), "obj", **SMALL, **fam)
    assert plain[0] != with_fam[0] and (cache / f"{with_fam[0]}.coseg-shape").is_file()
    warm = coseg.segment(chairs, cache_dir=cache, regions=4, **SMALL, **fam)
    assert warm["outcomes"] == ["hit"] * 6
    cold = coseg.segment(chairs, cache_dir=tmp_path / "c2", regions=4, **SMALL, **fam)
    assert all(np.array_equal(a, b) for a, b in zip(warm["labels"], cold["labels"]))


def test_failures_are_skipped_and_a_rerun_resumes(client, chairs, tmp_path):
    (chairs / "broken.obj").write_text("v 0 0 0\nv 1 0 0\nf 1 2 7\n")
    (chairs / "flat.off").write_text("OFF\n3 1 0\n0 0 0\n1 0 0\n2 0 0\n3 0 1 2\n")
    cache = tmp_path / "cache"
    rep = coseg.dask.precompute(chairs, client, cache, ship="path", **SMALL)
    failed = dict(rep.failed)
    assert sorted(Path(p).name for p in failed) == ["broken.obj", "flat.off"]
    assert all(Path(p).name in m for p, m in failed.items())
    assert len(rep.computed) == 6
    # A rerun submits nothing that is done.
    again = coseg.dask.precompute(chairs, client, cache, **SMALL)
    assert again.computed == [] and len(again.cached) == 6 and len(again.failed) == 2
    # Lose one entry (or corrupt it): only that shape is recomputed.
    victims = sorted(cache.glob("*.coseg-shape"))
    victims[0].unlink()
    data = bytearray(victims[1].read_bytes())
    data[-1] ^= 1
    victims[1].write_bytes(bytes(data))
    third = coseg.dask.precompute(chairs, client, cache, **SMALL)
    assert len(third.computed) == 2 and len(third.cached) == 4


def test_a_failing_task_does_not_lose_finished_entries(client, chairs, tmp_path, monkeypatch):
    """A shape whose task raises on the worker (here: its file vanishes before the worker
    reads it) is reported; the others are written."""
    files = coseg.dask.mesh_files(chairs)
    gone = tmp_path / "gone.obj"
    shutil.copy(files[0], gone)
    orig = coseg.shape_key

    def key_then_delete(data, fmt, **o):
        out = orig(data, fmt, **o)
        if gone.exists() and data == gone.read_bytes():
            gone.unlink()
        return out

    monkeypatch.setattr(coseg.dask, "shape_key", key_then_delete)
    rep = coseg.dask.precompute([str(gone)] + files[1:3], client, tmp_path / "c", ship="path", **SMALL)
    assert [Path(p).name for p, _ in rep.failed] == ["gone.obj"]
    assert len(rep.computed) == 2
    assert len(list((tmp_path / "c").glob("*.coseg-shape"))) == 2
