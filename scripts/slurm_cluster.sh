#!/usr/bin/env bash
# A one-node Slurm cluster on this machine, for scripts/slurm_check.sh and for trying
# docs/CLUSTER.md by hand: Debian's munged, slurmctld and slurmd, started without systemd
# from a configuration in a folder of their own, and stopped by the pids they were started
# with (never anything else).
#
#   scripts/slurm_cluster.sh start DIR   writes DIR/slurm.conf, starts the three daemons,
#                                        waits until the node takes jobs; prints the
#                                        `export SLURM_CONF=...` line the clients need
#   scripts/slurm_cluster.sh stop DIR    stops the daemons DIR/*.pid name
#
# TRIVOX_SLURM_MAX_ARRAY_SIZE sets the cluster's MaxArraySize (default Slurm's 1001).
# Needs root (SlurmUser=root; munged runs as the user who starts it, with --force) and the
# packages slurm-wlm and munge (scripts/install-deps.sh --slurm). The ports are chosen free
# at start. Exit status 77 (skip) when the packages or root are missing.
set -euo pipefail

usage() { echo "usage: scripts/slurm_cluster.sh start|stop DIR" >&2; exit 2; }
[ $# -eq 2 ] || usage
action=$1
dir=$(realpath -m "$2")

stop_cluster() {
  local name pid
  for name in slurmd slurmctld munged; do
    [ -f "$dir/$name.pid" ] || continue
    pid=$(cat "$dir/$name.pid")
    if [ -n "$pid" ] && kill -0 "$pid" 2>/dev/null; then
      kill "$pid" 2>/dev/null || true
      for _ in $(seq 1 50); do kill -0 "$pid" 2>/dev/null || break; sleep 0.1; done
      kill -9 "$pid" 2>/dev/null || true
    fi
    rm -f "$dir/$name.pid"
  done
}

# A TCP port nobody listens on, from the range above 20000.
free_port() {
  python3 - <<'EOF'
import socket
s = socket.socket()
s.bind(("127.0.0.1", 0))
print(s.getsockname()[1])
EOF
}

start_cluster() {
  for program in munged mungekey slurmctld slurmd sbatch; do
    if ! command -v "$program" >/dev/null 2>&1; then
      echo "slurm_cluster: skipped: $program is not installed (scripts/install-deps.sh --slurm installs slurm-wlm and munge)" >&2
      exit 77
    fi
  done
  if [ "$(id -u)" -ne 0 ]; then
    echo "slurm_cluster: skipped: the one-node cluster runs its daemons as root (SlurmUser=root)" >&2
    exit 77
  fi
  mkdir -p "$dir/state" "$dir/spool" "$dir/munge"
  chmod 700 "$dir" "$dir/munge"
  mungekey --create --keyfile="$dir/munge/munge.key" --force >/dev/null 2>&1 ||
    dd if=/dev/urandom of="$dir/munge/munge.key" bs=1024 count=1 status=none
  chmod 600 "$dir/munge/munge.key"
  munged --force --foreground --socket="$dir/munge/munge.socket" --key-file="$dir/munge/munge.key" \
    --pid-file="$dir/munge/munged.pidfile" --log-file="$dir/munged.log" --seed-file="$dir/munge/munged.seed" </dev/null >>"$dir/munged.log" 2>&1 &
  echo $! > "$dir/munged.pid"

  local host cpus memory_mb
  host=$(hostname -s)
  cpus=$(nproc)
  memory_mb=$(awk '/MemTotal/ { print int($2 / 1024 * 0.8) }' /proc/meminfo)
  cat > "$dir/slurm.conf" <<EOF
# A one-node cluster for trivox's checks (scripts/slurm_cluster.sh): no systemd, no cgroups.
ClusterName=trivox
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$(free_port)
SlurmdPort=$(free_port)
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$dir/munge/munge.socket
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pidfile
SlurmdPidFile=$dir/slurmd.pidfile
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
MpiDefault=none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
ReturnToService=2
MaxArraySize=${TRIVOX_SLURM_MAX_ARRAY_SIZE:-1001}
KillWait=30
SlurmdTimeout=60
MinJobAge=600
NodeName=$host NodeAddr=127.0.0.1 CPUs=$cpus RealMemory=$memory_mb State=UNKNOWN
PartitionName=check Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
  export SLURM_CONF="$dir/slurm.conf"
  # munged first: the others authenticate through its socket.
  for _ in $(seq 1 50); do [ -S "$dir/munge/munge.socket" ] && break; sleep 0.1; done
  slurmctld -D -i -f "$dir/slurm.conf" </dev/null >>"$dir/slurmctld.log" 2>&1 &
  echo $! > "$dir/slurmctld.pid"
  slurmd -D -f "$dir/slurm.conf" -N "$host" </dev/null >>"$dir/slurmd.log" 2>&1 &
  echo $! > "$dir/slurmd.pid"
  for _ in $(seq 1 300); do
    if sinfo -h -N -o '%T' 2>/dev/null | grep -Eq '^(idle|mixed|allocated)'; then
      echo "export SLURM_CONF=$dir/slurm.conf"
      return 0
    fi
    sleep 0.2
  done
  echo "slurm_cluster: the node did not come up in 60 s; the logs: $dir/*.log" >&2
  tail -n 20 "$dir"/slurmctld.log "$dir"/slurmd.log >&2 || true
  stop_cluster
  exit 1
}

case "$action" in
  start) start_cluster ;;
  stop) stop_cluster ;;
  *) usage ;;
esac
