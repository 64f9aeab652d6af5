#!/usr/bin/env bash
# A real single-node Slurm cluster for the campaign test, on loopback, with
# its configuration, state, logs and munge key in one folder:
#   slurm_cluster.sh start DIR   starts munged, slurmctld and slurmd; waits
#                                until the node is idle; prints the
#                                SLURM_CONF to export
#   slurm_cluster.sh stop DIR    stops the three (by their pid files)
# Exit 77 from start when Slurm or munge is not installed.
set -euo pipefail
command="${1:?start|stop}"
dir="$(cd "${2:?DIR}" && pwd)"

stop_pid_file() {
  local file="$1"
  [ -f "$file" ] || return 0
  local pid
  pid="$(cat "$file")"
  if [ -n "$pid" ] && kill -0 "$pid" 2>/dev/null; then
    kill "$pid" 2>/dev/null || true
    for _ in $(seq 50); do
      kill -0 "$pid" 2>/dev/null || break
      sleep 0.1
    done
    kill -9 "$pid" 2>/dev/null || true
  fi
  rm -f "$file"
}

if [ "$command" = stop ]; then
  stop_pid_file "$dir/slurmd.pid"
  stop_pid_file "$dir/slurmctld.pid"
  stop_pid_file "$dir/munged.pid"
  exit 0
fi

PATH="$PATH:/usr/sbin:/sbin"
for program in munged slurmctld slurmd sbatch sinfo; do
  if ! command -v "$program" >/dev/null 2>&1; then
    echo "slurm_cluster: $program not installed (Debian: slurm-wlm, munge)" >&2
    exit 77
  fi
done

mkdir -p "$dir/munge" "$dir/state" "$dir/spool"
chmod 700 "$dir/munge"
# munge's key: random, readable by its owner alone.
dd if=/dev/urandom of="$dir/munge/munge.key" bs=1024 count=1 status=none
chmod 400 "$dir/munge/munge.key"
munged --force --socket="$dir/munge/munge.socket" \
  --key-file="$dir/munge/munge.key" --pid-file="$dir/munged.pid" \
  --log-file="$dir/munge/munged.log" --seed-file="$dir/munge/munged.seed"

# Free loopback ports for the two daemons.
read -r ctld_port slurmd_port < <(python3 - <<'PY'
import socket
ports = []
sockets = []
for _ in range(2):
    s = socket.socket()
    s.bind(("127.0.0.1", 0))
    sockets.append(s)
    ports.append(s.getsockname()[1])
print(*ports)
PY
)
cpus="$(nproc)"
# 90 % of the memory: slurmd drains a node that has less than it claims.
memory_mb="$(awk '/^MemTotal:/ {printf "%d", $2 / 1024 * 0.9}' /proc/meminfo)"
host="$(hostname -s)"
cat > "$dir/slurm.conf" <<CONF
ClusterName=zebrageo-test
SlurmctldHost=${host}(127.0.0.1)
SlurmUser=$(id -un)
SlurmdUser=$(id -un)
SlurmctldPort=${ctld_port}
SlurmdPort=${slurmd_port}
AuthType=auth/munge
CredType=cred/munge
AuthInfo=socket=${dir}/munge/munge.socket
StateSaveLocation=${dir}/state
SlurmdSpoolDir=${dir}/spool
SlurmctldPidFile=${dir}/slurmctld.pid
SlurmdPidFile=${dir}/slurmd.pid
SlurmctldLogFile=${dir}/slurmctld.log
SlurmdLogFile=${dir}/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
SelectType=select/cons_tres
SelectTypeParameters=CR_Core_Memory
SchedulerType=sched/backfill
MpiDefault=none
ReturnToService=2
MinJobAge=600
SlurmdTimeout=300
InactiveLimit=0
KillWait=10
PlugStackConfig=${dir}/plugstack.conf
NodeName=zebrageo-node NodeHostname=${host} NodeAddr=127.0.0.1 CPUs=${cpus} RealMemory=${memory_mb} State=UNKNOWN
PartitionName=test Nodes=zebrageo-node Default=YES MaxTime=INFINITE State=UP
CONF
: > "$dir/plugstack.conf"
export SLURM_CONF="$dir/slurm.conf"
slurmctld -f "$SLURM_CONF"
slurmd -f "$SLURM_CONF" -N zebrageo-node
for _ in $(seq 120); do
  state="$(sinfo -h -n zebrageo-node -o %T 2>/dev/null || true)"
  if [ "$state" = idle ]; then
    echo "$SLURM_CONF"
    exit 0
  fi
  sleep 0.5
done
echo "slurm_cluster: the node did not become idle (state '${state:-}'):" >&2
tail -n 20 "$dir/slurmctld.log" "$dir/slurmd.log" >&2 || true
exit 1
