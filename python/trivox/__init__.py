"""trivox: slicing functionally graded material objects, from Python.

The same C++ library as the ``trivox`` program (docs/PYTHON.md): models and volumes with
numpy arrays, bulk evaluation and inversion with the GIL released, the volume constructors,
every material function of the scene file plus Python callables, scenes built in Python or
read from JSON, and slicing, one layer to numpy or whole jobs with byte-identical files.

    import trivox
    vol = trivox.read("examples/models/twisted_column.itd").volumes()[0]
    xyz = vol.evaluate([[1.0, 1.5, 2.0]])
    res = vol.invert(xyz)                      # res.uvw, res.status, res.residual
    labels = trivox.slice_layer("examples/scenes/quick_start.json", 100)

Importing trivox needs no numpy; the calls that take or return arrays do.
"""

from __future__ import annotations

import enum as _enum
import importlib.util as _importlib_util
import os as _os
import sys as _sys
import warnings as _warnings
from typing import Any, Union as _Union

if _importlib_util.find_spec("numpy") is None:
    # Importing works without numpy, but most calls take or return arrays: say at once what
    # is missing and how to get it, rather than leave a bare ModuleNotFoundError for later.
    _warnings.warn(
        f"trivox: numpy is not installed for this Python ({_sys.executable}); the calls that take "
        "or return arrays need it. Install it (Debian: apt install python3-numpy) or run trivox "
        "with a Python that has it (docs/PYTHON.md, 'Setting up').",
        stacklevel=2,
    )

from . import _trivox
from ._trivox import (
    ConstructionReport,
    Constructed,
    EmptyResultError,
    Error,
    ExpressionError,
    GlobalInversion,
    InputError,
    Inversion,
    IoError,
    JacobianReport,
    Layout,
    Model,
    ModelError,
    Patch,
    Spline,
    UnsupportedError,
    Volume,
    __version__,
    arrange_cube_faces,
    coons,
    extrude,
    find_library_material,
    formats,
    inspect_volume,
    join_surfaces,
    material_library,
    printer_profile,
    simd_target,
    simd_targets,
    use_simd_target,
    printer_profile_names,
    read,
    read_gismo_xml,
    read_itd,
    read_png,
    revolve,
    ruled,
    shell,
    sweep,
    to_itd,
    to_g2,
    to_gismo_xml,
    read_g2,
    untangle,
    write_png,
)
from .materials import (
    Blend,
    Constant,
    Expression,
    FieldScalar,
    Function,
    MaterialFunction,
    PngImage,
    PorousTiles,
    RawImage,
    ScalarGradient,
    Select,
    SplineField,
    Texture,
    TextureChannel,
    TiffImage,
    Threshold,
    Transfer,
    TwistingCurves,
    VoidMask,
)
from .scene import Cell, CellInfo, MaterialDef, NamedVolume, Region, Scene, Shell, Trim, Union, read_scene
from .slicing import JobResult, Layer, Slicer, slice, slice_layer

class _Status(_enum.IntEnum):
    """A status code that compares as its number and prints as its name."""

    def __repr__(self) -> str:
        return self.name

    __str__ = __repr__


# Status codes of Volume.invert and Volume.invert_global, in the C++ enums' order (the arrays
# hold these values as uint8).
InverseStatus = _Status(  # type: ignore[call-overload]
    "InverseStatus", [(n.upper().replace("-", "_"), i) for i, n in enumerate(_trivox._inverse_status_names)],
    module=__name__)
GlobalStatus = _Status(  # type: ignore[call-overload]
    "GlobalStatus", [(n.upper().replace("-", "_"), i) for i, n in enumerate(_trivox._global_status_names)],
    module=__name__)


def _statuses_of(kind: Any) -> property:
    def statuses(self: Any) -> Any:
        import numpy as np

        codes = np.asarray(self.status)
        named = np.empty(codes.shape, dtype=object)
        named.flat[:] = [kind(int(c)) for c in codes.flat]
        return named

    statuses.__doc__ = (f"The status array as {kind.__name__} members (an object array of the same shape), "
                        "which print by name.")
    return property(statuses)


