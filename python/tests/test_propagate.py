"""coseg.propagate: the CLI's labels byte for byte (folder and arrays in), and bad labels raise."""

import json
import subprocess
import threading
import time
from pathlib import Path

import numpy as np
import pytest

import coseg
from coseg import FileError, InputError
from conftest import COLLECTIONS, SMALL, cli_flags

GOBLETS = COLLECTIONS / "goblets"
SOURCE = GOBLETS / "goblets_00.labels.txt"
MESHES = sorted(GOBLETS.glob("*.obj"))
NAMES = [p.stem for p in MESHES]


def output_files(d):
    return sorted(p.name for p in Path(d).iterdir() if p.is_file())


@pytest.fixture(scope="module")
def cli_run(coseg_bin, tmp_path_factory):
    """`coseg propagate collections/goblets --labels goblets_00.labels.txt --no-pictures`."""
    out = tmp_path_factory.mktemp("cli") / "out"
    subprocess.run(
        [coseg_bin, "propagate", str(GOBLETS), "--labels", str(SOURCE), "-o", str(out), "--no-pictures",
         "--quiet", *cli_flags()],
        check=True,
        capture_output=True,
    )
    return out


def test_folder_matches_the_cli_byte_for_byte(cli_run, tmp_path):
    out = tmp_path / "py"
    r = coseg.propagate(GOBLETS, SOURCE, out=out, cache_dir=tmp_path / "cache", **SMALL)
    files = output_files(cli_run)
    # Per shape .labels.txt, .seg, .labels.ply, and summary.json: the same names, the same bytes
    # (the summary too: both name the same input paths and have no timings).
    assert len(files) == 3 * len(NAMES) + 1 and files == output_files(out)
    for f in files:
        assert (cli_run / f).read_bytes() == (out / f).read_bytes(), f
    assert sorted(map(str, r["written"])) == sorted(str(out / f) for f in files)
    assert r["names"] == NAMES and r["sources"] == ["goblets_00"]
    assert r["summary"] == json.loads((cli_run / "summary.json").read_text())
    assert r["outcomes"] == ["miss"] * len(NAMES)
    for name, labels, conf, mesh in zip(r["names"], r["labels"], r["confidence"], MESHES):
        txt = np.array((cli_run / f"{name}.labels.txt").read_text().split(), dtype=np.int32)
        assert labels.dtype == np.int32 and np.array_equal(labels, txt)
        assert conf.dtype == np.float64 and conf.shape == labels.shape
        assert np.all((conf >= 0) & (conf <= 1))
    truth = np.loadtxt(SOURCE, dtype=np.int64)
    assert np.array_equal(r["labels"][0], truth)  # the source keeps its annotation
    assert np.all(r["confidence"][0] == 1.0)
    assert r["parts"] == sorted(set(truth.tolist()) - {-1})
    assert r["shape_confidence"].shape == (len(NAMES),)
    # Warm: a second run reads the cache and gives the same labels.
    r2 = coseg.propagate(GOBLETS, [SOURCE], cache_dir=tmp_path / "cache", **SMALL)
    assert r2["outcomes"] == ["hit"] * len(NAMES)
    assert all(np.array_equal(a, b) for a, b in zip(r["labels"], r2["labels"]))


