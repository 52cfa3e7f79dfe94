"""Slicing from Python (docs/PYTHON.md, "Slicing"): one layer as numpy arrays, or the whole
job of ``trivox slice`` with the same settings and byte-identical files."""

from __future__ import annotations

import operator
import os
from typing import Any, Callable, Dict, List, NamedTuple, Optional, Sequence, Tuple, Union

from . import _trivox
from .scene import Scene, _read_scene_with, read_scene

__all__ = ["Slicer", "Layer", "JobResult", "slice_layer", "slice"]

SceneLike = Union[Scene, str, "os.PathLike[str]"]


def _scene(scene: SceneLike) -> Scene:
    return scene if isinstance(scene, Scene) else read_scene(scene)


class Layer(NamedTuple):
    """One sliced layer: labels (H, W) uint8 (0 void, 1 + j material j; row 0 is the top
    of the image, at the largest y), and when asked for, the fractions before dithering
    (H, W, m) float32 with the inside mask (H, W) uint8, and the owning cell of every pixel
    (H, W) int32 (-1 outside); stats: the layer's counts (stats.json's columns)."""

    labels: Any
    fractions: Optional[Any]
    inside: Optional[Any]
    owner: Optional[Any]
    stats: Dict[str, Any]


class JobResult(NamedTuple):
    """What a slicing job did: per-layer stats in layer order, every file it wrote (relative to
    the output folder, sorted), its wall time, threads, empty layers padded and layers a
    resumed job kept; total: the layers' counts summed (stats.json's "total" counts); the
    constructed volumes the construction cache supplied and what it warned about (damaged or
    unusable entries, which were built again)."""

    layers: List[Dict[str, Any]]
    files: List[str]
    seconds: float
    threads: int
    padded_layers: int
    layers_kept: int
    total: Optional[Dict[str, Any]] = None
    cache_hits: int = 0
    cache_warnings: Tuple[str, ...] = ()


class Slicer:
    """A scene prepared for slicing (outlines, global solvers, the layout), with the slicing
    settings of ``trivox slice``: tracing, residual_tolerance_mm, outline_tolerance_mm,
    dither (a method name; default the scene's), skin (voxels; default the scene's),
    vary_by_layer (default the scene's). Reuse one Slicer for several layers: preparing a
    scene costs about as much as slicing a layer."""

    def __init__(
        self,
        scene: SceneLike,
        *,
        tracing: str = "flood",
        residual_tolerance_mm: float = 1e-6,
        outline_tolerance_mm: Optional[float] = None,
        dither: Optional[str] = None,
        skin: Optional[int] = None,
        vary_by_layer: Optional[bool] = None,
    ):
        self.scene = _scene(scene)
        self._slicer = _trivox._Slicer(
            self.scene.handle, tracing, residual_tolerance_mm, outline_tolerance_mm, dither, skin, vary_by_layer
        )

    @property
    def layout(self) -> "_trivox.Layout":
        """Layers, bitmap size and where every pixel lies in model space (mm)."""
        return self._slicer.layout

    @property
    def background(self) -> Tuple[int, int, int, int]:
        """The job's background colour when slice() is given none: black, or white or a grey
        when a material takes black (the colour of label 0 in the printer images)."""
        return self._slicer.background

    @property
    def dithering(self) -> Dict[str, Any]:
        """The dithering in effect: method, serpentine, vary_by_layer, skin_voxels."""
        return self._slicer.dithering

    def slice_layer(self, layer: int, *, fractions: bool = False, owner: bool = False) -> Layer:
        """Slices layer `layer` (0-based) as the job does; the GIL is released meanwhile."""
        r = self._slicer.slice_layer(layer, fractions, owner)
        return Layer(r["labels"], r.get("fractions"), r.get("inside"), r.get("owner"), r["stats"])

    def slice(self, output_dir: Union[str, "os.PathLike[str]"], **job: Any) -> JobResult:
        """The whole job into output_dir; the keyword arguments are slice()'s job settings.
        The scene is already read, so the job locks the folder after it (slice() given a
        path locks before)."""
        return _run(self, output_dir, {}, **job)


def slice_layer(scene: SceneLike, layer: int, *, fractions: bool = False, **settings: Any) -> Any:
    """The material labels of layer `layer` (0-based) of a scene, (H, W) uint8: 0 void,
    1 + j material j, the pixels of the command line's images (row 0 at the top). With
    fractions=True, (labels, fractions): the fractions before dithering, (H, W, m) float32.
    The settings are Slicer's. For several layers, make one Slicer and call its slice_layer."""
    result = Slicer(scene, **settings).slice_layer(layer, fractions=fractions)
    return (result.labels, result.fractions) if fractions else result.labels


def _layer_range(layers: Union[None, int, range]) -> Tuple[int, int]:
    if layers is None:
        return 0, -1
    if not isinstance(layers, range) and hasattr(layers, "__index__"):  # int, numpy integers
        k = operator.index(layers)
        return k, k
    if isinstance(layers, range) and layers.step == 1 and len(layers) > 0:
        return layers.start, layers.stop - 1
    raise ValueError("layers: expected None (all), a layer index or a non-empty range of layer indices (step 1)")