Inversion.statuses = _statuses_of(InverseStatus)  # type: ignore[attr-defined]
GlobalInversion.statuses = _statuses_of(GlobalStatus)  # type: ignore[attr-defined]

InverseStatus.__doc__ = ("Status codes of Volume.invert (trivox::InverseStatus): CONVERGED, OUTSIDE (proved "
                         "outside by the global solver; with certified=False held on the domain's boundary), "
                         "NO_CONVERGENCE (iterations spent), SINGULAR (the Jacobian vanished).")
GlobalStatus.__doc__ = ("Status codes of Volume.invert_global (trivox::GlobalStatus): NONE (no preimage, proved), "
                        "UNIQUE, MULTIPLE (the volume folds over the point), DEGENERATE (preimages only where det J "
                        "vanishes), INCOMPLETE (the box budget ran out).")

# The C++ name of the scene file's "shell" constructor.
thick_shell = shell


def write(path: _Union[str, "_os.PathLike[str]"], model: Any) -> None:
    """Writes a Model, one Spline, Volume or Patch, or a list of them, as a model file chosen by
    the extension: IRIT .itd, G+Smo .xml (with the multi-patch interfaces) or GoTools .g2; 17
    significant digits. Knots, weights and the points of polynomial patches read back to the
    same doubles in every format, rational points too from G+Smo .xml; .itd and .g2 store a
    rational point as w * x, which may read back an ulp away (docs/FORMATS.md). Layer images,
    stacks and packages are written by slice()."""
    path = _os.fspath(path)
    if isinstance(model, (Spline, Volume, Patch)):
        model = [model]
    writers = {".itd": to_itd, ".xml": to_gismo_xml, ".g2": to_g2}
    ext = _os.path.splitext(path)[1].lower()
    if ext not in writers:
        raise ValueError(f"{path}: trivox writes models as IRIT .itd, G+Smo .xml or GoTools .g2 files; "
                         "name the file by one of these extensions")
    text = writers[ext](model)
    with open(path, "w", encoding="utf-8") as f:
        f.write(text)


def _same_kind(x: Any, change: Any) -> Any:
    return Volume(change(x.spline)) if isinstance(x, Volume) else change(x)


def elevate_degree(x: Any, dir: Any, times: int = 1) -> Any:  # noqa: A002 - the C++ name
    """Degree elevation along dir (0-2 or 'u', 'v', 'w') by `times`, exact; a Volume stays a Volume."""
    return _same_kind(x, lambda s: s.elevate_degree(dir, times))


def insert_knot(x: Any, dir: Any, t: float, times: int = 1) -> Any:  # noqa: A002
    """Knot insertion along dir, `times` times, exact; a Volume stays a Volume."""
    return _same_kind(x, lambda s: s.insert_knot(dir, t, times))


__all__ = [
    "Blend", "Cell", "CellInfo", "Constant", "Constructed", "ConstructionReport", "EmptyResultError", "Error",
    "Expression", "ExpressionError", "FieldScalar", "Function", "GlobalInversion", "GlobalStatus",
    "InputError", "InverseStatus", "Inversion", "IoError", "JacobianReport", "JobResult", "Layer",
    "Layout", "MaterialDef", "MaterialFunction", "Model", "ModelError", "NamedVolume", "Patch",
    "PngImage", "PorousTiles", "RawImage", "Region", "ScalarGradient", "Scene", "Select", "Shell",
    "Slicer", "Spline", "SplineField", "Texture", "TextureChannel", "Threshold", "TiffImage",
    "Transfer", "Trim", "TwistingCurves", "Union", "UnsupportedError", "VoidMask", "Volume",
    "__version__", "arrange_cube_faces", "coons", "elevate_degree", "extrude", "find_library_material",
    "formats",
    "insert_knot", "inspect_volume", "join_surfaces", "material_library", "materials",
    "printer_profile", "printer_profile_names", "read", "read_gismo_xml", "read_itd", "read_png",
    "read_scene", "revolve", "ruled", "scene", "shell", "simd_target", "simd_targets", "slice", "slice_layer",
    "slicing", "sweep",
    "thick_shell", "to_itd", "to_g2", "to_gismo_xml", "read_g2", "untangle", "use_simd_target", "write", "write_png",
]