def test_arrays_match_the_cli(cli_run, tmp_path):
    shapes = [coseg.read_mesh(p) for p in MESHES]
    truth = np.loadtxt(SOURCE, dtype=np.int64)
    labels = [truth] + [None] * (len(shapes) - 1)
    out = tmp_path / "arrays"
    r = coseg.propagate(shapes, labels, names=NAMES, out=out, **SMALL)
    assert r["names"] == NAMES and r["outcomes"] == ["computed"] * len(NAMES)
    for f in output_files(cli_run):
        if f != "summary.json":
            assert (cli_run / f).read_bytes() == (out / f).read_bytes(), f
    # The summary agrees but for where the inputs came from.
    sa, sb = (json.loads((d / "summary.json").read_text()) for d in (cli_run, out))
    assert sb["shapes"][0]["label_file"] == "<array>"
    for s in (sa, sb):
        for shape in s["shapes"]:
            shape.pop("file")
            shape.pop("label_file")
    assert sa == sb
    # The same through trimesh, with a dict naming the one source, and with the label file
    # as the source's entry of a list of mesh paths.
    trimesh = pytest.importorskip("trimesh")
    meshes = [trimesh.load(p, process=False) for p in MESHES]
    r2 = coseg.propagate(meshes, {"goblets_00": truth}, names=NAMES, **SMALL)
    r3 = coseg.propagate(MESHES, [SOURCE] + [None] * (len(MESHES) - 1), **SMALL)
    assert r3["names"] == NAMES
    for a, b, c in zip(r["labels"], r2["labels"], r3["labels"]):
        assert np.array_equal(a, b) and np.array_equal(a, c)
    assert all(np.array_equal(a, b) for a, b in zip(r["confidence"], r3["confidence"]))


def test_partial_and_int32_annotations(tmp_path):
    """Unlabelled vertices (-1, or any negative) of a source are filled, labelled ones kept;
    int32 and int64 arrays give the same result."""
    shapes = [coseg.read_mesh(p) for p in MESHES[:3]]
    truth = np.loadtxt(SOURCE, dtype=np.int64)
    partial = truth.copy()
    partial[::2] = -1
    odd = partial.copy()
    odd[odd < 0] = -7  # any negative means unlabelled
    r = coseg.propagate(shapes, [partial, None, None], **SMALL)
    r32 = coseg.propagate(shapes, [odd.astype(np.int32), None, None], **SMALL)
    labelled = partial >= 0
    assert np.array_equal(r["labels"][0][labelled], partial[labelled])
    assert np.all(r["labels"][0] >= 0)
    assert np.all(r["confidence"][0][labelled] == 1.0)
    assert all(np.array_equal(a, b) for a, b in zip(r["labels"], r32["labels"]))


def test_bad_labels_raise(tmp_path):
    shapes = [coseg.read_mesh(p) for p in MESHES[:2]]
    n0 = len(shapes[0][0])
    good = np.zeros(n0, dtype=np.int64)
    with pytest.raises(InputError, match=r"goblets|shape 0"):
        coseg.propagate(shapes, [good[:-1], None], **SMALL)  # one label short
    with pytest.raises(InputError, match="integers"):
        coseg.propagate(shapes, [good.astype(float), None], **SMALL)
    with pytest.raises(InputError, match="1-D"):
        coseg.propagate(shapes, [good.reshape(-1, 1), None], **SMALL)
    with pytest.raises(InputError, match="range"):
        coseg.propagate(shapes, [good + 2**40, None], **SMALL)
    with pytest.raises(InputError, match="no labelled shape"):
        coseg.propagate(shapes, [good - 1, None], **SMALL)  # every vertex unlabelled
    with pytest.raises(InputError, match="no labelled shape"):
        coseg.propagate(shapes, [None, None], **SMALL)
    with pytest.raises(InputError, match="entries for 2 shapes"):
        coseg.propagate(shapes, [good], **SMALL)
    with pytest.raises(InputError, match="no shape named"):
        coseg.propagate(shapes, {"chair": good}, **SMALL)
    with pytest.raises(FileError, match="missing.labels.txt"):
        coseg.propagate(shapes, [tmp_path / "missing.labels.txt", None], **SMALL)
    short = tmp_path / "short.labels.txt"
    short.write_text("0\n1\n")
    with pytest.raises(InputError, match="short.labels.txt"):
        coseg.propagate(shapes, [short, None], **SMALL)
    # Past the Python checks, the native module checks the same.
    opts = coseg._pipeline_opts(dict(SMALL))
    with pytest.raises(InputError, match="labels for a mesh of"):
        coseg._coseg.propagate(shapes, [good[:-3], None], None, opts)
    with pytest.raises(InputError, match="int64"):
        coseg._coseg.propagate(shapes, [good.astype(float), None], None, opts)
    with pytest.raises(InputError, match="32-bit"):
        coseg._coseg.propagate(shapes, [good + 2**40, None], None, opts)
    # A folder: a label file for no mesh names the file; bad options are InputErrors.
    nomesh = tmp_path / "nomesh.labels.txt"
    nomesh.write_text("0\n")
    with pytest.raises(InputError, match="nomesh.labels.txt"):
        coseg.propagate(GOBLETS, nomesh, cache_dir=tmp_path / "c", **SMALL)
    with pytest.raises(InputError, match="size_prior"):
        coseg.propagate(shapes, [good, None], size_prior=2.0, **SMALL)
    with pytest.raises(TypeError):
        coseg.propagate(shapes, [good, None], sweeps=2, **SMALL)


