#!/usr/bin/env python3
"""Inverting an array of points: (x, y, z) -> (u, v, w), every point at once.

    python3 examples/python/invert_points.py [MODEL] [--patch 0] [--points 100000]

Takes a model's trivariate (default: the bundled twisted column), maps random parameters to
model space, adds points beyond the volume's box, and inverts them all: first with the global
solver (every preimage, or the proof that there is none), then with Newton alone from hints
near the answers, as a tracker that follows a moving point would (certified=False: the default
would fall back to the global solver where Newton does not converge). Both run in C++ on every
core with the GIL released.
"""
import argparse
import os
import time

import numpy as np

import trivox

HERE = os.path.dirname(os.path.abspath(__file__))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("model", nargs="?", default=os.path.join(HERE, "..", "models", "twisted_column.itd"))
    parser.add_argument("--patch", type=int, default=0, help="index among the model's trivariates")
    parser.add_argument("--points", type=int, default=100000)
    args = parser.parse_args()

    vol = trivox.read(args.model).volumes()[args.patch]
    lo, hi = vol.domain[:, 0], vol.domain[:, 1]
    rng = np.random.default_rng(7)
    params = lo + (hi - lo) * rng.random((args.points, 3))
    points = vol.evaluate(params)
    # A tenth more, above the volume's box: they have no preimage.
    box = vol.bounds
    outside = box[1] + (box[1] - box[0]) * (0.05 + rng.random((args.points // 10, 3)))
    everything = np.concatenate([points, outside])
    print(f"{vol}: {len(points)} points inside, {len(outside)} outside")

    start = time.perf_counter()
    g = vol.invert_global(everything)
    seconds = time.perf_counter() - start
    counts = np.bincount(g.status, minlength=len(trivox.GlobalStatus))
    print(f"global solver: {seconds:.2f} s, " + ", ".join(f"{s.name.lower()} {counts[s]}" for s in trivox.GlobalStatus))
    unique = g.status[: len(points)] == trivox.GlobalStatus.UNIQUE
    first = g.uvw[g.offsets[:-1][: len(points)][unique]]
    print(f"  unique points: largest |uvw - original| {np.abs(first - params[unique]).max():.3g}, "
          f"largest residual {g.residual.max():.3g} mm")

    hint = params + 0.01 * (hi - lo) * rng.standard_normal(params.shape)
    start = time.perf_counter()
    n = vol.invert(points, hint, certified=False)
    seconds = time.perf_counter() - start
    converged = n.status == trivox.InverseStatus.CONVERGED
    print(f"Newton from nearby hints: {seconds:.2f} s, {converged.sum()} of {len(points)} converged, "
          f"{n.iterations[converged].mean():.2f} evaluations each, largest residual {n.residual[converged].max():.3g} mm")


if __name__ == "__main__":
    main()
