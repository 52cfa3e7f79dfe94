"""The module computes what the C++ library computes, bit for bit: evaluation, Jacobians,
Newton and the global solver on real models of ../shared/data (and the bundled column), each
compared with trivox_python_reference, a C++ program that calls the library one point at a
time (python/tests/reference.cpp). The module's calls are its bulk, parallel ones."""

import subprocess

import numpy as np
import pytest

import trivox
from conftest import COLUMN, bits, random_params

# (file under ../shared/data, trivariate index): rational and polynomial, orders 2 to 4.
SHARED_MODELS = [
    ("volumes/gismo/bent_pipe.xml", 0),
    ("volumes/gismo/muscleBeam.xml", 0),
    ("volumes/gismo/tensorBSpline.xml", 0),
    ("volumes/gismo/yeti3d_u21p.xml", 5),
    ("volumes/gismo/twistedFlatQuarterAnnulus.xml", 0),
    ("volumes/splinepy/splinepy_gismo_noindent_nolabels_b64_3d.xml", 0),
    ("volumes/irit/fltrtest.itd", 0),
]


def reference_run(reference, model, index, mode, points, tmp_path, deboor=False):
    src, out = tmp_path / f"{mode}.in.f64", tmp_path / f"{mode}.out.f64"
    np.ascontiguousarray(points, dtype=np.float64).tofile(src)
    args = [reference, str(model), str(index), mode, str(src), str(out)] + (["deboor"] if deboor else [])
    subprocess.run(args, check=True)
    return np.fromfile(out, dtype=np.float64)


def compare_with_reference(reference, path, index, tmp_path, deboor=False):
    vol = trivox.read(str(path)).volumes()[index]
    if deboor:
        vol = trivox.Volume(vol.spline, power_form=False)
        assert vol.kernel == "de_boor"
    params = random_params(vol, 10000, 11)  # more than one chunk: the parallel path
    ref = reference_run(reference, path, index, "evaluate", params, tmp_path, deboor).reshape(-1, 3)
    assert bits(vol.evaluate(params)) == bits(ref), "evaluate"
    values, jac = vol.jacobian(params, with_values=True)
    ref = reference_run(reference, path, index, "jacobian", params, tmp_path, deboor).reshape(-1, 12)
    assert bits(values) == bits(ref[:, :3]), "jacobian values"
    assert bits(jac.reshape(-1, 9)) == bits(ref[:, 3:]), "jacobian"

    # Points inside (images of parameters) and around the volume (its box, grown).
    x = vol.evaluate(params[:6000])
    box = vol.bounds
    rng = np.random.default_rng(12)
    around = box[0] - 0.2 * (box[1] - box[0]) + 1.4 * (box[1] - box[0]) * rng.random((2000, 3))
    points = np.concatenate([x, around])
    for mode, inv in (("invert", vol.invert(points)), ("newton", vol.invert(points, certified=False))):
        ref = reference_run(reference, path, index, mode, points, tmp_path, deboor).reshape(-1, 6)
        assert bits(inv.uvw) == bits(ref[:, :3]), mode + " uvw"
        assert (inv.status == ref[:, 3]).all() and bits(inv.residual) == bits(ref[:, 4]), mode
        assert (inv.iterations == ref[:, 5]).all(), mode

    few = np.concatenate([x[:250], around[:150]])
    g = vol.invert_global(few)
    ref = reference_run(reference, path, index, "global", few, tmp_path, deboor)
    at = 0
    for i in range(len(few)):
        status, boxes, count = ref[at:at + 3]
        at += 3
        assert g.status[i] == status and g.boxes_visited[i] == boxes, f"point {i}"
        lo, hi = g.offsets[i], g.offsets[i + 1]
        assert hi - lo == count, f"point {i}"
        rows = ref[at:at + 5 * int(count)].reshape(-1, 5)
        at += 5 * int(count)
        assert bits(g.uvw[lo:hi]) == bits(rows[:, :3]), f"point {i}"
        assert bits(g.residual[lo:hi]) == bits(rows[:, 3]) and bits(g.det[lo:hi]) == bits(rows[:, 4])
    assert at == len(ref)
    # The inside points were found, so the comparison is not of empty results.
    assert (g.status[:250] != trivox.GlobalStatus.NONE).all()


@pytest.mark.parametrize("model", SHARED_MODELS, ids=[m[0].split("/")[-1] for m in SHARED_MODELS])
def test_real_models_match_the_library_bit_for_bit(reference, shared_data, model, tmp_path):
    compare_with_reference(reference, shared_data / model[0], model[1], tmp_path)


def test_the_de_boor_kernel_matches_too(reference, shared_data, tmp_path):
    compare_with_reference(reference, shared_data / "volumes/gismo/bent_pipe.xml", 0, tmp_path, deboor=True)


def test_the_bundled_column_matches_the_library_bit_for_bit(reference, tmp_path):
    compare_with_reference(reference, COLUMN, 0, tmp_path)