def test_propagate_releases_the_gil():
    """While propagate computes on another thread, this one keeps running."""
    shapes = [coseg.read_mesh(p) for p in MESHES]
    truth = np.loadtxt(SOURCE, dtype=np.int64)
    done = {}

    def work():
        # 100 eigenpairs (not SMALL's 30): long enough on a fast host for the check below to
        # mean something (with SMALL it once took 0.42 s, under the 0.5 s the check needs).
        done["r"] = coseg.propagate(shapes, [truth] + [None] * 5, **dict(SMALL, eigenpairs=100))

    t = threading.Thread(target=work)
    t0 = time.perf_counter()
    t.start()
    last, gap = time.perf_counter(), 0.0
    while t.is_alive():
        time.sleep(0.005)
        now = time.perf_counter()
        gap, last = max(gap, now - last), now
    total = time.perf_counter() - t0
    assert "r" in done
    # Holding the GIL, the loop above would stall for the whole computation.
    assert total > 0.5 and gap < 0.5 * total, (gap, total)


def test_map_step_and_area_weights_match_the_cli(coseg_bin, tmp_path):
    """map_step=, map_agreement=, area_weighted=, normals= are the CLI's --map-step,
    --map-agreement, --area-weighted, --normals: the same files byte for byte, the map step's
    decisions in the summary."""
    cli = tmp_path / "cli"
    subprocess.run(
        [coseg_bin, "propagate", str(GOBLETS), "--labels", str(SOURCE), "-o", str(cli), "--no-pictures",
         "--quiet", *cli_flags(), "--map-step", "--map-agreement", "0.5", "--area-weighted", "true",
         "--features", "spectral,extrinsic", "--normals", "4", "--directions", "8"],
        check=True,
        capture_output=True,
    )
    out = tmp_path / "py"
    kw = dict(families="spectral,extrinsic", normals=4, directions=8, area_weighted=True, **SMALL)
    r = coseg.propagate(GOBLETS, SOURCE, out=out, map_step=True, map_agreement=0.5, **kw)
    for f in output_files(cli):
        assert (cli / f).read_bytes() == (out / f).read_bytes(), f
    assert r["summary"]["map_step"]["min_agreement"] == 0.5
    assert sum("map_step" in s for s in r["summary"]["shapes"]) == len(NAMES) - 1
    # Without the map step the summary has no trace of it.
    r0 = coseg.propagate(GOBLETS, SOURCE, cache_dir=tmp_path / "c0", **kw)
    assert "map_step" not in r0["summary"]
    # Shapes in memory have no cached spectra: a clear error, before any work.
    shapes = [coseg.read_mesh(p) for p in MESHES]
    with pytest.raises(InputError, match="map_step"):
        coseg.propagate(shapes, [SOURCE] + [None] * (len(shapes) - 1), map_step=True, **kw)
