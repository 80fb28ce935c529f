"""Helpers shared by the channel modules' cocotb tests (test_axil_write.py,
test_axil_read.py): the clock and reset, pause generators, and the modelled
register file's words.
"""

import random

import cocotb
from cocotb.clock import Clock
from cocotb.triggers import ClockCycles

CLOCK_NS = 10
# Word indices below this one are mapped (accepted) in the modelled register file.
MAPPED = 40
# Word indices the 8-bit byte address reaches.
WORDS = 64
# Transfers per test, many in flight at once.
TRANSFERS = 300


def pauses(seed, busy):
    """A pause generator: True (pause) with probability `busy`."""
    rng = random.Random(seed)
    while True:
        yield rng.random() < busy


async def start(dut):
    """The clock, then three clocks of reset."""
    cocotb.start_soon(Clock(dut.clock, CLOCK_NS, units="ns").start())
    dut.reset.value = 1
    dut.accepted.value = 0
    await ClockCycles(dut.clock, 3)
    dut.reset.value = 0


def word_of(index):
    """The modelled register file's word at `index` (distinct per index)."""
    return (0x9E3779B1 * (index + 1)) & 0xFFFFFFFF
