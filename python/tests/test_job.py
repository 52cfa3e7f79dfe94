"""A Python slicing job is the library's job (trivox::SliceJob, docs/PYTHON.md "Slicing"): it
locks the output folder before the scene is read, puts an absent or empty folder back as it
was when it fails on its input, reads the scene through the folder's construction cache,
raises EmptyResultError for a stack without the object, and its stats dicts name the values
the library lists."""

import json

import pytest

import trivox
from trivox import _trivox

# A tube revolved from an inline profile: a constructed cell that slices in moments.
TUBE = {
    "version": 1, "units": "mm", "printer": "j750-hm",
    "materials": [{"name": "VeroCyan", "rgba": [20, 100, 200, 255]}],
    "cells": [{
        "name": "tube",
        "geometry": {"revolve": {"profile": {
            "orders": [2, 2], "knots": [[0, 0, 1, 1], [0, 0, 1, 1]],
            "points": [[8, 0, 0], [10, 0, 0], [8, 0, 1.5], [10, 0, 1.5]]}, "angle_deg": 270}},
        "material": {"kind": "constant", "fractions": {"VeroCyan": 1}}}],
}

# A slanted slab a nanometre thick: its bitmap has pixels, but no pixel centre lies in it.
SHEET = {
    "version": 1, "units": "mm", "printer": "j750-hm", "materials": [{"name": "VeroCyan"}],
    "cells": [{
        "name": "c",
        "geometry": {"orders": [2, 2, 2], "knots": [[0, 0, 1, 1]] * 3,
                     "points": [[4.0 * i, 1.48 * i + 0.0123 + 1e-6 * j, 4.0 * k]
                                for k in range(2) for j in range(2) for i in range(2)]},
        "material": {"kind": "constant", "fractions": {"VeroCyan": 1}}}],
}

JOB = dict(layers=range(0, 3), min_layers=0, threads=1)


def write_scene(path, doc):
    path.write_text(json.dumps(doc))
    return path


def test_a_second_job_into_a_locked_folder_is_refused_before_its_scene_is_read(tmp_path):
    tube = write_scene(tmp_path / "tube.json", TUBE)
    out = tmp_path / "out"
    refused = []

    def progress(done, total):
        if done == 1:
            # The first job holds the folder: a second one naming no readable scene is refused
            # on the lock (Error), never on the scene (IoError).
            with pytest.raises(trivox.Error, match="another trivox job is writing into this folder") as e:
                trivox.slice(tmp_path / "no-such-scene.json", out)
            refused.append(e.value)

    trivox.slice(tube, out, progress=progress, **JOB)
    assert len(refused) == 1 and not isinstance(refused[0], trivox.IoError)
    assert not (out / ".trivox.lock").exists()


def test_a_scene_that_fails_leaves_an_absent_or_empty_folder_as_it_was(tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text('{"version": 1,')
    absent, empty, full = tmp_path / "absent", tmp_path / "empty", tmp_path / "full"
    empty.mkdir()
    full.mkdir()
    (full / "mine.txt").write_text("kept")
    for out in (absent, empty, full):
        with pytest.raises(trivox.InputError):
            trivox.slice(bad, out)
    assert not absent.exists()
    assert empty.is_dir() and not list(empty.iterdir())
    assert sorted(p.name for p in full.iterdir()) == ["mine.txt"]


def test_the_second_run_takes_the_constructed_volume_from_the_cache(tmp_path):
    tube = write_scene(tmp_path / "tube.json", TUBE)
    out = tmp_path / "out"
    first = trivox.slice(tube, out, **JOB)
    assert first.cache_hits == 0 and (out / ".trivox-cache").is_dir()
    second = trivox.slice(tube, out, **JOB)
    assert second.cache_hits == 1 and second.cache_warnings == ()
    assert second.total["pixels_inside"] == first.total["pixels_inside"] > 0
    # A Scene not yet read goes through the job too; without the cache nothing is kept.
    scene = trivox.Scene.__new__(trivox.Scene)
    scene._init(dict(TUBE), str(tube), str(tmp_path), None)
    assert trivox.slice(scene, out, **JOB).cache_hits == 1
    uncached = tmp_path / "uncached"
    assert trivox.slice(tube, uncached, construction_cache=False, **JOB).cache_hits == 0
    assert not (uncached / ".trivox-cache").exists()


def test_a_stack_without_the_object_raises_empty_result_error_after_writing_it(tmp_path):
    sheet = write_scene(tmp_path / "sheet.json", SHEET)
    out = tmp_path / "out"
    with pytest.raises(trivox.EmptyResultError, match="the stack holds no voxel of the object"):
        trivox.slice(sheet, out, **JOB)
    assert json.loads((out / "manifest.json").read_text())["status"] == "complete"
    result = trivox.slice(sheet, tmp_path / "allowed", allow_empty=True, **JOB)
    assert result.total["pixels_inside"] == 0
    assert issubclass(trivox.EmptyResultError, trivox.Error)


def test_stats_dicts_name_what_the_library_lists(tmp_path):
    names = _trivox._layer_stats_names()
    tube = write_scene(tmp_path / "tube.json", TUBE)
    result = trivox.slice(tube, tmp_path / "out", **JOB)
    for layer in result.layers:
        assert list(layer) == names
    assert list(trivox.Slicer(tube).slice_layer(0).stats) == names
    # The sum: the counts only (no layer index, height or times), as stats.json's total.
    counts = [n for n in names if n not in ("layer", "z_mm") and not n.startswith("seconds")]
    assert list(result.total) == counts
    stats = json.loads((tmp_path / "out" / "stats.json").read_text())
    assert sorted(stats["layers"][0]) == sorted(names)
    assert {n: stats["total"][n] for n in counts} == result.total
    # Python's layer is the 0-based index; stats.json numbers layers from 1 (CLI.md).
    assert [layer["layer"] + 1 for layer in result.layers] == [layer["layer"] for layer in stats["layers"]]
    assert result.layers[0]["layer"] == JOB["layers"][0]
