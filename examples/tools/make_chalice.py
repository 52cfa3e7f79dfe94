"""Writes examples/scenes/chalice.json, the paper's chalice built by trivox's constructors.

Run from the repository root: python3 examples/tools/make_chalice.py > examples/scenes/chalice.json
The shapes (profiles, strand paths) are designed here at 36 mm height and scaled by S.
"""
import json
import math

h = math.sqrt(2)/2
S = 0.75  # the whole chalice scaled from a 36 mm design to 27 mm
def r(x, n=6): return round(x, n)

def disc_section(rad):
    a = [-1, 0, 1]; wa = [1, h, 1]
    pts, w = [], []
    for j in range(3):
        for i in range(3):
            s = rad*h if (i != 1 and j != 1) else rad*math.sqrt(2)
            if i == 1 and j == 1: s = 0
            pts.append([r(s*a[i], 12), r(s*a[j], 12), 0])
            w.append(0.5 if (i == 1 and j == 1) else wa[i] * wa[j])
    return {"orders": [3, 3], "knots": [[0,0,0,1,1,1],[0,0,0,1,1,1]], "points": pts, "weights": w}

def strand_path(phase, rho, z0, H, turns, n=16):
    order = 4
    kv = [0]*order + [k/(n-order+1) for k in range(1, n-order+1)] + [1]*order
    gre = [sum(kv[i+1:i+order])/(order-1) for i in range(n)]
    def c(t):
        phi = phase + 2*math.pi*turns*(t - math.sin(2*math.pi*t)/(2*math.pi))
        return [rho*math.cos(phi), rho*math.sin(phi), z0 + H*t]
    pts = [c(t) for t in gre]
    # A torus-knot-like strand: it turns `turns` times around the axis at radius rho, slowest at
    # its ends (phi' = 0 there), sampled at the Greville abscissae of a cubic B-spline.
    # Vertical end tangents: the second and the second-last points straight above/below the ends.
    pts[1] = [pts[0][0], pts[0][1], pts[1][2]]
    pts[-2] = [pts[-1][0], pts[-1][1], pts[-2][2]]
    return {"orders": [order], "knots": [[r(k, 12) for k in kv]], "points": [[r(x) for x in p] for p in pts]}

def profile(outer, inner, order):
    n = len(outer)
    spans = n - order + 1
    kv = [0]*order + [r(k/spans, 12) for k in range(1, spans)] + [1]*order
    pts = []
    for j in range(n):
        pts.append([r(S*outer[j][0]), 0, r(S*outer[j][1])])
        pts.append([r(S*inner[j][0]), 0, r(S*inner[j][1])])
    return {"orders": [2, order], "knots": [[0,0,1,1], kv], "points": pts}

def base_profile():
    # u: bottom (z = 0) to top; v: from the axis outwards. Top flat at z = 4 out to r = 6.
    top = [(0, 4), (4, 4), (8, 4), (14, 1.5)]
    bottom = [(0, 0), (4, 0), (8, 0), (14, 0)]
    kv = [0,0,0,0.5,1,1,1]
    pts = []
    for j in range(4):
        pts.append([r(S*bottom[j][0]), 0, r(S*bottom[j][1])])
        pts.append([r(S*top[j][0]), 0, r(S*top[j][1])])
    return {"orders": [2, 3], "knots": [[0,0,1,1], kv], "points": pts}

outer = [(0, 16), (4, 16), (8, 16), (13, 19), (15, 26), (15.5, 36)]
inner = [(0, 18), (4, 18), (7.5, 18.2), (11.5, 21), (13.5, 27), (14, 36)]

colours = ["VeroCyan", "VeroMagenta", "VeroYellow"]
def cup_material(rad, shift, v):
    return {"kind": "twisting_curves",
            "points": [{"uv": [r(k/3, 6), v], "material": colours[k]} for k in range(3)],
            "radius": rad, "shift_per_w": [shift, 0], "wrap": ["u"], "background": "VeroClear"}

strand_material = {"kind": "twisting_curves",
  "points": [{"uv": [r(0.5 + 0.27*math.cos(2*math.pi*k/3), 6), r(0.5 + 0.27*math.sin(2*math.pi*k/3), 6)], "material": colours[k]} for k in range(3)],
  "radius": 0.11, "turns_per_w": 1.5, "background": "VeroClear"}

cells = [
  {"name": "base", "geometry": {"revolve": {"profile": base_profile(), "axis_point_mm": [0,0,0], "axis_dir": [0,0,1], "angle_deg": 360, "angle_param": "w"}},
   "material": {"kind": "twisting_curves", "points": [{"uv": [r(0.5 + 0.3*math.cos(2*math.pi*k/3), 6), r(0.5 + 0.3*math.sin(2*math.pi*k/3), 6)], "material": colours[k]} for k in range(3)],
                "radius": 0.09, "turns_per_w": 1, "background": "VeroClear"}},
]
for k in range(3):
    cells.append({"name": f"knot strand {k+1}", "geometry": {"sweep": {"section": disc_section(S*1.2),
        "path": strand_path(2*math.pi*k/3, S*3.0, S*4.0, S*12.0, 1.0), "stations": 33}},
        "material": strand_material})
cells.append({"name": "cup", "geometry": {"revolve": {"profile": profile(outer, inner, 3), "angle_param": "u"}},
   "material": cup_material(0.045, 0.5, 0.5)})

scene = {"$schema": "../../docs/scene.schema.json", "version": 1,
  "description": "The paper's chalice (Figure 1), built inside trivox: a base and a cup by revolution of profile surfaces about the z axis, and a stem knotted of three strands, each a disc of radius 0.9 mm swept along a torus-knot-like curve that turns once around the axis. Five cells, in clear material with coloured curves twisting through every cell (parametric domain). 27 mm tall, 23 mm wide. The parts are stacked so that no Boolean trimming is needed: the strands end in flat discs that touch the base's flat top at z = 3 mm and the cup's flat bottom at z = 12 mm, and do not meet each other.",
  "units": "mm", "printer": "j750-paper",
  "materials": [{"name": "VeroClear", "rgba": [235, 240, 242, 40]}, {"name": "VeroCyan", "rgba": [0, 160, 227, 255]},
                {"name": "VeroMagenta", "rgba": [236, 0, 140, 255]}, {"name": "VeroYellow", "rgba": [255, 237, 0, 255]}],
  "cells": cells}

def dump(o, ind=0):
    # Compact arrays of numbers on one line; objects spread out.
    sp = "  "*ind
    if isinstance(o, dict):
        items = [f'{sp}  {json.dumps(k)}: {dump(v, ind+1)}' for k, v in o.items()]
        return "{\n" + ",\n".join(items) + "\n" + sp + "}"
    if isinstance(o, list):
        if all(not isinstance(x, (dict,)) for x in o):
            return json.dumps(o)
        return "[\n" + ",\n".join(sp + "  " + dump(x, ind+1) for x in o) + "\n" + sp + "]"
    return json.dumps(o)
print(dump(scene))
