#!/bin/sh
# A one-node Slurm cluster on localhost for tests: munged, slurmctld and slurmd
# started as daemons of this user with every file under DIR (nothing in /etc,
# /run or /var is touched, so it can run beside a system Slurm).
#
#   tests/hpc/slurm_cluster.sh start DIR   # prints "export SLURM_CONF=DIR/slurm.conf"
#   tests/hpc/slurm_cluster.sh stop DIR
#
# Exit status of start: 0 up (the node answers `sinfo` as idle), 77 cannot start
# here (the reason on stderr; CTest reports the test as skipped), 1 other error.
set -eu
cmd=${1:-}
dir=${2:-}
if [ -z "$cmd" ] || [ -z "$dir" ]; then
  echo "usage: $0 start|stop DIR" >&2
  exit 1
fi
skip() { echo "slurm_cluster: cannot start a one-node Slurm here: $*" >&2; exit 77; }

stop() {
  for f in "$dir/slurmd.pid" "$dir/slurmctld.pid" "$dir/munge/munged.pid"; do
    [ -f "$f" ] || continue
    pid=$(cat "$f" 2>/dev/null || true)
    [ -n "$pid" ] && kill "$pid" 2>/dev/null || true
  done
  # Give them a moment to leave, then make sure.
  sleep 1
  for f in "$dir/slurmd.pid" "$dir/slurmctld.pid" "$dir/munge/munged.pid"; do
    [ -f "$f" ] || continue
    pid=$(cat "$f" 2>/dev/null || true)
    [ -n "$pid" ] && kill -9 "$pid" 2>/dev/null || true
    rm -f "$f"
  done
}

# A TCP port nobody listens on (asked from the kernel), so that concurrent
# test clusters and a system Slurm never collide.
free_port() {
  python3 -c 'import socket; s=socket.socket(); s.bind(("127.0.0.1",0)); print(s.getsockname()[1])'
}

start() {
  for exe in munged slurmctld slurmd sinfo sbatch; do
    command -v "$exe" >/dev/null 2>&1 || [ -x "/usr/sbin/$exe" ] ||
      skip "'$exe' not found (install Debian's slurm-wlm and munge: scripts/install-deps.sh)"
  done
  PATH="$PATH:/usr/sbin"
  mkdir -p "$dir/munge" "$dir/state" "$dir/spool" "$dir/log"
  dir=$(cd "$dir" && pwd)
  chmod 700 "$dir/munge"
  # munged refuses group/world-readable keys and, as root, needs --force.
  head -c 1024 /dev/urandom > "$dir/munge/munge.key"
  chmod 600 "$dir/munge/munge.key"
  force=""
  [ "$(id -u)" -eq 0 ] && force="--force"
  munged $force --key-file="$dir/munge/munge.key" --socket="$dir/munge/munge.sock" \
    --pid-file="$dir/munge/munged.pid" --log-file="$dir/munge/munged.log" \
    --seed-file="$dir/munge/munged.seed" 2>"$dir/log/munged.err" ||
    skip "munged did not start: $(tail -n 2 "$dir/log/munged.err" "$dir/munge/munged.log" 2>/dev/null | tr '\n' ' ')"

  host=$(hostname -s)
  user=$(id -un)
  # RealMemory below the machine's, so that jobs may ask for --mem (slurmd
  # drains a node that has less memory than configured).
  mem_mb=$(awk '/^MemTotal:/ { print int($2 / 1024 * 0.8) }' /proc/meminfo)
  ctld_port=$(free_port)
  d_port=$(free_port)
  cat > "$dir/slurm.conf" <<CONF
# Written by tests/hpc/slurm_cluster.sh: a one-node test cluster on localhost.
ClusterName=milltest
SlurmctldHost=$host(127.0.0.1)
SlurmctldPort=$ctld_port
SlurmdPort=$d_port
SlurmUser=$user
SlurmdUser=$user
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=$dir/munge/munge.sock
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/log/slurmctld.log
SlurmdLogFile=$dir/log/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
MpiDefault=none
ReturnToService=2
MinJobAge=600
JobCompType=jobcomp/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
NodeName=$host NodeAddr=127.0.0.1 CPUs=$(nproc) RealMemory=$mem_mb State=UNKNOWN
PartitionName=test Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
  export SLURM_CONF="$dir/slurm.conf"
  slurmctld -f "$SLURM_CONF" 2>"$dir/log/slurmctld.err" ||
    { stop; skip "slurmctld did not start: $(tail -n 3 "$dir/log/slurmctld.err" "$dir/log/slurmctld.log" 2>/dev/null | tr '\n' ' ')"; }
  slurmd -f "$SLURM_CONF" -N "$host" 2>"$dir/log/slurmd.err" ||
    { stop; skip "slurmd did not start: $(tail -n 3 "$dir/log/slurmd.err" "$dir/log/slurmd.log" 2>/dev/null | tr '\n' ' ')"; }
  # Wait until the node registers as idle.
  i=0
  while [ $i -lt 60 ]; do
    state=$(sinfo -h -N -o '%T' 2>/dev/null | head -n 1 || true)
    case "$state" in idle*) echo "export SLURM_CONF=$SLURM_CONF"; return 0 ;; esac
    sleep 1
    i=$((i + 1))
  done
  msg="node state '$state' after 60 s: $(tail -n 3 "$dir/log/slurmd.log" "$dir/log/slurmctld.log" 2>/dev/null | tr '\n' ' ')"
  stop
  skip "$msg"
}

case "$cmd" in
  start) start ;;
  stop) stop ;;
  *) echo "usage: $0 start|stop DIR" >&2; exit 1 ;;
esac
