#!/usr/bin/env python3
"""A layer shown with matplotlib: the dithered materials beside the fraction of one material
before dithering.

    python3 examples/python/show_layer.py [SCENE] [--layer N] [--material NAME] [--out FILE]

Slices one layer of a scene (default: the quick-start scene, its middle layer), and draws the
labels in the materials' colours and the chosen material's fraction, both in millimetres. With
a display the figure opens in a window; otherwise (or with --out) it is saved as a PNG.
matplotlib is optional (Debian: python3-matplotlib): without it the example says so and writes
the labels alone with trivox.write_png.
"""
import argparse
import os

import numpy as np

import trivox

HERE = os.path.dirname(os.path.abspath(__file__))


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene", nargs="?", default=os.path.join(HERE, "..", "scenes", "quick_start.json"))
    parser.add_argument("--layer", type=int, help="0-based layer (default: the middle one)")
    parser.add_argument("--material", help="the material whose fraction is drawn (default: the second)")
    parser.add_argument("--out", help="save the figure here instead of showing it")
    args = parser.parse_args()

    scene = trivox.read_scene(args.scene)
    slicer = trivox.Slicer(scene)
    L = slicer.layout
    k = L.num_layers // 2 if args.layer is None else args.layer
    layer = slicer.slice_layer(k, fractions=True)
    names = scene.material_names
    j = names.index(args.material) if args.material else min(1, len(names) - 1)
    colours = np.array([[255, 255, 255, 255]] + [m["rgba"] for m in scene.materials], dtype=np.uint8)
    rgba = colours[layer.labels]
    rgba[..., 3] = np.where(layer.labels > 0, 255, 0)  # opaque materials on a clear background

    try:
        import matplotlib
    except ImportError:
        out = args.out or f"layer_{k:05d}.png"
        print(f"matplotlib is not installed (Debian: python3-matplotlib), so the layer is not drawn; "
              f"writing its labels to {out} with trivox.write_png instead")
        trivox.write_png(out, colours[layer.labels])
        return
    if args.out or not os.environ.get("DISPLAY"):
        matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    # Pixel centres span x0 .. x0 + width pitch; row 0 is the top (largest y).
    extent = (L.x0_mm, L.x0_mm + L.width_px * L.pitch_x_mm, L.y_top_mm - L.height_px * L.pitch_y_mm, L.y_top_mm)
    fig, (a, b) = plt.subplots(1, 2, figsize=(12, 5), constrained_layout=True)
    a.imshow(rgba, extent=extent, interpolation="nearest")
    a.set_title(f"layer {k} at z = {L.z_of_layer(k):.3f} mm: materials after dithering")
    image = b.imshow(np.ma.masked_where(layer.inside == 0, layer.fractions[..., j]), extent=extent,
                     vmin=0, vmax=1, cmap="viridis", interpolation="nearest")
    b.set_title(f"fraction of {names[j]} before dithering")
    fig.colorbar(image, ax=b, shrink=0.8)
    for ax in (a, b):
        ax.set_xlabel("x (mm)")
        ax.set_ylabel("y (mm)")
        ax.set_aspect("equal")
    if args.out or not os.environ.get("DISPLAY"):
        out = args.out or f"layer_{k:05d}_plot.png"
        fig.savefig(out, dpi=120)
        print(f"saved the figure to {out}")
    else:
        plt.show()


if __name__ == "__main__":
    main()
