#!/usr/bin/env python3
"""The paper's Table 2 for trivox's bundled versions of its three models.

Slices each whole model (every layer, Voxel Print PNGs written) with the trivox program,
RUNS times, and prints one Markdown row per model: bitmap, layers, voxels in the bitmap and
inside the model, mean time per layer, total wall time (median of the runs), the share of
inside voxels that needed the global solver, and the pixels that the slicer could not resolve
or found folded (both must be 0). Counts come from the job's stats.json; times are wall
times of the whole process, so reading the scene and building its volumes are included.

    bench/paper_models.py [--trivox build/release/bin/trivox] [--runs 3] [--threads 0]
                          [--models chalice,teapot,duck] [--work DIR]

Every model is sliced for the "j750-paper" printer, the J750 with the paper's 30 um layers,
so that the rows compare with the paper's: the teapot and the duck name it in their scenes;
the bundled chalice prints at the J750's 27 um High Mix layer, so its scene is written into the
scratch folder with the printer set to "j750-paper". The teapot and the duck are built from
surfaces in ../shared/data; without it they are skipped with a message. A fourth model, duck-paper-size (not run unless named), is the duck
scaled so that it holds as many inside voxels as the paper's duck (2.69e9): the bundled duck
(scale 45, 1.0089e9 inside voxels) scaled by (2.69 / 1.0089)^(1/3) = 1.387, placement scale
62.4; its scene is written into the scratch folder with the model path made absolute. Run on
an idle machine.
"""
import argparse
import json
import os
import resource
import shutil
import statistics
import subprocess
import sys
import tempfile
import time

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
MODELS = {
    "chalice": ("examples/scenes/chalice.json", False),
    "teapot": ("examples/shared_scenes/teapot.json", True),
    "duck": ("examples/shared_scenes/duck.json", True),
    "duck-paper-size": ("examples/shared_scenes/duck.json", True),
}
PAPER_SIZE_DUCK_SCALE = 62.4
SHARED = os.path.join(ROOT, "..", "shared", "data")


def absolute_files(node, scene_dir):
    """The scene with every "file" path made absolute (they are relative to the scene)."""
    if isinstance(node, dict):
        return {k: (os.path.normpath(os.path.join(scene_dir, v)) if k == "file" and isinstance(v, str)
                    else absolute_files(v, scene_dir)) for k, v in node.items()}
    if isinstance(node, list):
        return [absolute_files(v, scene_dir) for v in node]
    return node


def paper_profile_chalice(work):
    """Writes the chalice for the paper's 30 um layers; returns the scene's path."""
    source = os.path.join(ROOT, MODELS["chalice"][0])
    with open(source, encoding="utf-8") as f:
        scene = absolute_files(json.load(f), os.path.dirname(source))
    scene.pop("$schema", None)
    scene["printer"] = "j750-paper"
    os.makedirs(work, exist_ok=True)
    path = os.path.join(work, "chalice_paper.json")
    with open(path, "w", encoding="utf-8") as f:
        json.dump(scene, f, indent=1)
    return path


def paper_size_duck(work):
    """Writes the duck scaled to the paper's inside-voxel count; returns the scene's path."""
    source = os.path.join(ROOT, MODELS["duck"][0])
    with open(source, encoding="utf-8") as f:
        scene = absolute_files(json.load(f), os.path.dirname(source))
    scene.pop("$schema", None)
    scene["cells"][0]["placement"]["scale"] = PAPER_SIZE_DUCK_SCALE
    os.makedirs(work, exist_ok=True)
    path = os.path.join(work, "duck_paper_size.json")
    with open(path, "w", encoding="utf-8") as f:
        json.dump(scene, f, indent=1)
    return path


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--trivox", default=os.path.join(ROOT, "build", "release", "bin", "trivox"))
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--threads", type=int, default=0, help="0: every core")
    ap.add_argument("--models", default="chalice,teapot,duck")
    ap.add_argument("--work", default=None, help="scratch folder (default: a temporary one)")
    args = ap.parse_args()

    work = args.work or tempfile.mkdtemp(prefix="trivox-models-")
    print("| model | bitmap | layers | voxels total, inside [x1e9] | time per layer [s] | "
          "total [s] (runs) | global solves [%] | unresolved, folded pixels |")
    print("|---|---|---|---|---|---|---|---|")
    for name in args.models.split(","):
        scene, needs_shared = MODELS[name]
        if needs_shared and not os.path.isdir(SHARED):
            print(f"paper_models: {name} skipped: it is built from ../shared/data, which is absent",
                  file=sys.stderr)
            continue
        if name == "duck-paper-size":
            scene_path = paper_size_duck(work)
        elif name == "chalice":
            scene_path = paper_profile_chalice(work)
        else:
            scene_path = os.path.join(ROOT, scene)
        walls = []
        stats = None
        for _ in range(args.runs):
            out = os.path.join(work, name)
            shutil.rmtree(out, ignore_errors=True)
            start = time.monotonic()
            subprocess.run([args.trivox, "slice", scene_path, "-o", out, "-q",
                            "-j", str(args.threads)], check=True, stdout=subprocess.DEVNULL)
            walls.append(time.monotonic() - start)
            with open(os.path.join(out, "stats.json"), encoding="utf-8") as f:
                stats = json.load(f)
        t, b = stats["total"], stats["bitmap"]
        wall = statistics.median(walls)
        runs = ", ".join(f"{w:.1f}" for w in walls)
        print(f"| {name} | {b['width_px']} x {b['height_px']} | {t['layers_sliced']} | "
              f"{t['pixels_total'] / 1e9:.3f}, {t['pixels_inside'] / 1e9:.4f} | "
              f"{wall / t['layers_sliced']:.4f} | {wall:.1f} ({runs}) | "
              f"{t['global_share_percent']:.4f} | {t['unresolved_pixels']}, {t['folded_pixels']} |",
              flush=True)
    peak_kib = resource.getrusage(resource.RUSAGE_CHILDREN).ru_maxrss
    print(f"\npeak resident memory of the largest job: {peak_kib / 1024:.0f} MiB; "
          f"threads: {args.threads or os.cpu_count()}")
    if not args.work:
        shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
