#!/usr/bin/env bash
# Regenerates docs/results.md: the measured figures this project quotes,
# each under the exact command that printed it, run now on this machine.
# Nothing in that page is typed by hand; rerun this after a change that
# moves a figure.
#
# Usage: scripts/results.sh            (about 10 minutes of CPU on 2 cores)
set -euo pipefail
cd "$(dirname "$0")/.."

cargo build --release --quiet
bin=target/release/gyrocal
out=docs/results.md
tmp="$(mktemp "${out}.XXXXXX")"
trap 'rm -f "$tmp"' EXIT

# The commands, in the order the page shows them.
commands=(
  "$bin reproduce --out target/results-page/reproduce"
  "$bin run --config tests/data/small_device.toml"
  "$bin field --config tests/data/field_paper.toml"
  "$bin field --config tests/data/field_coupled.toml"
  "$bin sweep --config examples/sweep/consumer.toml"
  "$bin calibrate --config tests/data/small_device.toml"
  "$bin datasheet --config tests/data/datasheet_small.toml"
)

{
  echo "# Measured figures"
  echo
  echo "Written by \`scripts/results.sh\` on $(date -u +%Y-%m-%d) from commit"
  echo "\`$(git rev-parse --short HEAD)\`$(git diff --quiet HEAD -- . ':!docs/results.md' || echo ' (with uncommitted changes)'),"
  echo "on $(nproc) cores ($(uname -m)). Each block is the command's standard output,"
  echo "unedited; wall times depend on the machine and its load."
  for c in "${commands[@]}"; do
    echo >&2 "running: ${c#"$bin "}"
    echo
    echo "## \`gyrocal ${c#"$bin "}\`"
    echo
    echo '```'
    $c 2>/dev/null
    echo '```'
  done
} > "$tmp"
mv "$tmp" "$out"
trap - EXIT
echo "wrote $out"
