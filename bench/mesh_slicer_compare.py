#!/usr/bin/env python3
"""trivox against a mesh slicer: the duck's geometry sliced by both at the same pixel grid.

The bundled duck (examples/shared_scenes/duck.json, built from ../shared/data) with one
constant material, so that only its geometry counts, is sliced whole by the trivox program
and, as a triangle mesh, by PrusaSlicer's SLA rasterizer (`prusa-slicer --export-sla`), each
RUNS times, the two alternating; the script prints the CPU time per layer of each (user +
system time of the whole process, all threads, from wait4; median of the runs), their ratio,
and the inside pixels each found, and fails (exit 1) when the totals differ by more than
--agree (relative).

    bench/mesh_slicer_compare.py [--trivox build/release/bin/trivox]
        [--outline-stl build/release/bench/outline_stl] [--prusa-slicer prusa-slicer]
        [--runs 3] [--threads 0] [--tolerance-mm T] [--also-tolerance-mm T2 ...]
        [--agree 1e-5] [--scale S] [--phases] [--work DIR]

Without prusa-slicer on the PATH (Debian's package `prusa-slicer`) or without ../shared/data
it prints why and exits 0.

The mesh is trivox's own outline of the duck (`outline_stl`, the mesh the slicer cuts into
each layer's outline: the six faces of the volume sampled on a grid until every grid cell
lies within the outline tolerance, by default the slicer's, an eighth of the finest pitch;
--tolerance-mm passes another), turned to face outwards and written as a binary STL in
printer mm. --also-tolerance-mm adds meshes at other tolerances, sliced by PrusaSlicer
alone: their rows show how its time follows the mesh's size; their counts are reported,
not checked. PrusaSlicer's time includes reading and repairing it; trivox's includes reading
the scene and building the duck's volume from its surfaces. Each side writes its usual
output: trivox a Voxel Print PNG per layer (RGBA), PrusaSlicer an .sl1 archive (a zip of one
8-bit PNG per layer).

The two grids are aligned exactly:

* x and y: trivox's bitmap of the scene is W x H pixels with its left edge at x0 and its top
  edge at y_top (stats.json; pitch 25.4/600 mm in x, 25.4/300 mm in y for "j750-paper").
  `outline_stl --frame M` moves the mesh so that this bitmap, widened by M pixels on every
  side, has its lower left corner at the origin. PrusaSlicer keeps the mesh's x and y
  (--dont-arrange) and rasterizes onto a display of (W + 2M) x (H + 2M) pixels of the same
  pitch whose lower left corner is the bed's origin (landscape, no mirroring), so its pixel
  (c, r) is trivox's pixel (c - M, r - M), row 0 at the top in both.
* the sampling rule: trivox takes a pixel whose centre is inside; PrusaSlicer with
  gamma_correction = 0 (no anti-aliasing: a threshold at half coverage) lights a pixel more
  than half covered. A straight edge through a pixel halves it exactly when it passes
  through the centre, so the two rules differ only where the outline bends or turns within
  a pixel, and by the rasterizer's 1/256-pixel coordinates. Supports, pad, hollowing, the
  elephant-foot and absolute corrections and the closing radius are off.
* layers: PrusaSlicer stands the mesh on the bed by its lowest point z_min and, with the
  first layer as thick as the others, slices at z_min + (k + 0.5) * layer for every k with
  z_min + (k + 1) * layer <= z_max. trivox slices its n layers at z0 + (l + 0.5) * layer.
  `outline_stl --frame` adds two tetrahedra of 1 um beside the model, one at z0 and one at
  z0 + (n + 0.25) * layer: no plane cuts them, but they make z_min = z0 and give PrusaSlicer
  exactly trivox's n planes.

On the duck PrusaSlicer's inside pixels of each layer are within 10 of the mesh's own pixel
centres on trivox's grid (within 2 in the five lowest and highest layers that hold any),
where a grid one layer off would differ by about 560 a layer on average.

The counts: trivox's from its stats.json (`pixels_inside` per layer); PrusaSlicer's by
counting the lit pixels of every PNG of the archive; and, as a third figure, the pixel
centres of trivox's grid inside the mesh itself (`outline_stl --count`), so that the mesh's
distance from the true surface and the rasterizers' rules can be told apart. trivox is also
run on its first layer alone (for the duck an empty one, below the model) to measure its set-up (reading the
scene, building the volume, its bounds and its outline mesh), reported beside the
per-layer figures.

Where the time goes: trivox's layers by the times stats.json gives each (inverse, material,
dithering, the rest); with --phases PrusaSlicer is run once more and the CPU time it has
used is read from /proc each time its progress line names a new step (reading the mesh,
slicing, merging the slices, rasterizing and writing the PNGs, the archive).
"""
import argparse
import json
import os
import pty
import re
import shutil
import statistics
import struct
import subprocess
import sys

