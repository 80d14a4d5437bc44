"""numpy in and out: shapes, dtypes, values, and that layouts and dtypes do not change results."""

import numpy as np
import pytest

import coseg
from conftest import COLLECTIONS, SMALL, octahedron_sphere


def parse_obj(path):
    V, F = [], []
    for line in open(path):
        p = line.split()
        if p and p[0] == "v":
            V.append([float(x) for x in p[1:4]])
        elif p and p[0] == "f":
            idx = [int(x.split("/")[0]) - 1 for x in p[1:]]
            F += [[idx[0], idx[k], idx[k + 1]] for k in range(1, len(idx) - 1)]
    return np.array(V), np.array(F)


def test_read_mesh_matches_the_file_exactly():
    path = COLLECTIONS / "chairs" / "chairs_00.obj"
    V, F = coseg.read_mesh(path)
    V2, F2 = parse_obj(path)
    assert V.dtype == np.float64 and V.shape == V2.shape and V.shape[1] == 3
    assert F.dtype == np.int64 and F.shape == F2.shape
    assert np.array_equal(V, V2)  # bit for bit: shortest round-trip decimals
    assert np.array_equal(F, F2)


def test_spectrum_is_mass_orthonormal_and_starts_at_zero():
    V, F = octahedron_sphere(3)
    evals, evecs, areas = coseg.spectrum(V, F, 12)
    assert evals.shape == (12,) and evecs.shape == (len(V), 12) and areas.shape == (len(V),)
    assert abs(areas.sum() - 1.0) < 1e-12  # unit area
    assert abs(evals[0]) < 1e-8
    assert np.all(np.diff(evals) >= -1e-12)
    gram = evecs.T @ (areas[:, None] * evecs)
    assert np.allclose(gram, np.eye(12), atol=1e-8)
    # On a unit-area sphere the first non-zero eigenvalue has multiplicity 3.
    assert np.allclose(evals[1:4], evals[1], rtol=2e-2)


def test_dtypes_and_layouts_give_identical_results():
    V, F = octahedron_sphere(2)
    ref = coseg.band_table(V, F, **SMALL)
    variants = [
        (V.astype(np.float32).astype(np.float64), F),  # same values through another dtype
        (np.asfortranarray(V), np.asfortranarray(F)),
        (V.copy(), F.astype(np.int32)),
        (V.copy(), F.astype(np.uint32)),
        (np.hstack([V, V])[:, :3], np.hstack([F, F])[:, 3:]),  # strided views
    ]
    for v, f in variants[1:]:
        assert np.array_equal(coseg.band_table(v, f, **SMALL), ref)
    t = coseg.band_table(*variants[0], **SMALL)
    assert t.shape == ref.shape


def test_features_names_families_and_table():
    V, F = octahedron_sphere(2)
    names, m = coseg.features(V, F, eigenpairs=20, hks=5, wks=4, curvature=3)
    assert m.shape == (len(V), 12) and m.dtype == np.float64
    assert names[:5] == [f"hks_{i:03d}" for i in range(5)]
    assert names[5:9] == [f"wks_{i:03d}" for i in range(4)]
    assert names[9:] == [f"curv_{i:03d}" for i in range(3)]
    assert np.all(np.isfinite(m))
    names2, m2 = coseg.features(V, F, families=("wks",), eigenpairs=20, hks=5, wks=4, curvature=3)
    assert names2 == names[5:9]
    assert np.array_equal(m2, m[:, 5:9])
    t = coseg.band_table(V, F, eigenpairs=20, hks=5, wks=4, curvature=3, bands=4)
    assert t.shape == m.shape and t.dtype == np.uint8 and t.max() == 3
    # Equal-count bands: a feature's band never decreases as its value increases.
    for j in range(m.shape[1]):
        col, lab = m[:, j], t[:, j].astype(int)
        for b in range(3):
            lo, hi = col[lab == b], col[lab == b + 1]
            if lo.size and hi.size:
                assert lo.max() <= hi.min()


def test_every_keyword_default_is_the_librarys():
    """Generated from the signatures: every keyword of every public function whose default is
    set must be the library's (``coseg.DEFAULTS``, ``coseg::jobs::defaults``): the command's
    own, else the per-shape one. A keyword the library does not export fails here too."""
    import inspect

    import coseg.dask

    d = coseg.DEFAULTS
    # Two keywords the Python package names differently from the flags.
    flag_of = {"families": "features", "k": "eigenpairs"}
    checked, wrong = 0, []
    for module in (coseg,):
        for name in module.__all__:
            f = getattr(module, name)
            if not inspect.isfunction(f):
                continue
            for p in inspect.signature(f).parameters.values():
                if p.default is inspect.Parameter.empty or p.default is None:
                    continue
                key = flag_of.get(p.name, p.name)
                missing = object()
                lib = d.get(name, {}).get(key, d["pipeline"].get(key, missing))
                if lib is missing or lib != p.default or type(lib) is not type(p.default):
                    wrong.append(f"{module.__name__}.{name}({p.name}={p.default!r}): library {lib!r}")
                else:
                    checked += 1
    assert not wrong, "\n".join(wrong)
    assert checked > 60
    assert d["pipeline"]["eigenpairs"] == 200 and d["segment"]["regions"] is None


def test_trimesh_objects_are_accepted():
    trimesh = pytest.importorskip("trimesh")
    V, F = octahedron_sphere(2)
    mesh = trimesh.Trimesh(V, F, process=False)
    assert np.array_equal(coseg.band_table(mesh.vertices, mesh.faces, **SMALL), coseg.band_table(V, F, **SMALL))
    r1 = coseg.segment([mesh, mesh], regions=3, **SMALL)
    r2 = coseg.segment([(V, F), (V, F)], regions=3, **SMALL)
    assert all(np.array_equal(a, b) for a, b in zip(r1["labels"], r2["labels"]))
