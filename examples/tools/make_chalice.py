"""Writes examples/scenes/chalice.json, the paper's chalice (Figure 1) built by trivox's constructors.

Run from the repository root: python3 examples/tools/make_chalice.py > examples/scenes/chalice.json

Three trivariates, as in the paper: the base and the cup revolve profile surfaces about the z
axis (exact, rational), and the knot sweeps a disc along a segment of a trefoil (a (2, 3)
torus knot around the z axis). The knot reaches into the base at its three lowest loops and
into the cup's bottom at its three highest, so the scene declares the three as named volumes
and splits their union into Boolean cells: base only, knot only, cup only, knot and base,
knot and cup. The cup and the base never meet, so the regions "base and cup" and "all three"
are empty and declared void. All lengths are in mm.
"""
import json
import math

h = math.sqrt(2) / 2
def r(x, n=6): return round(x, n)

# --- the base and the cup: profiles in the plane y = 0 (x is the radius), revolved about z.

def profile(first, second, order):
    """A ruled profile surface: u from the polyline `first` to `second`, v along them, each a
    clamped B-spline of the given order with these control points."""
    n = len(first)
    spans = n - order + 1
    kv = [0] * order + [r(k / spans, 12) for k in range(1, spans)] + [1] * order
    pts = []
    for j in range(n):
        pts.append([r(first[j][0]), 0, r(first[j][1])])
        pts.append([r(second[j][0]), 0, r(second[j][1])])
    return {"orders": [2, order], "knots": [[0, 0, 1, 1], kv], "points": pts}

# Base: 3 mm thick and flat on top out to a radius of 4.5 mm, thinning to 1.125 mm at its
# rim (radius 10.5 mm). u: bottom to top, v: from the axis outwards, w: around.
BASE_TOP = 3.0
base_bottom = [(0, 0), (3, 0), (6, 0), (10.5, 0)]
base_top = [(0, BASE_TOP), (3, BASE_TOP), (6, BASE_TOP), (10.5, 1.125)]

# Cup: its outer bottom flat at z = 11.5 out to a radius of 4.5 mm, 3 mm thick at the axis
# (room for the knot's ends), the wall rising to the rim at z = 27. u: around, v: from the
# outside in, w: from the axis up the wall to the rim.
CUP_BOTTOM = 11.5
cup_outer = [(0, CUP_BOTTOM), (3, CUP_BOTTOM), (6, CUP_BOTTOM), (9.5, 13.5), (11.25, 19.5), (11.6, 27)]
cup_inner = [(0, 14.5), (3, 14.5), (6, 14.6), (8.7, 16.4), (10.15, 20.6), (10.5, 27)]

# --- the knot: a disc swept along a segment of the trefoil (2, 3) torus knot around z.

KNOT_RADIUS = 3.3     # the torus: distance of its core circle from the axis
KNOT_WOBBLE = 1.5     # the torus' tube radius (radial swing of the curve)
KNOT_DISC = 0.9       # radius of the swept disc
# The curve's highest and lowest centres; the B-spline through its samples (knot_path) peaks
# about 0.1 mm short of them, so each loop reaches about 1.1 mm into the cup or the base.
KNOT_PEAK = CUP_BOTTOM + 0.3
KNOT_VALLEY = BASE_TOP - 0.3
KNOT_END_DEPTH = 1.0  # the two ends sink this much deeper, so their end discs are buried
KNOT_CONTROL_POINTS = 48
KNOT_STATIONS = 129

def smoothstep(x):
    x = min(max(x, 0.0), 1.0)
    return x * x * (3 - 2 * x)

def knot_point(s):
    """The knot's centre curve at s in [0, 1]: the torus knot
    ((R + a cos 3t) cos 2t, (R + a cos 3t) sin 2t, zc + hz sin 3t) for 3t from -pi/2 (a
    lowest point, in the base) to 9pi/2 (a highest point, in the cup): five sixths of the
    closed knot, turning 5/3 times around the axis through three lowest and three highest
    loops. Over its first and last fifth (before its first highest loop, after its last
    lowest one) it sinks smoothly a further KNOT_END_DEPTH into the base and the cup, so its
    end discs lie inside them."""
    a = -math.pi / 2 + 5 * math.pi * s
    t = a / 3
    zc, hz = (KNOT_PEAK + KNOT_VALLEY) / 2, (KNOT_PEAK - KNOT_VALLEY) / 2
    radius = KNOT_RADIUS + KNOT_WOBBLE * math.cos(a)
    ends = KNOT_END_DEPTH * (smoothstep((s - 0.8) / 0.2) - smoothstep((0.2 - s) / 0.2))
    return [radius * math.cos(2 * t), radius * math.sin(2 * t), zc + hz * math.sin(a) + ends]

def knot_path(n=KNOT_CONTROL_POINTS, order=4):
    """A cubic B-spline whose control points are the curve at the Greville abscissae of its
    uniform knot vector (a smooth approximation, checked by the scene's reader and tests)."""
    kv = [0] * order + [k / (n - order + 1) for k in range(1, n - order + 1)] + [1] * order
    greville = [sum(kv[i + 1:i + order]) / (order - 1) for i in range(n)]
    return {"orders": [order], "knots": [[r(k, 12) for k in kv]],
            "points": [[r(x) for x in knot_point(g)] for g in greville]}

