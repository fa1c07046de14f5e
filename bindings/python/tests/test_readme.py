"""The Python example of the repository README runs as printed (in a scratch directory with
a copy of the asset it reads)."""
import os
import re
import shutil

import pytest

from conftest import needs

ROOT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "..")
MARKER = "<!-- tested by bindings/python/tests/test_readme.py -->"


def readme_example():
    path = os.path.join(ROOT, "README.md")
    if not os.path.exists(path):
        pytest.skip("README.md not found (not run from the repository)")
    with open(path, encoding="utf-8") as f:
        text = f.read()
    m = re.search(re.escape(MARKER) + r"\s*```python\n(.*?)```", text, re.S)
    assert m, f"README.md has no python block after {MARKER}"
    return m.group(1)


@needs("lod")
def test_readme_python_example(tmp_path, monkeypatch, capsys):
    code = readme_example()
    assert len(code.strip().splitlines()) <= 12, "the README example stays short"
    (tmp_path / "assets").mkdir()
    shutil.copy(os.path.join(ROOT, "assets", "dirty_two_boxes.obj"), tmp_path / "assets")
    monkeypatch.chdir(tmp_path)
    exec(compile(code, "README.md", "exec"), {})
    out = capsys.readouterr().out.splitlines()
    assert out[0] == "False" and len(out) == 3 and all(line.endswith("True") for line in out[1:])
    assert (tmp_path / "two_boxes_lod20.obj").exists()
