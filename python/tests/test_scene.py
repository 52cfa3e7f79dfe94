"""Scenes: to_json() gives a file that `trivox slice` accepts and that reads back equal; the
chalice built in Python (examples/python/chalice.py) is the chalice of its scene file; errors
are the library's exception classes with the command line's messages."""

import importlib.util
import json

import numpy as np
import pytest

import trivox
from conftest import COLUMN, EXAMPLES, SCENES, bits, cli_error, run_cli


def load_example(name):
    spec = importlib.util.spec_from_file_location(name, EXAMPLES / "python" / f"{name}.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


@pytest.fixture(scope="module")
def chalices():
    return trivox.read_scene(SCENES / "chalice.json"), load_example("chalice").chalice_scene()


def test_the_python_chalice_has_the_volumes_and_cells_of_the_scene_file(chalices):
    from_file, built = chalices
    assert list(built.volumes) == ["base", "knot", "cup"]
    for name, vol in from_file.volumes.items():
        assert built.volumes[name] == vol, name  # every knot, point and weight, bit for bit
    assert [c.name for c in built.cells] == [c.name for c in from_file.cells]
    assert [c.material for c in built.cells] == [c.material for c in from_file.cells]
    assert built.materials == from_file.materials
    # The union's regions are the scene file's objects.
    assert built.document()["unions"] == json.loads((SCENES / "chalice.json").read_text())["unions"]


def test_the_python_chalice_slices_as_the_scene_file(chalices):
    from_file, built = chalices
    a, b = trivox.Slicer(from_file), trivox.Slicer(built)
    assert a.layout.num_layers == b.layout.num_layers == 1001
    for layer in (80, 250, 400):
        assert (a.slice_layer(layer).labels == b.slice_layer(layer).labels).all(), layer


def test_to_json_is_a_scene_file_the_program_slices_alike(cli, chalices, tmp_path):
    _, built = chalices
    path = tmp_path / "chalice.json"
    built.save(path)
    run_cli(cli, "slice", path, "-o", tmp_path / "out", "--layers", "251:251", "--min-layers", "0", "-q")
    labels = trivox.Slicer(built).slice_layer(250).labels
    # Printer images are opaque: every material's colour with alpha 255.
    colours = np.array([trivox.Slicer(built).background] + [list(m["rgba"][:3]) + [255] for m in built.materials],
                       dtype=np.uint8)
    assert (colours[labels] == trivox.read_png(str(tmp_path / "out" / "slice_00001.png"))).all()
    back = trivox.read_scene(path)
    assert back.to_json() == built.to_json()
    assert all(back.volumes[n] == v for n, v in built.volumes.items())


@pytest.mark.parametrize("name", sorted(p.stem for p in SCENES.glob("*.json")))
def test_every_example_scene_reads_back_equal_from_to_json(name, tmp_path):
    scene = trivox.read_scene(SCENES / f"{name}.json")
    path = tmp_path / "again.json"
    scene.save(path)  # file names made absolute: the copy lives elsewhere
    back = trivox.read_scene(path)
    assert back.to_json() == scene.to_json()
    assert [c.name for c in back.cells] == [c.name for c in scene.cells]
    for a, b in zip(back.cells, scene.cells):
        assert a.volume == b.volume and a.material == b.material
    assert back.materials == scene.materials and back.printer == scene.printer
    # The same files were read (their hashes), under absolute names now.
    assert sorted(h for _, h in back.input_files) == sorted(h for _, h in scene.input_files)
    a, b = trivox.Slicer(back), trivox.Slicer(scene)
    k = a.layout.num_layers // 2
    assert bits(a.slice_layer(k).labels) == bits(b.slice_layer(k).labels)


def test_a_scene_from_python_objects(tmp_path):
    column = trivox.read(str(COLUMN)).volumes()[0]
    scene = trivox.Scene(
        printer={"base": "j750-hq", "layer_thickness_mm": 0.5, "name": "coarse"},
        materials=["VeroCyan", trivox.MaterialDef("soft", "#C8C8C8")],
        cells=[trivox.Cell(trivox.Constant({"soft": 1}), geometry=column, name="column",
                           placement={"translate": [100, 0, 0]}),
               trivox.Cell("VeroCyan", volume="slab")],
        volumes={"slab": trivox.extrude(trivox.Spline([2, 2], [[0, 0, 1, 1]] * 2,
                                                      [[0, 0, 0], [10, 0, 0], [0, 10, 0], [10, 10, 0]]),
                                        [0, 0, 5]).volume},
        dithering={"method": "stucki"},
    )
    assert scene.printer["name"] == "coarse" and scene.printer["layer_thickness_mm"] == 0.5
    assert [c.name for c in scene.cells] == ["column", "cell 1"]
    assert scene.cells[1].scene_volume == "slab"
    np.testing.assert_allclose(scene.cells[0].volume.points, column.points + [100, 0, 0])
    assert column.source[0] in scene.to_json()  # the model file is named, not copied
    assert trivox.Slicer(scene).dithering["method"] == "stucki"
    scene.save(tmp_path / "s.json")
    assert trivox.read_scene(tmp_path / "s.json").to_json() == scene.to_json()


def test_scene_errors_carry_the_command_lines_messages(cli, tmp_path):
    bad = json.loads((SCENES / "box_gradient.json").read_text())
    bad["cells"][0]["materail"] = bad["cells"][0].pop("material")
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(bad))
    with pytest.raises(trivox.InputError) as e:
        trivox.read_scene(path)
    assert str(e.value) == cli_error(cli, "slice", path, "-o", tmp_path / "out")
    assert e.value.file == str(path) and e.value.where == "/cells/0/materail"
    assert "unknown key" in e.value.rule
    with pytest.raises(trivox.InputError, match=r"<python scene>: /materials/0: .*Unobtainium"):
        trivox.Scene(printer="j750-hq", materials=["Unobtainium"], cells=[]).handle
    expr = trivox.Scene(printer="j750-hq", materials=["VeroCyan"],
                        cells=[trivox.Cell(trivox.Expression({"VeroCyan": "u +* 2"}), geometry={"file": str(COLUMN)})])
    with pytest.raises(trivox.InputError, match=r"/cells/0/material/fractions/VeroCyan: expression \"u \+\* 2\""):
        expr.handle


def test_file_errors_carry_the_command_lines_messages(cli, tmp_path, shared_data):
    missing = tmp_path / "missing.itd"
    with pytest.raises(trivox.IoError) as e:
        trivox.read(str(missing))
    assert str(e.value) == cli_error(cli, "info", missing)
    broken = tmp_path / "broken.itd"
    broken.write_text("[OBJECT X\n    [TRIVAR BSPLINE 2 2 2 2 2 2 E3\n")
    with pytest.raises(trivox.InputError) as e:
        trivox.read(str(broken))
    assert str(e.value) == cli_error(cli, "info", broken) and e.value.line > 0
    thb = shared_data / "volumes" / "gismo" / "thbcube.xml"
    with pytest.raises(trivox.UnsupportedError) as e:
        trivox.read(str(thb))
    assert isinstance(e.value, trivox.InputError) and isinstance(e.value, trivox.Error)
    assert str(e.value) == cli_error(cli, "info", thb)


def test_evaluate_material_names_a_missing_cell():
    scene = trivox.read_scene(SCENES / "quick_start.json")
    with pytest.raises(KeyError, match="no cell 'lid'"):
        scene.evaluate_material("lid", [[0, 0, 0]])
    with pytest.raises(IndexError):
        scene.evaluate_material(3, [[0, 0, 0]])
