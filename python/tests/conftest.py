"""Fixtures of the Python API's tests (docs/PYTHON.md).

CTest runs each test file with PYTHONPATH at the build's python/ folder and these variables
(python/CMakeLists.txt): TRIVOX_CLI (the trivox program), TRIVOX_PYTHON_REFERENCE (the C++
reference program of test_library_equal.py), TRIVOX_SHARED_DATA_DIR (../shared/data). Tests that
need ../shared/data skip with a message when it is absent.
"""

import os
import pathlib
import subprocess

import numpy as np
import pytest

import trivox

ROOT = pathlib.Path(__file__).resolve().parents[2]
EXAMPLES = ROOT / "examples"
SCENES = EXAMPLES / "scenes"
COLUMN = EXAMPLES / "models" / "twisted_column.itd"
ANNULUS = EXAMPLES / "models" / "annulus_sector.itd"


def _build_file(variable, relative):
    path = os.environ.get(variable)
    if path:
        return pathlib.Path(path)
    candidate = ROOT / "build" / "release" / relative
    return candidate if candidate.exists() else None


@pytest.fixture(scope="session")
def cli():
    path = _build_file("TRIVOX_CLI", "bin/trivox")
    if path is None:
        pytest.skip("the trivox program is not built (TRIVOX_CLI unset)")
    return str(path)


@pytest.fixture(scope="session")
def reference():
    path = _build_file("TRIVOX_PYTHON_REFERENCE", "bin/trivox_python_reference")
    if path is None:
        pytest.skip("trivox_python_reference is not built (TRIVOX_PYTHON_REFERENCE unset)")
    return str(path)


@pytest.fixture(scope="session")
def shared_data():
    path = pathlib.Path(os.environ.get("TRIVOX_SHARED_DATA_DIR", ROOT.parent / "shared" / "data"))
    if not path.is_dir():
        pytest.skip(f"{path} is absent: the real models of ../shared/data are needed for this test")
    return path


@pytest.fixture(scope="session")
def column():
    return trivox.read(str(COLUMN)).volumes()[0]


def run_cli(cli, *args, check=True):
    """Runs the trivox program; returns (exit code, stdout, stderr)."""
    p = subprocess.run([cli, *map(str, args)], capture_output=True, text=True)
    if check and p.returncode != 0:
        raise AssertionError(f"trivox {' '.join(map(str, args))} failed ({p.returncode}): {p.stderr}")
    return p.returncode, p.stdout, p.stderr


def cli_error(cli, *args):
    """The message the trivox program prints for an error, without its "trivox: KIND: " prefix."""
    code, _, err = run_cli(cli, *args, check=False)
    assert code != 0, f"trivox {' '.join(map(str, args))} succeeded"
    line = err.strip().splitlines()[0]
    prefix, _, message = line.partition(": ")
    assert prefix == "trivox"
    return message.partition(": ")[2]


def bits(a):
    """The bytes of an array, for comparisons bit for bit (-0.0 differs from 0.0, NaN equals NaN)."""
    return np.ascontiguousarray(a).tobytes()


def random_params(volume, n, seed):
    """n parameters in the volume's domain, the domain's faces and corners among them."""
    rng = np.random.default_rng(seed)
    lo, hi = volume.domain[:, 0], volume.domain[:, 1]
    p = lo + (hi - lo) * rng.random((n, 3))
    corners = np.array([[a, b, c] for a in (0, 1) for b in (0, 1) for c in (0, 1)], dtype=float)
    p[: len(corners)] = lo + (hi - lo) * corners
    p[len(corners): 2 * len(corners), 0] = lo[0]
    return p
