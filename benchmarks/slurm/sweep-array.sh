#!/bin/bash
# One shard of a sweep per job-array task: task K runs `--shard K/N` into
# OUT/shards/K. Submitted by submit.sh; one task again (it resumes):
#   sbatch --array=K --output=OUT/logs/%x-%A_%a.out sweep-array.sh SWEEP OUT N
# N is given, not taken from the array: an array of the one task K to redo
# still runs shard K of N. CPUs per task: submit.sh asks for what a node has.
#SBATCH --job-name=sfp-sweep
#SBATCH --time=04:00:00
set -euo pipefail
if [ $# -ne 3 ]; then
    echo "usage: sbatch --array=1-N $0 SWEEP.toml OUT N" >&2
    exit 2
fi
SWEEP="$1"; OUT="$2"; N="$3"
K="${SLURM_ARRAY_TASK_ID:?run as a job array task (sbatch --array=1-N)}"
SFP="${SFP:-sfp}"
# The methods run in parallel inside; use the CPUs Slurm gave this task.
export RAYON_NUM_THREADS="${SLURM_CPUS_PER_TASK:-1}"
exec "$SFP" bench "$SWEEP" --out "$OUT/shards/$K" --shard "$K/$N"
