#!/usr/bin/env bash
# The cluster path on a real Slurm (docs/CLUSTER.md), on a one-node cluster started here
# (scripts/slurm_cluster.sh; its daemons stopped by pid at the end, however the check ends):
#
#   1. `trivox cluster slurm --submit` of a bundled scene in 4 shards, as Voxel Print PNGs and
#      a GrabCAD package (a stack format: the shards keep their layers, the merge job writes
#      it): the array, then merge and verify; every file of the merged folder, manifest.json
#      and the package included, is byte-identical to a one-process run's (stats.json and the
#      shards' stats.shard-I-of-N.json describe each run's own work and are left out);
#   2. a shard task signalled mid-job as Slurm signals one before its time limit (USR1): it
#      stops after its layers in progress, requeues itself, and its rerun resumes the shard;
#      the folder is again byte-identical to one process's;
#   3. a second machine: one shard runs as host `othernode` (`unshare --uts --pid`), is killed
#      mid-job, and a shard of this host resumes beside it: a temporary of `othernode` stays,
#      since no process of another machine can be judged from here; the merge removes it.
#
#   scripts/slurm_check.sh [TRIVOX]     (default build/release/bin/trivox)
#
# Exit 0 when every check passes, 1 naming the first that fails, 77 (skipped, with a
# message) where Slurm and munge are not installed or the user is not root. The release
# pass of the test suite runs it (Cluster.SlurmCheck); CI installs the packages first
# (scripts/install-deps.sh --slurm).
set -euo pipefail
cd "$(dirname "$0")/.."
trivox=$(realpath "${1:-build/release/bin/trivox}")
[ -x "$trivox" ] || { echo "slurm_check: no trivox program at $trivox" >&2; exit 1; }

work=$(mktemp -d "${TMPDIR:-/tmp}/trivox-slurm-XXXXXX")
cleanup() {
  scripts/slurm_cluster.sh stop "$work/cluster" || true
  rm -rf "$work"
}
trap cleanup EXIT

set +e
# MaxArraySize 3: a job of 4 shards goes in as two arrays (indices 1-2 with offsets 0 and 2).
env_line=$(TRIVOX_SLURM_MAX_ARRAY_SIZE=3 scripts/slurm_cluster.sh start "$work/cluster")
status=$?
set -e
[ "$status" -eq 77 ] && exit 77
[ "$status" -eq 0 ] || { echo "slurm_check: the one-node cluster did not start" >&2; exit 1; }
eval "$env_line"

fail() {
  echo "slurm_check: FAILED: $*" >&2
  for log in "$work"/*/slurm/*.log "$work"/*/slurm/*.out; do
    [ -f "$log" ] && { echo "--- $log" >&2; tail -n 15 "$log" >&2; }
  done
  exit 1
}

# Waits until Slurm has no job of these ids left, then checks that each COMPLETED.
wait_for_jobs() {
  local deadline=$((SECONDS + 240)) id state
  while [ -n "$(squeue -h -j "$(IFS=,; echo "$*")" 2>/dev/null)" ]; do
    [ "$SECONDS" -lt "$deadline" ] || fail "jobs $* still queued or running after 240 s"
    sleep 0.5
  done
  for id in "$@"; do
    state=$(scontrol show job "$id" 2>/dev/null | grep -o 'JobState=[A-Z_]*' | sort -u | tr '\n' ' ')
    [ "$state" = "JobState=COMPLETED " ] || fail "job $id ended as '$state'"
  done
}

# Submits the scene in N shards into DIR, with further job options; prints the job ids: the
# merge's, then the arrays'.
submit() {
  local scene=$1 dir=$2 shards=$3 out
  shift 3
  out=$("$trivox" cluster slurm "$scene" -o "$dir" --shards "$shards" -j 1 "$@" --submit) || fail "submit: $out"
  echo "$out" >&2
  sed -n 's/^submitted the shards as jobs\{0,1\} \(.*\) and the merge as job \([0-9]*\) .*/\2 \1/p' <<<"$out" | tr -d ','
}

# Every file of the one-process folder REF, but stats.json, is in DIR with the same bytes,
# and DIR holds no other file but the shards' statistics, the Slurm scripts and their logs.
same_as_one_process() {
  local ref=$1 dir=$2 name
  (cd "$ref" && find . -type f ! -name stats.json | sort) > "$work/ref.list"
  (cd "$dir" && find . -type f ! -name 'stats.*json' ! -path './slurm/*' ! -path './.trivox-cache/*' | sort) > "$work/dir.list"
  diff -u "$work/ref.list" "$work/dir.list" >&2 || fail "$dir does not hold the files of the one-process run"
  while read -r name; do
    cmp -s "$ref/$name" "$dir/$name" || fail "$dir/$name differs from the one-process run's"
  done < "$work/ref.list"
  "$trivox" verify "$dir" >/dev/null || fail "trivox verify $dir"
}

scene=$(realpath examples/scenes/quick_start.json)
"$trivox" slice "$scene" -o "$work/one" -q --format voxelprint gcvf > /dev/null

