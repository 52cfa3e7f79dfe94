#!/usr/bin/env python3
"""The Python API's cost against the C++ library it binds (docs/PERFORMANCE.md, "Python API").

    PYTHONPATH=build/release/python python3 bench/python/api_bench.py [--points 1000000] [--runs 5]
        [--baseline build/release/bench/trivox_python_baseline] [--model FILE] [--layers 24]

Measures, side by side in one run, each figure the median of --runs repetitions with the
Python and the C++ repetitions alternating (so that both see the same load):

1. points per second of vol.evaluate, vol.jacobian and vol.invert (Newton from the domain's
   centre) on --points random points, against the C++ bulk calls on the same points
   (trivox_python_baseline: Volume::evaluate_many, evaluate_jacobian_many, invert() point by
   point, in the chunks the module uses, into arrays made before), on one thread and on every
   core; evaluate and jacobian both into new arrays (the default) and into arrays given as
   out=. On one thread the CPU time of the calling thread is given too: it is the work itself,
   whatever else the machine runs;
2. the cost of one call of vol.evaluate on small arrays (1 to 1000 points) against the C++
   call on the same points (CPU time of the thread, many calls per repetition): the
   difference is the per-call overhead;
3. two Python threads inverting half the points each at once, against one after the other
   (threads=1 each): what releasing the GIL gives (wall time); and how fast a pure Python loop
   runs in another thread while one thread inverts, against while it sleeps (held, the GIL
   would stop the loop);
4. a slicing job whose cell has a Python (numpy) material against the same job with the equal
   expression material (--layers layers of the bundled twisted column, files written), wall
   time and the process's CPU time.

The model is the bundled twisted column (cubic, 6 x 6 x 6 control points) unless --model
names another file (its first trivariate). The load average is printed before and after.
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


def cpp_run(args, mode, threads, points_file, loops=1):
    """(wall, thread CPU) seconds per call of the C++ baseline, one repetition."""
    out = subprocess.run([args.baseline, str(args.model), "0", mode, str(threads), "1", str(points_file), str(loops)],
                         check=True, capture_output=True, text=True).stdout
    r = json.loads(out)
    return r["seconds"][0], r["cpu_seconds"][0]


def timed(call):
    """(wall, thread CPU, process CPU) seconds of call()."""
    w, t, p = time.perf_counter(), time.thread_time(), time.process_time()
    call()
    return time.perf_counter() - w, time.thread_time() - t, time.process_time() - p


def bulk(args, vol, params, points, params_file, points_file):
    rows = []
    hint = vol.domain.mean(axis=1)
    values, jacobians = np.empty_like(params), np.empty(params.shape + (3,))
    for name, mode, py_call, data_file in (
        ("evaluate", "evaluate", lambda t: vol.evaluate(params, threads=t), params_file),
        ("evaluate, out=", "evaluate", lambda t: vol.evaluate(params, threads=t, out=values), params_file),
        ("jacobian", "jacobian", lambda t: vol.jacobian(params, threads=t), params_file),
        ("jacobian, out=", "jacobian", lambda t: vol.jacobian(params, threads=t, out=jacobians), params_file),
        ("invert", "invert", lambda t: vol.invert(points, hint, threads=t), points_file),
    ):
        for threads in (1, 0):
            py, cpp = [], []
            for _ in range(args.runs):
                cpp.append(cpp_run(args, mode, threads, data_file))
                py.append(timed(lambda: py_call(threads))[:2])
            n = len(params)
            pw, pc = (statistics.median(x[i] for x in py) for i in (0, 1))
            cw, cc = (statistics.median(x[i] for x in cpp) for i in (0, 1))
            rows.append((name, threads, n / pw, n / cw, cw / pw, cc / pc if threads == 1 else None))
    return rows


def per_call(args, vol, params, tmp):
    rows = []
    for n in (1, 10, 100, 1000):
        batch = np.ascontiguousarray(params[:n])
        path = pathlib.Path(tmp) / f"batch{n}.f64"
        batch.tofile(path)
        calls = max(100, 100000 // n)

        def loop():
            for _ in range(calls):
                vol.evaluate(batch)

        py, cpp = [], []
        for _ in range(args.runs):
            cpp.append(cpp_run(args, "evaluate", 1, path, loops=calls)[1])
            py.append(timed(loop)[1] / calls)
        p, c = statistics.median(py), statistics.median(cpp)
        rows.append((n, p * 1e6, c * 1e6, (p - c) * 1e6))
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

    def spin_rate(call):
        """Iterations per second of a pure Python loop in another thread while call() runs."""
        stop, count = threading.Event(), [0]

        def spin():
            while not stop.is_set():
                count[0] += 1

        t = threading.Thread(target=spin)
        start = time.perf_counter()
        t.start()
        call()
        elapsed = time.perf_counter() - start
        stop.set()
        t.join()
        return count[0] / elapsed

    seq, con, share = [], [], []
    for _ in range(args.runs):
        seq.append(timed(sequential)[0])
        con.append(timed(concurrent)[0])
        alone = spin_rate(lambda: time.sleep(0.3))
        share.append(spin_rate(lambda: vol.invert(a, hint, threads=1)) / alone)
    return statistics.median(seq), statistics.median(con), statistics.median(share)


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
                    holder = {}
                    wall, _, cpu = timed(lambda: holder.update(r=trivox.slice(slicer, out, layers=layers, min_layers=0,
                                                                               threads=threads)))
                r = holder["r"]
                results[name].append((wall, cpu, sum(layer["seconds_material"] for layer in r.layers), r.threads))
        e = [statistics.median(x[i] for x in results["expression"]) for i in (0, 1, 2)]
        p = [statistics.median(x[i] for x in results["python"]) for i in (0, 1, 2)]
        rows.append((results["python"][0][3], e, p))
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
    print(f"model {os.path.relpath(args.model, ROOT)}: {vol}; {args.points} points; median of {args.runs} runs")
    print(f"trivox {trivox.__version__}, {os.cpu_count()} processors, load average {os.getloadavg()[0]:.1f}\n")
    with tempfile.TemporaryDirectory() as tmp:
        params_file, points_file = pathlib.Path(tmp) / "params.f64", pathlib.Path(tmp) / "points.f64"
        params.tofile(params_file)
        points.tofile(points_file)
        print("| call | threads | Python points/s | C++ points/s | Python / C++ (wall) | Python / C++ (CPU) |")
        print("|---|---|---|---|---|---|")
        for mode, threads, py, cpp, ratio, cpu in bulk(args, vol, params, points, params_file, points_file):
            cpu_text = f"{cpu:.2f}" if cpu is not None else ""
            print(f"| {mode} | {threads or 'all'} | {py:.3g} | {cpp:.3g} | {ratio:.2f} | {cpu_text} |")
        print("\n| points per call | Python call (us CPU) | C++ call (us CPU) | overhead per call (us) |")
        print("|---|---|---|---|")
        for n, p, c, over in per_call(args, vol, params, tmp):
            print(f"| {n} | {p:.3f} | {c:.3f} | {over:.2f} |")
    seq, con, share = gil(args, vol, points)
    print(f"\ntwo threads inverting {args.points // 2} points each (threads=1), wall: one after the other {seq:.3f} s, "
          f"at once {con:.3f} s, ratio {con / seq:.2f}")
    print(f"a Python loop in another thread while one inverts {args.points // 2} points: {share:.2f} of its speed "
          "while this thread sleeps")
    print("\n| job threads | expression job (s wall / CPU) | Python material job (s wall / CPU) | ratio wall / CPU "
          "| material evaluation, expression / Python (s) |")
    print("|---|---|---|---|---|")
    for threads, e, p in material_job(args):
        print(f"| {threads} | {e[0]:.2f} / {e[1]:.2f} | {p[0]:.2f} / {p[1]:.2f} | {p[0] / e[0]:.2f} / {p[1] / e[1]:.2f} "
              f"| {e[2]:.2f} / {p[2]:.2f} |")
    print(f"({args.layers} layers of the twisted column, Voxel Print PNGs written; material evaluation: the layers' "
          "seconds_material summed)")
    print(f"\nload average at the end {os.getloadavg()[0]:.1f}")


if __name__ == "__main__":
    main()
