"""Build gyro_interface_axi.v in one simulator and run a cocotb test module.

usage: run.py SIMULATOR VERILOG BUILD_DIR [TESTCASE] [--toplevel MODULE --tests TEST_MODULE]
By default the toplevel is gyro_interface_axi and the tests test_gyro_axi.py;
a channel module of the export (gyro_interface_axi__axil_write, ...) runs
under its own test module (test_axil_write.py, ...).
Each test runs in a simulator of its own, from power-up: the datapath core
has no reset, so a test must not inherit another's state.
Exit status 0 when every test passed, 1 otherwise (cocotb's results.xml).
"""

import argparse
import re
import sys
from pathlib import Path

from cocotb.runner import get_results, get_runner


def extract(verilog, module, build_dir):
    """The module `module` of the export and its own submodules
    (`module`__*), alone in a file of the build directory, the module renamed
    to its last name (gyro_interface_axi__axil_write -> axil_write): Verilator
    5.006 finds no --top-module whose name holds a double underscore."""
    text = verilog.read_text()
    parts = re.split(r"(?m)^(?=module )", text)
    keep = [p for p in parts if re.match(rf"module {re.escape(module)}(\(|__)", p)]
    assert keep, f"no module {module} in {verilog}"
    short = module.split("__")[-1]
    body = "".join(keep).replace(f"module {module}(", f"module {short}(", 1)
    build_dir.mkdir(parents=True, exist_ok=True)
    path = build_dir / f"{short}.v"
    path.write_text(body)
    return path, short


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("sim")
    parser.add_argument("verilog", type=Path)
    parser.add_argument("build_dir", type=Path)
    parser.add_argument("testcase", nargs="?")
    parser.add_argument("--toplevel", default="gyro_interface_axi")
    parser.add_argument("--tests", default="test_gyro_axi")
    args = parser.parse_args()
    sim, verilog, build_dir, testcase = args.sim, args.verilog, args.build_dir, args.testcase
    toplevel, tests = args.toplevel, args.tests
    if toplevel != "gyro_interface_axi":
        verilog, toplevel = extract(verilog, toplevel, build_dir)
    here = Path(__file__).resolve().parent
    sys.path.insert(0, str(here))  # the runner passes sys.path on as PYTHONPATH
    runner = get_runner(sim)
    build_args = ["-Wno-fatal", "-Wno-lint", "-Wno-style"] if sim == "verilator" else []
    runner.build(
        verilog_sources=[verilog],
        hdl_toplevel=toplevel,
        build_dir=build_dir,
        build_args=build_args,
        timescale=("1ns", "1ps"),
    )
    source = (here / f"{tests}.py").read_text()
    names = re.findall(r"@cocotb\.test\(\)\nasync def (\w+)\(", source)
    total = failed = 0
    for name in names if testcase is None else [testcase]:
        results = runner.test(
            test_module=tests,
            hdl_toplevel=toplevel,
            test_dir=build_dir,
            build_dir=build_dir,
            testcase=name,
            timescale=("1ns", "1ps"),
            results_xml=f"results_{name}.xml",
        )
        n, f = get_results(results)
        total, failed = total + n, failed + f
    print(f"cocotb {sim} {toplevel}: {total} tests, {failed} failed")
    sys.exit(1 if failed or total != len(names if testcase is None else [testcase]) else 0)


if __name__ == "__main__":
    main()
