"""Slicing from Python against the trivox program: slice_layer gives the pixels of the
program's layer images, and slice() writes the same bytes as `trivox slice` for every bundled
example (a few layers of each; every file but stats.json's timings and the program's
construction cache); the fractions before
dithering dither to the labels; progress, Ctrl-C and resume."""

import json
import os
import pathlib
import signal
import threading

import numpy as np
import pytest

import trivox
from conftest import SCENES, run_cli

SCENE_NAMES = sorted(p.stem for p in SCENES.glob("*.json"))


def folder_files(folder):
    """Every file below folder: relative name -> bytes, stats.json without its timings. The
    program's construction cache (.trivox-cache/, docs/CLI.md) holds no output: left out."""
    out = {}
    for path in sorted(pathlib.Path(folder).rglob("*")):
        if path.is_file():
            name = path.relative_to(folder).as_posix()
            if name.startswith(".trivox-cache/"):
                continue
            data = path.read_bytes()
            if name.startswith("stats"):
                data = json.dumps(_without_timings(json.loads(data)), sort_keys=True).encode()
            out[name] = data
    return out


def _without_timings(node):
    if isinstance(node, dict):
        return {k: _without_timings(v) for k, v in node.items() if not k.startswith("seconds")}
    if isinstance(node, list):
        return [_without_timings(v) for v in node]
    return node


