#!/bin/bash
# Submits a sweep as a job array of N shards plus a dependent merge job.
#   benchmarks/slurm/submit.sh SWEEP.toml OUT N [extra sbatch options...]
# Environment: SFP (the sfp binary, default: sfp on PATH), SFP_MESH_DIR
# (meshes of presets a and b), both passed on to the jobs.
set -euo pipefail
if [ $# -lt 3 ]; then
    echo "usage: $0 SWEEP.toml OUT N [sbatch options...]" >&2
    exit 2
fi
SWEEP="$(realpath "$1")"; OUT="$(realpath -m "$2")"; N="$3"; shift 3
HERE="$(dirname "$(realpath "$0")")"
mkdir -p "$OUT"
export SWEEP OUT
ARRAY=$(sbatch --parsable --export=ALL --array="1-$N" "$@" "$HERE/sweep-array.sh")
MERGE=$(sbatch --parsable --export=ALL --dependency="afterok:$ARRAY" "$@" "$HERE/merge.sh")
echo "shards: job array $ARRAY (1-$N) → $OUT/shards/K; merge: job $MERGE → $OUT/merged"