def disc_section(rad):
    """An exact disc: a biquadratic rational patch whose four edges are quarter circles."""
    a = [-1, 0, 1]; wa = [1, h, 1]
    pts, w = [], []
    for j in range(3):
        for i in range(3):
            s = rad * h if (i != 1 and j != 1) else rad * math.sqrt(2)
            if i == 1 and j == 1: s = 0
            pts.append([r(s * a[i], 12), r(s * a[j], 12), 0])
            w.append(0.5 if (i == 1 and j == 1) else wa[i] * wa[j])
    return {"orders": [3, 3], "knots": [[0, 0, 0, 1, 1, 1], [0, 0, 0, 1, 1, 1]], "points": pts, "weights": w}

# --- materials: clear, with coloured curves twisting through every cell's parameters.

colours = ["VeroCyan", "VeroMagenta", "VeroYellow"]

def ring(radius, order):
    return [{"uv": [r(0.5 + radius * math.cos(2 * math.pi * k / 3), 6), r(0.5 + radius * math.sin(2 * math.pi * k / 3), 6)],
             "material": colours[order[k]]} for k in range(3)]

base_material = {"kind": "twisting_curves", "points": ring(0.3, [0, 1, 2]), "radius": 0.09, "turns_per_w": 1,
                 "background": "VeroClear"}
# Three curves along the knot (w), turning three times about its centre line over its 63 mm; in
# the parts of the knot inside the base and the cup the same curves (in the knot's parameters)
# take other colours, so each of the five cells has its own material function.
knot_curves = {"radius": 0.11, "turns_per_w": 3, "background": "VeroClear"}
knot_material = {"kind": "twisting_curves", "points": ring(0.27, [0, 1, 2]), **knot_curves}
knot_in_base_material = {"kind": "twisting_curves", "points": ring(0.27, [1, 2, 0]), **knot_curves}
knot_in_cup_material = {"kind": "twisting_curves", "points": ring(0.27, [2, 0, 1]), **knot_curves}
cup_material = {"kind": "twisting_curves",
                "points": [{"uv": [r(k / 3, 6), 0.5], "material": colours[k]} for k in range(3)],
                "radius": 0.045, "shift_per_w": [0.5, 0], "wrap": ["u"], "background": "VeroClear"}

volumes = [
    {"name": "base", "geometry": {"revolve": {"profile": profile(base_bottom, base_top, 3), "axis_point_mm": [0, 0, 0],
                                              "axis_dir": [0, 0, 1], "angle_deg": 360, "angle_param": "w"}}},
    {"name": "knot", "geometry": {"sweep": {"section": disc_section(KNOT_DISC), "path": knot_path(),
                                            "stations": KNOT_STATIONS, "jacobian_samples": 65}}},
    {"name": "cup", "geometry": {"revolve": {"profile": profile(cup_outer, cup_inner, 3), "angle_param": "u"}}},
]

unions = [{
    "name": "chalice",
    "volumes": ["base", "knot", "cup"],
    "regions": [
        {"of": ["base"], "material": base_material},
        {"of": ["knot"], "material": knot_material},
        {"of": ["cup"], "material": cup_material},
        {"of": ["base", "knot"], "parametrize": "knot", "name": "knot in base", "material": knot_in_base_material},
        {"of": ["knot", "cup"], "parametrize": "knot", "name": "knot in cup", "material": knot_in_cup_material},
        {"of": ["base", "cup"], "material": "void"},
        {"of": ["base", "knot", "cup"], "material": "void"},
    ]}]

scene = {"$schema": "../../docs/scene.schema.json", "version": 1,
  "description": ("The paper's chalice (Figure 1), built inside trivox from three trivariates: a base and a cup by "
                  "revolution of profile surfaces about the z axis (exact, rational), and a knot, a disc of radius "
                  "0.9 mm swept along five sixths of a trefoil ((2, 3) torus knot) that winds around the axis. The "
                  "knot's lowest loops reach into the base and its highest into the cup's bottom, so the three are "
                  "named volumes and their union is split into five Boolean cells that print: base only, knot only, "
                  "cup only, knot in base and knot in cup (the last two parametrized by the knot); the base and the "
                  "cup never meet, so the regions of both and of all three are empty (void). Clear material with "
                  "coloured curves twisting through every cell's parametric domain. 27 mm tall, 23 mm wide "
                  "(examples/tools/make_chalice.py writes this file)."),
  "units": "mm", "printer": "j750-hm",
  "materials": [{"name": "VeroClear", "rgba": [235, 240, 242, 40]}, {"name": "VeroCyan", "rgba": [0, 160, 227, 255]},
                {"name": "VeroMagenta", "rgba": [236, 0, 140, 255]}, {"name": "VeroYellow", "rgba": [255, 237, 0, 255]}],
  "volumes": volumes,
  "unions": unions}

def dump(o, ind=0):
    # Compact arrays of numbers on one line; objects spread out.
    sp = "  " * ind
    if isinstance(o, dict):
        items = [f'{sp}  {json.dumps(k)}: {dump(v, ind + 1)}' for k, v in o.items()]
        return "{\n" + ",\n".join(items) + "\n" + sp + "}"
    if isinstance(o, list):
        if all(not isinstance(x, (dict,)) for x in o):
            return json.dumps(o)
        return "[\n" + ",\n".join(sp + "  " + dump(x, ind + 1) for x in o) + "\n" + sp + "]"
    return json.dumps(o)

if __name__ == "__main__":
    print(dump(scene))
