#!/usr/bin/env bash
# Installs the Debian 12 (bookworm) packages that building and testing trivox needs. Runs
# apt-get only when a package is missing, so running it again costs one dpkg-query per
# package. Nothing else is ever downloaded: the build and the tests use these packages only.
#
# `scripts/install-deps.sh --optional` also installs the optional packages: prusa-slicer
# (large), whose `--export-sla` archives tests/tools/check_sl1_archive.py compares trivox's
# SL1/SL1S archives with; that check is skipped where it is absent. `--slurm` also installs
# slurm-wlm and munge, for the one-node Slurm of scripts/slurm_check.sh (CI installs them; the
# check is skipped where they are absent).
set -euo pipefail

optional=(prusa-slicer)

packages=(
  build-essential cmake ninja-build pkg-config
  libfmt-dev libpugixml-dev nlohmann-json3-dev libcli11-dev libtbb-dev
  libpng-dev zlib1g-dev libtiff-dev libmuparser-dev libeigen3-dev libssl-dev
  libgtest-dev libgmock-dev libbenchmark-dev
  # the evaluation kernels' SIMD targets, chosen at run time (docs/ARCHITECTURE.md)
  libhwy-dev
  # the "vdb" output: OpenVDB and the Boost headers its headers include
  libopenvdb-dev libboost-dev
  # mesh trims: STL, OBJ and PLY through assimp, 3MF through lib3mf (assimp's 3MF importer
  # drops files that use the production extension)
  libassimp-dev lib3mf-dev
  # the tests open the .gcvf archive with Python's zipfile, a reader independent of trivox's
  python3
  # the Python module (python/, docs/PYTHON.md): its headers, pybind11, numpy, and pytest for
  # its tests; matplotlib draws a layer in examples/python/show_layer.py
  python3-dev pybind11-dev python3-pybind11 python3-numpy python3-pytest python3-matplotlib
  # clang with libFuzzer and the sanitizer runtimes: scripts/fuzz.sh, scripts/tsan.sh
  clang libclang-rt-14-dev
  # the format check of CI (scripts/check_format.sh)
  clang-format
  # a transcript of docs/FORMATS.md lists the GrabCAD package with it (scripts/check_docs.py)
  unzip
)

# A one-node Slurm for scripts/slurm_check.sh (docs/CLUSTER.md); CI installs it.
slurm=(slurm-wlm munge)

for option in "$@"; do
  case "$option" in
    --optional) packages+=("${optional[@]}") ;;
    --slurm) packages+=("${slurm[@]}") ;;
    *) echo "install-deps: unknown option '$option' (expected --optional or --slurm)" >&2; exit 2 ;;
  esac
done

if ! command -v dpkg-query >/dev/null 2>&1; then
  echo "install-deps: dpkg-query not found: this script installs Debian packages (Debian 12 bookworm)." >&2
  echo "install-deps: on another system, install the equivalents of: ${packages[*]}" >&2
  exit 1
fi

missing=()
for p in "${packages[@]}"; do
  if [ "$(dpkg-query -W -f='${db:Status-Status}' "$p" 2>/dev/null)" != "installed" ]; then
    missing+=("$p")
  fi
done

if [ "${#missing[@]}" -eq 0 ]; then
  echo "install-deps: all ${#packages[@]} packages are installed"
  exit 0
fi

echo "install-deps: installing ${missing[*]}"
if [ "$(id -u)" -eq 0 ]; then
  as_root=()
elif command -v sudo >/dev/null 2>&1; then
  as_root=(sudo)
else
  echo "install-deps: these packages are missing and installing them needs root: ${missing[*]}" >&2
  echo "install-deps: run this script as root, or install sudo, or ask an administrator for:" >&2
  echo "  apt-get install ${missing[*]}" >&2
  exit 1
fi
"${as_root[@]}" apt-get update
"${as_root[@]}" env DEBIAN_FRONTEND=noninteractive apt-get install -y --no-install-recommends "${missing[@]}"
