#!/bin/bash
# Merges the shards of a sweep once every array task has finished
# (submitted by submit.sh with --dependency=afterok on the array job).
#SBATCH --job-name=sfp-merge
#SBATCH --cpus-per-task=1
#SBATCH --time=00:30:00
#SBATCH --output=%x-%j.out
set -euo pipefail
: "${OUT:?set OUT to the output folder}"
SFP="${SFP:-sfp}"
# Shards in task order; the merged rows are in plan order whatever this order.
mapfile -t SHARDS < <(find "$OUT/shards" -mindepth 1 -maxdepth 1 -type d | sort -V)
# Merging also runs the report once the report writer is part of `sfp bench merge`.
exec "$SFP" bench merge "${SHARDS[@]}" --out "$OUT/merged"
