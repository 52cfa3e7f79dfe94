#!/usr/bin/env bash
# The README's first command: installs what is missing, builds the trivox program (release
# preset), slices the knot of the bundled chalice (the paper's Figure 1: base and cup by
# revolution, a knot by a sweep, five Boolean cells) into a Voxel Print PNG stack in
# out/chalice with a preview of three layers (the knot in the base, in the stem and in the
# cup), then shows `trivox info` and `trivox probe` on a bundled model. Layers 57 to 500 of
# the chalice's 1001 keep the demo short; drop --layers to slice it whole. Last, it builds the
# Python module and makes `import trivox` work for the user's python3 (docs/PYTHON.md): a
# trivox-build.pth file in the user's site-packages names the build's python/ folder.
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

# The Python module, when the build has it (TRIVOX_PYTHON: pybind11, numpy and the Python
# headers found). A .pth file in the user's site-packages puts the build's python/ folder on
# sys.path of every interpreter of that Python version that reads it (Debian's python3, and a
# pyenv python3 of the same version share ~/.local/lib/python3.X/site-packages).
if grep -q '^TRIVOX_PYTHON:BOOL=ON' build/release/CMakeCache.txt; then
  cmake --build --preset release --parallel "${TRIVOX_JOBS:-$(nproc)}" --target trivox_python
  python=$(sed -n 's/^Python3_EXECUTABLE:[A-Z]*=//p' build/release/CMakeCache.txt)
  package_dir="$(pwd)/build/release/python"
  echo
  if site=$("$python" -c 'import site, sys; sys.exit(0 if site.ENABLE_USER_SITE else 1); ' 2>/dev/null &&
            "$python" -m site --user-site); then
    mkdir -p "$site"
    echo "$package_dir" > "$site/trivox-build.pth"
    echo "Python: $site/trivox-build.pth points at $package_dir"
    echo "\$ python3 -c \"import trivox; print(trivox.__version__)\""
    "$python" -c "import trivox; print(trivox.__version__)"
  else
    echo "Python: user site-packages are off for $python; use the module with"
    echo "  export PYTHONPATH=$package_dir"
  fi
fi

