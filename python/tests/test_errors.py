"""Bad input raises the package's exceptions with the library's messages; never a crash."""

import numpy as np
import pytest

import coseg
from coseg import FileError, InputError, _coseg
from conftest import SMALL, octahedron_sphere

V, F = octahedron_sphere(1)


@pytest.mark.parametrize(
    "v,f,words",
    [
        (V[:, :2], F, "n x 3"),
        (V, F[:, :2], "m x 3"),
        (V.ravel(), F, "n x 3"),
        (np.where(np.arange(len(V))[:, None] == 3, np.nan, V), F, "non-finite"),
        (np.where(np.arange(len(V))[:, None] == 2, np.inf, V), F, "non-finite"),
        (V, np.where(F == F.max(), len(V), F), f"vertex {len(V)}"),
        (V, np.where(F == 0, -1, F), "vertex -1"),
        (V, F.astype(np.float64), "integers"),
        (V.astype(np.complex128), F, "real numbers"),
        (V.astype(str), F, "real numbers"),
        (np.zeros((0, 3)), np.zeros((0, 3), dtype=int), "empty"),
        (np.zeros((3, 3)), np.array([[0, 1, 2]]), "area"),
    ],
)
def test_bad_arrays_raise_input_error(v, f, words):
    for call in (
        lambda: coseg.spectrum(v, f, 5),
        lambda: coseg.band_table(v, f, **SMALL),
        lambda: coseg.features(v, f, eigenpairs=5),
    ):
        with pytest.raises(InputError) as e:
            call()
        assert isinstance(e.value, ValueError)
        assert words.lower() in str(e.value).lower(), str(e.value)


def test_the_native_layer_checks_too():
    """Arrays that bypass the Python checks are still refused by the Rust side."""
    with pytest.raises(InputError, match="non-finite|NaN|finite"):
        bad = V.copy()
        bad[0, 0] = np.nan
        _coseg.spectrum(bad, F, 5)
    with pytest.raises(InputError, match="refers to vertex"):
        _coseg.spectrum(V, np.where(F == 0, 10**6, F), 5)
    with pytest.raises(InputError, match="refers to vertex -5"):
        _coseg.spectrum(V, np.where(F == 0, -5, F), 5)
    with pytest.raises(InputError, match="n x 3"):
        _coseg.spectrum(np.zeros((4, 4)), F, 5)
    with pytest.raises(TypeError):
        _coseg.spectrum(V.astype(np.float32), F, 5)  # wrong dtype: numpy's conversion error


def test_file_errors_are_oserrors(tmp_path):
    with pytest.raises(FileError) as e:
        coseg.read_mesh(tmp_path / "missing.obj")
    assert isinstance(e.value, OSError) and "missing.obj" in str(e.value)
    bad = tmp_path / "bad.off"
    bad.write_text("OFF\n3 1 0\n0 0 0\n1 0 0\n")
    with pytest.raises(InputError) as e:
        coseg.read_mesh(bad)
    assert "bad.off" in str(e.value)
    with pytest.raises(InputError, match="unsupported mesh format"):
        coseg.read_mesh(tmp_path / "x.stl")


def test_bad_options():
    with pytest.raises(TypeError, match="unknown"):
        coseg.shape_key(b"", "obj", eigenpair=3)
    with pytest.raises(InputError, match="map_preset"):
        coseg.pair((V, F), (V, F), map_preset="sideways", **SMALL)
    with pytest.raises(InputError, match="algorithm"):
        coseg.pair((V, F), (V, F), algorithm="fast", **SMALL)
    with pytest.raises(InputError):
        coseg.band_table(V, F, eigenpairs=0)
    with pytest.raises(InputError, match="families"):
        coseg.features(V, F, families=("hks", "sift"))
    with pytest.raises(InputError, match="at least 2"):
        coseg.segment([(V, F)], **SMALL)
    with pytest.raises(InputError, match="shape 1"):
        coseg.segment([(V, F), (V[:, :2], F)], **SMALL)
    with pytest.raises(InputError, match="64-digit"):
        coseg.entry_is_valid("/tmp", "nothex", 3)


def test_untrusted_entries_are_refused(tmp_path):
    obj = b"v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 0.5 0.5 1\nf 1 2 5\nf 2 3 5\nf 3 4 5\nf 4 1 5\nf 1 3 2\nf 1 4 3\n"
    e = coseg.shape_entry(obj, "obj", eigenpairs=3, hks=2, wks=2, curvature=2, bands=2)
    corrupt = bytearray(e.entry)
    corrupt[-1] ^= 0xFF
    with pytest.raises(InputError, match="checksum"):
        coseg.store_entry(tmp_path, e.key, e.vertices, bytes(corrupt), e.bands_entry)
    with pytest.raises(InputError, match="truncated"):
        coseg.store_entry(tmp_path, e.key, e.vertices, e.entry[:-10], e.bands_entry)
    other = "0" * 64
    with pytest.raises(InputError, match="key"):
        coseg.store_entry(tmp_path, other, e.vertices, e.entry, e.bands_entry)
    assert list(tmp_path.iterdir()) == []  # nothing written
    coseg.store_entry(tmp_path, e.key, e.vertices, e.entry, e.bands_entry)
    assert coseg.entry_is_valid(tmp_path, e.key, e.vertices)
    assert not coseg.entry_is_valid(tmp_path, e.key, e.vertices + 1)
