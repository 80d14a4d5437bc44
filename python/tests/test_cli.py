"""The package gives the CLI's results: region files byte for byte, cache entries byte for byte."""

import json
import subprocess
from pathlib import Path

import numpy as np

import coseg
from conftest import COLLECTIONS, SMALL, cli_flags


def region_files(d):
    return sorted(p.name for p in Path(d).iterdir() if ".regions." in p.name)


def assert_same_outputs(a, b):
    names = region_files(a)
    assert names and names == region_files(b)
    for n in names:
        assert (Path(a) / n).read_bytes() == (Path(b) / n).read_bytes(), n
    sa, sb = (json.loads((Path(d) / "summary.json").read_text()) for d in (a, b))
    for s in (sa, sb):  # input paths are spelled differently; everything else must agree
        for shape in s.get("shapes", []):
            shape.pop("file", None)
    assert sa == sb


def test_segment_matches_the_cli(coseg_bin, chairs, tmp_path):
    cli_out, py_out = tmp_path / "cli", tmp_path / "py"
    subprocess.run(
        [coseg_bin, "segment", str(chairs), "-o", str(cli_out), "--regions", "4", *cli_flags()],
        check=True,
        capture_output=True,
    )
    r = coseg.segment(chairs, out=py_out, regions=4, **SMALL)
    assert_same_outputs(cli_out, py_out)
    # The CLI's cache entries are the pure task's bytes: same content key, same content.
    for obj in sorted(chairs.glob("*.obj")):
        e = coseg.shape_entry(obj.read_bytes(), "obj", **SMALL)
        assert (cli_out / ".cache" / f"{e.key}.coseg-shape").read_bytes() == e.entry
        assert (cli_out / ".cache" / f"{e.key}.coseg-bands").read_bytes() == e.bands_entry
    # The folder form read the CLI's entries? No: it used its own <out>/.cache. Both agree.
    assert all(o == "miss" for o in r["outcomes"])
    # Arrays in give the same labels as the folder.
    shapes = [coseg.read_mesh(p) for p in sorted(chairs.glob("*.obj"))]
    names = [p.stem for p in sorted(chairs.glob("*.obj"))]
    r2 = coseg.segment(shapes, names=names, regions=4, **SMALL)
    assert r2["names"] == r["names"] == names
    for a, b in zip(r["labels"], r2["labels"]):
        assert a.dtype == np.int32 and np.array_equal(a, b)
    # Labels are the region files' content.
    for name, labels in zip(r["names"], r["labels"]):
        txt = (py_out / f"{name}.regions.txt").read_text().split()
        assert np.array_equal(np.array(txt, dtype=np.int32), labels)


def test_pair_matches_the_cli(coseg_bin, tmp_path):
    a = COLLECTIONS / "goblets" / "goblets_00.obj"
    b = COLLECTIONS / "goblets" / "goblets_01.obj"
    cli_out, py_out = tmp_path / "cli", tmp_path / "py"
    subprocess.run(
        [coseg_bin, "pair", str(a), str(b), "-o", str(cli_out), "--pairs", "5", *cli_flags()],
        check=True,
        capture_output=True,
    )
    r = coseg.pair(a, b, out=py_out, pairs=5, **SMALL)
    names = region_files(cli_out)
    assert names == region_files(py_out) == ["goblets_00.regions.ply", "goblets_00.regions.txt",
                                              "goblets_01.regions.ply", "goblets_01.regions.txt"]
    for n in names:
        assert (cli_out / n).read_bytes() == (py_out / n).read_bytes(), n
    sa = json.loads((cli_out / "summary.json").read_text())
    sb = r["summary"]
    for s in (sa, sb):
        s.pop("seconds", None)
        for shape in s["shapes"]:
            shape.pop("file")
    assert sa == sb
    assert r["labels_a"].shape == (coseg.read_mesh(a)[0].shape[0],)
    assert len(np.unique(r["labels_b"])) <= 5


def test_feature_families_match_the_cli(coseg_bin, chairs, tmp_path):
    """families=, up=, directions=, family_weights= are the CLI's --features, --up,
    --directions, --family-weights: same region files byte for byte."""
    cli_out, py_out = tmp_path / "cli", tmp_path / "py"
    subprocess.run(
        [coseg_bin, "segment", str(chairs), "-o", str(cli_out), "--regions", "4", *cli_flags(),
         "--features", "spectral,extrinsic", "--up", "z", "--directions", "8",
         "--family-weights", "extrinsic=2", "--no-pictures"],
        check=True,
        capture_output=True,
    )
    r = coseg.segment(chairs, out=py_out, regions=4, families=("spectral", "extrinsic"), up="z",
                      directions=8, family_weights={"extrinsic": 2}, **SMALL)
    assert_same_outputs(cli_out, py_out)
    # The weights matter: equal weights give other regions (else the test could not fail).
    r1 = coseg.segment(chairs, regions=4, families="spectral,extrinsic", up="z", directions=8,
                       cache_dir=tmp_path / "c1", **SMALL)
    assert any(not np.array_equal(a, b) for a, b in zip(r["labels"], r1["labels"]))
    # The extrinsic columns follow the spectral ones in the feature table.
    V, F = coseg.read_mesh(sorted(chairs.glob("*.obj"))[0])
    names, X = coseg.features(V, F, families=("spectral", "extrinsic"), directions=8, **{
        k: SMALL[k] for k in ("eigenpairs", "hks", "wks", "curvature")})
    assert X.shape == (len(V), len(names)) and len(names) > 36
    assert names[:12] == [f"hks_{i:03d}" for i in range(12)]
    assert all(n.startswith("ext_") for n in names[36:])
    names2, X2 = coseg.features(V, F, families="extrinsic", directions=8)
    assert names2 == names[36:] and np.array_equal(X2, X[:, 36:])


