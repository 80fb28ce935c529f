"""cocotb test of gyro_interface_axi__axil_read (hdl/src/host/axil_read.rs),
the bus top's read channels (AR, R) as their own toplevel, after
verilog-axi's per-module tests of axil_reg_if_rd.

The master is cocotbext-axi's AxiLiteMasterRead with random pauses on AR and
R (R meets backpressure), with many reads in flight. The register file's
side is a model: a distinct word per index below MAPPED, the rest answered
SLVERR. Checked on every clock: no read strobe while R is pending. Per
transfer: one read strobe with the transfer's index, in order, and R's
response and data.
"""

import random

import cocotb
from channel_util import MAPPED, TRANSFERS, WORDS, pauses, start, word_of
from cocotb.triggers import ClockCycles, FallingEdge
from cocotbext.axi import AxiLiteMasterRead, AxiLiteReadBus, AxiResp


@cocotb.test()
async def reads_return_the_word_of_their_index(dut):
    await start(dut)
    master = AxiLiteMasterRead(AxiLiteReadBus.from_prefix(dut, "s_axil"), dut.clock, dut.reset)
    master.ar_channel.set_pause_generator(pauses(4, 0.4))
    master.r_channel.set_pause_generator(pauses(5, 0.5))
    strobes = []

    async def register_file():
        # Mid-cycle, `index` (a register's output) is stable for the coming
        # edge: answer its word, and record a read.
        while True:
            await FallingEdge(dut.clock)
            index = int(dut.index.value)
            dut.accepted.value = int(index < MAPPED)
            dut.word.value = word_of(index) if index < MAPPED else 0
            if int(dut.read.value):
                assert not int(dut.s_axil_rvalid.value), "a read while R is pending"
                strobes.append(index)

    cocotb.start_soon(register_file())
    rng = random.Random(8)
    indices = [rng.randrange(WORDS) for _ in range(TRANSFERS)]
    ops = [master.init_read(4 * i, 4) for i in indices]
    for op in ops:
        await op.wait()
    await ClockCycles(dut.clock, 4)
    assert strobes == indices, "one read strobe per transfer, in order"
    for n, (index, op) in enumerate(zip(indices, ops)):
        resp, data = op.data.resp, int.from_bytes(op.data.data, "little")
        if index < MAPPED:
            assert resp == AxiResp.OKAY and data == word_of(index), (
                f"transfer {n} from word {index}: {resp} {data:#x}"
            )
        else:
            assert resp == AxiResp.SLVERR, f"transfer {n} from word {index}: {resp}"
