#!/usr/bin/env bash
# Creates the Python virtual environment of the IP-packaging tests: FuseSoC
# (tests/fusesoc.rs), PeakRDL (tests/systemrdl.rs) and LiteX (tests/litex.rs),
# at pinned versions. Does nothing when the environment already holds exactly
# these versions.
#
# Where: $GYROCAL_IP_VENV, default target/ip-venv/ at the repository root
# (git-ignored). The Rust tests read the same variable with the same default.
#
# Usage: scripts/ip/install-venv.sh
set -euo pipefail
cd "$(dirname "$0")/../.."

# The pinned versions; scripts/ip/pins.txt is the list the tests check.
mapfile -t PINS < <(grep -v '^#' scripts/ip/pins.txt | grep .)

venv="${GYROCAL_IP_VENV:-target/ip-venv}"
stamp="$venv/gyrocal-pins.txt"
wanted="$(printf '%s\n' "${PINS[@]}")"
if [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$wanted" ] \
   && [ -x "$venv/bin/fusesoc" ] && [ -x "$venv/bin/peakrdl" ]; then
  exit 0
fi
echo "creating $venv with ${PINS[*]}"
python3 -m venv "$venv" || { echo "python3 -m venv failed: install the Debian package python3-venv"; exit 1; }
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check --no-input "${PINS[@]}"
printf '%s\n' "$wanted" > "$stamp"
