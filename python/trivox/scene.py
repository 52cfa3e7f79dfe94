"""Scenes built from Python objects or read from scene files (docs/PYTHON.md, "Scenes").

A ``Scene`` is a scene file's document (docs/SCENE.md) composed from Python objects
(volumes, splines, material functions, cells, unions) or read from JSON, and the library's
scene read from it: the library's scene reader checks and builds every scene, so a scene made
here obeys the same rules and gives the same messages as a file, and ``to_json()`` gives a
file that ``trivox slice`` accepts.
"""

from __future__ import annotations

import json
import os
from typing import Any, Callable, Dict, List, Mapping, NamedTuple, Optional, Sequence, Tuple
from typing import Union as _Union

from . import _trivox
from .materials import Function, MaterialFunction, to_json_value

__all__ = ["Scene", "Cell", "NamedVolume", "Union", "Region", "Trim", "Shell", "MaterialDef", "CellInfo", "read_scene"]

# Keys of a scene document whose string values are file names, relative to the scene's folder.
_FILE_KEYS = ("file", "png", "tiff", "raw")

_PYTHON_SCENE = "<python scene>"


def _geometry(geometry: Any) -> Any:
    return to_json_value(geometry)


class MaterialDef:
    """A material of the scene: its name (a library material's name may leave out the
    colour), the colour (r, g, b[, a]) or "#RRGGBB[AA]" used in the images, a description."""

    def __init__(self, name: str, rgba: Optional[_Union[str, Sequence[int]]] = None, description: Optional[str] = None):
        self.name, self.rgba, self.description = name, rgba, description

    def to_json(self) -> dict:
        """The scene file's object (JSON-ready)."""
        out: dict = {"name": self.name}
        if self.rgba is not None:
            out["rgba"] = self.rgba if isinstance(self.rgba, str) else [int(c) for c in self.rgba]
        if self.description is not None:
            out["description"] = self.description
        return out


class Shell:
    """A closed set of surfaces for a trim: ``Shell(file=...)`` (every surface of a model
    file) or ``Shell(surfaces=[...])`` (Splines or the scene file's dicts), with an optional
    placement dict."""

    def __init__(self, surfaces: Optional[Sequence[Any]] = None, file: Optional[str] = None, placement: Optional[Mapping[str, Any]] = None):
        if (surfaces is None) == (file is None):
            raise ValueError("a Shell is given either by surfaces or by a file")
        self.surfaces, self.file, self.placement = surfaces, file, placement

    def to_json(self) -> dict:
        """The scene file's object (JSON-ready)."""
        out: dict = {"file": str(self.file)} if self.file is not None else {"surfaces": to_json_value(list(self.surfaces or []))}
        if self.placement is not None:
            out["placement"] = to_json_value(self.placement)
        return out


class Trim:
    """One trim clause: ``side`` "inside" or "outside" of exactly one of a named ``volume``,
    a model-space ``shell`` or a ``parametric`` shell (Shell objects or dicts)."""

    def __init__(self, side: str, volume: Optional[str] = None, shell: Any = None, parametric: Any = None):
        if sum(x is not None for x in (volume, shell, parametric)) != 1:
            raise ValueError("a trim clause names exactly one of volume, shell, parametric")
        self.side, self.volume, self.shell, self.parametric = side, volume, shell, parametric

    def to_json(self) -> dict:
        """The scene file's object (JSON-ready)."""
        out: dict = {"side": self.side}
        for key in ("volume", "shell", "parametric"):
            if getattr(self, key) is not None:
                out[key] = to_json_value(getattr(self, key))
        return out


class Cell:
    """A cell: its geometry (a Volume, or the scene file's geometry dict: a file reference, an
    inline spline or a constructor) or the name of one of the scene's volumes, its material
    (a material function, a material's name, or a Python callable), and optionally a name, a
    placement dict and trim clauses."""

    def __init__(
        self,
        material: Any,
        geometry: Any = None,
        *,
        volume: Optional[str] = None,
        name: Optional[str] = None,
        placement: Optional[Mapping[str, Any]] = None,
        trim: Optional[Sequence[Any]] = None,
    ):
        if (geometry is None) == (volume is None):
            raise ValueError("a Cell has either a geometry or the name of one of the scene's volumes")
        self.material, self.geometry, self.volume, self.name, self.placement, self.trim = (
            material, geometry, volume, name, placement, trim)

    def to_json(self) -> dict:
        """The scene file's object (JSON-ready)."""
        out: dict = {}
        if self.name is not None:
            out["name"] = self.name
        if self.geometry is not None:
            out["geometry"] = _geometry(self.geometry)
        if self.volume is not None:
            out["volume"] = self.volume
        if self.placement is not None:
            out["placement"] = to_json_value(self.placement)
        if self.trim is not None:
            out["trim"] = [to_json_value(t) for t in self.trim]
        out["material"] = _material(self.material)
        return out


