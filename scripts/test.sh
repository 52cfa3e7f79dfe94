#!/usr/bin/env bash
# The README's second command: installs what is missing, builds and runs the whole test suite.
#   scripts/test.sh                   release preset (build/release)
#   scripts/test.sh --sanitize        release, then asan (AddressSanitizer + UBSan, -Werror)
#   scripts/test.sh --sanitize-only   asan only (CI runs it after the plain command)
# Tests that need ../shared/data skip with a message when it is absent. Parallel jobs:
# TRIVOX_JOBS, default the number of processors. Ends with one summary line.
set -euo pipefail
cd "$(dirname "$0")/.."

case "${1:-}" in
  "") presets=(release) ;;
  --sanitize) presets=(release asan) ;;
  --sanitize-only) presets=(asan) ;;
  *) echo "test.sh: unknown option '$1' (expected --sanitize or --sanitize-only)" >&2; exit 2 ;;
esac
jobs="${TRIVOX_JOBS:-$(nproc)}"

scripts/install-deps.sh

summary=()
failed=0
for preset in "${presets[@]}"; do
  scripts/build.sh "$preset"
  log="build/$preset/ctest-output.log"
  set +e
  # Heavy checks run in the release pass only. Under the sanitizers these are left out (each
  # takes from 10 s to over 3 minutes there, on the real models of ../shared/data or twenty
  # whole jobs; the same code runs under the sanitizers on the bundled models): the pixel
  # decision's equivalence on the shared scenes and meshes and on the four largest bundled
  # examples (the smaller ones run it here), probe and info on every shared volume file, the
  # chalice, the duck, the teapot and the shared models sliced whole, the twenty kills at
  # random moments and the library's twenty stops at random layer counts (one stop and resume
  # runs under the sanitizers), the mesh containment property on a fine soup (the smaller ones
  # run there), every example sliced at several thread counts (the determinism of the
  # output, a release property; ThreadSanitizer checks the threads), the pipeline
  # fuzzer's checked-in inputs (scripts/fuzz.sh replays them under the same sanitizers), and
  # the documentation's transcripts and examples (scripts/check_docs.py: the program's text),
  # and the jobs submitted to a one-node Slurm (scripts/slurm_check.sh).
  exclude=()
  heavy='LayerDecision.*(shared_scenes|EveryMeshTrimAndRule)|CliSharedProbe\.|CliInfo\.ReadsEveryShared'
  heavy+='|LayerDecisionOfExample.*(column_scalar_gradient|column_greyscale_sl1s|twisted_column_porous|chalice)'
  heavy+='|CliInfo\.JacobianClassesMatchProvenance|FuzzInputs\..*/pipeline'
  heavy+='|Chalice\.|FillInterior\.SharedDuck|DuckTrimmedBox\.|TeapotTrimmedBox\.|SharedModels\.'
  heavy+='|CliKill\.TwentyKills|DeterminismOfExample\.|Docs\.|Cluster\.'
  heavy+='|JobResume\.StoppedAtTwentyRandomLayerCounts|ShellMesh\.ContainsAgreesWithTheWindingNumberOfAFinerSoup'
  [ "$preset" = asan ] && exclude=(-E "$heavy")
  ctest --preset "$preset" --parallel "$jobs" "${exclude[@]}" 2>&1 | tee "$log"
  status=${PIPESTATUS[0]}
  set -e
  result=$(grep -E 'tests passed|No tests were found' "$log" | tail -n 1 || true)
  summary+=("$preset: ${result:-ctest exited with status $status}")
  [ "$status" -eq 0 ] || failed=1
done

line="test.sh:"
separator=" "
for s in "${summary[@]}"; do
  line+="$separator$s"
  separator="; "
done
echo "$line"
exit "$failed"
