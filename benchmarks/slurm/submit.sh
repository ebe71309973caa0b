#!/bin/bash
# Submits a sweep as a job array of N shards plus a merge job that runs when
# the whole array has ended (and refuses to merge incomplete shards).
#   benchmarks/slurm/submit.sh SWEEP.toml OUT N [sbatch options for the array tasks...]
# Environment: SFP (the sfp binary, default: sfp on PATH), SFP_MESH_DIR
# (meshes of presets a and b), both passed on to the jobs; SFP_CPUS (CPUs
# per task, default: the CPUs of the smallest node sinfo lists); sbatch's own
# SBATCH_PARTITION, SBATCH_ACCOUNT, … for options both jobs need.
# Job logs go to OUT/logs/.
set -euo pipefail
if [ $# -lt 3 ]; then
    echo "usage: $0 SWEEP.toml OUT N [sbatch options for the array tasks...]" >&2
    exit 2
fi
SWEEP="$(realpath "$1")"; OUT="$(realpath -m "$2")"; N="$3"; shift 3
if ! [[ "$N" =~ ^[1-9][0-9]*$ ]]; then
    echo "error: N must be a positive number of shards, not '$N'" >&2
    exit 2
fi
HERE="$(dirname "$(realpath "$0")")"
CPUS="${SFP_CPUS:-$(sinfo --noheader --format=%c | sort -n | head -n 1)}"
if ! [[ "$CPUS" =~ ^[1-9][0-9]*$ ]]; then
    echo "error: cannot tell the CPUs of a node (sinfo gave '$CPUS'): set SFP_CPUS" >&2
    exit 2
fi
mkdir -p "$OUT/logs"
ARRAY=$(sbatch --parsable --array="1-$N" --cpus-per-task="$CPUS" \
    --output="$OUT/logs/%x-%A_%a.out" "$@" "$HERE/sweep-array.sh" "$SWEEP" "$OUT" "$N")
ARRAY="${ARRAY%%;*}"
MERGE=$(sbatch --parsable --dependency="afterany:$ARRAY" --output="$OUT/logs/%x-%j.out" \
    "$HERE/merge.sh" "$OUT" "$N")
MERGE="${MERGE%%;*}"
echo "shards: job array $ARRAY (1-$N, $CPUS CPUs each) → $OUT/shards/K; merge: job $MERGE → $OUT/merged; logs: $OUT/logs"
echo "re-run task K: sbatch --array=K --cpus-per-task=$CPUS --output='$OUT/logs/%x-%A_%a.out' $* '$HERE/sweep-array.sh' '$SWEEP' '$OUT' $N"
echo "then merge:    sbatch --output='$OUT/logs/%x-%j.out' '$HERE/merge.sh' '$OUT' $N"
