"""cocotb test of gyro_interface_axi__axil_write (hdl/src/host/axil_write.rs),
the bus top's write channels (AW, W, B) as their own toplevel, after
verilog-axi's per-module tests of axil_reg_if_wr.

The master is cocotbext-axi's AxiLiteMasterWrite with random pauses on AW, W
and B, so AW and W come in either order or together and B meets
backpressure, with many writes in flight. The register file's side is a
model: indices below MAPPED accepted, the rest answered SLVERR. Checked on
every clock: no write strobe while B is pending. Per transfer: one write
strobe, with the transfer's word index, data and byte mask (from the
master's strobes, for every offset and length), and B's response.
"""

import random

import cocotb
from channel_util import MAPPED, TRANSFERS, WORDS, pauses, start
from cocotb.triggers import ClockCycles, FallingEdge
from cocotbext.axi import AxiLiteMasterWrite, AxiLiteWriteBus, AxiResp


@cocotb.test()
async def writes_reach_the_register_file_once_each(dut):
    await start(dut)
    master = AxiLiteMasterWrite(AxiLiteWriteBus.from_prefix(dut, "s_axil"), dut.clock, dut.reset)
    master.aw_channel.set_pause_generator(pauses(1, 0.4))
    master.w_channel.set_pause_generator(pauses(2, 0.4))
    master.b_channel.set_pause_generator(pauses(3, 0.5))
    seen = []

    async def register_file():
        # Mid-cycle, the channel's outputs (all from its registers) are
        # stable for the coming edge: answer `accepted` and record a write.
        while True:
            await FallingEdge(dut.clock)
            index = int(dut.index.value)
            dut.accepted.value = int(index < MAPPED)
            if int(dut.write.value):
                assert not int(dut.s_axil_bvalid.value), "a write while B is pending"
                seen.append((index, int(dut.data.value), int(dut.mask.value)))

    cocotb.start_soon(register_file())
    rng = random.Random(7)
    expected = []
    ops = []
    for _ in range(TRANSFERS):
        index = rng.randrange(WORDS)
        offset = rng.randrange(4)
        length = rng.randrange(1, 5 - offset)
        data = bytes(rng.randrange(256) for _ in range(length))
        pad = bytes(4 - offset - length)
        word = int.from_bytes(bytes(offset) + data + pad, "little")
        mask = int.from_bytes(bytes(offset) + b"\xff" * length + pad, "little")
        expected.append((index, word, mask))
        ops.append(master.init_write(4 * index + offset, data))
    for op in ops:
        await op.wait()
    await ClockCycles(dut.clock, 4)
    assert len(seen) == len(expected), f"{len(seen)} writes for {len(expected)} transfers"
    for n, (got, want, op) in enumerate(zip(seen, expected, ops)):
        index, word, mask = want
        assert got[0] == index and got[2] == mask, f"transfer {n}: {got} for {want}"
        assert got[1] & mask == word & mask, f"transfer {n}: data {got[1]:#x} for {word:#x}"
        resp = op.data.resp
        assert resp == (AxiResp.OKAY if index < MAPPED else AxiResp.SLVERR), (
            f"transfer {n} to word {index}: {resp}"
        )
