#!/bin/bash
# One shard of a sweep per job-array task: task K of N runs `--shard K/N`
# into its own folder. Submitted by submit.sh; see benchmarks/README.md.
#SBATCH --job-name=sfp-sweep
#SBATCH --cpus-per-task=8
#SBATCH --time=04:00:00
#SBATCH --output=%x-%A_%a.out
set -euo pipefail
: "${SWEEP:?set SWEEP to the sweep file}" "${OUT:?set OUT to the output folder}"
SFP="${SFP:-sfp}"
N="${SLURM_ARRAY_TASK_COUNT:?run as a job array (sbatch --array=1-N)}"
K="${SLURM_ARRAY_TASK_ID:?run as a job array (sbatch --array=1-N)}"
# The methods run in parallel inside; use the CPUs Slurm gave this task.
export RAYON_NUM_THREADS="${SLURM_CPUS_PER_TASK:-1}"
# Re-running a failed or pre-empted task resumes its shard.
exec "$SFP" bench "$SWEEP" --out "$OUT/shards/$K" --shard "$K/$N"
