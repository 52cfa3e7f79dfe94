#!/usr/bin/env bash
# Makes the preview images of docs/EXAMPLES.md with trivox itself, from the scenes in the
# repository: the chalice always; the teapot and the duck when ../shared (the real models
# they are built from) is beside the repository. Writes docs/images/*.png; scratch output goes to
# out/doc_images/. Build first (scripts/build.sh release trivox_cli).
set -euo pipefail
cd "$(dirname "$0")/.."

trivox=build/release/bin/trivox
scratch=out/doc_images
mkdir -p docs/images
rm -rf "$scratch"

# The chalice: every layer, for the contact sheet and the vertical cut through the stack;
# one layer through the knotted stem at full resolution.
"$trivox" slice examples/scenes/chalice.json -o "$scratch/chalice" --format preview --preview 250 -q
cp "$scratch/chalice/preview/cut_xz.png" docs/images/chalice_cut_xz.png
cp "$scratch/chalice/preview/contact_sheet.png" docs/images/chalice_contact_sheet.png
cp "$scratch/chalice/preview/layer_00250.png" docs/images/chalice_layer_250.png

if [ -d ../shared/data ]; then
  # The teapot: two single layers (the full stack takes minutes), through the spout and
  # handle, and lower through the body's texture.
  "$trivox" slice examples/shared_scenes/teapot.json -o "$scratch/teapot" --layers 300:300 --preview 300 \
    --min-layers 0 -q
  cp "$scratch/teapot/preview/layer_00300.png" docs/images/teapot_layer_300.png
  "$trivox" slice examples/shared_scenes/teapot.json -o "$scratch/teapot" --layers 760:760 --preview 760 \
    --min-layers 0 -q
  cp "$scratch/teapot/preview/layer_00760.png" docs/images/teapot_layer_760.png
  # The duck: one layer through the body and the neck, showing the porous tiles.
  "$trivox" slice examples/shared_scenes/duck.json -o "$scratch/duck" --layers 1500:1500 --preview 1500 \
    --min-layers 0 -q
  cp "$scratch/duck/preview/layer_01500.png" docs/images/duck_layer_1500.png
else
  echo "make_doc_images.sh: ../shared/data is absent: the teapot's and the duck's images are left as they are" >&2
fi
ls -l docs/images
