#!/usr/bin/env python3
"""The Python API's cost against the C++ library it binds (docs/PERFORMANCE.md, "Python API").

    PYTHONPATH=build/release/python python3 bench/python/api_bench.py [--points 1000000] [--runs 5]
        [--baseline build/release/bench/trivox_python_baseline] [--model FILE] [--layers 24]

Measures, side by side in one run, each figure the median of --runs repetitions with the
Python and the C++ repetitions alternating (so that both see the same load):

1. points per second of vol.evaluate, vol.jacobian and vol.invert (Newton from the domain's
   centre) on --points random points, against the C++ bulk calls on the same points
   (trivox_python_baseline: Volume::evaluate_many, evaluate_jacobian_many, invert() point by
   point, in the chunks the module uses), on one thread and on every core;
2. the cost of one call on small arrays (1 to 1000 points), against the C++ time of the same
   points, which gives the per-call overhead;
3. two Python threads inverting half the points each at once, against one after the other
   (threads=1 each): what releasing the GIL gives;
4. a slicing job whose cell has a Python (numpy) material against the same job with the equal
   expression material (--layers layers of the bundled twisted column, files written).

The model is the bundled twisted column (cubic, 6 x 6 x 6 control points) unless --model
names another file (its first trivariate).
"""
import argparse
import json
import os
import pathlib
import statistics
import subprocess
import tempfile
import threading
import time

import numpy as np

import trivox

ROOT = pathlib.Path(__file__).resolve().parents[2]


def median_time(call, runs):
    times = []
    for _ in range(runs):
        start = time.perf_counter()
        call()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def cpp_time(baseline, model, mode, threads, points_file):
    out = subprocess.run([baseline, str(model), "0", mode, str(threads), "1", str(points_file)], check=True,
                         capture_output=True, text=True).stdout
    return json.loads(out)["seconds"][0]


def bulk(args, vol, params, points, points_file, params_file):
    rows = []
    hint = vol.domain.mean(axis=1)
    for mode, py_call, data_file in (
        ("evaluate", lambda t: vol.evaluate(params, threads=t), params_file),
        ("jacobian", lambda t: vol.jacobian(params, threads=t), params_file),
        ("invert", lambda t: vol.invert(points, hint, threads=t), points_file),
    ):
        for threads in (1, 0):
            py, cpp = [], []
            for _ in range(args.runs):
                cpp.append(cpp_time(args.baseline, args.model, mode, threads, data_file))
                start = time.perf_counter()
                py_call(threads)
                py.append(time.perf_counter() - start)
            n = len(params)
            p, c = statistics.median(py), statistics.median(cpp)
            rows.append((mode, threads, n / p, n / c, c / p))
    return rows