def slice(  # noqa: A001 - the verb is the API's name
    scene: Union[SceneLike, Slicer],
    output_dir: Union[str, "os.PathLike[str]"],
    *,
    formats: Sequence[str] = ("voxelprint",),
    layers: Union[None, int, range] = None,
    threads: int = 0,
    prefix: str = "slice_",
    background: Optional[Sequence[int]] = None,
    min_layers: Optional[int] = None,
    preview: Sequence[int] = (),
    shard: Optional[Tuple[int, int]] = None,
    resume: bool = False,
    progress: Optional[Callable[[int, int], Any]] = None,
    checks: bool = True,
    memory_limit_mb: Optional[float] = None,
    manifest_interval_s: float = 1.0,
    construction_cache: bool = True,
    allow_empty: bool = False,
    **settings: Any,
) -> JobResult:
    """Runs the job of ``trivox slice`` and writes the same bytes (every file but the timings in
    stats.json), in parallel over layers on `threads` workers (0: every core).

    formats: the outputs (trivox.formats()); layers: None for all, a layer or a range of
    layers, 0-based (``--layers 51:450`` is ``layers=range(50, 450)``); preview: 0-based layers
    also written as preview images (``--preview 80`` is ``preview=[79]``); shard: (I, N) as
    ``--shard I/N``; resume: continue the job recorded in the folder's manifest; progress:
    progress(done, total) called on this thread after layers complete; min_layers: pad the
    stack with empty layers up to this many (None: 30 when a format GrabCAD Voxel Print reads,
    voxelprint or gcvf, is written, else 0, as ``--min-layers`` left out); checks: refuse a job
    the estimate says will not fit the disk or the memory (memory_limit_mb, default the
    machine's); construction_cache: read the scene through the folder's construction cache
    (``--no-cache`` is False); allow_empty: accept a stack without a voxel of the object
    (``--allow-empty``); the other keyword arguments are Slicer's settings.

    As the command line, the job locks output_dir before the scene is read (Error when
    another job writes into it); a scene given as a path, or a Scene not yet read, is read
    through the folder's construction cache. A job that fails on its input leaves the folder
    as it found it (absent or empty); one that fails to write keeps its completed layers for
    a resume. A job that sliced every layer of the object itself and found no voxel of it
    raises EmptyResultError once the files are written, unless allow_empty.

    Ctrl-C (KeyboardInterrupt), or an exception raised by `progress`, stops the job: no new
    layer starts, the manifest is marked interrupted, and the exception is raised once the
    layers in progress have stopped (within a row of voxels: a slow Python material is not run
    to the end of its layer); ``resume=True`` continues it.
    """
    if isinstance(scene, Slicer) and settings:
        raise TypeError("give the slicing settings to the Slicer, not to slice()")
    return _run(
        scene, output_dir, settings, formats=formats, layers=layers, threads=threads, prefix=prefix,
        background=background, min_layers=min_layers, preview=preview, shard=shard, resume=resume, progress=progress,
        checks=checks, memory_limit_mb=memory_limit_mb, manifest_interval_s=manifest_interval_s,
        construction_cache=construction_cache, allow_empty=allow_empty)


def _job_scene(job: Any, scene: SceneLike) -> Scene:
    """The scene, read (or parsed, when not yet) through the job and its construction cache."""
    if isinstance(scene, Scene):
        scene._library_scene(job.parse_scene)
        return scene
    return _read_scene_with(scene, job.read_scene)


def _run(
    scene: Union[SceneLike, Slicer],
    output_dir: Union[str, "os.PathLike[str]"],
    settings: Dict[str, Any],
    *,
    formats: Sequence[str] = ("voxelprint",),
    layers: Union[None, int, range] = None,
    threads: int = 0,
    prefix: str = "slice_",
    background: Optional[Sequence[int]] = None,
    min_layers: Optional[int] = None,
    preview: Sequence[int] = (),
    shard: Optional[Tuple[int, int]] = None,
    resume: bool = False,
    progress: Optional[Callable[[int, int], Any]] = None,
    checks: bool = True,
    memory_limit_mb: Optional[float] = None,
    manifest_interval_s: float = 1.0,
    construction_cache: bool = True,
    allow_empty: bool = False,
) -> JobResult:
    if isinstance(formats, str):
        formats = [f for f in formats.split(",") if f]
    first, last = _layer_range(layers)
    shard_index, shard_count = shard if shard is not None else (1, 1)
    # The library's job (trivox::SliceJob): the lock now, before the scene is read; the
    # folder put back as found, on close, when the job failed on its input.
    job = _trivox._Job(
        os.fspath(output_dir), list(formats), first, last, threads, prefix,
        None if background is None else list(background), min_layers, list(preview), shard_index, shard_count,
        resume, checks, memory_limit_mb, manifest_interval_s, construction_cache, allow_empty)
    try:
        slicer = scene if isinstance(scene, Slicer) else Slicer(_job_scene(job, scene), **settings)
        r = job.run(slicer._slicer, progress)
        hits, warnings = job.cache_hits, job.cache_warnings
    finally:
        job.close()
    return JobResult(
        r["layers"], r["files"], r["seconds"], r["threads"], r["padded_layers"], r["layers_kept"], r["total"], hits,
        tuple(warnings))
