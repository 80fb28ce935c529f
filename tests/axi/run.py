"""Build gyro_interface_axi.v in one simulator and run test_gyro_axi.py.

usage: run.py SIMULATOR VERILOG BUILD_DIR [TESTCASE]
Each test runs in a simulator of its own, from power-up: the datapath core
has no reset, so a test must not inherit another's state.
Exit status 0 when every test passed, 1 otherwise (cocotb's results.xml).
"""

import re
import sys
from pathlib import Path

from cocotb.runner import get_results, get_runner


def main():
    sim, verilog, build_dir = sys.argv[1], Path(sys.argv[2]), Path(sys.argv[3])
    testcase = sys.argv[4] if len(sys.argv) > 4 else None
    here = Path(__file__).resolve().parent
    sys.path.insert(0, str(here))  # the runner passes sys.path on as PYTHONPATH
    runner = get_runner(sim)
    build_args = ["-Wno-fatal", "-Wno-lint", "-Wno-style"] if sim == "verilator" else []
    runner.build(
        verilog_sources=[verilog],
        hdl_toplevel="gyro_interface_axi",
        build_dir=build_dir,
        build_args=build_args,
        timescale=("1ns", "1ps"),
    )
    source = (here / "test_gyro_axi.py").read_text()
    names = re.findall(r"@cocotb\.test\(\)\nasync def (\w+)\(", source)
    total = failed = 0
    for name in names if testcase is None else [testcase]:
        results = runner.test(
            test_module="test_gyro_axi",
            hdl_toplevel="gyro_interface_axi",
            test_dir=build_dir,
            build_dir=build_dir,
            testcase=name,
            timescale=("1ns", "1ps"),
            results_xml=f"results_{name}.xml",
        )
        n, f = get_results(results)
        total, failed = total + n, failed + f
    print(f"cocotb {sim}: {total} tests, {failed} failed")
    sys.exit(1 if failed or total != len(names if testcase is None else [testcase]) else 0)


if __name__ == "__main__":
    main()
