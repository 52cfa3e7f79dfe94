#!/usr/bin/env python3
"""Cuts through a stack of Voxel Print layers at full resolution, and how often its rows repeat.

  scripts/stack_cut.py DIR --row R [--cols A:B] [--scale SX,SY] -o cut.png
  scripts/stack_cut.py DIR --column C [--rows A:B] [--scale SX,SY] -o cut.png
  scripts/stack_cut.py DIR --repetition

DIR holds the layer images of `trivox slice` (slice_NNNNN.png, 8-bit RGBA). A cut shows one
image row (or column) of every layer, the first layer at the bottom, each voxel as SX x SY
pixels (default 2,2), written as an RGB PNG. R and C default to the middle row and column.
--repetition prints, over the layers that hold the model, the share of voxels that repeat
the colour of the same voxel in the layer below, for the whole stack and the middle row,
next to what independent patterns would give (from the colour frequencies around each voxel
over all layers), and the largest excess of a row and of a column over it (docs/DITHERING.md,
"Streaks").
Standard library only (zlib); reads only non-interlaced PNGs, as trivox writes them.
"""
import argparse
import glob
import os
import struct
import sys
import zlib


def read_png_rgba(path):
    with open(path, "rb") as f:
        data = f.read()
    if data[:8] != b"\x89PNG\r\n\x1a\n":
        sys.exit(f"{path}: not a PNG")
    at, idat, width, height = 8, b"", 0, 0
    while at < len(data):
        length, kind = struct.unpack(">I4s", data[at:at + 8])
        body = data[at + 8:at + 8 + length]
        if kind == b"IHDR":
            width, height, depth, colour, _, _, interlace = struct.unpack(">IIBBBBB", body)
            if depth != 8 or colour != 6 or interlace != 0:
                sys.exit(f"{path}: not an 8-bit RGBA non-interlaced PNG")
        elif kind == b"IDAT":
            idat += body
        at += 12 + length
    raw = zlib.decompress(idat)
    stride, bpp = width * 4, 4
    rows, prev = [], bytearray(stride)
    for y in range(height):
        ftype = raw[y * (stride + 1)]
        line = bytearray(raw[y * (stride + 1) + 1:(y + 1) * (stride + 1)])
        for i in range(stride):
            a = line[i - bpp] if i >= bpp else 0
            b = prev[i]
            c = prev[i - bpp] if i >= bpp else 0
            if ftype == 1:
                line[i] = (line[i] + a) & 255
            elif ftype == 2:
                line[i] = (line[i] + b) & 255
            elif ftype == 3:
                line[i] = (line[i] + (a + b) // 2) & 255
            elif ftype == 4:
                p = a + b - c
                pa, pb, pc = abs(p - a), abs(p - b), abs(p - c)
                line[i] = (line[i] + (a if pa <= pb and pa <= pc else b if pb <= pc else c)) & 255
        rows.append(bytes(line))
        prev = line
    return width, height, rows


def write_png_rgb(path, width, height, rows):
    def chunk(kind, body):
        return struct.pack(">I", len(body)) + kind + body + struct.pack(">I", zlib.crc32(kind + body) & 0xFFFFFFFF)
    raw = b"".join(b"\x00" + bytes(r) for r in rows)
    png = b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
    png += chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b"")
    with open(path, "wb") as f:
        f.write(png)


def layers_of(folder):
    files = sorted(glob.glob(os.path.join(folder, "slice_*.png")))
    if not files:
        sys.exit(f"{folder}: no slice_*.png")
    return [read_png_rgba(p) for p in files]


def pixel(rows, x, y):
    return rows[y][4 * x:4 * x + 4]