class NamedVolume:
    """A named trivariate of the scene ("volumes"): a cell's parametrization, a trim, a
    union's member."""

    def __init__(self, name: str, geometry: Any, placement: Optional[Mapping[str, Any]] = None):
        self.name, self.geometry, self.placement = name, geometry, placement

    def to_json(self) -> dict:
        """The scene file's object (JSON-ready)."""
        out: dict = {"name": self.name, "geometry": _geometry(self.geometry)}
        if self.placement is not None:
            out["placement"] = to_json_value(self.placement)
        return out


class Region:
    """A region of a union: the volumes its points are inside (``of``), its material, which
    of them parametrizes it, and its name."""

    def __init__(self, of: Sequence[str], material: Any, parametrize: Optional[str] = None, name: Optional[str] = None):
        self.of, self.material, self.parametrize, self.name = list(of), material, parametrize, name

    def to_json(self) -> dict:
        """The scene file's object (JSON-ready)."""
        out: dict = {"of": self.of}
        if self.parametrize is not None:
            out["parametrize"] = self.parametrize
        if self.name is not None:
            out["name"] = self.name
        out["material"] = _material(self.material)
        return out


class Union:
    """Boolean cells: overlapping named volumes split into one region per non-empty set."""

    def __init__(self, name: str, volumes: Sequence[str], regions: Sequence[Any]):
        self.name, self.volumes, self.regions = name, list(volumes), list(regions)

    def to_json(self) -> dict:
        """The scene file's object (JSON-ready)."""
        return {"name": self.name, "volumes": self.volumes, "regions": [to_json_value(r) for r in self.regions]}


class _PythonMaterialSlot:
    """A cell's Python callable, kept out of the JSON document (see Scene)."""

    def __init__(self, fn: Callable[..., Any]):
        self.fn = fn


def _material(material: Any) -> Any:
    if isinstance(material, Function):
        return _PythonMaterialSlot(material.fn)
    if callable(material) and not isinstance(material, (MaterialFunction, type)):
        return _PythonMaterialSlot(material)
    return to_json_value(material)


class CellInfo(NamedTuple):
    """A cell as the library read it: its name, JSON pointer, volume (mm, placement applied),
    material kind and the JSON pointer of the material, the named volume that parametrizes it
    (or None) and its trim clauses."""

    name: str
    pointer: str
    volume: "_trivox.Volume"
    material: str
    material_pointer: str
    scene_volume: Optional[str]
    trim: List[Dict[str, str]]


def _absolute_files(node: Any, base: str) -> Any:
    """The document with relative file names made absolute against `base`."""
    if isinstance(node, dict):
        out = {}
        for key, value in node.items():
            if key in _FILE_KEYS and isinstance(value, str):
                out[key] = os.path.normpath(os.path.join(base, value))
            elif key in _FILE_KEYS and isinstance(value, list) and all(isinstance(v, str) for v in value):
                out[key] = [os.path.normpath(os.path.join(base, v)) for v in value]
            else:
                out[key] = _absolute_files(value, base)
        return out
    if isinstance(node, list):
        return [_absolute_files(v, base) for v in node]
    return node


