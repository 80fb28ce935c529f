#!/usr/bin/env bash
# The model engine's speed side by side: this tree's gyrocal against the
# one built at a base revision (default 4afc731, issue 23's baseline), on
# one core, runs alternated so that both see the same machine, then the
# medians of each and their ratio (this tree over the base). This tree runs
# once per round for each instruction set the processor runs
# (GYROCAL_ISA=portable, the x86-64 baseline the base was built for, then
# x86-64-v3 and x86-64-v4 where supported; the widest is the one it
# chooses), so the gain of each change shows apart from the wider builds.
#
# Usage: scripts/bench-against.sh [BASE_REV] [ROUNDS] [CPU]
#   BASE_REV  a revision to build and compare with (default 4afc731)
#   ROUNDS    alternations (default 3); each runs both binaries'
#             `gyrocal bench --engines model --repetitions 3 --no-reproduce`,
#             then both binaries' `gyrocal reproduce` (issue 23's own
#             measure: its wall time on one core, the figures written)
#   CPU       the core both run on (default the last one)
#
# The base is built once in a git worktree under target/bench-base/REV
# with its own target directory, and only its binary is kept there; the
# first call takes some minutes. Only the timings go to stdout; builds and
# progress go to stderr. Besides the pooled medians it prints the paired
# ratios: each round's median over the base's in that round, their median
# over the rounds (robust where the machine's speed drifts over minutes).
set -euo pipefail
cd "$(dirname "$0")/.."

base_rev=${1:-4afc731}
rounds=${2:-3}
cpu=${3:-$(($(nproc) - 1))}
if ! [[ "$rounds" =~ ^[1-9][0-9]*$ ]]; then
  echo "error: ROUNDS = $rounds: allowed a whole number >= 1" >&2
  exit 2
fi
if ! [[ "$cpu" =~ ^[0-9]+$ ]] || ((cpu >= $(nproc))); then
  echo "error: CPU = $cpu: allowed 0..$(($(nproc) - 1))" >&2
  exit 2
fi
base_sha=$(git rev-parse --verify --quiet "$base_rev^{commit}") || {
  echo "error: BASE_REV = $base_rev: not a revision of this repository" >&2
  exit 2
}

base_dir=target/bench-base/${base_sha:0:12}
if [ ! -x "$base_dir/gyrocal" ]; then
  echo "building the base $base_rev ($base_sha) in $base_dir" >&2
  tree="$base_dir/tree"
  rm -rf "$tree"
  git worktree prune
  git worktree add --detach --force "$tree" "$base_sha" >&2
  (cd "$tree" && CARGO_TARGET_DIR="$PWD/../target" cargo build --release --quiet --bin gyrocal) >&2
  cp "$base_dir/target/release/gyrocal" "$base_dir/gyrocal.tmp"
  mv "$base_dir/gyrocal.tmp" "$base_dir/gyrocal"
  # Only the binary is kept: the tree and its build are gigabytes.
  git worktree remove --force "$tree"
  rm -rf "$base_dir/target"
fi
echo "building this tree" >&2
cargo build --release --quiet --bin gyrocal >&2
head_bin=$PWD/target/release/gyrocal
base_bin=$PWD/$base_dir/gyrocal

out=$(mktemp -d)
trap 'rm -rf "$out"' EXIT
# The instruction sets this processor runs: an unsupported GYROCAL_ISA
# stops any command in one line, so a tiny bench tells.
isas=portable
for isa in x86-64-v3 x86-64-v4; do
  if GYROCAL_ISA=$isa "$head_bin" bench --engines model --repetitions 1 --scale 0.001 \
    --no-reproduce --json >/dev/null 2>&1; then
    isas="$isas $isa"
  fi
done
run() { # name binary round [VAR=value...]
  echo "round $3: $1" >&2
  taskset -c "$cpu" env RAYON_NUM_THREADS=1 "${@:4}" "$2" bench --engines model \
    --repetitions 3 --no-reproduce --json >"$out/$1.$3.json"
}
# Issue 23's own measure: `gyrocal reproduce` on one core, wall to wall
# (the figures written), each binary in a directory of its own.
reproduce() { # name binary round
  echo "round $3: $1 reproduce" >&2
  mkdir -p "$out/$1.reproduce.$3"
  local start end
  start=$(date +%s%N)
  (cd "$out/$1.reproduce.$3" && taskset -c "$cpu" env RAYON_NUM_THREADS=1 "$2" reproduce --quiet >/dev/null)
  end=$(date +%s%N)
  echo $((end - start)) >"$out/$1.reproduce.$3.ns"
}
for r in $(seq 1 "$rounds"); do
  run base "$base_bin" "$r"
  for isa in $isas; do
    run "$isa" "$head_bin" "$r" GYROCAL_ISA="$isa"
  done
  reproduce base "$base_bin" "$r"
  reproduce head "$head_bin" "$r"
