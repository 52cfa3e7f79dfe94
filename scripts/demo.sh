#!/usr/bin/env bash
# The README's first command: installs what is missing, builds the trivox program (release
# preset), slices the knot of the bundled chalice (the paper's Figure 1: base and cup by
# revolution, a knot by a sweep, five Boolean cells) into a Voxel Print PNG stack in
# out/chalice with a preview of three layers (the knot in the base, in the stem and in the
# cup), then shows `trivox info` and `trivox probe` on a bundled model. Layers 57 to 500 of
# the chalice's 1001 keep the demo short; drop --layers to slice it whole.
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/install-deps.sh
scripts/build.sh release trivox_cli

trivox=build/release/bin/trivox
echo
echo "\$ trivox slice examples/scenes/chalice.json -o out/chalice --layers 57:500 --preview 89,278,444"
"$trivox" slice examples/scenes/chalice.json -o out/chalice --layers 57:500 --preview 89,278,444
echo "previews: out/chalice/preview/layer_00089.png, layer_00278.png, layer_00444.png"
echo
echo "\$ trivox info examples/models/twisted_column.itd"
"$trivox" info examples/models/twisted_column.itd
echo
echo "\$ trivox probe examples/models/twisted_column.itd < examples/probe_points.txt"
"$trivox" probe examples/models/twisted_column.itd < examples/probe_points.txt