def per_call(args, vol, params, cpp_rate):
    rows = []
    for n in (1, 10, 100, 1000):
        batch = params[:n]
        calls = max(200, 200000 // n)

        def loop():
            for _ in range(calls):
                vol.evaluate(batch)

        t = median_time(loop, args.runs) / calls
        rows.append((n, t * 1e6, n / cpp_rate * 1e6, (t - n / cpp_rate) * 1e6))
    return rows


def gil(args, vol, points):
    half = len(points) // 2
    a, b = points[:half], points[half:2 * half]
    hint = vol.domain.mean(axis=1)

    def sequential():
        vol.invert(a, hint, threads=1)
        vol.invert(b, hint, threads=1)

    def concurrent():
        t = threading.Thread(target=lambda: vol.invert(b, hint, threads=1))
        t.start()
        vol.invert(a, hint, threads=1)
        t.join()

    seq, con = [], []
    for _ in range(args.runs):
        seq.append(median_time(sequential, 1))
        con.append(median_time(concurrent, 1))
    return statistics.median(seq), statistics.median(con)


def material_job(args):
    column = trivox.read(str(ROOT / "examples" / "models" / "twisted_column.itd")).volumes()[0]
    expression = trivox.Expression({"VeroCyan": "1 - w", "VeroMagenta": "0.5 * w", "VeroYellow": "0.25 * u * v * w"})

    def numpy_material(u, v, w, x, y, z):
        return np.stack([1 - w, 0.5 * w, 0.25 * u * v * w], axis=1)

    def scene(material):
        return trivox.Scene(printer="j750-paper", materials=["VeroCyan", "VeroMagenta", "VeroYellow"],
                            cells=[trivox.Cell(material, geometry=column)])

    slicers = {"expression": trivox.Slicer(scene(expression)), "python": trivox.Slicer(scene(numpy_material))}
    first = slicers["expression"].layout.num_layers // 2
    layers = range(first, first + args.layers)
    rows = []
    for threads in (1, 0):
        results = {name: [] for name in slicers}
        for _ in range(args.runs):
            for name, slicer in slicers.items():
                with tempfile.TemporaryDirectory() as out:
                    r = trivox.slice(slicer, out, layers=layers, min_layers=0, threads=threads)
                results[name].append((r.seconds, sum(layer["seconds_material"] for layer in r.layers), r.threads))
        e = [statistics.median(x[i] for x in results["expression"]) for i in (0, 1)]
        p = [statistics.median(x[i] for x in results["python"]) for i in (0, 1)]
        rows.append((results["python"][0][2], e[0], p[0], p[0] / e[0], e[1], p[1]))
    return rows


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--points", type=int, default=1000000)
    parser.add_argument("--runs", type=int, default=5)
    parser.add_argument("--baseline", default=str(ROOT / "build" / "release" / "bench" / "trivox_python_baseline"))
    parser.add_argument("--model", default=str(ROOT / "examples" / "models" / "twisted_column.itd"))
    parser.add_argument("--layers", type=int, default=24)
    args = parser.parse_args()

    vol = trivox.read(args.model).volumes()[0]
    rng = np.random.default_rng(2024)
    lo, hi = vol.domain[:, 0], vol.domain[:, 1]
    params = lo + (hi - lo) * rng.random((args.points, 3))
    points = vol.evaluate(params)
    with tempfile.TemporaryDirectory() as tmp:
        params_file, points_file = pathlib.Path(tmp) / "params.f64", pathlib.Path(tmp) / "points.f64"
        params.tofile(params_file)
        points.tofile(points_file)
        print(f"model {os.path.relpath(args.model, ROOT)}: {vol}; {args.points} points; median of {args.runs} runs")
        print(f"trivox {trivox.__version__}, {os.cpu_count()} processors\n")
        print("| call | threads | Python points/s | C++ points/s | Python / C++ |")
        print("|---|---|---|---|---|")
        rows = bulk(args, vol, params, points, points_file, params_file)
        for mode, threads, py, cpp, ratio in rows:
            print(f"| {mode} | {threads or 'all'} | {py:.3g} | {cpp:.3g} | {ratio:.2f} |")
    cpp_evaluate_rate = next(r[3] for r in rows if r[0] == "evaluate" and r[1] == 1)
    print("\n| points per call | time per call (us) | C++ time of the points (us) | overhead per call (us) |")
    print("|---|---|---|---|")
    for n, t, c, over in per_call(args, vol, params, cpp_evaluate_rate):
        print(f"| {n} | {t:.2f} | {c:.3f} | {over:.2f} |")
    seq, con = gil(args, vol, points)
    print(f"\ntwo threads inverting {args.points // 2} points each (threads=1): one after the other {seq:.3f} s, "
          f"at once {con:.3f} s, ratio {con / seq:.2f}")
    print(f"\n| job threads | expression job (s) | Python material job (s) | ratio | expression material (s) "
          f"| Python material (s) |")
    print("|---|---|---|---|---|---|")
    for threads, e, p, ratio, em, pm in material_job(args):
        print(f"| {threads} | {e:.3f} | {p:.3f} | {ratio:.2f} | {em:.3f} | {pm:.3f} |")
    print(f"({args.layers} layers of the twisted column, Voxel Print PNGs written; the last two columns: the "
          "layers' material evaluation alone, summed over layers)")


if __name__ == "__main__":
    main()
