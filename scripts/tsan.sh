#!/usr/bin/env bash
# Builds the library and the parallel tests under ThreadSanitizer (preset "tsan") and runs
# them: the slice job on 1, 2 and more threads, the slicer, the tracer and the expression
# material's evaluator pool (tests/CMakeLists.txt, trivox_parallel_tests). Fails on any data
# race report. Suppressions: tests/tsan/suppressions.txt (what each one hides and why).
# Parallel jobs: TRIVOX_JOBS, default the number of processors.
set -euo pipefail
cd "$(dirname "$0")/.."
jobs="${TRIVOX_JOBS:-$(nproc)}"

scripts/install-deps.sh
cmake --preset tsan
cmake --build --preset tsan --parallel "$jobs" --target trivox_parallel_tests
# halt_on_error: the first race fails the run; exitcode 66 tells a race from a test failure.
export TSAN_OPTIONS="halt_on_error=1:exitcode=66:second_deadlock_stack=1:suppressions=$PWD/tests/tsan/suppressions.txt"
build/tsan/tests/trivox_parallel_tests
