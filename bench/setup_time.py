#!/usr/bin/env python3
"""How long `trivox slice` takes before its first layer (docs/PERFORMANCE.md, "Set-up").

Runs one layer of a scene (by default the paper's duck, examples/shared_scenes/duck.json, its
layer 1200) with each trivox program given, and reports the set-up: the command's wall time
less the seconds the job itself reports ("sliced 1 layers ... in X s"), so program start,
reading the scene, building its volumes, the slicer's set-up and the one-layer estimate. A
"first" run slices into a new folder; a "repeat" run into the folder of an earlier run,
where a trivox with the construction cache finds the volumes built. Runs of the programs
alternate, so that a change in the machine's load touches them alike; the medians are printed.

  bench/setup_time.py TRIVOX [TRIVOX ...] [--scene PATH] [--layer N] [--runs N]
"""
import argparse
import os
import re
import resource
import shutil
import statistics
import subprocess
import tempfile
import time

HERE = os.path.dirname(os.path.abspath(__file__))


def run(program, scene, layer, out):
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.monotonic()
    done = subprocess.run(
        [program, "slice", scene, "-o", out, "--layers", f"{layer}:{layer}", "--min-layers", "0", "-q"],
        capture_output=True, text=True, check=True)
    wall = time.monotonic() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    job = float(re.search(r"sliced 1 layers .* in ([0-9.]+) s", done.stdout).group(1))
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall - job, wall, cpu


def main():
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("programs", nargs="+")
    parser.add_argument("--scene", default=os.path.join(HERE, "..", "examples", "shared_scenes", "duck.json"))
    parser.add_argument("--layer", type=int, default=1200)
    parser.add_argument("--runs", type=int, default=5)
    args = parser.parse_args()
    scratch = tempfile.mkdtemp(prefix="trivox-setup-time-")
    results = {(p, kind): [] for p in args.programs for kind in ("first", "repeat")}
    try:
        for r in range(args.runs):
            for i, program in enumerate(args.programs):
                out = os.path.join(scratch, f"{i}-{r}")
                results[(program, "first")].append(run(program, args.scene, args.layer, out))
                results[(program, "repeat")].append(run(program, args.scene, args.layer, out))
                shutil.rmtree(out)
    finally:
        shutil.rmtree(scratch, ignore_errors=True)
    print(f"{args.scene}, layer {args.layer}: median of {args.runs} runs (seconds)")
    print(f"{'program':<40} {'run':<7} {'set-up':>7} {'wall':>7} {'CPU':>7}  set-up of each run")
    for (program, kind), rows in results.items():
        setup = statistics.median(r[0] for r in rows)
        wall = statistics.median(r[1] for r in rows)
        cpu = statistics.median(r[2] for r in rows)
        each = " ".join(f"{r[0]:.2f}" for r in rows)
        print(f"{program:<40} {kind:<7} {setup:7.2f} {wall:7.2f} {cpu:7.2f}  {each}")


if __name__ == "__main__":
    main()