from paper_models import absolute_files  # the scene with its "file" paths made absolute
import tempfile
import time
import zipfile
import zlib

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
SHARED = os.path.join(ROOT, "..", "shared", "data")
DUCK = os.path.join(ROOT, "examples", "shared_scenes", "duck.json")
MARGIN_PX = 8


def geometry_only_duck(work, scale):
    """Writes the duck with one constant material (its first), at placement scale `scale`
    (None: the scene's); returns the scene's path."""
    with open(DUCK, encoding="utf-8") as f:
        scene = absolute_files(json.load(f), os.path.dirname(DUCK))
    scene.pop("$schema", None)
    first = scene["materials"][0]
    scene["materials"] = [first]
    scene["description"] = "The bundled duck with one constant material (bench/mesh_slicer_compare.py)."
    for cell in scene["cells"]:
        cell["material"] = {"kind": "constant", "fractions": {first["name"]: 1}}
        if scale is not None:
            cell["placement"]["scale"] = scale
    path = os.path.join(work, "duck_geometry.json")
    with open(path, "w", encoding="utf-8") as f:
        json.dump(scene, f, indent=1)
    return path


def prusa_config(layout, margin, path):
    """Writes PrusaSlicer's SLA settings for trivox's grid widened by `margin` pixels."""
    b = layout["bitmap"]
    px, py = b["width_px"] + 2 * margin, b["height_px"] + 2 * margin
    w, h = px * b["pitch_x_mm"], py * b["pitch_y_mm"]
    settings = {
        "printer_technology": "SLA",
        "display_orientation": "landscape",
        "display_pixels_x": px,
        "display_pixels_y": py,
        "display_width": repr(w),
        "display_height": repr(h),
        "display_mirror_x": 0,
        "display_mirror_y": 0,
        "bed_shape": f"0x0,{w!r}x0,{w!r}x{h!r},0x{h!r}",
        "max_print_height": 1000,
        "layer_height": b["layer_mm"],
        "initial_layer_height": b["layer_mm"],
        # binary pixels: a threshold at half coverage, no anti-aliasing
        "gamma_correction": 0,
        # the geometry as given
        "supports_enable": 0,
        "pad_enable": 0,
        "hollowing_enable": 0,
        "elefant_foot_compensation": 0,
        "absolute_correction": 0,
        "relative_correction": "1,1",
        "material_correction": "1,1,1",
        "slice_closing_radius": 0,
        "slicing_mode": "regular",
    }
    with open(path, "w", encoding="utf-8") as f:
        for k, v in settings.items():
            f.write(f"{k} = {v}\n")


def timed(cmd, log):
    """Runs cmd, its output into the file `log`; returns (CPU seconds, user + system, of the
    process and all its threads; wall seconds; peak resident MiB)."""
    with open(log, "wb") as out:
        start = time.monotonic()
        proc = subprocess.Popen(cmd, stdout=out, stderr=subprocess.STDOUT)
        # wait4 gives this child's own resource use, whatever else runs on the machine.
        _, status, usage = os.wait4(proc.pid, 0)
        wall = time.monotonic() - start
    proc.returncode = os.waitstatus_to_exitcode(status)
    if proc.returncode != 0:
        with open(log, encoding="utf-8", errors="replace") as f:
            tail = f.read()[-2000:]
        sys.exit(f"mesh_slicer_compare: {' '.join(cmd)} failed ({proc.returncode}):\n{tail}")
    return usage.ru_utime + usage.ru_stime, wall, usage.ru_maxrss / 1024


