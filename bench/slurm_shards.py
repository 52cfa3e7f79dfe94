#!/usr/bin/env python3
"""One job as 1, 2 and 4 shards on a one-node Slurm (docs/CLUSTER.md): wall, CPU, imbalance.

Starts the one-node cluster of scripts/slurm_cluster.sh on this machine (root, with Debian's
slurm-wlm and munge), and for each shard count submits SCENE with `trivox cluster slurm
--submit` (-j: the machine's cores over the shards, at least 1), waits for the shards and the
merge, and prints:

- wall: from the start of the first shard task to the end of the merge job (Slurm's own start and end times of the
  tasks, from `scontrol show job`, so the 1-second polling does not count);
- each shard's run time (the `seconds` of its stats.shard-I-of-N.json, or stats.json for one
  shard) and the imbalance, the slowest shard over the mean;
- layer CPU: every layer's time summed over the shards (a layer runs on one thread, so this is
  the CPU time of the slicing; the scene's reading and the writing of the folder's
  whole-job files are not in it), and per inside voxel.

    bench/slurm_shards.py [--trivox build/release/bin/trivox]
        [--scene examples/shared_scenes/duck.json] [--shards 1,2,4] [--layers FIRST:LAST]
        [--format F ...] [--keep]

and the merge job's own time (merge, the stack outputs' resume for a stack format, verify).

Exit 77 with a message where the cluster cannot start (no packages, not root); exit 1 when a
job does not complete.
"""
import argparse
import json
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
from datetime import datetime

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def run(cmd, **kw):
    return subprocess.run(cmd, check=True, text=True, capture_output=True, **kw).stdout


def job_times(job_id, env):
    """(earliest start, latest end) of a job's records (an array's tasks included), seconds."""
    text = run(["scontrol", "show", "job", job_id], env=env)
    fmt = "%Y-%m-%dT%H:%M:%S"
    starts = [datetime.strptime(s, fmt).timestamp() for s in re.findall(r"StartTime=(\S+)", text)]
    ends = [datetime.strptime(s, fmt).timestamp() for s in re.findall(r"EndTime=(\S+)", text)]
    return min(starts), max(ends)


def wait_for(ids, env, limit_s):
    deadline = time.time() + limit_s
    while run(["squeue", "-h", "-j", ",".join(ids)], env=env).strip():
        if time.time() > deadline:
            sys.exit(f"slurm_shards: jobs {ids} still running after {limit_s} s")
        time.sleep(1)
    for i in ids:
        states = set(re.findall(r"JobState=(\w+)", run(["scontrol", "show", "job", i], env=env)))
        if states != {"COMPLETED"}:
            sys.exit(f"slurm_shards: job {i} ended as {states}; its logs are in the job's slurm/ folder")


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--trivox", default=os.path.join(ROOT, "build/release/bin/trivox"))
    ap.add_argument("--scene", default=os.path.join(ROOT, "examples/shared_scenes/duck.json"))
    ap.add_argument("--shards", default="1,2,4")
    ap.add_argument("--layers", default="")
    ap.add_argument("--format", nargs="+", default=[], help="the job's formats (default: trivox's, voxelprint)")
    ap.add_argument("--limit-s", type=int, default=3600)
    ap.add_argument("--keep", action="store_true", help="keep the work folder (the jobs' logs)")
    a = ap.parse_args()
    trivox, scene = os.path.abspath(a.trivox), os.path.abspath(a.scene)
    cores = os.cpu_count() or 1
    work = tempfile.mkdtemp(prefix="trivox-slurm-bench-")
    cluster = os.path.join(work, "cluster")
    start = subprocess.run([os.path.join(ROOT, "scripts/slurm_cluster.sh"), "start", cluster], text=True,
                           capture_output=True)
    if start.returncode == 77:
        print(start.stderr.strip())
        shutil.rmtree(work, ignore_errors=True)
        return 77
    if start.returncode != 0:
        sys.exit("slurm_shards: the one-node cluster did not start: " + start.stderr)
    env = dict(os.environ, SLURM_CONF=os.path.join(cluster, "slurm.conf"))
    rows = []
    try:
        for n in [int(s) for s in a.shards.split(",")]:
            out_dir = os.path.join(work, f"shards-{n}")
            threads = max(1, cores // n)
            cmd = [trivox, "cluster", "slurm", scene, "-o", out_dir, "--shards", str(n), "-j", str(threads),
                   "--submit"]
            if a.layers:
                cmd += ["--layers", a.layers]
            if a.format:
                cmd += ["--format"] + a.format
            answer = run(cmd, env=env)
            m = re.search(r"submitted the shards as jobs? ([\d, ]+) and the merge as job (\d+)", answer)
            if not m:
                sys.exit("slurm_shards: no job ids in: " + answer)
            arrays, merge = [s.strip() for s in m.group(1).split(",")], m.group(2)
            wait_for(arrays + [merge], env, a.limit_s)
            first = min(job_times(i, env)[0] for i in arrays)
            merge_start, merge_end = job_times(merge, env)
            wall = merge_end - first
            names = ["stats.json"] if n == 1 else [f"stats.shard-{i}-of-{n}.json" for i in range(1, n + 1)]
            shard_s, layer_cpu, inside = [], 0.0, 0
            for name in names:
                with open(os.path.join(out_dir, name)) as f:
                    st = json.load(f)
                shard_s.append(st["total"]["seconds"])
                layer_cpu += sum(layer["seconds"] for layer in st["layers"])
                inside += st["total"]["pixels_inside"]
            mean = sum(shard_s) / len(shard_s)
            rows.append((n, threads, wall, max(shard_s), mean, max(shard_s) / mean, layer_cpu, inside))
            print(f"{n} shard(s) x {threads} thread(s): wall {wall:.0f} s (first shard start to the merge end), "
                  f"shards {min(shard_s):.1f}-{max(shard_s):.1f} s (mean {mean:.1f}, imbalance {max(shard_s) / mean:.3f}), "
                  f"layer CPU {layer_cpu:.1f} s = {layer_cpu / max(inside, 1) * 1e9:.1f} ns per inside voxel "
                  f"({inside} inside voxels); the merge job {merge_end - merge_start:.0f} s", flush=True)
            shutil.rmtree(out_dir, ignore_errors=True)
    finally:
        subprocess.run([os.path.join(ROOT, "scripts/slurm_cluster.sh"), "stop", cluster])
        if a.keep:
            print(f"slurm_shards: the work folder is {work}")
        else:
            shutil.rmtree(work, ignore_errors=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