def test_parts_starts_and_normals_match_the_cli(coseg_bin, chairs, tmp_path):
    """parts=, refine_sizes=, starts=, normals= are the CLI's --parts, --refine-sizes, --starts,
    --normals: same region files and summary (with its parts report) byte for byte."""
    fam = ["--features", "spectral,extrinsic", "--up", "y", "--directions", "8", "--normals", "4"]
    kw = dict(families="spectral,extrinsic", up="y", directions=8, normals=4, **SMALL)
    runs = [
        (["--regions", "5", "--parts", "3", "--parts-from", "adaptive", "--refine-sizes", "keep:0.3"],
         dict(regions=5, parts=3, parts_from="adaptive", refine_sizes="keep:0.3")),
        (["--parts", "auto"], dict(parts="auto")),
        (["--regions", "3", "--starts", "2"], dict(regions=3, starts=2)),
        (["--regions", "6", "--parts", "3", "--parts-from", "geometry"],
         dict(regions=6, parts=3, parts_from="geometry")),
        (["--regions", "6", "--parts", "3", "--parts-from", "geometry", "--snap-band", "0.05"],
         dict(regions=6, parts=3, parts_from="geometry", snap_band=0.05)),
    ]
    for k, (flags, opts) in enumerate(runs):
        cli_out, py_out = tmp_path / f"cli{k}", tmp_path / f"py{k}"
        subprocess.run(
            [coseg_bin, "segment", str(chairs), "-o", str(cli_out), *cli_flags(), *fam, *flags,
             "--no-pictures"],
            check=True,
            capture_output=True,
        )
        r = coseg.segment(chairs, out=py_out, **opts, **kw)
        assert_same_outputs(cli_out, py_out)
        if "parts" in opts:
            assert r["summary"]["parts"]["region_leaves"]
            # Mirror pairs are compared on the spectral columns (a likeness) in both.
            assert all(p["likeness"] is not None for p in r["summary"]["parts"]["mirror_pairs"])
            if opts.get("parts_from") == "geometry":
                band = opts.get("snap_band", 0.1)
                assert r["summary"]["options"]["parts_from"] == {
                    "kind": "geometry", "leaves": 6, "band": band}
                assert r["summary"]["parts"]["stop"] == {"reason": "equal_area_leaves"}
            elif opts["parts"] == 3:
                assert len(r["summary"]["parts"]["region_leaves"]) == 3
                assert r["summary"]["options"]["refine_sizes"] == {"rule": "keep", "tolerance": 0.3}
        else:
            assert "parts" not in r["summary"]
            assert len(r["summary"]["starts"]["scores"]) == 2
    # The normal columns are in the table, banded by value.
    V, F = coseg.read_mesh(sorted(chairs.glob("*.obj"))[0])
    names, X = coseg.features(V, F, families="extrinsic", directions=8, normals=4)
    assert names[-4:] == [f"ext_nrm_{i:03d}" for i in range(4)]
    T = coseg.band_table(V, F, families="extrinsic", directions=8, normals=4, bands=10)
    assert np.array_equal(T[:, -4:], np.minimum(np.floor(X[:, -4:] * 10), 9).astype(np.uint8))


def test_bad_parts_options_raise(chairs):
    cases = [
        (dict(parts=0), "expected"),
        (dict(parts="many"), "expected"),
        (dict(refine_sizes="keep:-1"), "expected"),
        (dict(refine_sizes="tight"), "expected"),
        (dict(parts="auto", starts=3), "starts = 3"),  # several starts: equal-area mode only
        (dict(parts=2, parts_from="size"), "expected"),
        (dict(parts=2, parts_from="adaptive", snap_band=0.1), "parts from geometry"),  # the band is geometry's
        (dict(parts=2, parts_from="geometry", snap_band=-1.0), "finite value"),
    ]
    for bad, message in cases:
        try:
            coseg.segment(chairs, **bad, **SMALL)
        except coseg.InputError as e:
            assert message in str(e), (bad, str(e))
        else:
            raise AssertionError(f"{bad} accepted")


def test_bare_segment_matches_the_bare_cli(coseg_bin, chairs, tmp_path):
    """coseg.segment(shapes) with no mode or family options is the bare `coseg segment`: parts,
    their number and the feature families chosen from the data, each choice with its reason."""
    cli_out, py_out = tmp_path / "cli", tmp_path / "py"
    subprocess.run(
        [coseg_bin, "segment", str(chairs), "-o", str(cli_out), *cli_flags(), "--no-pictures"],
        check=True,
        capture_output=True,
    )
    r = coseg.segment(chairs, out=py_out, **SMALL)
    assert_same_outputs(cli_out, py_out)
    s = r["summary"]
    assert s["features"]["chosen"] in ("intrinsic", "intrinsic_extrinsic") and s["features"]["reason"]
    assert s["part_count"]["count"] == len(s["regions"]) and s["part_count"]["reason"]
