#!/usr/bin/env bash
# Submit a sharded sweep to Slurm: N array tasks, then the merge once all
# of them have succeeded.
#
#   examples/sweep/slurm-submit.sh CONFIG N [OUT]
set -euo pipefail
if [ $# -lt 2 ]; then
  echo "usage: $0 CONFIG N [OUT]" >&2
  exit 2
fi
here=$(dirname "$0")
export CONFIG=$1 OUT=${3:-sweep-parts}
jid=$(sbatch --parsable --array="1-$2" "$here/slurm.sbatch")
sbatch --dependency="afterok:$jid" "$here/slurm-merge.sbatch"