def span(text, n):
    if not text:
        return 0, n
    a, b = text.split(":")
    return int(a), int(b)


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("dir")
    ap.add_argument("--row", type=int)
    ap.add_argument("--column", type=int)
    ap.add_argument("--cols", help="A:B, the columns of a row cut")
    ap.add_argument("--rows", help="A:B, the rows of a column cut")
    ap.add_argument("--scale", default="2,2")
    ap.add_argument("--repetition", action="store_true")
    ap.add_argument("-o", "--output")
    a = ap.parse_args()
    layers = layers_of(a.dir)
    width, height = layers[0][0], layers[0][1]
    background = pixel(layers[0][2], 0, 0)
    # Layers that hold the model (padding layers are all background).
    layers = [l for l in layers if any(r != bytes(background) * width for r in l[2])]
    if a.repetition:
        # Per voxel (x, y): how often it repeats the layer below; and how often independent
        # patterns would, from the local colour frequencies (over the layers and a window of
        # +-8 columns and +-2 rows, so that a pattern that repeats does not bias its own
        # estimate): the sum of their squares. Voxels outside the part in every layer are not
        # counted.
        n = len(layers) - 1
        bg = bytes(background)
        palette = {}
        counts = []  # per voxel, per colour index: layers with that colour
        same = [[0] * width for _ in range(height)]
        inside = [[False] * width for _ in range(height)]
        for y in range(height):
            row_counts = []
            for x in range(width):
                stack = [l[2][y][4 * x:4 * x + 4] for l in layers]
                inside[y][x] = any(p != bg for p in stack)
                c = {}
                for p in stack:
                    k = palette.setdefault(p, len(palette))
                    c[k] = c.get(k, 0) + 1
                row_counts.append(c)
                same[y][x] = sum(1 for p, q in zip(stack, stack[1:]) if p == q)
            counts.append(row_counts)
        k_all = len(palette)

        def window(y, x):
            total = [0] * k_all
            for yy in range(max(0, y - 2), min(height, y + 3)):
                for xx in range(max(0, x - 8), min(width, x + 9)):
                    if not inside[yy][xx]:
                        continue
                    for k, v in counts[yy][xx].items():
                        total[k] += v
            t = sum(total)
            return sum((v / t) ** 2 for v in total) if t else 0.0

        row = [[0.0, 0.0, 0] for _ in range(height)]
        col = [[0.0, 0.0, 0] for _ in range(width)]
        all_same = all_expected = 0.0
        all_count = 0
        for y in range(height):
            for x in range(width):
                if not inside[y][x]:
                    continue
                r, e = same[y][x] / n, window(y, x)
                for acc in (row[y], col[x]):
                    acc[0] += r
                    acc[1] += e
                    acc[2] += 1
                all_same += r
                all_expected += e
                all_count += 1
        rows = [((s_ - e_) / c, y) for y, (s_, e_, c) in enumerate(row) if c]
        cols = [((s_ - e_) / c, x) for x, (s_, e_, c) in enumerate(col) if c]
        mid = height // 2
        print(f"{len(layers)} layers of {width} x {height} px; share of voxels repeating the layer below, "
              f"and what independent patterns would repeat")
        print(f"whole stack: {all_same / all_count:.3f} (independent {all_expected / all_count:.3f})")
        print(f"middle row {mid}: {row[mid][0] / row[mid][2]:.3f} (independent {row[mid][1] / row[mid][2]:.3f})")
        print(f"largest excess of a row: {max(rows)[0]:.3f} (row {max(rows)[1]}); "
              f"of a column: {max(cols)[0]:.3f} (column {max(cols)[1]})")
        return
    sx, sy = (int(v) for v in a.scale.split(","))
    out = []
    for w, h, rows in reversed(layers):  # the top layer first: the image reads upwards
        if a.column is not None or a.row is None and a.rows:
            c = width // 2 if a.column is None else a.column
            lo, hi = span(a.rows, h)
            line = [pixel(rows, c, y)[:3] for y in range(lo, hi)]
        else:
            r = height // 2 if a.row is None else a.row
            lo, hi = span(a.cols, w)
            line = [pixel(rows, x, r)[:3] for x in range(lo, hi)]
        scaled = bytearray(b"".join(bytes(p) * sx for p in line))
        out.extend([scaled] * sy)
    write_png_rgb(a.output, len(out[0]) // 3, len(out), out)


if __name__ == "__main__":
    main()
