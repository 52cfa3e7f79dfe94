"""The module's behaviour at run time: the bulk calls and slicing release the GIL, a million
calls leak nothing, and importing trivox needs no numpy.

The GIL test is not timed: with the interpreter's switch interval set far beyond the test's
length, a thread that holds the GIL keeps it until it blocks, so the main thread can run while
another thread is inside a call only if the call released the GIL. (How much two threads gain
from it on two cores is measured by bench/python/api_bench.py, docs/PERFORMANCE.md.)
"""

import os
import subprocess
import sys
import threading

import numpy as np
import pytest

import trivox
from conftest import SCENES, random_params


def runs_without_the_gil(call):
    """True when the main thread runs Python code while another thread is inside call()."""
    started, finished = threading.Event(), threading.Event()

    def worker():
        started.set()
        call()
        finished.set()

    old = sys.getswitchinterval()
    sys.setswitchinterval(1000.0)
    try:
        t = threading.Thread(target=worker)
        t.start()
        started.wait()
        ran_meanwhile = not finished.is_set()
        t.join()
    finally:
        sys.setswitchinterval(old)
    return ran_meanwhile


@pytest.fixture(scope="module")
def big(column):
    p = random_params(column, 400000, 21)
    return p, column.evaluate(p)


def test_bulk_calls_release_the_gil(column, big):
    p, x = big
    assert runs_without_the_gil(lambda: column.evaluate(np.tile(p, (4, 1)), threads=1))
    assert runs_without_the_gil(lambda: column.jacobian(p, threads=1))
    assert runs_without_the_gil(lambda: column.invert(x, threads=1))
    assert runs_without_the_gil(lambda: column.invert_global(x[:20000], threads=1))


def test_slicing_releases_the_gil(tmp_path):
    slicer = trivox.Slicer(trivox.read_scene(SCENES / "quick_start.json"))
    assert runs_without_the_gil(lambda: [slicer.slice_layer(k) for k in range(95, 100)])
    assert runs_without_the_gil(lambda: trivox.slice(slicer, tmp_path, layers=range(95, 100), min_layers=0, threads=1))


def test_the_check_sees_a_call_that_holds_the_gil():
    # sorted() is C code that holds the GIL throughout, and time.sleep releases it.
    strings = [str(i) for i in range(300000)]
    assert not runs_without_the_gil(lambda: sorted(strings))
    assert runs_without_the_gil(lambda: __import__("time").sleep(0.2))


def resident_bytes():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")


def test_a_million_calls_leak_nothing(column):
    p = np.array([[1.0, 1.5, 2.0]])
    x = column.evaluate(p)
    calls = [(lambda: column.evaluate(p), 500000), (lambda: column.jacobian(p, with_values=True), 200000),
             (lambda: column.invert(x), 200000), (lambda: column.invert_global(x), 100000)]
    for call, _ in calls:  # warm up: the solver, the interpreter's free lists
        for _ in range(5000):
            call()
    before = resident_bytes()
    for call, n in calls:
        for _ in range(n):
            call()
    grown = resident_bytes() - before
    # A leak of one small object per call would be tens of megabytes.
    assert grown < 4 << 20, f"resident memory grew by {grown} bytes over a million calls"


def test_importing_trivox_needs_no_numpy():
    code = "import sys; sys.modules['numpy'] = None; import trivox; print(trivox.__version__)"
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert out.stdout.strip() == trivox.__version__
    assert trivox.__version__.count(".") == 2
    # ... but it says at once what is missing and how to get it, naming the interpreter.
    assert "numpy is not installed for this Python (" + sys.executable + ")" in out.stderr, out.stderr
    assert "apt install python3-numpy" in out.stderr
    # With numpy there, nothing is said.
    quiet = subprocess.run([sys.executable, "-c", "import trivox"], capture_output=True, text=True, check=True)
    assert quiet.stderr == ""


def test_simd_targets_can_be_chosen_and_evaluate_alike(column):
    targets = trivox.simd_targets()
    assert targets and trivox.simd_target() == targets[0]
    p = np.array([[1.0, 1.5, 2.0], [0.25, 0.5, 0.75]])
    try:
        values = {}
        for t in targets:
            trivox.use_simd_target(t)
            assert trivox.simd_target() == t
            # A volume built now evaluates on target t.
            v = trivox.Volume(column.spline)
            values[t] = v.evaluate(p)
        for t in targets:
            np.testing.assert_allclose(values[t], values[targets[0]], rtol=0, atol=1e-12)
        with pytest.raises(trivox.InputError, match="unknown target 'avx3'"):
            trivox.use_simd_target("avx3")
    finally:
        trivox.use_simd_target("best")
    assert trivox.simd_target() == targets[0]
