#!/usr/bin/env python3
"""A cell whose material is a numpy function: a gyroid lattice graded by a stress field.

    python3 examples/python/numpy_material.py [--out out/numpy_material] [--layer 600]

The bundled twisted column (examples/models/twisted_column.itd) as a cantilever fixed at
z = 0 and pushed sideways at its top: the bending stress grows towards the base and towards
the faces x = min and x = max. The material is a gyroid lattice whose walls thicken with the
stress, cyan where the stress is low turning magenta where it is high, void between the walls.
Any procedural material or a field sampled from an analysis result can be written this way:
trivox calls the function once per row of voxels with numpy arrays (u, v, w normalised to
[0, 1], x, y, z in mm), never per voxel.
"""
import argparse
import os
import time

import numpy as np

import trivox

HERE = os.path.dirname(os.path.abspath(__file__))
COLUMN = os.path.join(HERE, "..", "models", "twisted_column.itd")

PERIOD_MM = 6.0  # the gyroid's cell size


def stress(x, y, z):
    """A bending stress of the cantilever, normalised to [0, 1]: the moment grows linearly
    towards the fixed base, the stress with the distance from the neutral plane x = 22 mm."""
    moment = np.clip(1.0 - z / 60.0, 0.0, 1.0)
    return moment * np.clip(np.abs(x - 22.0) / 25.0, 0.0, 1.0)


def lattice(u, v, w, x, y, z):
    """Fractions of VeroCyan and VeroMagenta for whole rows of samples."""
    k = 2.0 * np.pi / PERIOD_MM
    g = np.sin(k * x) * np.cos(k * y) + np.sin(k * y) * np.cos(k * z) + np.sin(k * z) * np.cos(k * x)
    s = stress(x, y, z)
    solid = (np.abs(g) < 0.25 + 0.9 * s).astype(np.float64)  # walls from 0.25 to 1.15 thick
    return np.stack([solid * (1.0 - s), solid * s], axis=1)


def scene():
    column = trivox.read(COLUMN).volumes()[0]
    return trivox.Scene(printer="j750-hm", materials=["VeroCyan", "VeroMagenta"],
                        cells=[trivox.Cell(lattice, geometry=column, name="lattice column")])


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--out", default="out/numpy_material", help="output folder")
    parser.add_argument("--layer", type=int, default=600, help="layer to slice (0-based)")
    args = parser.parse_args()

    s = scene()
    slicer = trivox.Slicer(s)
    start = time.perf_counter()
    layer = slicer.slice_layer(args.layer, fractions=True)
    seconds = time.perf_counter() - start
    inside = int(layer.inside.sum())
    solid = np.bincount(layer.labels.ravel(), minlength=3)
    print(f"layer {args.layer} (z = {slicer.layout.z_of_layer(args.layer):.3f} mm): {inside} voxels inside, "
          f"{solid[1]} cyan, {solid[2]} magenta, {inside - solid[1] - solid[2]} void; {seconds:.2f} s")
    print(f"mean solid fraction inside: {layer.fractions.sum(axis=2)[layer.inside > 0].mean():.3f}")
    colours = np.array([[255, 255, 255, 255]] + [m["rgba"] for m in s.materials], dtype=np.uint8)
    os.makedirs(args.out, exist_ok=True)
    path = os.path.join(args.out, f"layer_{args.layer:05d}.png")
    trivox.write_png(path, colours[layer.labels])
    print(f"wrote {path}")


if __name__ == "__main__":
    main()
