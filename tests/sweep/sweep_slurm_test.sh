#!/usr/bin/env bash
# SPDX-License-Identifier: MIT
# `rheofeed sweep --backend slurm --submit` against a real one-node Slurm started here: a private
# munged (its own key and socket) and slurmctld + slurmd on localhost (proctrack/linuxproc,
# task/none, no cgroups, no accounting), configured in WORK_DIR/cluster and stopped at the end.
# The tiny sweep runs as a job array of 2 tasks (3 + 1 jobs, --jobs-per-task 3) with the collect
# job after it (afterany); every record must be "ok" and sweep.csv identical to REFERENCE_CSV (the
# local backend's). Exit code 77 (ctest: skipped) with the reason when the cluster cannot start:
# not root, the Debian packages slurm-wlm and munge missing, or a daemon that does not come up.
#   bash sweep_slurm_test.sh RHEOFEED SPEC WORK_DIR REFERENCE_CSV
set -uo pipefail
bin=$1 spec=$2 work=$3 reference=$4
cluster="$work/cluster"
skip() {
  echo "SKIPPED: $*"
  exit 77
}
logs() {
  for f in "$cluster"/*.log "$work"/sweep.log "$work"/sweep/slurm/submit_1/logs/*; do
    [ -f "$f" ] && { echo "--- $f"; tail -n 30 "$f"; }
  done
}
fail() {
  echo "FAIL: $*"
  logs
  exit 1
}
[ "$(id -u)" -eq 0 ] || skip "slurmd must run as root to start jobs; run the tests as root"
for c in munged slurmctld slurmd sbatch squeue sinfo scontrol; do
  command -v "$c" > /dev/null || skip "$c not found (Debian packages slurm-wlm and munge; .ci/deps installs them)"
done

# The daemons, stopped whatever happens.
stop() {
  SLURM_CONF="$cluster/slurm.conf" scontrol shutdown > /dev/null 2>&1
  for p in slurmd slurmctld munged; do
    [ -f "$cluster/$p.pid" ] && kill "$(cat "$cluster/$p.pid")" 2> /dev/null
  done
  sleep 1
  for p in slurmd slurmctld munged; do
    [ -f "$cluster/$p.pid" ] && kill -9 "$(cat "$cluster/$p.pid")" 2> /dev/null
  done
  return 0
}
rm -rf "$work"
mkdir -p "$cluster/state" "$cluster/spool"
chmod 700 "$work" "$cluster"
trap stop EXIT

# Two free TCP ports for slurmctld and slurmd.
free_port() {
  local p
  for p in $(seq "$1" $(($1 + 500))); do
    (echo > "/dev/tcp/127.0.0.1/$p") 2> /dev/null || { echo "$p"; return; }
  done
}
ctld_port=$(free_port $((20000 + $$ % 20000)))
slurmd_port=$(free_port $((ctld_port + 1)))
host=$(hostname -s)

head -c 1024 /dev/urandom > "$cluster/munge.key"
chmod 400 "$cluster/munge.key"
munged --force --socket="$cluster/munge.socket" --key-file="$cluster/munge.key" \
  --pid-file="$cluster/munged.pid" --seed-file="$cluster/munged.seed" \
  --log-file="$cluster/munged.log" || { logs; skip "munged did not start"; }

: > "$cluster/plugstack.conf"
cat > "$cluster/slurm.conf" << CONF
ClusterName=rheofeedtest
SlurmctldHost=$host
SlurmUser=root
SlurmdUser=root
SlurmctldPort=$ctld_port
SlurmdPort=$slurmd_port
AuthType=auth/munge
AuthInfo=socket=$cluster/munge.socket
CredType=cred/munge
StateSaveLocation=$cluster/state
SlurmdSpoolDir=$cluster/spool
SlurmctldPidFile=$cluster/slurmctld.pid
SlurmdPidFile=$cluster/slurmd.pid
SlurmctldLogFile=$cluster/slurmctld.log
SlurmdLogFile=$cluster/slurmd.log
PlugStackConfig=$cluster/plugstack.conf
MailProg=/bin/true
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
MpiDefault=none
SwitchType=switch/none
SchedulerType=sched/backfill
SelectType=select/cons_tres
SelectTypeParameters=CR_Core
ReturnToService=2
NodeName=$host NodeAddr=127.0.0.1 CPUs=$(nproc) State=UNKNOWN
PartitionName=test Nodes=$host Default=YES MaxTime=INFINITE State=UP
CONF
export SLURM_CONF="$cluster/slurm.conf"
slurmctld -f "$SLURM_CONF" || { logs; skip "slurmctld did not start"; }
slurmd -f "$SLURM_CONF" || { logs; skip "slurmd did not start"; }
state=""
for _ in $(seq 1 120); do
  state=$(sinfo -h -o %t 2> /dev/null)
  [ "$state" = idle ] && break
  sleep 0.5
done
[ "$state" = idle ] || { logs; skip "the node did not become idle (state '$state')"; }
echo "one-node Slurm up: $host, slurmctld port $ctld_port, slurmd port $slurmd_port"

# The sweep as a job array of two tasks, and its collect job.
"$bin" sweep "$spec" --backend slurm --submit --jobs-per-task 3 --out "$work/sweep" \
  > "$work/sweep.log" 2>&1 || fail "rheofeed sweep --backend slurm --submit exited with $?"
cat "$work/sweep.log"
submit="$work/sweep/slurm/submit_1"
[ "$(wc -l < "$submit/tasks.txt")" -eq 2 ] || fail "tasks.txt has not 2 tasks: $(cat "$submit/tasks.txt")"
grep -q -- '--array=0-1' "$submit/array.sh" || fail "array.sh is not an array of 2 tasks"
collect_job=$(cat "$submit/collect.jobid")
# Until the collect job has left the queue (the bound only keeps a stuck cluster from hanging
# the test).
for _ in $(seq 1 1800); do
  [ -z "$(squeue -h -j "$collect_job" 2> /dev/null)" ] && break
  sleep 0.5
done
[ -z "$(squeue -h -j "$collect_job" 2> /dev/null)" ] && [ -f "$submit/logs/collect.out" ] ||
  fail "the collect job $collect_job did not end"
cat "$submit/logs/collect.out"
grep -q 'collect: 4 of 4 jobs finished' "$submit/logs/collect.out" || fail "collect did not find 4 finished jobs"
[ "$(grep -l '"status": "ok"' "$work/sweep/records/"*.json | wc -l)" -eq 4 ] || fail "not 4 ok records"
cmp "$reference" "$work/sweep/results/sweep.csv" || fail "sweep.csv differs from the local backend's"
echo "Slurm sweep: 4 jobs in 2 array tasks, collected after the array; sweep.csv identical to the local backend's"
