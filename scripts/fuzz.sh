#!/usr/bin/env bash
# Builds the libFuzzer targets (preset "fuzz": clang, AddressSanitizer + UBSan) and runs each
# for SECONDS (default 90), two at a time (TRIVOX_FUZZ_PARALLEL, default 2):
#   scripts/fuzz.sh [SECONDS] [TARGET...]     TARGETs: itd gismo_xml scene expression g2 pipeline
#                                             cache_entry (all)
# Seeds: fuzz/corpus/<target>/ (written for the fuzzers), the regression inputs
# fuzz/regressions/<target>/, and files staged from examples/ and tests/data/ at run time.
# New inputs go to build/fuzz/corpus/<target>/ (kept between runs), crash inputs to
# build/fuzz/artifacts/<target>/. Fails when any target reports a crash, a leak, undefined
# behaviour, a timeout (10 s per input) or an out-of-memory (2 GB). Ends with one line per
# target: seconds, executions, corpus size, findings; the same table goes to
# build/fuzz/summary.tsv. The random seed is fixed (TRIVOX_FUZZ_SEED, default 1) so that a
# run is repeatable: CI fails on the code, not on the luck of the draw. Set another seed to
# explore further.
set -euo pipefail
cd "$(dirname "$0")/.."

seconds="${1:-90}"
shift || true
targets=("$@")
[ "${#targets[@]}" -gt 0 ] || targets=(itd gismo_xml scene expression g2 pipeline cache_entry)
case "$seconds" in
  ''|*[!0-9]*) echo "fuzz.sh: SECONDS must be a whole number, got '$seconds'" >&2; exit 2 ;;
esac
jobs="${TRIVOX_JOBS:-$(nproc)}"
seed="${TRIVOX_FUZZ_SEED:-1}"
case "$seed" in
  ''|*[!0-9]*) echo "fuzz.sh: TRIVOX_FUZZ_SEED must be a whole number, got '$seed'" >&2; exit 2 ;;
esac

scripts/install-deps.sh
cmake --preset fuzz
cmake --build --preset fuzz --parallel "$jobs" --target "${targets[@]/#/fuzz_}"

