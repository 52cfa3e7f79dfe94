#!/usr/bin/env python3
"""Checks trivox's Prusa SL1 and SL1S print archives against the ones PrusaSlicer writes.

For each printer, the same simple part (two boxes of different sizes, 1 mm tall, placed so
that a mirrored or turned image would not match) is sliced twice: by `prusa-slicer
--export-sla` from an STL, with the printer, print and material profiles that Debian's
prusa-slicer package ships ("Original Prusa SL1" / "0.05 Normal" / "Prusa Orange Tough @0.05",
and the SL1S SPEED counterparts; supports, pad and elephant-foot compensation off), and by
`trivox slice --format sl1|sl1s` from a scene of the same boxes. The archives must agree on:

  - the members: config.ini, prusaslicer.ini and one PNG per layer named <jobDir><5 digits>.png
    from 0 (trivox adds the two thumbnails PrusaSlicer's program writes only from its window;
    they are checked to decode at their sizes);
  - config.ini: the same keys; the same layer height, printer model, layer counts (numFast,
    numSlow, numFade) and exposure times;
  - prusaslicer.ini: every key trivox writes is one PrusaSlicer writes, with the same value
    for the display, the layer height, the printer and the exposure;
  - every layer image: the size of the display in PrusaSlicer's orientation, 8-bit
    greyscale, and the same grey in every pixel up to anti-aliasing: PrusaSlicer exposes an
    edge pixel by its exact covered area, trivox by k x k sub-samples (k = 4 here), so an
    edge pixel may differ by up to 255 / (2k) + 1 levels and every other pixel not at all
    (mirroring or turning the image, or placing the part elsewhere on the display, changes
    thousands of them by 255).

Exits 0 when everything agrees, 1 when something differs (each difference is printed), and
77 (the "skipped" code CTest is told about) when prusa-slicer or its profiles are absent.
Run: tests/tools/check_sl1_archive.py --trivox build/release/bin/trivox
"""
import argparse
import configparser
import json
import os
import re
import shutil
import struct
import subprocess
import sys
import tempfile
import zipfile
import zlib

SKIP = 77

PROFILES = {
    "sl1": ("Original Prusa SL1", "0.05 Normal", "Prusa Orange Tough @0.05"),
    "sl1s": ("Original Prusa SL1S SPEED", "0.05 Normal @SL1S", "Prusa Orange Tough @0.05 SL1S"),
}

# (x0, y0, x1, y1) in mm, 1 mm tall: a long bar and a small block beside one of its ends.
BOXES = [(0.0, 0.0, 20.0, 5.0), (0.0, 8.0, 3.0, 11.0)]
HEIGHT = 1.0
# trivox's anti-aliasing: k x k sub-samples per edge pixel.
K = 4
TOLERANCE = 255 // (2 * K) + 1 + 1  # half a sub-sample row or column of grey, and rounding on both sides

CONFIG_VALUES = ["action", "expTime", "expTimeFirst", "hollow", "layerHeight", "numFade", "numFast", "numSlow",
                 "printerModel", "printerVariant"]
PRUSASLICER_VALUES = ["display_width", "display_height", "display_pixels_x", "display_pixels_y",
                      "display_orientation", "display_mirror_x", "display_mirror_y", "layer_height",
                      "initial_layer_height", "printer_model", "printer_technology", "exposure_time",
                      "initial_exposure_time", "faded_layers", "fast_tilt_time", "slow_tilt_time", "area_fill"]


def read_bundle(path):
    """The sections of a PrusaSlicer vendor bundle: name -> {key: value} (inherits unresolved)."""
    sections, current = {}, None
    with open(path, encoding="utf-8") as f:
        for line in f:
            line = line.rstrip("\n")
            m = re.match(r"^\[(.*)\]$", line)
            if m:
                current = sections.setdefault(m.group(1), {})
            elif current is not None and line and not line.startswith("#") and " =" in line:
                key, _, value = line.partition(" =")
                current[key.strip()] = value[1:] if value.startswith(" ") else value
    return sections


def resolve(sections, kind, name):
    """A profile with its parents' settings under its own, as PrusaSlicer merges them."""
    section = sections[f"{kind}:{name}"]
    out = {}
    for parent in [p.strip() for p in section.get("inherits", "").split(";") if p.strip()]:
        out.update(resolve(sections, kind, parent))
    out.update({k: v for k, v in section.items() if k != "inherits"})
    return out


def write_stl(path):
    triangles = []
    for x0, y0, x1, y1 in BOXES:
        v = [(x, y, z) for z in (0.0, HEIGHT) for y in (y0, y1) for x in (x0, x1)]
        for a, b, c, d in [(0, 2, 3, 1), (4, 5, 7, 6), (0, 1, 5, 4), (2, 6, 7, 3), (0, 4, 6, 2), (1, 3, 7, 5)]:
            triangles += [(v[a], v[b], v[c]), (v[a], v[c], v[d])]
    with open(path, "wb") as f:
        f.write(b"\0" * 80 + struct.pack("<I", len(triangles)))
        for t in triangles:
            f.write(struct.pack("<3f", 0, 0, 0) + b"".join(struct.pack("<3f", *p) for p in t) + b"\0\0")


