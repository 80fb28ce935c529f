"""LiteX's RemoteClient (litex==2024.12) against `gyrocal serve`.

Usage: python remote_client.py PORT VERSION LAST

VERSION is the VERSION word and LAST the offset of the last register, as
the register map (gyrocal_regs::map) says; tests/serve.rs passes them.

Run by tests/serve.rs on a freshly served board (every setting at its
power-up value). Register offsets are those of verilog-out/REGISTERS.md,
from address 0. RemoteClient 2024.12 answers a read that timed out with 0
and says nothing, so every read below is checked against a value that 0
is not. Exits non-zero with a message on the first failed check; prints
one line per check.
"""

import sys
import time

from litex.tools.litex_client import RemoteClient

ID, VERSION, AMP1, AMP2, CIC_DECIMATION, SAMPLE_COUNT = 0x00, 0x04, 0x20, 0x24, 0x28, 0x48


def check(what, ok, detail):
    if not ok:
        sys.exit(f"FAILED {what}: {detail}")
    print(f"ok {what}: {detail}")


def counts_advance(bus, what):
    """SAMPLE_COUNT moves forward (the board runs when the machine lets it:
    up to 5 s)."""
    first = second = bus.read(SAMPLE_COUNT)
    deadline = time.monotonic() + 5
    while second == first and time.monotonic() < deadline:
        time.sleep(0.01)
        second = bus.read(SAMPLE_COUNT)
    check(what, second != first and (second - first) % 2**32 < 2**31, f"{first} then {second}")
    return second


def main():
    port = int(sys.argv[1])
    version, last = int(sys.argv[2], 0), int(sys.argv[3], 0)
    bus = RemoteClient(host="127.0.0.1", port=port)
    bus.open()
    check("ID", bus.read(ID) == 0x4759524F, hex(bus.read(ID)))
    check("VERSION", bus.read(VERSION) == version, hex(bus.read(VERSION)))
    bus.write(AMP1, 0x1234)
    check("AMP1 written and read back", bus.read(AMP1) == 0x1234, hex(bus.read(AMP1)))
    bus.write(AMP1, 0x8001)
    check("AMP1 sign-extended", bus.read(AMP1) == 0xFFFF8001, hex(bus.read(AMP1)))
    bus.write(AMP1, [5, 7])  # one record of two words: AMP1, AMP2
    counts_advance(bus, "SAMPLE_COUNT advances")

    words = bus.read(ID, length=last // 4 + 1)
    expected = {ID: 0x4759524F, VERSION: version, AMP1: 5, AMP2: 7, CIC_DECIMATION: 256}
    got = {a: words[a // 4] for a in expected}
    check("burst read of the whole map", len(words) == last // 4 + 1 and got == expected, got)

    # One record is served whole between two clocks, as one bus transaction.
    counts = bus.read(SAMPLE_COUNT, length=64, burst="fixed")
    check("fixed burst of SAMPLE_COUNT, one record", len(counts) == 64 and len(set(counts)) == 1, f"{counts[0]} x {len(counts)}")

    check("unmapped word reads 0", bus.read(0x80) == 0 and bus.read(0x100) == 0, "0x80, 0x100")
    before = bus.read(SAMPLE_COUNT)
    bus.close()

    time.sleep(0.05)
    again = RemoteClient(host="127.0.0.1", port=port)
    again.open()
    check("a second connection sees the settings", again.read(AMP2) == 7, hex(again.read(AMP2)))
    after = counts_advance(again, "the board ran on between connections")
    check("count kept counting", (after - before) % 2**32 < 2**31 and after != before, f"{before} then {after}")
    again.close()
    print("all checks passed")


if __name__ == "__main__":
    main()