def middle_layers(slicer, count):
    layers = slicer.layout.num_layers
    first = max(0, layers // 2 - count // 2)
    return range(first, min(layers, first + count))


def compare_with_cli(cli, scene_path, tmp_path, count, formats=("voxelprint",), preview=None):
    """Slices `count` layers from the middle of the scene with slice() and with the program."""
    ours, theirs = tmp_path / "python", tmp_path / "cli"
    slicer = trivox.Slicer(trivox.read_scene(str(scene_path)))  # the scene's name as the program gets it
    layers = middle_layers(slicer, count)
    preview = [layers.start + 1] if preview else []
    result = trivox.slice(slicer, ours, layers=layers, min_layers=0, threads=2, formats=formats, preview=preview)
    args = ["slice", str(scene_path), "-o", theirs, "--layers", f"{layers.start + 1}:{layers.stop}",
            "--min-layers", "0", "-j", "2", "--format", ",".join(formats), "-q"]
    if preview:
        args += ["--preview", ",".join(str(k + 1) for k in preview)]
    run_cli(cli, *args)
    a, b = folder_files(ours), folder_files(theirs)
    assert sorted(a) == sorted(b)
    for name in a:
        assert a[name] == b[name], f"{scene_path.name}: {name} differs"
    assert len(result.layers) == len(layers)
    assert sum(layer["pixels_inside"] for layer in result.layers) > 0, "the layers compared hold no voxel"
    return result


@pytest.mark.parametrize("name", SCENE_NAMES)
def test_slice_writes_the_bytes_of_the_cli_for_every_example(cli, name, tmp_path):
    compare_with_cli(cli, SCENES / f"{name}.json", tmp_path, 2)


# Formats for masked-resin printers (a printer profile with a display), which a J750 scene
# cannot take.
RESIN_FORMATS = ("greyscale", "sl1", "sl1s")


def test_every_format_and_previews_match_the_cli(cli, tmp_path):
    result = compare_with_cli(cli, SCENES / "boolean_pair.json", tmp_path, 3, formats=tuple(f for f in trivox.formats() if f not in RESIN_FORMATS),
                              preview=True)
    assert "manifest.json" in os.listdir(tmp_path / "python")
    assert any(f.startswith("gcvf/") for f in result.files) and any(f.startswith("vdb/") for f in result.files)


def label_colours(scene):
    background = trivox.Slicer(scene).background
    # Printer images are opaque: every material's colour with alpha 255.
    return np.array([background] + [list(m["rgba"][:3]) + [255] for m in scene.materials], dtype=np.uint8)


@pytest.mark.parametrize("name,layer", [("quick_start", 100), ("chalice", 249), ("texture_composition", 40)])
def test_slice_layer_gives_the_pixels_of_the_cli_layer_image(cli, name, layer, tmp_path):
    path = SCENES / f"{name}.json"
    scene = trivox.read_scene(path)
    labels = trivox.slice_layer(scene, layer)
    assert labels.dtype == np.uint8 and labels.ndim == 2
    run_cli(cli, "slice", path, "-o", tmp_path, "--layers", f"{layer + 1}:{layer + 1}", "--min-layers", "0", "-q")
    image = trivox.read_png(str(tmp_path / "slice_00001.png"))
    assert image.shape == labels.shape + (4,)
    assert (label_colours(scene)[labels] == image).all()
    assert len(np.unique(labels)) >= 2


def test_fractions_before_dithering_dither_to_the_labels():
    scene = trivox.read_scene(SCENES / "chalice.json")
    slicer = trivox.Slicer(scene)
    layer = slicer.slice_layer(249, fractions=True, owner=True)
    h, w = layer.labels.shape
    assert layer.fractions.shape == (h, w, 4) and layer.fractions.dtype == np.float32
    inside = layer.inside > 0
    assert layer.stats["pixels_inside"] == inside.sum() > 0
    assert (layer.fractions[~inside] == 0).all() and (layer.labels[~inside] == 0).all()
    assert (layer.fractions.sum(axis=2) <= 1 + 1e-4).all()
    assert ((layer.owner >= 0) == inside).all()
    # Every cell that owns pixels is one of the chalice's five printing cells.
    owners = set(np.unique(layer.owner[inside]).tolist())
    assert owners and owners <= set(range(len(scene.cells)))
    assert np.bincount(layer.owner[inside], minlength=len(scene.cells)).tolist() == layer.stats["pixels_per_cell"]
    # The mean material is what the labels hold, within the dithering's spatial error.
    share = np.bincount(layer.labels[inside], minlength=5)[1:] / inside.sum()
    np.testing.assert_allclose(share, layer.fractions[inside].mean(axis=0), atol=0.01)
    labels, fractions = trivox.slice_layer(scene, 249, fractions=True)
    assert (labels == layer.labels).all() and (fractions == layer.fractions).all()


def test_settings_reach_the_slicer_as_on_the_command_line(cli, tmp_path):
    path = SCENES / "box_gradient.json"  # graded: the dithering shows
    scene = trivox.read_scene(path)
    settings = dict(dither="blue-noise", skin=2, tracing="full", vary_by_layer=False)
    slicer = trivox.Slicer(scene, **settings)
    assert slicer.dithering == {"method": "blue-noise", "serpentine": True, "vary_by_layer": False, "skin_voxels": 2}
    k = slicer.layout.num_layers // 2
    labels = slicer.slice_layer(k).labels
    run_cli(cli, "slice", path, "-o", tmp_path, "--layers", f"{k + 1}:{k + 1}", "--min-layers", "0", "-q",
            "--dither", "blue-noise", "--skin", "2", "--tracing", "full", "--vary-by-layer", "false")
    assert (label_colours(scene)[labels] == trivox.read_png(str(tmp_path / "slice_00001.png"))).all()
    assert not (labels == trivox.slice_layer(scene, k)).all()
    with pytest.raises(ValueError, match="tracing"):
        trivox.Slicer(scene, tracing="sideways")
    with pytest.raises(IndexError, match="out of range"):
        slicer.slice_layer(slicer.layout.num_layers)


def test_progress_is_reported_on_the_calling_thread(tmp_path):
    seen = []
    me = threading.get_ident()
    trivox.slice(SCENES / "box_gradient.json", tmp_path, layers=range(0, 6), min_layers=0, threads=2,
                 progress=lambda done, total: seen.append((done, total, threading.get_ident())))
    assert [(d, t) for d, t, _ in seen] == [(k, 6) for k in range(1, 7)]
    assert {ident for _, _, ident in seen} == {me}


def test_ctrl_c_stops_the_job_and_resume_finishes_it(tmp_path):
    path = SCENES / "quick_start.json"
    layers = range(60, 76)
    straight = tmp_path / "straight"
    trivox.slice(path, straight, layers=layers, threads=1)
    stopped = tmp_path / "stopped"
    done = []

    def progress(d, total):
        done.append(d)
        if d == 2:
            # What Ctrl-C does: SIGINT from elsewhere, while the job runs in C++.
            threading.Thread(target=os.kill, args=(os.getpid(), signal.SIGINT)).start()

    with pytest.raises(KeyboardInterrupt):
        trivox.slice(path, stopped, layers=layers, threads=1, progress=progress)
    manifest = json.loads((stopped / "manifest.json").read_text())
    assert manifest["status"] == "interrupted"
    assert 2 <= max(done) < 16 + 14  # 16 layers and 14 empty ones to reach 30
    result = trivox.slice(path, stopped, layers=layers, threads=1, resume=True)
    assert result.layers_kept >= 2
    a, b = folder_files(straight), folder_files(stopped)
    for files in (a, b):
        files.pop("stats.json")
    assert a == b


def test_an_exception_of_progress_stops_the_job_resumably(tmp_path):
    class Enough(Exception):
        pass

    def progress(d, total):
        if d == 1:
            raise Enough()

    with pytest.raises(Enough):
        trivox.slice(SCENES / "box_gradient.json", tmp_path, layers=range(0, 8), threads=1, progress=progress)
    assert json.loads((tmp_path / "manifest.json").read_text())["status"] == "interrupted"


def test_a_job_that_fails_on_its_input_leaves_no_folder(tmp_path):
    with pytest.raises(trivox.Error, match="selects no layer"):
        trivox.slice(SCENES / "box_gradient.json", tmp_path / "out", layers=range(100000, 100001))
    assert not (tmp_path / "out").exists()
    with pytest.raises(ValueError, match="unknown format"):
        trivox.slice(SCENES / "box_gradient.json", tmp_path / "out", formats=["jpeg"])
