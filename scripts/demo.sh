#!/usr/bin/env bash
# The README's first command: installs what is missing, builds the trivox program (release
# preset) and slices the bundled quick-start scene into a Voxel Print PNG stack in out/,
# then shows `trivox info` and `trivox probe` on a bundled model.
set -euo pipefail
cd "$(dirname "$0")/.."

scripts/install-deps.sh
scripts/build.sh release trivox_cli

trivox=build/release/bin/trivox
echo
echo "\$ trivox slice examples/scenes/quick_start.json -o out/quick_start"
"$trivox" slice examples/scenes/quick_start.json -o out/quick_start
echo
echo "\$ trivox info examples/models/twisted_column.itd"
"$trivox" info examples/models/twisted_column.itd
echo
echo "\$ trivox probe examples/models/twisted_column.itd < examples/probe_points.txt"
"$trivox" probe examples/models/twisted_column.itd < examples/probe_points.txt
