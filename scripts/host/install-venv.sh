#!/usr/bin/env bash
# Creates the Python virtual environment with LiteX's Etherbone client
# (litex.tools.litex_client.RemoteClient), the third-party client that
# tests/serve.rs runs against `gyrocal serve`. Does nothing when the
# environment already holds exactly these versions.
#
# Pinned, installed without dependency resolution: the client imports litex
# and migen only (litex's other requirements, requests and pyserial, serve
# its UART and board tools); migen needs colorama.
#
# Where: $GYROCAL_LITEX_VENV, default target/litex-venv/ at the repository
# root (git-ignored). tests/serve.rs reads the same variable with the same
# default.
#
# Usage: scripts/host/install-venv.sh
set -euo pipefail
cd "$(dirname "$0")/../.."

PINS=(
  "litex==2024.12"
  "migen==0.10.0"
  "colorama==0.4.6"
)

venv="${GYROCAL_LITEX_VENV:-target/litex-venv}"
stamp="$venv/gyrocal-pins.txt"
wanted="$(printf '%s\n' "${PINS[@]}")"
if [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$wanted" ] && [ -x "$venv/bin/python" ]; then
  exit 0
fi
echo "creating $venv with ${PINS[*]}"
python3 -m venv "$venv" || { echo "python3 -m venv failed: install the Debian package python3-venv"; exit 1; }
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check --no-input --no-deps "${PINS[@]}"
"$venv/bin/python" -c "from litex.tools.litex_client import RemoteClient"
printf '%s\n' "$wanted" > "$stamp"
