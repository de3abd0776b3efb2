#!/usr/bin/env bash
# Runs a command on a Slurm cluster of one node (this machine), started in DIR from Debian's
# slurmctld, slurmd and munge and stopped after it: SLURM_CONF points the command's sbatch and
# squeue at it. For the tests of examples/shards; needs root (slurmd starts the jobs).
# usage: single_node_slurm.sh DIR command...
set -euo pipefail
[ $# -ge 2 ] || { echo "usage: $0 DIR command..." >&2; exit 2; }
dir=$(mkdir -p "$1" && cd "$1" && pwd)
shift
for p in munged slurmctld slurmd sbatch; do
    command -v "$p" >/dev/null || [ -x "/usr/sbin/$p" ] ||
        { echo "$0: $p is not installed (tools/setup.sh --tests installs it)" >&2; exit 3; }
done
export PATH="$PATH:/usr/sbin"
mkdir -p "$dir"/{state,spool,munge}
chmod 700 "$dir/munge"
# Ports of this run's own, so that a cluster left by another run cannot answer.
port=$((20000 + ($$ % 20000) * 2))
host=$(hostname -s)

dd if=/dev/urandom of="$dir/munge/key" bs=128 count=1 2>/dev/null
chmod 600 "$dir/munge/key"
cat >"$dir/slurm.conf" <<EOF
ClusterName=dayflux-test
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
SlurmctldPort=$port
SlurmdPort=$((port + 1))
AuthType=auth/munge
AuthInfo=socket=$dir/munge/socket
StateSaveLocation=$dir/state
SlurmdSpoolDir=$dir/spool
SlurmctldPidFile=$dir/slurmctld.pid
SlurmdPidFile=$dir/slurmd.pid
SlurmctldLogFile=$dir/slurmctld.log
SlurmdLogFile=$dir/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
SchedulerType=sched/builtin
SchedulerParameters=sched_min_interval=0,batch_sched_delay=0
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
MpiDefault=none
JobCompType=jobcomp/none
AccountingStorageType=accounting_storage/none
NodeName=$host CPUs=$(nproc) State=UNKNOWN
PartitionName=test Nodes=ALL Default=YES MaxTime=INFINITE State=UP
EOF
export SLURM_CONF=$dir/slurm.conf

stop() {
    for pid in slurmd.pid slurmctld.pid munge/pid; do
        [ -s "$dir/$pid" ] && kill "$(cat "$dir/$pid")" 2>/dev/null || true
    done
}
trap stop EXIT
munged --force --key-file="$dir/munge/key" --socket="$dir/munge/socket" \
    --pid-file="$dir/munge/pid" --log-file="$dir/munge/log" --seed-file="$dir/munge/seed"
slurmctld -f "$SLURM_CONF"
slurmd -f "$SLURM_CONF"
for _ in $(seq 1 60); do
    [ "$(sinfo -h -o %t 2>/dev/null)" = idle ] && break
    sleep 0.5
done
[ "$(sinfo -h -o %t 2>/dev/null)" = idle ] || {
    echo "$0: the node did not come up; logs in $dir" >&2
    exit 3
}
"$@"
