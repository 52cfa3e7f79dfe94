"""Material functions from Python: the classes write the scene file's objects (the chalice's
and SCENE.md's examples), and a Python callable material gives the output of the equal
expression material, bit for bit, called once per row of voxels; its errors reach the caller."""

import json
import os
import signal
import threading
import time

import numpy as np
import pytest

import trivox
from conftest import COLUMN, SCENES


def column_scene(material, materials=("VeroCyan", "VeroMagenta", "VeroYellow"), **kw):
    column = trivox.read(str(COLUMN)).volumes()[0]
    return trivox.Scene(printer="j750-paper", materials=list(materials),
                        cells=[trivox.Cell(material, geometry=column, name="column")], **kw)


EXPRESSION = trivox.Expression({"VeroCyan": "1 - w", "VeroMagenta": "0.5 * w", "VeroYellow": "0.25 * u * v * w"})


def python_material(u, v, w, x, y, z):
    return np.stack([1 - w, 0.5 * w, 0.25 * u * v * w], axis=1)


def test_a_python_material_gives_the_output_of_the_equal_expression_material(tmp_path):
    expr, fn = column_scene(EXPRESSION), column_scene(python_material)
    a, b = trivox.Slicer(expr), trivox.Slicer(fn)
    for layer in (3, a.layout.num_layers // 2, a.layout.num_layers - 4):
        la, lb = a.slice_layer(layer, fractions=True), b.slice_layer(layer, fractions=True)
        assert la.stats["pixels_inside"] > 0
        assert la.fractions.tobytes() == lb.fractions.tobytes()
        assert (la.labels == lb.labels).all()
    # Whole jobs: the same layer images (the manifests differ only in the scene they name).
    trivox.slice(a, tmp_path / "expr", layers=range(800, 806), min_layers=0, threads=2)
    trivox.slice(b, tmp_path / "fn", layers=range(800, 806), min_layers=0, threads=2)
    images = sorted(p.name for p in (tmp_path / "expr").glob("slice_*.png"))
    assert len(images) == 6
    for name in images:
        assert (tmp_path / "expr" / name).read_bytes() == (tmp_path / "fn" / name).read_bytes(), name
    uvw = np.random.default_rng(3).random((1000, 3)) * 3
    assert expr.evaluate_material(0, uvw).tobytes() == fn.evaluate_material("column", uvw).tobytes()


def test_a_python_material_may_return_a_sequence_of_arrays_and_numbers():
    fn = column_scene(lambda u, v, w, x, y, z: (1 - w, 0.5 * w, 0.25 * u * v * w))
    expr = column_scene(EXPRESSION)
    uvw = np.random.default_rng(4).random((500, 3)) * 3
    assert fn.evaluate_material(0, uvw).tobytes() == expr.evaluate_material(0, uvw).tobytes()
    const = column_scene(trivox.Function(lambda u, v, w, x, y, z: [0.25, 0, 0.5]))
    assert (const.evaluate_material(0, uvw) == np.float32([0.25, 0, 0.5])).all()
    single = column_scene(lambda u, v, w, x, y, z: w, materials=["VeroCyan"])
    np.testing.assert_array_equal(single.evaluate_material(0, uvw)[:, 0], (uvw[:, 2] / 3).astype(np.float32))


def test_the_python_material_is_called_once_per_row_not_per_voxel():
    calls, samples = [], []

    def counting(u, v, w, x, y, z):
        calls.append(len(u))
        samples.append(len(u))
        return python_material(u, v, w, x, y, z)

    slicer = trivox.Slicer(column_scene(counting))
    layer = slicer.slice_layer(1000)
    inside = layer.stats["pixels_inside"]
    assert sum(samples) == inside > 0
    assert len(calls) <= slicer.layout.height_px  # a single cell: at most one call per row
    assert max(calls) > 100


def test_ctrl_c_during_a_slow_python_material_stops_the_job_within_a_row(tmp_path):
    rows = []
    trivox.Slicer(column_scene(lambda u, v, w, x, y, z: rows.append(len(u)) or python_material(u, v, w, x, y, z)))\
        .slice_layer(1000)
    assert len(rows) > 60  # the rows of the layer that hold the column
    calls = []

    def slow(u, v, w, x, y, z):
        calls.append(len(u))
        if len(calls) == 3:
            # What Ctrl-C does: SIGINT from elsewhere, while the layer is being evaluated.
            threading.Thread(target=os.kill, args=(os.getpid(), signal.SIGINT)).start()
        time.sleep(0.05)
        return python_material(u, v, w, x, y, z)

    # Without the checks, whose sample layer would meet the signal before the job starts (and
    # leave nothing written, as the program does).
    with pytest.raises(KeyboardInterrupt):
        trivox.slice(trivox.Slicer(column_scene(slow)), tmp_path, layers=range(1000, 1001), min_layers=0, threads=1,
                     checks=False)
    # Python looks for the signal every tenth of a second: a few rows more, never the layer's rest.
    assert 3 <= len(calls) <= 3 + 20 < len(rows)
    assert json.loads((tmp_path / "manifest.json").read_text())["status"] == "interrupted"


def test_the_fraction_policy_applies_and_names_the_cell():
    too_much = column_scene(lambda u, v, w, x, y, z: (0.7 + 0 * u, 0.7 + 0 * u, 0 * u))
    with pytest.raises(trivox.InputError, match=r"/cells/0/material: cell 'column': the fractions sum to 1\.4") as e:
        trivox.slice_layer(too_much, 500)
    assert e.value.where == "/cells/0/material" and e.value.file == "<python scene>"
    fine = column_scene(lambda u, v, w, x, y, z: (0.7 + 0 * u, 0.7 + 0 * u, 0 * u), fraction_sums={"policy": "normalise"})
    labels, fractions = trivox.slice_layer(fine, 500, fractions=True)
    inside = fractions.sum(axis=2) > 0
    np.testing.assert_allclose(fractions[inside][:, :2], 0.5, rtol=1e-6)


def test_errors_of_the_python_function_reach_the_caller(tmp_path):
    def broken(u, v, w, x, y, z):
        return 1 / 0

    with pytest.raises(ZeroDivisionError):
        trivox.slice_layer(column_scene(broken), 500)
    with pytest.raises(ZeroDivisionError):
        trivox.slice(column_scene(broken), tmp_path / "out", layers=range(500, 504), threads=2)
    assert not (tmp_path / "out").exists()  # rolled back, as the command line does
    with pytest.raises(ValueError, match=r"Python material of cell 'column' returned an array of shape \(\d+, 2\)"):
        trivox.slice_layer(column_scene(lambda u, v, w, x, y, z: np.zeros((len(u), 2))), 500)
    with pytest.raises(ValueError, match="returned a sequence of 2 items"):
        trivox.slice_layer(column_scene(lambda u, v, w, x, y, z: (u, v)), 500)


def test_a_scene_with_a_python_material_cannot_be_written():
    with pytest.raises(TypeError, match="/cells/0/material: a Python material cannot be written"):
        column_scene(python_material).to_json()
    with pytest.raises(TypeError, match="whole material"):
        column_scene(trivox.Blend("VeroCyan", python_material, 0.5)).handle


def test_the_classes_write_the_scene_files_objects():
    chalice = json.loads((SCENES / "chalice.json").read_text())
    regions = chalice["unions"][0]["regions"]
    knot = regions[1]["material"]
    made = trivox.TwistingCurves([(p["uv"], p["material"]) for p in knot["points"]], radius=0.11, turns_per_w=3,
                                 background="VeroClear")
    assert made.to_json() == knot
    cup = regions[2]["material"]
    made = trivox.TwistingCurves([(p["uv"], p["material"]) for p in cup["points"]], radius=0.045,
                                 shift_per_w=(0.5, 0), wrap=["u"], background="VeroClear")
    assert made.to_json() == cup
    # SCENE.md's composition example.
    doc = {
        "kind": "void_mask",
        "void": "sin(x) * sin(z) > 0.9 ? 1 : 0",
        "material": {
            "kind": "select",
            "regions": [{"box": {"lo": [0, 0.4, 0], "hi": [1, 0.6, 1]}, "material": "VeroYellow"}],
            "otherwise": {"kind": "blend", "a": "VeroCyan", "b": "VeroMagenta", "weight": "u"},
        },
    }
    made = trivox.VoidMask(trivox.Select([([0, 0.4, 0], [1, 0.6, 1], "VeroYellow")],
                                         trivox.Blend("VeroCyan", "VeroMagenta", "u")), "sin(x) * sin(z) > 0.9 ? 1 : 0")
    assert made.to_json() == doc
    texture = json.loads((SCENES / "texture_composition.json").read_text())
    assert texture["cells"][0]["material"]["kind"] in {"void_mask", "blend", "transfer", "texture"}


def test_every_kind_reads_and_evaluates():
    field = trivox.Spline([2, 1, 1], [[0, 0, 1, 1], [0, 1], [0, 1]], [[1, 0, 0], [0, 1, 0]])
    scalar = trivox.Spline([2, 2, 2], [[0, 0, 1, 1]] * 3, [0, 0, 0, 0, 1, 1, 1, 1])
    ramp = [(0.0, {"VeroCyan": 1}), (1.0, {"VeroMagenta": 1})]
    kinds = [
        trivox.Constant({"VeroCyan": 0.3, "VeroYellow": 0.7}),
        EXPRESSION,
        trivox.Expression({"VeroCyan": "0.5 * (1 + sin(2 * pi * x / p))"}, constants={"p": 10}),
        trivox.SplineField(["VeroCyan", "VeroMagenta", "VeroYellow"], field),
        trivox.ScalarGradient(scalar, ramp),
        trivox.PorousTiles([4, 4, 6], ["VeroCyan", "VeroYellow"], radius=0.3),
        trivox.TwistingCurves([((0.8, 0.5), "VeroCyan")], radius=0.08, turns_per_w=1.5, background="VeroYellow"),
        trivox.Texture(trivox.PngImage(str(SCENES.parent / "textures" / "quadrants_8x8.png")),
                       ["VeroCyan", "VeroMagenta", "VeroYellow"], filter="nearest", wrap="repeat", repeats=[4, 2, 1]),
        trivox.Transfer(trivox.TextureChannel(trivox.RawImage(str(SCENES.parent / "textures" / "checker_4x4x4.raw"),
                                                              [4, 4, 4]), wrap="mirror", repeats=3), ramp),
        trivox.Transfer(trivox.FieldScalar(field, component=1), ramp),
        trivox.Transfer(trivox.FieldScalar(field, magnitude=True), ramp),
        trivox.Threshold("w", 0.5, "VeroCyan", trivox.Constant({"VeroMagenta": 1})),
        trivox.VoidMask("VeroCyan", 0.25),
        "VeroMagenta",
        {"kind": "constant", "fractions": {"VeroYellow": 1}},
    ]
    uvw = np.random.default_rng(5).random((200, 3)) * 3
    for material in kinds:
        f = column_scene(material).evaluate_material(0, uvw)
        assert f.shape == (200, 3) and (f >= 0).all() and (f.sum(axis=1) <= 1 + 1e-4).all(), material
        assert f.sum() > 0, material