def proc_cpu_seconds(pid):
    """User + system time so far of a running process, all its threads (/proc/PID/stat)."""
    with open(f"/proc/{pid}/stat", encoding="ascii") as f:
        fields = f.read().rsplit(")", 1)[1].split()
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def prusa_phases(cmd):
    """Runs PrusaSlicer once, reading its progress lines ("55% => Rasterizing layers") as it
    writes them (through a terminal, so that they are not buffered) and the CPU time it has
    used when each new step begins; returns [(step, CPU seconds spent in it)]."""
    master, slave = pty.openpty()
    proc = subprocess.Popen(cmd, stdout=slave, stderr=slave)
    os.close(slave)
    steps, pending = [("reading the mesh and the settings", 0.0)], b""
    while True:
        try:
            chunk = os.read(master, 65536)
        except OSError:  # the terminal closes when the program ends
            break
        if not chunk:
            break
        cpu = proc_cpu_seconds(proc.pid)
        *lines, pending = (pending + chunk).split(b"\n")
        for line in lines:
            m = re.match(r"\s*\d+% => (.*)", line.decode(errors="replace").strip())
            if m and m.group(1) != steps[-1][0]:
                steps.append((m.group(1), cpu))
    _, status, usage = os.wait4(proc.pid, 0)
    os.close(master)
    if os.waitstatus_to_exitcode(status) != 0:
        sys.exit(f"mesh_slicer_compare: {' '.join(cmd)} failed")
    steps.append(("end", usage.ru_utime + usage.ru_stime))
    return [(steps[i][0], steps[i + 1][1] - steps[i][1]) for i in range(len(steps) - 1)]


def png_lit_pixels(data):
    """Nonzero pixels of an 8-bit greyscale PNG whose rows are unfiltered (PrusaSlicer's)."""
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError("not a PNG")
    pos, idat, w, h = 8, [], None, None
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        if kind == b"IHDR":
            w, h, depth, colour = struct.unpack(">IIBB", data[pos + 8:pos + 18])
            if depth != 8 or colour != 0:
                raise ValueError(f"not 8-bit greyscale (depth {depth}, colour type {colour})")
        elif kind == b"IDAT":
            idat.append(data[pos + 8:pos + 8 + n])
        pos += 12 + n
    raw = zlib.decompress(b"".join(idat))
    if len(raw) != h * (w + 1):
        raise ValueError("unexpected image size")
    # Each row starts with its filter byte; 0 (none) everywhere keeps pixels as they are.
    if raw[::w + 1].count(0) != h:
        raise ValueError("filtered rows: counting them needs unfiltering")
    return len(raw) - raw.count(0)


def sl1_counts(path):
    """Lit pixels per layer of a PrusaSlicer SLA archive, in layer order."""
    with zipfile.ZipFile(path) as z:
        names = sorted(n for n in z.namelist() if n.endswith(".png") and "thumbnail" not in n)
        return [png_lit_pixels(z.read(n)) for n in names]


def median_text(values, fmt="{:.1f}"):
    return f"{fmt.format(statistics.median(values))} ({', '.join(fmt.format(v) for v in values)})"


def outline_mesh(args, scene, work, tolerance_mm):
    """Writes the duck's outline mesh for PrusaSlicer's grid (outline_stl --frame); returns
    outline_stl's report with the STL's path added."""
    name = "duck_outline" if tolerance_mm is None else f"duck_outline_{tolerance_mm * 1e3:g}um"
    stl = os.path.join(work, name + ".stl")
    cmd = [args.outline_stl, scene, stl, "--frame", str(MARGIN_PX), "--count"]
    if tolerance_mm is not None:
        cmd += ["--tolerance-mm", repr(tolerance_mm)]
    report = json.loads(subprocess.run(cmd, check=True, capture_output=True, text=True).stdout)
    report["stl"] = stl
    report["name"] = name
    return report


