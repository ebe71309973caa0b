#!/bin/bash
# The cluster path on a real Slurm: starts a one-node cluster on this
# machine (munge + slurmctld + slurmd, Debian's slurm-wlm, installed when
# missing; needs root), submits benchmarks/sweeps/smoke.toml through
# submit.sh with no extra options, re-runs one task and the merge the way
# benchmarks/README.md documents, and compares the merged results.csv with
# the unsharded run byte for byte. Stops the daemons it started.
#   benchmarks/slurm/ci-test.sh [path/to/sfp]   (default: target/release/sfp)
set -euo pipefail
ROOT="$(cd "$(dirname "$0")/../.." && pwd)"
SFP="$(realpath "${1:-$ROOT/target/release/sfp}")"
export SFP
START=$SECONDS
TIMEOUT=90 # seconds to wait for one round of jobs
if [ "$(id -u)" -ne 0 ]; then
    echo "slurm test: skipped (needs root to start a cluster)"
    exit 0
fi
if ! command -v slurmctld >/dev/null || ! command -v munged >/dev/null; then
    echo "slurm test: installing slurm-wlm and munge"
    DEBIAN_FRONTEND=noninteractive apt-get install -y -qq slurm-wlm munge >/dev/null
fi

WORK="$(mktemp -d /tmp/sfp-slurm.XXXXXX)"
chmod 755 "$WORK"
PIDS=()
stop() {
    for pid in "${PIDS[@]}"; do kill "$pid" 2>/dev/null || true; done
    for pid in "${PIDS[@]}"; do
        while kill -0 "$pid" 2>/dev/null; do sleep 0.1; done
    done
    echo "slurm test: daemons stopped"
    rm -rf "$WORK"
}
trap stop EXIT

# munge: its own key and socket, so a machine's munge is left alone.
mkdir -p "$WORK/munge"
chown munge: "$WORK/munge" && chmod 711 "$WORK/munge"
dd if=/dev/urandom of="$WORK/munge/munge.key" bs=1024 count=1 status=none
chown munge: "$WORK/munge/munge.key" && chmod 400 "$WORK/munge/munge.key"
SOCKET="$WORK/munge/munge.socket"
runuser -u munge -- munged --key-file="$WORK/munge/munge.key" --socket="$SOCKET" \
    --pid-file="$WORK/munge/munged.pid" --log-file="$WORK/munge/munged.log" \
    --seed-file="$WORK/munge/munged.seed"
for _ in $(seq 50); do [ -s "$WORK/munge/munged.pid" ] && break; sleep 0.1; done
PIDS+=("$(cat "$WORK/munge/munged.pid")")

HOST="$(hostname -s)"
CPUS="$(nproc)"
mkdir -p "$WORK/state" "$WORK/spool"
export SLURM_CONF="$WORK/slurm.conf"
cat >"$SLURM_CONF" <<CONF
ClusterName=sfp-ci
SlurmctldHost=$HOST
SlurmUser=root
SlurmdUser=root
AuthType=auth/munge
AuthInfo=socket=$SOCKET
CredType=cred/munge
SlurmctldPort=17817
SlurmdPort=17818
StateSaveLocation=$WORK/state
SlurmdSpoolDir=$WORK/spool
SlurmctldPidFile=$WORK/slurmctld.pid
SlurmdPidFile=$WORK/slurmd.pid
SlurmctldLogFile=$WORK/slurmctld.log
SlurmdLogFile=$WORK/slurmd.log
ProctrackType=proctrack/linuxproc
TaskPlugin=task/none
JobAcctGatherType=jobacct_gather/none
AccountingStorageType=accounting_storage/none
JobCompType=jobcomp/none
MpiDefault=none
SelectType=select/cons_tres
SelectTypeParameters=CR_CPU
SchedulerType=sched/builtin
ReturnToService=2
NodeName=$HOST CPUs=$CPUS State=UNKNOWN
PartitionName=ci Nodes=$HOST Default=YES MaxTime=INFINITE State=UP
CONF
slurmctld -i
slurmd
for _ in $(seq 50); do
    [ -s "$WORK/slurmctld.pid" ] && [ -s "$WORK/slurmd.pid" ] && break
    sleep 0.1
done
PIDS+=("$(cat "$WORK/slurmd.pid")" "$(cat "$WORK/slurmctld.pid")")
for _ in $(seq 100); do
    sinfo --noheader --format=%T 2>/dev/null | grep -q idle && break
    sleep 0.2
done
sinfo

# Waits for every job to leave the queue, at most TIMEOUT seconds.
wait_queue() {
    local until=$((SECONDS + TIMEOUT))
    while [ -n "$(squeue --noheader --format=%i)" ]; do
        if [ $SECONDS -gt $until ]; then
            squeue
            echo "slurm test: FAILED, jobs still queued after ${TIMEOUT} s" >&2
            exit 1
        fi
        sleep 0.5
    done
}

SMOKE="$ROOT/benchmarks/sweeps/smoke.toml"
"$SFP" bench "$SMOKE" --out "$WORK/whole" >/dev/null
OUT="$WORK/cluster"
cd "$WORK" # the submission directory: no log may land here
"$ROOT/benchmarks/slurm/submit.sh" "$SMOKE" "$OUT" 2 | tee "$WORK/submitted.txt"
wait_queue
ls "$OUT/logs"
cmp "$OUT/merged/results.csv" "$WORK/whole/results.csv"
echo "slurm test: merged results.csv = unsharded results.csv ($(wc -l <"$OUT/merged/results.csv") lines)"
if ls "$WORK"/*.out 2>/dev/null; then
    echo "slurm test: FAILED, job logs in the submission directory" >&2
    exit 1
fi

# A lost task: the merge refuses; re-run as documented, it resumes and merges.
rm -rf "$OUT/shards/2" "$OUT/merged"
RERUN="$(sed -n 's/^re-run task K: //p' "$WORK/submitted.txt")"
MERGE="$(sed -n 's/^then merge: *//p' "$WORK/submitted.txt")"
eval "$MERGE" >/dev/null
wait_queue
if [ -e "$OUT/merged/results.csv" ]; then
    echo "slurm test: FAILED, the merge ran with a shard missing" >&2
    exit 1
fi
grep -h "task 2 failed or never ran" "$OUT"/logs/sfp-merge-*.out
eval "${RERUN/--array=K/--array=2}" >/dev/null
wait_queue
eval "$MERGE" >/dev/null
wait_queue
cmp "$OUT/merged/results.csv" "$WORK/whole/results.csv"
echo "slurm test: task 2 re-run and merged again: results.csv identical"
echo "slurm test: passed in $((SECONDS - START)) s"
cd "$ROOT"
