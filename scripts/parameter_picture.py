#!/usr/bin/env python3
"""A picture of how a volume's parameters u, v, w run: its boundary as a wireframe of
iso-parameter curves, each coloured by the parameter that varies along it (u red, v green,
w blue), and at the corner (0, 0, 0) (a black dot) an arrow along each of its three edges,
labelled.

  scripts/parameter_picture.py MODEL.itd -o picture.svg [--view AZIMUTH,ELEVATION] [--trivox PATH]

MODEL is a model file with the volume as patch 0 (for a constructor: `trivox build SPEC -o
MODEL.itd`). The volume is evaluated with `trivox probe --eval`, so the picture shows what
trivox computes; it is drawn in a parallel projection seen from AZIMUTH degrees around z
(from +x towards +y) and ELEVATION degrees above the xy plane (default -60,30). Writes a
small SVG. Standard library only.
"""
import argparse
import json
import math
import subprocess
import sys

COLOURS = ("#d62728", "#2ca02c", "#1f77b4")  # u, v, w
NAMES = ("u", "v", "w")
SAMPLES = 24  # points per curve
ARROW = 9  # of them in the arrows from the corner (0, 0, 0)
ISO = (0.25, 0.5, 0.75)  # interior iso-lines on each face


def domain(trivox, model):
    info = json.loads(subprocess.run([trivox, "info", "--json", model], check=True, capture_output=True,
                                     text=True).stdout)
    return info["patches"][0]["domain"]


def evaluate(trivox, model, params):
    text = "\n".join(f"{u!r} {v!r} {w!r}" for u, v, w in params) + "\n"
    out = subprocess.run([trivox, "probe", "--eval", "--patch", "0", model], input=text, check=True,
                         capture_output=True, text=True).stdout
    return [json.loads(line)["position"] for line in out.splitlines() if line.strip()]


def curves(dom):
    """Each curve: (direction, list of parameter triples). Edges first, then iso-lines."""
    lo = [d[0] for d in dom]
    hi = [d[1] for d in dom]
    at = lambda d, t: lo[d] + t * (hi[d] - lo[d])
    out = []
    for d in range(3):
        a, b = [k for k in range(3) if k != d]
        fixed = [(ta, tb) for ta in (0.0, 1.0) for tb in (0.0, 1.0)]  # the four edges along d
        fixed += [(t, s) for t in ISO for s in (0.0, 1.0)] + [(s, t) for t in ISO for s in (0.0, 1.0)]
        for ta, tb in fixed:
            pts = []
            for i in range(SAMPLES + 1):
                p = [0.0, 0.0, 0.0]
                p[d] = at(d, i / SAMPLES)
                p[a] = at(a, ta)
                p[b] = at(b, tb)
                pts.append(tuple(p))
            edge = ta in (0.0, 1.0) and tb in (0.0, 1.0)
            out.append((d, edge, ta == 0.0 and tb == 0.0, pts))
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("model")
    ap.add_argument("-o", "--output", required=True)
    ap.add_argument("--view", default="-60,30")
    ap.add_argument("--trivox", default="build/release/bin/trivox")
    ap.add_argument("--size", type=int, default=300, help="the picture's larger side in pixels")
    a = ap.parse_args()
    az, el = (math.radians(float(v)) for v in a.view.split(","))
    dom = domain(a.trivox, a.model)
    cs = curves(dom)
    flat = [p for _, _, _, pts in cs for p in pts]
    positions = evaluate(a.trivox, a.model, flat)
    if len(positions) != len(flat):
        sys.exit("probe did not evaluate every point")
    # Parallel projection: screen x along the horizontal direction of the view, screen y up.
    right = (-math.sin(az), math.cos(az), 0.0)
    up = (-math.sin(el) * math.cos(az), -math.sin(el) * math.sin(az), math.cos(el))
    proj = [(sum(p[i] * right[i] for i in range(3)), sum(p[i] * up[i] for i in range(3))) for p in positions]
    xs = [p[0] for p in proj]
    ys = [p[1] for p in proj]
    margin = 28
    span = max(max(xs) - min(xs), max(ys) - min(ys)) or 1.0
    scale = (a.size - 2 * margin) / span
    width = int((max(xs) - min(xs)) * scale + 2 * margin)
    height = int((max(ys) - min(ys)) * scale + 2 * margin)
    to_svg = lambda p: ((p[0] - min(xs)) * scale + margin, (max(ys) - p[1]) * scale + margin)
    svg = [f'<svg xmlns="http://www.w3.org/2000/svg" width="{width}" height="{height}" '
           f'viewBox="0 0 {width} {height}" font-family="sans-serif" font-size="14">',
           '<rect width="100%" height="100%" fill="white"/>',
           '<defs>' + "".join(
               f'<marker id="arrow{d}" viewBox="0 0 10 10" refX="9" refY="5" markerWidth="7" markerHeight="7" '
               f'orient="auto-start-reverse"><path d="M 0 0 L 10 5 L 0 10 z" fill="{COLOURS[d]}"/></marker>'
               for d in range(3)) + '</defs>']
    at = 0
    labels = []
    for d, edge, from_origin, pts in cs:
        screen = [to_svg(p) for p in proj[at:at + len(pts)]]
        at += len(pts)
        path = " ".join(f"{x:.0f},{y:.0f}" for x, y in screen)
        width_px = 1.2 if edge else 0.6
        opacity = "" if edge else ' stroke-opacity="0.55"'
        svg.append(f'<polyline points="{path}" fill="none" stroke="{COLOURS[d]}" stroke-width="{width_px}"'
                   f'{opacity}/>')
        if from_origin:
            # The direction at the corner (0, 0, 0): an arrow over the first part of the edge.
            head = screen[:ARROW + 1]
            arrow = " ".join(f"{x:.0f},{y:.0f}" for x, y in head)
            svg.append(f'<polyline points="{arrow}" fill="none" stroke="{COLOURS[d]}" stroke-width="3"'
                       f' marker-end="url(#arrow{d})"/>')
            x1, y1 = head[-1]
            dx, dy = x1 - head[-2][0], y1 - head[-2][1]
            n = math.hypot(dx, dy) or 1.0
            labels.append((x1 + 14 * dx / n - 4, y1 + 14 * dy / n + 5, NAMES[d], COLOURS[d]))
            origin = screen[0]
    svg.append(f'<circle cx="{origin[0]:.1f}" cy="{origin[1]:.1f}" r="3.5" fill="black"/>')
    for x, y, text, colour in labels:
        svg.append(f'<text x="{x:.1f}" y="{y:.1f}" fill="{colour}" font-weight="bold">{text}</text>')
    svg.append("</svg>")
    with open(a.output, "w") as f:
        f.write("\n".join(svg) + "\n")


if __name__ == "__main__":
    main()
