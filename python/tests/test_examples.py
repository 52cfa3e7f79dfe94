"""The Python examples (examples/python/) run and do what they say, on small settings."""

import subprocess
import sys

import pytest

import trivox
from conftest import EXAMPLES

PYTHON_EXAMPLES = EXAMPLES / "python"


def run(script, *args, prelude="pass"):
    code = (f"import runpy, sys; {prelude}; sys.argv = {[str(script), *map(str, args)]!r}; "
            f"runpy.run_path({str(script)!r}, run_name='__main__')")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert p.returncode == 0, p.stderr
    return p.stdout


def test_every_example_is_tested():
    assert sorted(p.name for p in PYTHON_EXAMPLES.glob("*.py")) == [
        "chalice.py", "invert_points.py", "numpy_material.py", "show_layer.py"]


def test_chalice(tmp_path):
    out = run(PYTHON_EXAMPLES / "chalice.py", "--out", tmp_path, "--layers", "250:251")
    assert "knot: " in out and "2 layers" in out
    assert trivox.read_scene(tmp_path / "chalice.json").num_materials == 4
    assert (tmp_path / "slice_00002.png").exists()


def test_numpy_material(tmp_path):
    out = run(PYTHON_EXAMPLES / "numpy_material.py", "--out", tmp_path, "--layer", "300")
    assert "voxels inside" in out
    image = trivox.read_png(str(tmp_path / "layer_00300.png"))
    assert len({tuple(c) for c in image.reshape(-1, 4)[::97]}) >= 3  # white, cyan-ish, magenta-ish


def test_invert_points():
    out = run(PYTHON_EXAMPLES / "invert_points.py", "--points", "3000")
    assert "none 300, unique 3000" in out and "3000 of 3000 converged" in out


def test_show_layer_with_matplotlib(tmp_path):
    pytest.importorskip("matplotlib")
    out = run(PYTHON_EXAMPLES / "show_layer.py", "--layer", "20", "--out", tmp_path / "plot.png")
    assert "saved the figure" in out and (tmp_path / "plot.png").stat().st_size > 10000


def test_show_layer_says_so_without_matplotlib(tmp_path):
    out = run(PYTHON_EXAMPLES / "show_layer.py", "--layer", "20", "--out", tmp_path / "labels.png",
              prelude="sys.modules['matplotlib'] = None")
    assert "matplotlib is not installed" in out
    assert trivox.read_png(str(tmp_path / "labels.png")).shape[2] == 4
