#!/bin/bash
# Merges the N shards of a sweep into OUT/merged and writes its report.
# submit.sh submits it with --dependency=afterany on the array, so it runs
# even when a task failed: then it refuses (a shard folder missing, or
# rows missing) and says which task to re-run. Again by hand:
#   sbatch --output=OUT/logs/%x-%j.out merge.sh OUT N
#SBATCH --job-name=sfp-merge
#SBATCH --cpus-per-task=1
#SBATCH --time=00:30:00
set -euo pipefail
if [ $# -ne 2 ]; then
    echo "usage: sbatch $0 OUT N" >&2
    exit 2
fi
OUT="$1"; N="$2"
SFP="${SFP:-sfp}"
SHARDS=()
for K in $(seq 1 "$N"); do
    if [ ! -f "$OUT/shards/$K/results.jsonl" ]; then
        echo "error: $OUT/shards/$K has no results: task $K failed or never ran; re-run it" \
             "(sbatch --array=$K … sweep-array.sh), then this merge" >&2
        exit 2
    fi
    SHARDS+=("$OUT/shards/$K")
done
exec "$SFP" bench merge "${SHARDS[@]}" --complete --out "$OUT/merged"
