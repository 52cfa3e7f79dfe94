"""Material functions M(u, v, w) as Python objects (docs/PYTHON.md, "Materials").

Each class is one ``kind`` of the scene file (docs/SCENE.md, "Material functions") with the
same keys as keyword arguments; ``to_json()`` gives the scene file's object, and the
library's scene reader builds the material from it, so a material made here behaves exactly
as the same object in a scene file. Wherever a material function is expected, a material's
name (``"VeroCyan"``, ``"void"``) and a plain ``dict`` in the scene file's form work too.

One kind exists only in Python: ``Function(f)`` (or any callable given as a cell's
material), ``f(u, v, w, x, y, z) -> fractions`` called on whole rows of samples as numpy
arrays.

Nothing here imports numpy: arrays are converted where they are met.
"""

from __future__ import annotations

from typing import Any, Callable, Mapping, Optional, Sequence, Union

__all__ = [
    "MaterialFunction",
    "Constant",
    "Expression",
    "SplineField",
    "ScalarGradient",
    "PorousTiles",
    "TwistingCurves",
    "Texture",
    "Transfer",
    "Blend",
    "Threshold",
    "Select",
    "VoidMask",
    "FieldScalar",
    "TextureChannel",
    "PngImage",
    "TiffImage",
    "RawImage",
    "Function",
    "to_json_value",
]


class MaterialFunction:
    """Base of the material function classes: ``to_json()`` gives the scene file's object."""

    kind: str = ""

    def _fields(self) -> dict:
        raise NotImplementedError

    def to_json(self) -> dict:
        """The scene file's object for this material function (JSON-ready: lists, numbers, strings)."""
        out = {"kind": self.kind}
        for key, value in self._fields().items():
            if value is not None:
                out[key] = to_json_value(value)
        return out

    def __repr__(self) -> str:
        return f"trivox.{type(self).__name__}({self.to_json()!r})"

    def __eq__(self, other: object) -> bool:
        return type(self) is type(other) and self.to_json() == other.to_json()  # type: ignore[union-attr]


def _spline_json(spline: Any, scalar_field: bool = False) -> dict:
    """An inline spline of the scene file (orders, knots, points u fastest, weights); a
    Volume read from a model file is named by its file and trivariate index instead."""
    from . import _trivox

    if isinstance(spline, _trivox.Volume):
        if spline.source is not None:
            file, patch = spline.source
            return {"file": file, "patch": patch}
        spline = spline.spline
    if any(spline.periodic):
        # The scene file has no periodic knot vectors: the same geometry, clamped.
        spline = spline.clamped()
    out: dict = {"orders": list(spline.orders), "knots": [k.tolist() for k in spline.knots]}
    points = spline.points
    out["points"] = points[:, 0].tolist() if scalar_field and spline.point_dim == 1 else points.tolist()
    if spline.is_rational:
        out["weights"] = spline.weights.tolist()
    return out


def to_json_value(value: Any) -> Any:
    """Converts what a scene may hold (material functions, splines, volumes, numpy arrays and
    numbers, mappings, sequences) into JSON-ready values."""
    from . import _trivox

    if hasattr(value, "to_json") and not isinstance(value, type):
        return value.to_json()
    if isinstance(value, (_trivox.Spline, _trivox.Volume)):
        return _spline_json(value)
    if isinstance(value, (str, bool, int, float)) or value is None:
        return value
    if isinstance(value, Mapping):
        return {str(k): to_json_value(v) for k, v in value.items()}
    if hasattr(value, "tolist"):  # numpy arrays and scalars
        return value.tolist()
    if isinstance(value, (list, tuple, range)):
        return [to_json_value(v) for v in value]
    if callable(value):
        raise TypeError(
            "a Python material (a callable) cannot be written to a scene file; "
            "it can only be a cell's or a region's whole material"
        )
    raise TypeError(f"cannot put a {type(value).__name__} into a scene")


def _field(field: Any, scalar: bool = False) -> Any:
    from . import _trivox

    if isinstance(field, (_trivox.Spline, _trivox.Volume)):
        return _spline_json(field, scalar_field=scalar)
    return field


Fractions = Mapping[str, Union[float, str]]
MaterialLike = Union[MaterialFunction, str, Mapping[str, Any], Callable[..., Any]]


class Constant(MaterialFunction):
    """The same fractions everywhere: ``Constant({"VeroCyan": 0.3, "VeroWhite": 0.7})``."""

    kind = "constant"

    def __init__(self, fractions: Mapping[str, float]):
        self.fractions = dict(fractions)

    def _fields(self) -> dict:
        return {"fractions": self.fractions}


class Expression(MaterialFunction):
    """One muParser expression per material over u, v, w (the cell's parameters normalised to
    [0, 1]) and x, y, z (mm): ``Expression({"VeroCyan": "1 - w", "VeroMagenta": "w"},
    constants={"period_mm": 10})``."""

    kind = "expression"

    def __init__(self, fractions: Mapping[str, Union[str, float]], constants: Optional[Mapping[str, float]] = None):
        self.fractions = dict(fractions)
        self.constants = dict(constants) if constants else None

    def _fields(self) -> dict:
        return {"constants": self.constants, "fractions": self.fractions}


