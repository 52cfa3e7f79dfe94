#!/usr/bin/env bash
# Configures and builds one CMake preset (CMakePresets.json):
#   scripts/build.sh release [TARGET...]   -> build/release (optimised; tests, benchmarks)
#   scripts/build.sh asan [TARGET...]      -> build/asan (AddressSanitizer + UBSan, -Werror)
# With TARGETs only those are built (e.g. trivox_cli). Parallel jobs: TRIVOX_JOBS, default
# the number of processors.
set -euo pipefail
cd "$(dirname "$0")/.."

preset="${1:-release}"
shift || true
case "$preset" in
  release|asan) ;;
  *) echo "build.sh: unknown preset '$preset' (expected release or asan)" >&2; exit 2 ;;
esac
jobs="${TRIVOX_JOBS:-$(nproc)}"

cmake --preset "$preset"
if [ "$#" -gt 0 ]; then
  cmake --build --preset "$preset" --parallel "$jobs" --target "$@"
else
  cmake --build --preset "$preset" --parallel "$jobs"
fi
