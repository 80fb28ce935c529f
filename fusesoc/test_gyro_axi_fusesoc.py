"""cocotb entry of the FuseSoC `sim` target of gyro_interface_axi.core.

FuseSoC copies tests/axi/test_gyro_axi.py and verilog-out/gyro_interface_regs.h
into its work folder beside this file (copyto) and runs Icarus there with
COCOTB_TEST_MODULES=test_gyro_axi_fusesoc. This module points the tests at
that header and collects them: every test of test_gyro_axi.py runs.

Two inputs come from gyrocal's Rust model, not from the core's files:
GYRO_PROGRAM (the bus writes of a working frequency plan) and GYRO_VECTORS
(golden vectors of the bit-true model). tests/fusesoc.rs writes both and sets
them; run `cargo test --release --test fusesoc` (docs/fpga-ip.md).
"""

import os
from pathlib import Path

HERE = Path(__file__).resolve().parent
os.environ.setdefault("GYRO_HEADER", str(HERE / "gyro_interface_regs.h"))
for variable in ("GYRO_PROGRAM", "GYRO_VECTORS"):
    if variable not in os.environ:
        raise RuntimeError(
            f"{variable} is not set: it names a file that gyrocal's model writes; "
            "run the target through `cargo test --release --test fusesoc` (docs/fpga-ip.md)"
        )

from test_gyro_axi import *  # noqa: E402,F401,F403  (the cocotb tests themselves)