# Seeds taken from files the repository already holds for other purposes.
stage_seeds() {
  local target="$1" dir="$2"
  rm -rf "$dir"
  mkdir -p "$dir"
  case "$target" in
    itd) cp examples/models/*.itd tests/data/models/*.itd tests/data/malformed/*.itd "$dir"/ ;;
    gismo_xml) cp tests/data/models/*.xml tests/data/malformed/*.xml "$dir"/ ;;
    scene) cp examples/scenes/*.json "$dir"/ ;;
    g2)
      cp tests/data/models/*.g2 tests/data/malformed/*.g2 "$dir"/
      # The real GoTools files, when ../shared is beside the repository (read, not copied into it).
      if [ -d ../shared/data/gotools ]; then cp ../shared/data/gotools/*.g2 "$dir"/; fi ;;
    pipeline | cache_entry) ;;  # fuzz/corpus/<target> holds their seeds
    expression)
      # Each fractions value of the example scenes, one file per expression.
      grep -ho '"Vero[A-Za-z]*": "[^"]*"' examples/scenes/*.json | sed 's/^[^:]*: "//; s/"$//' |
        awk -v dir="$dir" '{ print > (dir "/example_" NR ".txt") }' ;;
  esac
}

# The pipeline target's outcome per input (fuzz_pipeline.cpp), summarised at the end.
export TRIVOX_FUZZ_PIPELINE_LOG="$PWD/build/fuzz/pipeline_outcomes.tsv"
rm -f "$TRIVOX_FUZZ_PIPELINE_LOG"
export UBSAN_OPTIONS="halt_on_error=1:print_stacktrace=1"
export ASAN_OPTIONS="detect_leaks=1:allocator_may_return_null=0"
summary=build/fuzz/summary.tsv
printf 'target\tseconds\texecutions\tcorpus_files\tfindings\n' > "$summary"
# One target for SECONDS; its line goes to build/fuzz/<target>.row, its exit status to
# build/fuzz/<target>.status.
run_one() {
  local target="$1"
  local work="build/fuzz/corpus/$target" seeds="build/fuzz/seeds/$target" artifacts="build/fuzz/artifacts/$target/"
  rm -rf "$artifacts"  # findings are counted per run
  mkdir -p "$work" "$artifacts" "fuzz/regressions/$target"
  stage_seeds "$target" "$seeds"
  local log="build/fuzz/$target.log"
  echo "fuzz.sh: fuzz_$target for ${seconds}s (log: $log)"
  set +e
  "build/fuzz/fuzz/fuzz_$target" -max_total_time="$seconds" -seed="$seed" -timeout=10 -rss_limit_mb=2048 \
    -print_final_stats=1 -artifact_prefix="$artifacts" \
    "$work" "fuzz/corpus/$target" "fuzz/regressions/$target" "$seeds" > "$log" 2>&1
  local status=$?
  set -e
  local runs files findings
  runs=$(grep -o 'stat::number_of_executed_units: *[0-9]*' "$log" | grep -o '[0-9]*$' | tail -n 1 || true)
  files=$(find "$work" -type f | wc -l)
  findings=$(find "$artifacts" -type f | wc -l)
  printf '%s\t%s\t%s\t%s\t%s\n' "$target" "$seconds" "${runs:-?}" "$files" "$findings" > "build/fuzz/$target.row"
  echo "$status" > "build/fuzz/$target.status"
}

parallel="${TRIVOX_FUZZ_PARALLEL:-2}"
case "$parallel" in
  ''|*[!0-9]*|0) echo "fuzz.sh: TRIVOX_FUZZ_PARALLEL must be a whole number >= 1, got '$parallel'" >&2; exit 2 ;;
esac
running=0
for target in "${targets[@]}"; do
  run_one "$target" &
  running=$((running + 1))
  if [ "$running" -ge "$parallel" ]; then
    wait -n || true
    running=$((running - 1))
  fi
done
wait || true

failed=0
for target in "${targets[@]}"; do
  cat "build/fuzz/$target.row" >> "$summary"
  status=$(cat "build/fuzz/$target.status")
  if [ "$status" -ne 0 ]; then
    failed=1
    log="build/fuzz/$target.log"
    echo "fuzz.sh: fuzz_$target FAILED (exit $status); the report:" >&2
    grep -E -A 30 '^==[0-9]+==ERROR|runtime error|^SUMMARY|deadly signal|timeout|out-of-memory' "$log" | head -n 60 >&2 || tail -n 40 "$log" >&2
  fi
done

awk -F"\t" '{ printf "%-12s %8s %12s %12s %9s\n", $1, $2, $3, $4, $5 }' "$summary"
# Columns: outcome, pixels, seconds, heap growth (MB), the job's own estimate (MB), refusal.
if [ -s "$TRIVOX_FUZZ_PIPELINE_LOG" ]; then
  awk -F"\t" '{ n[$1]++; if ($3 > slow) { slow = $3; slow_px = $2 }
         if ($4 >= 0) { heap++; if ($4 > big) { big = $4; big_est = $5 }
                        if ($5 >= 16 && $4 / $5 > worst) worst = $4 / $5 } }
       END { printf "pipeline jobs: %d sliced, %d refused, %d too large, %d stopped; slowest %.2f s (%d px); heap measured for %d: largest growth %.1f MB (estimate %.1f MB), largest growth over estimate where that is 16 MB or more: %.2f\n",
                    n["sliced"], n["refused"], n["too-large"], n["stopped"], slow, slow_px, heap, big, big_est, worst }' "$TRIVOX_FUZZ_PIPELINE_LOG"
fi
exit "$failed"
