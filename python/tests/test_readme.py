"""The README's Python example runs as printed (from the repository root)."""

import re
import subprocess
import sys

import pytest

from conftest import REPO

MARKER = "<!-- python example: python/tests/test_readme.py runs it -->"


def test_readme_example_runs():
    pytest.importorskip("trimesh")
    text = (REPO / "README.md").read_text()
    assert MARKER in text
    block = re.search(r"```python\n(.*?)```", text[text.index(MARKER):], re.S).group(1)
    assert len(block.strip().splitlines()) <= 10
    r = subprocess.run([sys.executable, "-c", block], cwd=REPO, capture_output=True, text=True, timeout=900)
    assert r.returncode == 0, r.stderr
    lines = r.stdout.splitlines()
    assert len(lines) == 6 and lines[0].startswith("shape000") and "confidence 1.00" in lines[0]