done

python3 - "$out" "$rounds" "$base_rev" "$(git rev-parse --short HEAD)" $isas <<'EOF'
import json, statistics, sys
out, rounds, base_rev, head_rev = sys.argv[1], int(sys.argv[2]), sys.argv[3], sys.argv[4]
isas = sys.argv[5:]
# runs[name][r]: the measurements of round r (from 0), each file read once.
runs = {name: [json.load(open(f"{out}/{name}.{r}.json")) for r in range(1, rounds + 1)]
        for name in ["base"] + isas}
def speeds(name):
    s = {False: [], True: []}
    for run in runs[name]:
        for m in run["measurements"]:
            if m.get("lanes", 1) == 1:
                s[m["with_gyro"]].extend(m["samples"])
    return s
def median_of(run, gyro):
    return next(m["median_clocks_per_s"] for m in run["measurements"]
                if m["with_gyro"] == gyro and m.get("lanes", 1) == 1)
def lanes_of(run):
    # The lanes measurement (a base from before lanes has none).
    return next((m for m in run["measurements"] if m.get("lanes", 1) > 1), None)
def paired(name, gyro):
    # Each round's median over the base's median in the same round: on a
    # machine whose speed drifts over minutes, the ratio of runs seconds
    # apart holds where the pooled medians wander.
    ratios = [median_of(run, gyro) / median_of(base_run, gyro)
              for run, base_run in zip(runs[name], runs["base"])]
    return statistics.median(ratios), sum(x > 1 for x in ratios)
for isa in isas:
    ran = runs[isa][0]["model_isa"]
    assert ran == isa, f"GYROCAL_ISA={isa} ran {ran}"
speed = {name: speeds(name) for name in ["base"] + isas}
print(f"model engine, one core, {rounds} alternated rounds of 3 repetitions (M clocks/s)")
print(f"this tree {head_rev} for each instruction set this processor runs"
      f" (it chooses {isas[-1]})")
print(f"{'setting':<20} {'base ' + base_rev:>24}" + "".join(f"{isa:>24}" for isa in isas)
      + f"{'ratios':>{7 * len(isas)}}")
cell = lambda v: f"{statistics.median(v) / 1e6:.2f} ({min(v) / 1e6:.1f}..{max(v) / 1e6:.1f})"
for gyro, label in [(False, "datapath alone"), (True, "with the gyroscope")]:
    b = statistics.median(speed["base"][gyro])
    cells = "".join(f"{cell(speed[name][gyro]):>24}" for name in ["base"] + isas)
    ratios = "".join(f"{statistics.median(speed[isa][gyro]) / b:>7.3f}" for isa in isas)
    print(f"{label:<20} {cells}{ratios}")
print(f"paired: the median over rounds of each round's ratio (rounds above 1 of {rounds})")
for gyro, label in [(False, "datapath alone"), (True, "with the gyroscope")]:
    cells = ""
    for isa in isas:
        ratio, above = paired(isa, gyro)
        cells += f" {isa:>10} {ratio:.3f} ({above})"
    print(f"{label:<20}{cells}")
lanes = [lanes_of(run) for run in runs[isas[-1]]]
if all(lanes):
    n = lanes[0]["lanes"]
    ratios = [m["median_clocks_per_s"] / median_of(b, True) for m, b in zip(lanes, runs["base"])]
    each = statistics.median(x for m in lanes for x in m["samples"])
    print(f"in {n} lanes ({isas[-1]}, lane clocks/s): {each / 1e6:.2f} M, paired over the base"
          f" with the gyroscope {statistics.median(ratios):.3f} ({sum(x > 1 for x in ratios)})")
wall = {name: [int(open(f"{out}/{name}.reproduce.{r}.ns").read()) / 1e9 for r in range(1, rounds + 1)]
        for name in ["base", "head"]}
ratios = [b / h for b, h in zip(wall["base"], wall["head"])]
print(f"gyrocal reproduce, one core, wall (s): base {' '.join(f'{t:.2f}' for t in wall['base'])};"
      f" this tree {' '.join(f'{t:.2f}' for t in wall['head'])}; paired ratio"
      f" {statistics.median(ratios):.3f} ({sum(x > 1 for x in ratios)} of {rounds} above 1)")
EOF
