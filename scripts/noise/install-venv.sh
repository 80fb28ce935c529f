#!/usr/bin/env bash
# Make the Python venv the datasheet test checks against (tests/datasheet_cli.rs):
# allantools and its numerics, pinned, under target/ (git-ignored).
#
#   scripts/noise/install-venv.sh            # creates target/noise-venv once
#   GYROCAL_NOISE_VENV=DIR scripts/noise/install-venv.sh
#
# Prints the venv's python on its last line. Needs python3 with venv and the
# PyPI registry (ordinary pip client); nothing else is downloaded.
set -euo pipefail
root="$(cd "$(dirname "$0")/../.." && pwd)"
venv="${GYROCAL_NOISE_VENV:-$root/target/noise-venv}"
py="$venv/bin/python"
if ! "$py" -c "import allantools, scipy, numpy" 2>/dev/null; then
    python3 -m venv "$venv"
    "$py" -m pip install --quiet --disable-pip-version-check \
        numpy==2.2.6 scipy==1.15.3 allantools==2024.6
fi
"$py" -c "import allantools, scipy, numpy" >/dev/null
echo "$py"
