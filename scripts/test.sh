#!/usr/bin/env bash
# Runs every test of gyrocal on a fresh Debian machine.
#
# Installs the tools the tests need (iverilog, verilator, yosys, make, g++,
# nextpnr-ice40, python3-venv) with apt-get when they are missing (root,
# non-interactive) and the YoWASP ECP5 tools into a Python virtual environment
# (scripts/fpga/install-venv.sh: $GYROCAL_FPGA_VENV, default .venv-fpga/), then runs the whole
# test suite in release mode (the co-simulation tests need optimized code),
# with the Verilator engine enabled, and the format and lint checks.
set -euo pipefail
cd "$(dirname "$0")/.."

missing=()
command -v iverilog >/dev/null 2>&1 || missing+=(iverilog)
command -v verilator >/dev/null 2>&1 || missing+=(verilator)
command -v yosys >/dev/null 2>&1 || missing+=(yosys)
# Verilator's C++ build (the replay testbench and the verilator engine).
command -v make >/dev/null 2>&1 || missing+=(make)
command -v g++ >/dev/null 2>&1 || missing+=(g++)
# Place and route (tests/verilog_pnr.rs): iCE40 natively, ECP5 from PyPI.
command -v nextpnr-ice40 >/dev/null 2>&1 || missing+=(nextpnr-ice40)
python3 -c 'import ensurepip, venv' >/dev/null 2>&1 || missing+=(python3-venv)
if [ ${#missing[@]} -gt 0 ]; then
  echo "installing Debian packages: ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -q
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q "${missing[@]}"
fi
scripts/fpga/install-venv.sh

cargo fmt --all -- --check
cargo clippy --release --workspace --all-targets --all-features -- -D warnings
cargo test --release --workspace --all-features