def main() -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    ap.add_argument("--trivox", default=os.path.join(ROOT, "build", "release", "bin", "trivox"))
    ap.add_argument("--outline-stl", default=os.path.join(ROOT, "build", "release", "bench", "outline_stl"))
    ap.add_argument("--prusa-slicer", default="prusa-slicer")
    ap.add_argument("--runs", type=int, default=3)
    ap.add_argument("--threads", type=int, default=0, help="trivox's -j (0: every core)")
    ap.add_argument("--tolerance-mm", type=float, default=None,
                    help="the mesh's outline tolerance (default: the slicer's)")
    ap.add_argument("--also-tolerance-mm", type=float, action="append", default=[],
                    help="also slice, with PrusaSlicer alone, the mesh at this tolerance (repeatable); "
                         "its counts are reported, not checked")
    ap.add_argument("--agree", type=float, default=1e-5,
                    help="largest relative difference of the inside pixel totals")
    ap.add_argument("--scale", type=float, default=None,
                    help="the duck's placement scale (default: the scene's, 45; smaller for a quick check)")
    ap.add_argument("--phases", action="store_true",
                    help="then run PrusaSlicer once more on the first mesh and report the CPU time of each "
                         "of its steps")
    ap.add_argument("--work", default=None, help="scratch folder (default: a temporary one, removed)")
    args = ap.parse_args()

    prusa = shutil.which(args.prusa_slicer)
    if prusa is None:
        print(f"mesh_slicer_compare: skipped: {args.prusa_slicer} is not installed "
              "(Debian: apt-get install prusa-slicer)", file=sys.stderr)
        return 0
    if not os.path.isdir(SHARED):
        print("mesh_slicer_compare: skipped: the duck is built from ../shared/data, which is absent",
              file=sys.stderr)
        return 0
    for tool in (args.trivox, args.outline_stl):
        if not os.access(tool, os.X_OK):
            sys.exit(f"mesh_slicer_compare: {tool} is missing: build it first "
                     "(scripts/build.sh release trivox_cli outline_stl)")
    version = subprocess.run([prusa, "--help"], capture_output=True, text=True).stdout.split()
    version = next((word for word in version if word.startswith("PrusaSlicer-")), "PrusaSlicer")

    work = args.work or tempfile.mkdtemp(prefix="trivox-meshcompare-")
    os.makedirs(work, exist_ok=True)
    scene = geometry_only_duck(work, args.scale)
    meshes = [outline_mesh(args, scene, work, t) for t in [args.tolerance_mm] + args.also_tolerance_mm]
    config = os.path.join(work, "sla.ini")
    prusa_config(meshes[0], MARGIN_PX, config)
    b = meshes[0]["bitmap"]
    print(f"duck: {b['width_px']} x {b['height_px']} px, {b['layers']} layers; {version}")
    for m in meshes:
        print(f"mesh {m['name']}: {m['triangles']} triangles (tolerance {m['tolerance_mm'] * 1e3:.2f} um, "
              f"measured deviation {m['deviation_mm'] * 1e3:.2f} um), {os.path.getsize(m['stl']) / 2**20:.0f} MiB",
              flush=True)

    datadir = os.path.join(work, "prusa_datadir")
    os.makedirs(datadir, exist_ok=True)
    tv_out, setup_out = os.path.join(work, "trivox"), os.path.join(work, "trivox_setup")
    jobs = [("trivox", tv_out, [args.trivox, "slice", scene, "-o", tv_out, "-q", "-j", str(args.threads)])]
    for m in meshes:
        m["out"] = os.path.join(work, "prusa_" + m["name"])
        jobs.append((m["name"], m["out"], [prusa, "--datadir", datadir, "--loglevel", "1", "--load", config,
                                           "--dont-arrange", "--export-sla", "-o",
                                           os.path.join(m["out"], "duck.sl1"), m["stl"]]))
    # trivox on its first layer alone (empty, below the model): its set-up.
    jobs.append(("setup", setup_out, [args.trivox, "slice", scene, "-o", setup_out, "-q", "-j",
                                      str(args.threads), "--layers", "1:1", "--min-layers", "0", "--allow-empty"]))
    runs = {name: [] for name, _, _ in jobs}
    for r in range(args.runs):
        # Alternating, so that a change of the machine's load falls on every job alike.
        for name, out, cmd in jobs:
            shutil.rmtree(out, ignore_errors=True)
            os.makedirs(out)
            runs[name].append(timed(cmd, os.path.join(work, f"{name}.log")))
            print(f"run {r + 1} {name}: {runs[name][-1][0]:.2f} s CPU, {runs[name][-1][1]:.2f} s wall",
                  file=sys.stderr, flush=True)

    with open(os.path.join(tv_out, "stats.json"), encoding="utf-8") as f:
        stats = json.load(f)
    tv_layers = [layer["pixels_inside"] for layer in stats["layers"]]
    n = len(tv_layers)
    tv = sum(tv_layers)
    cpu = {k: [run[0] for run in v] for k, v in runs.items()}
    wall = {k: statistics.median(run[1] for run in v) for k, v in runs.items()}
    peak = {k: max(run[2] for run in v) for k, v in runs.items()}
    per_layer = {k: statistics.median(1e3 * c / n for c in v) for k, v in cpu.items()}
    setup = statistics.median(cpu["setup"])
    tv_layers_alone = statistics.median(1e3 * (c - setup) / n for c in cpu["trivox"])

    print(f"\n| | CPU [s] (runs) | CPU per layer [ms] | wall [s] | peak memory [MiB] | inside pixels |")
    print("|---|---|---|---|---|---|")
    print(f"| trivox, whole job (-j {args.threads or os.cpu_count()}) | {median_text(cpu['trivox'])} | "
          f"{per_layer['trivox']:.2f} | {wall['trivox']:.1f} | {peak['trivox']:.0f} | {tv} |")
    print(f"| trivox, set-up alone (first layer only) | {median_text(cpu['setup'], '{:.2f}')} | | "
          f"{wall['setup']:.1f} | {peak['setup']:.0f} | |")
    print(f"| trivox, layers alone (whole job less set-up) | | {tv_layers_alone:.2f} | | | |")
    for m in meshes:
        name = m["name"]
        m["ps_layers"] = sl1_counts(os.path.join(m["out"], "duck.sl1"))
        if len(m["ps_layers"]) != n:
            sys.exit(f"mesh_slicer_compare: PrusaSlicer wrote {len(m['ps_layers'])} layers of {name}, "
                     f"trivox {n}: the grids are not aligned in z")
        print(f"| PrusaSlicer --export-sla, {m['triangles'] / 1e6:.2f} M triangles | {median_text(cpu[name])} | "
              f"{per_layer[name]:.2f} | {wall[name]:.1f} | {peak[name]:.0f} | {sum(m['ps_layers'])} |")
    for m in meshes:
        print(f"| the {m['triangles'] / 1e6:.2f} M-triangle mesh, pixel centres inside | | | | | "
              f"{m['mesh_pixels_inside']} |")

    print(f"\n{n} layers; CPU per layer, trivox / PrusaSlicer:")
    for m in meshes:
        ps, mesh = sum(m["ps_layers"]), m["mesh_pixels_inside"]
        print(f"- {m['triangles'] / 1e6:.2f} M triangles: {per_layer['trivox'] / per_layer[m['name']]:.2f} "
              f"(trivox's layers alone: {tv_layers_alone / per_layer[m['name']]:.2f}); inside pixels, "
              f"PrusaSlicer against trivox {ps - tv:+d} ({(ps - tv) / tv:+.2e}), the mesh's centres against "
              f"trivox {mesh - tv:+d} ({(mesh - tv) / tv:+.2e}), PrusaSlicer against the mesh's centres "
              f"{ps - mesh:+d}; largest difference in one layer: PrusaSlicer against the mesh's centres "
              f"{max(abs(a - b) for a, b in zip(m['ps_layers'], m['mesh_pixels_inside_per_layer']))}, "
              f"against trivox {max(abs(a - b) for a, b in zip(m['ps_layers'], tv_layers))}")

    # Where trivox's layers spend their time: each layer's times in stats.json, summed (time
    # on the worker's clock, so on a loaded machine waiting counts too; the shares hold).
    sums = {k: sum(layer[k] for layer in stats["layers"])
            for k in ("seconds", "seconds_inverse", "seconds_material", "seconds_dither")}
    rest = sums["seconds"] - sums["seconds_inverse"] - sums["seconds_material"] - sums["seconds_dither"]
    print(f"\ntrivox's layers (stats.json, shares of the layers' time): inverse "
          f"{100 * sums['seconds_inverse'] / sums['seconds']:.0f} %, material "
          f"{100 * sums['seconds_material'] / sums['seconds']:.0f} %, dithering "
          f"{100 * sums['seconds_dither'] / sums['seconds']:.0f} %, the rest {100 * rest / sums['seconds']:.0f} %")
    if args.phases:
        print(f"\nPrusaSlicer's steps, CPU seconds ({meshes[0]['triangles'] / 1e6:.2f} M triangles, one run):")
        out = meshes[0]["out"]
        shutil.rmtree(out, ignore_errors=True)
        os.makedirs(out)
        for step, seconds in prusa_phases(jobs[1][2]):
            if seconds > 0:  # the steps turned off (supports, pad, hollowing) take none
                print(f"- {'writing the archive' if step == 'Slicing done' else step}: {seconds:.2f}")
    if not args.work:
        shutil.rmtree(work, ignore_errors=True)
    rel = abs(sum(meshes[0]["ps_layers"]) - tv) / tv
    if rel > args.agree:
        print(f"mesh_slicer_compare: the inside pixel totals of trivox and PrusaSlicer differ by {rel:.2e}, "
              f"more than --agree {args.agree:g}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