class SplineField(MaterialFunction):
    """A trivariate field with k components: component i is the fraction of material
    ``components[i]`` ("void" to ignore it). ``field``: a Spline (inline) or a dict
    ``{"file": ..., "patch": N}``; the cell's parameters map onto the field's domain."""

    kind = "spline_field"

    def __init__(self, components: Sequence[str], field: Any):
        self.components = list(components)
        self.field = field

    def _fields(self) -> dict:
        return {"components": self.components, "field": _field(self.field)}


def _stops(stops: Sequence[Any]) -> list:
    out = []
    for s in stops:
        if isinstance(s, Mapping):
            out.append(dict(s))
        else:
            value, fractions = s
            out.append({"value": value, "fractions": dict(fractions)})
    return out


class ScalarGradient(MaterialFunction):
    """A scalar field (one component) through a ramp of stops:
    ``ScalarGradient(field, [(0.0, {"VeroCyan": 1}), (1.0, {"VeroWhite": 1})])``."""

    kind = "scalar_gradient"

    def __init__(self, field: Any, stops: Sequence[Any]):
        self.field = field
        self.stops = _stops(stops)

    def _fields(self) -> dict:
        return {"field": _field(self.field, scalar=True), "stops": self.stops}


class PorousTiles(MaterialFunction):
    """The duck's porous microstructure: tiles (nu, nv, nw) or n, two materials alternating,
    two orthogonal cylinders of ``radius`` (fraction of the tile side) removed from each tile."""

    kind = "porous_tiles"

    def __init__(
        self,
        tiles: Union[int, Sequence[int]],
        materials: Sequence[str],
        radius: Optional[float] = None,
        cylinder_axes: Optional[Sequence[str]] = None,
    ):
        self.tiles = tiles if isinstance(tiles, int) else list(tiles)
        self.materials = list(materials)
        self.radius = radius
        self.cylinder_axes = list(cylinder_axes) if cylinder_axes is not None else None

    def _fields(self) -> dict:
        return {
            "tiles": self.tiles,
            "radius": self.radius,
            "materials": self.materials,
            "cylinder_axes": self.cylinder_axes,
        }


class TwistingCurves(MaterialFunction):
    """The chalice's twisting coloured curves: ``points`` is a list of ``((u0, v0), material)``
    (or dicts ``{"uv": ..., "material": ...}``) at w = 0, turning and shifting with w."""

    kind = "twisting_curves"

    def __init__(
        self,
        points: Sequence[Any],
        radius: float,
        centre: Optional[Sequence[float]] = None,
        turns_per_w: Optional[float] = None,
        shift_per_w: Optional[Sequence[float]] = None,
        wrap: Optional[Sequence[str]] = None,
        background: Optional[str] = None,
    ):
        self.points = [
            dict(p) if isinstance(p, Mapping) else {"uv": list(p[0]), "material": p[1]} for p in points
        ]
        self.radius = radius
        self.centre = list(centre) if centre is not None else None
        self.turns_per_w = turns_per_w
        self.shift_per_w = list(shift_per_w) if shift_per_w is not None else None
        self.wrap = list(wrap) if wrap is not None else None
        self.background = background

    def _fields(self) -> dict:
        return {
            "points": self.points,
            "radius": self.radius,
            "centre": self.centre,
            "turns_per_w": self.turns_per_w,
            "shift_per_w": self.shift_per_w,
            "wrap": self.wrap,
            "background": self.background,
        }


class PngImage:
    """A texture image from PNG files, one per slice along w: ``PngImage("t.png")`` or
    ``PngImage(["z0.png", "z1.png"])``."""

    def __init__(self, files: Union[str, Sequence[str]]):
        self.files = files if isinstance(files, str) else [str(f) for f in files]

    def to_json(self) -> dict:
        """The scene file's object (JSON-ready)."""
        return {"png": str(self.files) if isinstance(self.files, str) else self.files}


class TiffImage:
    """A texture image from a (multi-page) TIFF file: every page one slice."""

    def __init__(self, file: str):
        self.file = str(file)

    def to_json(self) -> dict:
        """The scene file's object (JSON-ready)."""
        return {"tiff": self.file}


class RawImage:
    """A headerless raw array: size (nx, ny, nz), x fastest; type "uint8", "uint16" or
    "float32"; byte_order "little" or "big"."""

    def __init__(
        self,
        file: str,
        size: Sequence[int],
        channels: Optional[int] = None,
        type: Optional[str] = None,  # noqa: A002 - the scene file's key
        byte_order: Optional[str] = None,
    ):
        self.file, self.size, self.channels, self.type, self.byte_order = str(file), list(size), channels, type, byte_order

    def to_json(self) -> dict:
        """The scene file's object (JSON-ready)."""
        out: dict = {"raw": self.file, "size": self.size}
        for key in ("channels", "type", "byte_order"):
            if getattr(self, key) is not None:
                out[key] = getattr(self, key)
        return out