class Scene:
    """An FGM object to print: the printer, the materials, the cells (and named volumes and
    unions), as in a scene file (docs/SCENE.md). Build it from Python objects,

        Scene(printer="j750-paper", materials=["VeroCyan", "VeroMagenta"],
              cells=[Cell(Expression({"VeroCyan": "1 - w", "VeroMagenta": "w"}), geometry=volume)])

    or read it with ``read_scene(path)`` / ``Scene.from_json(text)``. Arguments are the scene
    file's keys; any of them may be given in the scene file's own (dict) form. The library
    reads the scene when it is first needed (and raises InputError for anything wrong, with
    the JSON pointer of the place); after that the scene is fixed.
    """

    def __init__(
        self,
        printer: _Union[str, Mapping[str, Any]],
        materials: Sequence[Any],
        cells: Sequence[Any] = (),
        *,
        volumes: _Union[Sequence[Any], Mapping[str, Any]] = (),
        unions: Sequence[Any] = (),
        fraction_sums: Optional[Mapping[str, Any]] = None,
        dithering: Optional[Mapping[str, Any]] = None,
        description: Optional[str] = None,
        source: str = _PYTHON_SCENE,
    ):
        doc: dict = {"version": 1}
        if description is not None:
            doc["description"] = description
        doc["units"] = "mm"
        doc["printer"] = to_json_value(printer)
        doc["materials"] = [to_json_value(m) for m in materials]
        if fraction_sums is not None:
            doc["fraction_sums"] = to_json_value(fraction_sums)
        if dithering is not None:
            doc["dithering"] = to_json_value(dithering)
        if isinstance(volumes, Mapping):
            volumes = [NamedVolume(name, geometry) for name, geometry in volumes.items()]
        if volumes:
            doc["volumes"] = [to_json_value(v) for v in volumes]
        if cells:
            doc["cells"] = [c.to_json() if isinstance(c, Cell) else _raw_cell(c) for c in cells]
        if unions:
            doc["unions"] = [_union_json(u if isinstance(u, Union) else Union(**u)) for u in unions]
        self._init(doc, source, os.getcwd(), None)

    def _init(self, doc: dict, source: str, base: str, handle: Optional[Any]) -> None:
        self._doc = doc
        self._source = source
        self._base = base
        self._handle = handle
        self._python_materials: List[Tuple[str, Callable[..., Any]]] = []

    @classmethod
    def from_json(cls, text: str, source: str = _PYTHON_SCENE) -> "Scene":
        """A scene from the text of a scene file; ``source`` names it in messages, and
        relative file names resolve against its folder (the current folder by default)."""
        scene = cls.__new__(cls)
        handle = _trivox._parse_scene(text, source)
        base = os.path.dirname(os.path.abspath(source)) if source != _PYTHON_SCENE else os.getcwd()
        scene._init(json.loads(text), source, base, handle)
        return scene

    # --- the document -------------------------------------------------------------------

    def document(self) -> dict:
        """The scene file's object (JSON-ready), file names made absolute. Raises TypeError
        when a cell's material is a Python callable, which a file cannot hold."""
        return _absolute_files(_check_no_python(self._doc), self._base)

    def to_json(self, indent: Optional[int] = 2) -> str:
        """The scene as the text of a scene file that ``trivox slice`` accepts and that
        ``read_scene`` reads back to the same scene. File names are absolute, so the file
        works from any folder; inline splines carry every double exactly."""
        return json.dumps(self.document(), indent=indent) + "\n"

    def save(self, path: _Union[str, "os.PathLike[str]"]) -> None:
        """Writes to_json() to path."""
        with open(path, "w", encoding="utf-8") as f:
            f.write(self.to_json())

    # --- the library's scene ------------------------------------------------------------

    @property
    def handle(self) -> Any:
        """The library's scene (read on first use)."""
        return self._library_scene(_trivox._parse_scene)

    def _library_scene(self, parse: Callable[[str, str], Any]) -> Any:
        """The library's scene, parsed by parse(text, source) when it is not yet: a slicing
        job passes its own, which reads constructed volumes through its folder's cache."""
        if self._handle is None:
            doc, slots = _split_python_materials(self._doc)
            text = json.dumps(_absolute_files(doc, self._base))
            handle = parse(text, self._source)
            if slots:
                handle = handle.with_python_materials(slots)
            self._handle = handle
        return self._handle

    @property
    def source(self) -> str:
        """The scene file as given, or "<python scene>"."""
        return self.handle.source

    @property
    def printer(self) -> dict:
        """The printer profile: name, x_dpi, y_dpi, layer_thickness_mm, max_materials."""
        return self.handle.printer

    @property
    def materials(self) -> List[dict]:
        """The materials in order (index j of every fraction array): name, rgba, library."""
        return self.handle.materials

    @property
    def material_names(self) -> List[str]:
        """The materials' names in order."""
        return [m["name"] for m in self.handle.materials]

    @property
    def num_materials(self) -> int:
        """m: how many fractions a sample has."""
        return len(self.handle.materials)

    @property
    def cells(self) -> List[CellInfo]:
        """The cells as the library read them (unions expanded into their regions' cells)."""
        return [CellInfo(**c) for c in self.handle.cells]

    @property
    def volumes(self) -> Dict[str, "_trivox.Volume"]:
        """The named volumes (mm, placement applied)."""
        return {v["name"]: v["volume"] for v in self.handle.volumes}

    @property
    def bounds(self) -> Any:
        """(2, 3): a box [lo, hi] in mm that holds every cell (their control points' box)."""
        return self.handle.bounds

    @property
    def input_files(self) -> List[Tuple[str, str]]:
        """Every model or image file the scene read, with its SHA-256."""
        return self.handle.input_files

    def evaluate_material(self, cell: _Union[int, str], params: Any) -> Any:
        """The fractions (..., m) float32 of a cell's material (with the scene's fraction policy)
        at its parameters (..., 3), the positions computed by its volume."""
        if isinstance(cell, str):
            names = [c["name"] for c in self.handle.cells]
            if cell not in names:
                raise KeyError(f"the scene has no cell '{cell}' (its cells: {', '.join(names)})")
            cell = names.index(cell)
        return self.handle.evaluate_material(cell, params)

    def __repr__(self) -> str:
        if self._handle is None:
            return f"<trivox.Scene {self._source!r} (not read yet)>"
        return f"<trivox.Scene {self._source!r}: {len(self._handle.cells)} cells, {self.num_materials} materials>"


