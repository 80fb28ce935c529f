#!/usr/bin/env bash
# A sharded gyrocal sweep on one machine with GNU parallel: N shards, JOBS
# at a time, each with the machine's cores shared among the jobs, then the
# merge into OUT/merged.json and OUT/merged/.
#
#   examples/sweep/parallel.sh CONFIG N [OUT]
#
# Environment: GYROCAL (the binary, default `gyrocal` on PATH), JOBS
# (shards at once, default N).
set -euo pipefail
if [ $# -lt 2 ]; then
  echo "usage: $0 CONFIG N [OUT]" >&2
  exit 2
fi
CONFIG=$1
N=$2
OUT=${3:-sweep-parts}
GYROCAL=${GYROCAL:-gyrocal}
JOBS=${JOBS:-$N}
threads=$(( $(nproc) / JOBS ))
[ "$threads" -ge 1 ] || threads=1
mkdir -p "$OUT"
export CONFIG N OUT GYROCAL
seq 1 "$N" | RAYON_NUM_THREADS=$threads parallel --halt now,fail=1 -j "$JOBS" \
  '"$GYROCAL" sweep --config "$CONFIG" --shard {}/"$N" --json > "$OUT"/shard-{}-of-"$N".json.part && mv "$OUT"/shard-{}-of-"$N".json.part "$OUT"/shard-{}-of-"$N".json'
"$GYROCAL" sweep merge "$OUT"/shard-*-of-"$N".json --json --out "$OUT/merged" > "$OUT/merged.json"