class Texture(MaterialFunction):
    """A volumetric texture whose channels are material fractions: ``image`` (PngImage,
    TiffImage, RawImage or the scene file's dict), ``channels`` one material name (or
    "void") per channel; filter "nearest" or "trilinear"; wrap "clamp", "repeat" or "mirror"
    (or one per direction); repeats a number or one per direction."""

    kind = "texture"

    def __init__(
        self,
        image: Any,
        channels: Sequence[str],
        filter: Optional[str] = None,  # noqa: A002 - the scene file's key
        wrap: Optional[Union[str, Sequence[str]]] = None,
        repeats: Optional[Union[float, Sequence[float]]] = None,
    ):
        self.image, self.channels, self.filter, self.wrap, self.repeats = image, list(channels), filter, wrap, repeats

    def _fields(self) -> dict:
        return {
            "image": self.image,
            "filter": self.filter,
            "wrap": self.wrap,
            "repeats": self.repeats,
            "channels": self.channels,
        }


class FieldScalar:
    """A scalar source from a spline field: its component k, or with magnitude=True the
    length of its vector of components (e.g. an analysis result)."""

    def __init__(self, field: Any, component: Optional[int] = None, magnitude: bool = False):
        self.field, self.component, self.magnitude = field, component, magnitude

    def to_json(self) -> dict:
        """The scene file's object (JSON-ready)."""
        out: dict = {"field": to_json_value(_field(self.field))}
        if self.magnitude:
            out["magnitude"] = True
        elif self.component is not None:
            out["component"] = self.component
        return out


class TextureChannel:
    """A scalar source from one channel of a volume image, sampled as for Texture."""

    def __init__(
        self,
        image: Any,
        channel: Optional[int] = None,
        filter: Optional[str] = None,  # noqa: A002
        wrap: Optional[Union[str, Sequence[str]]] = None,
        repeats: Optional[Union[float, Sequence[float]]] = None,
    ):
        self.image, self.channel, self.filter, self.wrap, self.repeats = image, channel, filter, wrap, repeats

    def to_json(self) -> dict:
        """The scene file's object (JSON-ready)."""
        out = {"texture": to_json_value(self.image)}
        for key in ("channel", "filter", "wrap", "repeats"):
            if getattr(self, key) is not None:
                out[key] = to_json_value(getattr(self, key))
        return out


class Transfer(MaterialFunction):
    """A scalar source (number, expression string, FieldScalar, TextureChannel) through a
    ramp of stops, as ScalarGradient's."""

    kind = "transfer"

    def __init__(self, source: Any, stops: Sequence[Any]):
        self.source, self.stops = source, _stops(stops)

    def _fields(self) -> dict:
        return {"source": self.source, "stops": self.stops}


class Blend(MaterialFunction):
    """(1 - t) a + t b, t the scalar source ``weight`` clamped to [0, 1]."""

    kind = "blend"

    def __init__(self, a: MaterialLike, b: MaterialLike, weight: Any):
        self.a, self.b, self.weight = a, b, weight

    def _fields(self) -> dict:
        return {"a": self.a, "b": self.b, "weight": self.weight}


class Threshold(MaterialFunction):
    """``below`` where the scalar source is below ``level``, else ``above``."""

    kind = "threshold"

    def __init__(self, source: Any, level: float, below: MaterialLike, above: MaterialLike):
        self.source, self.level, self.below, self.above = source, level, below, above

    def _fields(self) -> dict:
        return {"source": self.source, "level": self.level, "below": self.below, "above": self.above}


class Select(MaterialFunction):
    """The material of the first region whose box (normalised parameters) holds the sample:
    ``regions`` is a list of ``(lo, hi, material)`` (or the scene file's dicts)."""

    kind = "select"

    def __init__(self, regions: Sequence[Any], otherwise: MaterialLike):
        self.regions = [
            dict(r) if isinstance(r, Mapping) else {"box": {"lo": list(r[0]), "hi": list(r[1])}, "material": r[2]}
            for r in regions
        ]
        self.otherwise = otherwise

    def _fields(self) -> dict:
        return {"regions": self.regions, "otherwise": self.otherwise}


class VoidMask(MaterialFunction):
    """``material`` times (1 - t), t the scalar source ``void`` clamped to [0, 1]: porosity."""

    kind = "void_mask"

    def __init__(self, material: MaterialLike, void: Any):
        self.material, self.void = material, void

    def _fields(self) -> dict:
        return {"void": self.void, "material": self.material}


class Function:
    """A material computed by Python: ``f(u, v, w, x, y, z)`` receives whole rows of samples
    as float64 arrays (u, v, w the cell's parameters normalised to [0, 1], x, y, z in mm)
    and returns the fractions of the scene's materials in their order: an (n, m) array, or a
    sequence of m arrays of n values (or numbers). The library calls it once per row of
    voxels, holding the GIL only for that call, from the job's worker threads. A scene that
    holds one cannot be written to a scene file."""

    def __init__(self, fn: Callable[..., Any]):
        if not callable(fn):
            raise TypeError("Function needs a callable f(u, v, w, x, y, z)")
        self.fn = fn

    def __call__(self, *args: Any) -> Any:
        return self.fn(*args)

    def __repr__(self) -> str:
        return f"trivox.Function({self.fn!r})"