def write_scene(path, printer):
    def box(x0, y0, x1, y1):
        return {"orders": [2, 2, 2], "knots": [[0, 0, 1, 1]] * 3,
                "points": [[x, y, z] for z in (0.0, HEIGHT) for y in (y0, y1) for x in (x0, x1)]}
    scene = {"version": 1, "units": "mm", "printer": printer,
             "materials": [{"name": "resin", "rgba": [255, 128, 64]}],
             "greyscale": {"source": {"material": "resin"}, "curve": [[0, 0], [1, 255]], "antialiasing": K},
             "cells": [{"name": f"box {i}", "geometry": box(*b), "material": "resin"} for i, b in enumerate(BOXES)]}
    with open(path, "w", encoding="utf-8") as f:
        json.dump(scene, f, indent=1)


def png_info(data):
    """Width, height, bit depth, colour type and the rows (bytes) of an 8-bit greyscale PNG."""
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        raise ValueError("not a PNG")
    pos, idat, ihdr = 8, b"", None
    while pos < len(data):
        n, kind = struct.unpack(">I4s", data[pos:pos + 8])
        body = data[pos + 8:pos + 8 + n]
        if kind == b"IHDR":
            ihdr = struct.unpack(">IIBBBBB", body)
        elif kind == b"IDAT":
            idat += body
        pos += 12 + n
    width, height, depth, colour = ihdr[:4]
    rows = []
    if depth == 8 and colour == 0:
        raw, prev = zlib.decompress(idat), bytearray(width)
        for y in range(height):
            f = raw[y * (width + 1)]
            line = bytearray(raw[y * (width + 1) + 1:(y + 1) * (width + 1)])
            if f == 1:
                for i in range(1, width):
                    line[i] = (line[i] + line[i - 1]) & 255
            elif f == 2:
                line = bytearray((a + b) & 255 for a, b in zip(line, prev))
            elif f in (3, 4):
                for i in range(width):
                    a = line[i - 1] if i else 0
                    b, c = prev[i], (prev[i - 1] if i else 0)
                    if f == 3:
                        line[i] = (line[i] + (a + b) // 2) & 255
                    else:
                        p = a + b - c
                        pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                        line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
            rows.append(bytes(line))
            prev = line
    return width, height, depth, colour, rows


def ini(text):
    parser = configparser.ConfigParser(interpolation=None, delimiters=("=",))
    parser.optionxform = str
    parser.read_string("[top]\n" + text)
    return dict(parser["top"])


def layer_names(names, job_dir):
    pattern = re.compile(re.escape(job_dir) + r"(\d{5})\.png$")
    return sorted(n for n in names if pattern.fullmatch(n))


def check(printer, trivox, work, problems):
    say = lambda text: problems.append(f"{printer}: {text}")
    bundle = os.path.join(os.path.dirname(shutil.which("prusa-slicer")), "..", "share", "PrusaSlicer", "profiles",
                          "PrusaResearch.ini")
    sections = read_bundle(bundle)
    printer_name, print_name, material_name = PROFILES[printer]
    settings = {}
    for kind, name in (("printer", printer_name), ("sla_print", print_name), ("sla_material", material_name)):
        settings.update(resolve(sections, kind, name))
    for key in ("compatible_printers_condition", "compatible_prints_condition", "printer_notes", "inherits"):
        settings.pop(key, None)
    settings.update({"supports_enable": "0", "pad_enable": "0", "elefant_foot_compensation": "0"})
    config_path = os.path.join(work, f"{printer}.ini")
    with open(config_path, "w", encoding="utf-8") as f:
        f.writelines(f"{k} = {v}\n" for k, v in sorted(settings.items()))
    stl, scene = os.path.join(work, "boxes.stl"), os.path.join(work, f"boxes_{printer}.json")
    write_stl(stl)
    write_scene(scene, printer)
    theirs_path = os.path.join(work, f"prusaslicer.{printer}")
    subprocess.run(["prusa-slicer", "--export-sla", "--load", config_path, "--output", theirs_path, stl],
                   check=True, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    out = os.path.join(work, f"trivox_{printer}")
    subprocess.run([trivox, "slice", scene, "-o", out, "--format", printer, "--min-layers", "0", "-q"], check=True,
                   stdout=subprocess.DEVNULL)
    ours_path = os.path.join(out, printer, f"slice.{printer}")
    theirs, ours = zipfile.ZipFile(theirs_path), zipfile.ZipFile(ours_path)
    for z in (theirs, ours):
        if z.testzip() is not None:
            say(f"{z.filename}: a member fails its CRC")

    their_config, our_config = ini(theirs.read("config.ini").decode()), ini(ours.read("config.ini").decode())
    if set(their_config) != set(our_config):
        say(f"config.ini keys differ: PrusaSlicer only {sorted(set(their_config) - set(our_config))}, "
            f"trivox only {sorted(set(our_config) - set(their_config))}")
    for key in CONFIG_VALUES:
        if their_config.get(key) != our_config.get(key) and not _same_number(their_config.get(key),
                                                                               our_config.get(key)):
            say(f"config.ini {key}: PrusaSlicer {their_config.get(key)!r}, trivox {our_config.get(key)!r}")
    their_ini, our_ini = ini(theirs.read("prusaslicer.ini").decode()), ini(ours.read("prusaslicer.ini").decode())
    unknown = sorted(set(our_ini) - set(their_ini))
    if unknown:
        say(f"prusaslicer.ini keys PrusaSlicer does not write: {unknown}")
    for key in PRUSASLICER_VALUES:
        if their_ini.get(key) != our_ini.get(key) and not _same_number(their_ini.get(key), our_ini.get(key)):
            say(f"prusaslicer.ini {key}: PrusaSlicer {their_ini.get(key)!r}, trivox {our_ini.get(key)!r}")

    their_layers = layer_names(theirs.namelist(), their_config["jobDir"])
    our_layers = layer_names(ours.namelist(), our_config["jobDir"])
    expected = [f"{our_config['jobDir']}{i:05d}.png" for i in range(len(our_layers))]
    if our_layers != expected:
        say(f"trivox's layer images are not numbered from 0 without gaps: {our_layers[:3]}...")
    if len(their_layers) != len(our_layers):
        say(f"layer count: PrusaSlicer {len(their_layers)}, trivox {len(our_layers)}")
    extra = sorted(set(ours.namelist()) - set(our_layers) - {"config.ini", "prusaslicer.ini"})
    if extra != ["thumbnail/thumbnail400x400.png", "thumbnail/thumbnail800x480.png"]:
        say(f"members besides the layers and the ini files: {extra}")
    for name in extra:
        data = ours.read(name)
        size = struct.unpack(">II", data[16:24]) if data[:8] == b"\x89PNG\r\n\x1a\n" else None
        if size != tuple(int(n) for n in re.findall(r"(\d+)x(\d+)", name)[0]):
            say(f"{name} is not a PNG of its size")

    display = (int(their_ini["display_pixels_x"]), int(their_ini["display_pixels_y"]))
    portrait = their_ini["display_orientation"] == "portrait"
    size = (display[1], display[0]) if portrait else display
    exposed_total = beyond = largest = 0
    for index, (a, b) in enumerate(zip(their_layers, our_layers)):
        wa, ha, _, _, rows_a = png_info(theirs.read(a))
        wb, hb, depth, colour, rows_b = png_info(ours.read(b))
        if (wb, hb) != size or (wa, ha) != size:
            say(f"layer {index}: images {wa} x {ha} (PrusaSlicer), {wb} x {hb} (trivox); the display is {size}")
            continue
        if (depth, colour) != (8, 0):
            say(f"layer {index}: trivox's image is not 8-bit greyscale (depth {depth}, colour type {colour})")
            continue
        for ra, rb in zip(rows_a, rows_b):
            exposed_total += len(ra) - ra.count(0)
            if ra == rb:
                continue
            for va, vb in zip(ra, rb):
                d = abs(va - vb)
                largest = max(largest, d)
                beyond += d > TOLERANCE
    print(f"{printer}: {len(our_layers)} layers, {exposed_total} pixels exposed by PrusaSlicer; the largest "
          f"difference is {largest} grey levels, {beyond} pixels differ by more than {TOLERANCE}")
    if beyond:
        say(f"{beyond} pixels differ by more than {TOLERANCE} grey levels: placement, orientation or mirroring")


def _same_number(a, b):
    try:
        return a is not None and b is not None and abs(float(a) - float(b)) <= 1e-9 * max(1.0, abs(float(a)))
    except ValueError:
        return False


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--trivox", default="build/release/bin/trivox")
    parser.add_argument("--keep", help="keep the archives in this folder")
    args = parser.parse_args()
    prusa = shutil.which("prusa-slicer")
    bundle = prusa and os.path.join(os.path.dirname(prusa), "..", "share", "PrusaSlicer", "profiles",
                                    "PrusaResearch.ini")
    if not prusa or not os.path.exists(bundle):
        print("check_sl1_archive: skipped: prusa-slicer and its profiles are not installed "
              "(Debian: apt-get install prusa-slicer)")
        return SKIP
    work = args.keep or tempfile.mkdtemp(prefix="trivox-sl1-check-")
    os.makedirs(work, exist_ok=True)
    problems = []
    try:
        for printer in PROFILES:
            check(printer, os.path.abspath(args.trivox), work, problems)
    finally:
        if not args.keep:
            shutil.rmtree(work, ignore_errors=True)
    for p in problems:
        print("DIFFERS:", p)
    print("check_sl1_archive: " + ("the archives agree" if not problems else f"{len(problems)} differences"))
    return 1 if problems else 0


if __name__ == "__main__":
    sys.exit(main())
