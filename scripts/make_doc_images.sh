#!/usr/bin/env bash
# Makes the preview images of docs/EXAMPLES.md with trivox itself, from the scenes in the
# repository: the chalice and every scene of examples/scenes always (for the greyscale column,
# its grey layer images); the teapot, the duck and
# the scenes of examples/shared_scenes when ../shared (the real models they are built from) is
# beside the repository. Writes docs/images/*.png; scratch output goes to out/doc_images/.
# Build first (scripts/build.sh release trivox_cli).
set -euo pipefail
cd "$(dirname "$0")/.."

trivox=build/release/bin/trivox
scratch=out/doc_images
mkdir -p docs/images
rm -rf "$scratch"

# One layer of a scene as docs/images/NAME_layer_LAYER.png (LAYER 1-based, as in the file names).
one_layer() {
  local scene=$1 layer=$2 name=$3
  "$trivox" slice "$scene" -o "$scratch/$name" --layers "$layer:$layer" --preview "$layer" --min-layers 0 -q
  cp "$scratch/$name/preview/layer_$(printf %05d "$layer").png" "docs/images/${name}_layer_${layer}.png"
}

# The chalice: every layer, for the contact sheet and the vertical cut through the stack;
# three layers at full resolution: the knot in the base, the knot's five passes through the
# stem, the knot in the cup's bottom.
"$trivox" slice examples/scenes/chalice.json -o "$scratch/chalice" --format preview --preview 89,278,444 -q
cp "$scratch/chalice/preview/cut_xz.png" docs/images/chalice_cut_xz.png
cp "$scratch/chalice/preview/contact_sheet.png" docs/images/chalice_contact_sheet.png
for layer in 89 278 444; do
  cp "$scratch/chalice/preview/layer_$(printf %05d "$layer").png" "docs/images/chalice_layer_${layer}.png"
done

# The other bundled scenes, one layer each (mostly the middle one).
one_layer examples/scenes/boolean_pair.json 186 boolean_pair
one_layer examples/scenes/box_gradient.json 186 box_gradient
one_layer examples/scenes/column_scalar_gradient.json 667 column_scalar_gradient
one_layer examples/scenes/cylinder_sector_curves.json 1429 cylinder_sector_curves
one_layer examples/scenes/dithering_skin.json 38 dithering_skin
one_layer examples/scenes/expression_layers.json 185 expression_layers
one_layer examples/scenes/quick_start.json 112 quick_start
one_layer examples/scenes/texture_composition.json 38 texture_composition
one_layer examples/scenes/twisted_column_porous.json 1217 twisted_column_porous

# The greyscale column for the SL1S: the grey layers themselves (greyscale/), at a tenth, half
# and nine tenths of the height.
for layer in 120 600 1080; do
  "$trivox" slice examples/scenes/column_greyscale_sl1s.json -o "$scratch/column_greyscale_sl1s_$layer" \
    --layers "$layer:$layer" --format greyscale --min-layers 0 -q
  cp "$scratch/column_greyscale_sl1s_$layer/greyscale/slice_00001.png" \
    "docs/images/column_greyscale_sl1s_layer_${layer}.png"
done

if [ -d ../shared/data ]; then
  # The teapot: two single layers (the full stack takes minutes), through the spout and
  # handle, and lower through the body's texture.
  one_layer examples/shared_scenes/teapot.json 300 teapot
  one_layer examples/shared_scenes/teapot.json 760 teapot
  # The duck: one layer through the body and the neck, showing the porous tiles.
  one_layer examples/shared_scenes/duck.json 1500 duck
  # The boxes trimmed by the duck's and the teapot's shells, through their middles.
  one_layer examples/shared_scenes/duck_trimmed_box.json 167 duck_trimmed_box
  one_layer examples/shared_scenes/teapot_trimmed_box.json 201 teapot_trimmed_box
  # Mesh trims: the box filled inside the bunny's STL, through its body and its ears; the
  # revolved ring inside the hex nut's STL, through its middle.
  one_layer examples/shared_scenes/bunny_mesh_box.json 630 bunny_mesh_box
  one_layer examples/shared_scenes/bunny_mesh_box.json 1000 bunny_mesh_box
  one_layer examples/shared_scenes/hex_nut_radial.json 140 hex_nut_radial
else
  echo "make_doc_images.sh: ../shared/data is absent: the images of the scenes built from it are left as they are" >&2
fi
ls -l docs/images