# 1. Four shards in two arrays, merged (the package written) and verified by the job that
# depends on both.
read -r merge arrays < <(submit "$scene" "$work/four" 4 --format voxelprint gcvf)
[ -n "${arrays:-}" ] || fail "no job ids from trivox cluster slurm --submit"
read -r -a arrays <<<"$arrays"
[ "${#arrays[@]}" -eq 2 ] || fail "4 shards at MaxArraySize 3 went in as ${#arrays[@]} arrays, not 2"
wait_for_jobs "${arrays[@]}" "$merge"
grep -q '^ok: ' "$work/four/slurm/merge-$merge.log" || fail "the merge job's verify did not say ok"
same_as_one_process "$work/one" "$work/four"
[ -f "$work/four/gcvf/stack.gcvf" ] && [ ! -e "$work/four/stack_parts" ] || fail "no package, or stack parts left"
echo "slurm_check: 4 shards through Slurm equal one process ($(wc -l < "$work/ref.list") files) ($SECONDS s)"

# 2. A task signalled as before its time limit: stop, requeue, resume.
slow=$(realpath examples/scenes/box_gradient.json)
"$trivox" slice "$slow" -o "$work/one-slow" -q > /dev/null
read -r merge array < <(submit "$slow" "$work/requeue" 2)
log="$work/requeue/slurm/shard-2.log"
deadline=$((SECONDS + 60))
until grep -q 'sliced [0-9]*/[0-9]* layers ([1-9][0-9]*%)' "$log" 2>/dev/null; do
  [ "$SECONDS" -lt "$deadline" ] || fail "shard 2 made no progress in 60 s"
  sleep 0.1
done
scancel --signal=USR1 --batch "${array}_2"
# Slurm makes a requeued job eligible two minutes later; the check does not wait for that.
deadline=$((SECONDS + 60))
until scontrol show job "${array}_2" 2>/dev/null | grep -q 'Reason=BeginTime'; do
  [ "$SECONDS" -lt "$deadline" ] || fail "shard 2 was not requeued within 60 s of the warning"
  sleep 0.2
done
scontrol update JobId="${array}_2" StartTime=now
wait_for_jobs "$array" "$merge"
grep -q 'stopped before the time limit; requeueing' "$log" || fail "shard 2 did not requeue itself"
grep -q 'resumed: [1-9][0-9]* layers\? w' "$log" || fail "the requeued shard 2 kept no layer"
same_as_one_process "$work/one-slow" "$work/requeue"
echo "slurm_check: a shard stopped by Slurm's warning, requeued and resumed, equals one process ($SECONDS s)"

# 3. A shard of another machine beside one of this machine.
if ! unshare --uts --pid --fork true 2>/dev/null; then
  echo "slurm_check: ok (the second host's check skipped: this machine does not allow unshare --uts --pid)"
  exit 0
fi
hosts="$work/hosts"
# A process of host othernode: its own UTS namespace (the host name) and PID namespace (its
# pids mean nothing here), killed with unshare.
as_othernode() { unshare --uts --pid --fork --kill-child=KILL bash -c 'hostname othernode && exec "$@"' bash "$@"; }
set +e
# (unshare itself in the background, so that $! is its pid and killing it kills the shard)
unshare --uts --pid --fork --kill-child=KILL bash -c 'hostname othernode && exec "$@"' bash \
  "$trivox" slice "$slow" -o "$hosts" --shard 1/2 -q > /dev/null 2>&1 &
othernode=$!
deadline=$((SECONDS + 30))
until [ -f "$hosts/manifest.shard-1-of-2.json" ] && [ -n "$(find "$hosts" -name 'slice_*.png' -print -quit)" ]; do
  [ "$SECONDS" -lt "$deadline" ] || break
  sleep 0.05
done
kill -KILL "$othernode"
wait "$othernode"
set -e
[ -f "$hosts/manifest.shard-1-of-2.json" ] || fail "the shard of othernode wrote no manifest before it was killed"
grep -q 'host=othernode' "$hosts/.trivox-shard-1.lock" 2>/dev/null ||
  [ ! -e "$hosts/.trivox-shard-1.lock" ] || fail "the killed shard's lock does not name host othernode"
left="$hosts/slice_00001.png.tmp-999999-0@othernode"
echo partial > "$left"
"$trivox" slice "$slow" -o "$hosts" --shard 2/2 -q > /dev/null
"$trivox" slice "$slow" -o "$hosts" --shard 2/2 -q --resume > /dev/null
[ -f "$left" ] || fail "a resumed shard of this host removed a temporary of host othernode"
as_othernode "$trivox" slice "$slow" -o "$hosts" --shard 1/2 -q --resume > /dev/null || fail "othernode's shard did not resume"
"$trivox" merge "$hosts" > /dev/null || fail "merge of the two hosts' shards"
[ ! -e "$left" ] || fail "the merge left othernode's stale temporary"
same_as_one_process "$work/one-slow" "$hosts"
echo "slurm_check: shards of two hosts, one killed and resumed, equal one process ($SECONDS s)"
echo "slurm_check: ok ($SECONDS s)"
