#!/usr/bin/env python3
"""The paper's chalice built in Python: the same three volumes and five Boolean cells as
examples/scenes/chalice.json, from the same data (examples/tools/make_chalice.py), made by
trivox's constructors called from Python instead of by the scene reader.

    python3 examples/python/chalice.py [--out out/chalice_py] [--layers 240:259]

Builds the base and the cup by revolution and the knot by a sweep, prints each construction's
report, makes the scene (the union of the three split into Boolean cells, each with coloured
curves twisting through it), writes it as a scene file (OUT/chalice.json, which `trivox slice`
reads) and slices the layers asked for (0-based FIRST:LAST, inclusive) into OUT, as
`trivox slice` would.
"""
import argparse
import os
import sys

import trivox

sys.path.insert(0, os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "tools"))
import make_chalice as mc  # noqa: E402 - the chalice's geometry and materials, as numbers


def spline(d):
    """A trivox.Spline from the scene file's inline form."""
    return trivox.Spline(d["orders"], d["knots"], d["points"], d.get("weights"))


def curves(points, **kw):
    return trivox.TwistingCurves([(p["uv"], p["material"]) for p in points], **kw)


def chalice_scene(verbose=False):
    """The chalice as a trivox.Scene, its volumes built in Python."""
    base = trivox.revolve(spline(mc.profile(mc.base_bottom, mc.base_top, 3)),
                          axis_point_mm=(0, 0, 0), axis_dir=(0, 0, 1), angle_deg=360, angle_param="w")
    knot = trivox.sweep(spline(mc.disc_section(mc.KNOT_DISC)), spline(mc.knot_path()),
                        stations=mc.KNOT_STATIONS, jacobian_samples=65)
    cup = trivox.revolve(spline(mc.profile(mc.cup_outer, mc.cup_inner, 3)), angle_param="u")
    if verbose:
        for name, built in (("base", base), ("knot", knot), ("cup", cup)):
            r = built.report
            extra = "" if r.exact else f", within {r.approximation_error_mm:.2g} mm of the ideal sweep"
            print(f"{name}: {built.volume}: {r.describe()}{extra}")

    knot_curves = dict(radius=0.11, turns_per_w=3, background="VeroClear")
    regions = [
        trivox.Region(["base"], curves(mc.ring(0.3, [0, 1, 2]), radius=0.09, turns_per_w=1, background="VeroClear")),
        trivox.Region(["knot"], curves(mc.ring(0.27, [0, 1, 2]), **knot_curves)),
        trivox.Region(["cup"], curves([{"uv": [mc.r(k / 3, 6), 0.5], "material": mc.colours[k]} for k in range(3)],
                                      radius=0.045, shift_per_w=(0.5, 0), wrap=["u"], background="VeroClear")),
        trivox.Region(["base", "knot"], curves(mc.ring(0.27, [1, 2, 0]), **knot_curves), parametrize="knot",
                      name="knot in base"),
        trivox.Region(["knot", "cup"], curves(mc.ring(0.27, [2, 0, 1]), **knot_curves), parametrize="knot",
                      name="knot in cup"),
        trivox.Region(["base", "cup"], "void"),
        trivox.Region(["base", "knot", "cup"], "void"),
    ]
    return trivox.Scene(
        printer="j750-hm",
        materials=[trivox.MaterialDef("VeroClear", (235, 240, 242, 40)), trivox.MaterialDef("VeroCyan", (0, 160, 227, 255)),
                   trivox.MaterialDef("VeroMagenta", (236, 0, 140, 255)), trivox.MaterialDef("VeroYellow", (255, 237, 0, 255))],
        volumes={"base": base.volume, "knot": knot.volume, "cup": cup.volume},
        unions=[trivox.Union("chalice", ["base", "knot", "cup"], regions)],
        description="The paper's chalice, built in Python (examples/python/chalice.py).",
    )


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out/chalice_py", help="output folder")
    parser.add_argument("--layers", default="240:259", help="0-based FIRST:LAST layers to slice (inclusive)")
    args = parser.parse_args()

    scene = chalice_scene(verbose=True)
    cells = ", ".join(c.name for c in scene.cells)
    print(f"{scene}: cells {cells}")
    os.makedirs(args.out, exist_ok=True)
    scene.save(os.path.join(args.out, "chalice.json"))
    first, last = (int(x) for x in args.layers.split(":"))
    result = trivox.slice(scene, args.out, layers=range(first, last + 1), min_layers=0,
                          progress=lambda done, total: print(f"\rsliced {done}/{total} layers", end="", flush=True))
    inside = sum(layer["pixels_inside"] for layer in result.layers)
    print(f"\n{len(result.layers)} layers in {result.seconds:.2f} s, {inside} voxels inside; "
          f"scene file and images in {args.out}")


if __name__ == "__main__":
    main()