def _raw_cell(cell: Any) -> Any:
    if isinstance(cell, Mapping) and "material" in cell:
        out = {k: to_json_value(v) for k, v in cell.items() if k != "material"}
        out["material"] = _material(cell["material"])
        return out
    return to_json_value(cell)


def _union_json(u: Union) -> dict:
    regions = []
    for r in u.regions:
        if isinstance(r, Region):
            regions.append(r.to_json())
        elif isinstance(r, Mapping) and "material" in r:
            out = {k: to_json_value(v) for k, v in r.items() if k != "material"}
            out["material"] = _material(r["material"])
            regions.append(out)
        else:
            regions.append(to_json_value(r))
    return {"name": u.name, "volumes": u.volumes, "regions": regions}


def _split_python_materials(doc: dict) -> Tuple[dict, List[Tuple[str, Callable[..., Any]]]]:
    """The document with every Python material replaced by "void", and (JSON pointer, callable)
    for each, for the library to put in their place."""
    slots: List[Tuple[str, Callable[..., Any]]] = []
    doc = dict(doc)

    def take(entry: dict, pointer: str) -> dict:
        material = entry.get("material")
        if isinstance(material, _PythonMaterialSlot):
            slots.append((pointer + "/material", material.fn))
            entry = dict(entry)
            entry["material"] = "void"
        return entry

    if "cells" in doc:
        doc["cells"] = [take(c, f"/cells/{i}") for i, c in enumerate(doc["cells"])]
    if "unions" in doc:
        unions = []
        for i, u in enumerate(doc["unions"]):
            u = dict(u)
            u["regions"] = [take(r, f"/unions/{i}/regions/{j}") for j, r in enumerate(u.get("regions", []))]
            unions.append(u)
        doc["unions"] = unions
    _check_no_python(doc)
    return doc, slots


def _check_no_python(node: Any, pointer: str = "") -> Any:
    if isinstance(node, _PythonMaterialSlot):
        raise TypeError(
            f"{pointer or '/'}: a Python material cannot be written to a scene file (it exists only in this "
            "process); give the cell a material function of the scene file to save it"
        )
    if isinstance(node, dict):
        for key, value in node.items():
            _check_no_python(value, f"{pointer}/{key}")
    elif isinstance(node, list):
        for i, value in enumerate(node):
            _check_no_python(value, f"{pointer}/{i}")
    return node


def read_scene(path: _Union[str, "os.PathLike[str]"]) -> Scene:
    """Reads a scene file (trivox::read_scene): files it names are read relative to its
    folder. Raises IoError when it cannot be read, InputError ("scene.json: /json/pointer:
    rule") for anything wrong in it or in the files it names."""
    return _read_scene_with(path, _trivox._read_scene)


def _read_scene_with(path: _Union[str, "os.PathLike[str]"], read: Callable[[str], Any]) -> Scene:
    """read_scene with the library's scene from read(path): a slicing job passes its own."""
    path = os.fspath(path)
    handle = read(path)
    with open(path, encoding="utf-8") as f:
        text = f.read()
    scene = Scene.__new__(Scene)
    scene._init(json.loads(text), path, os.path.dirname(os.path.abspath(path)), handle)
    return scene
