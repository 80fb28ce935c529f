"""Migen simulation of pmod_converters.PmodAD1DA2 against models of the parts.

The AD7476A model takes its sample at the fall of CS and shifts out
0 0 0 0 D11..D0, a new bit 2 system clocks (40 ns at 50 MHz, the datasheet's
maximum access time) after each SCLK fall; the DAC121S101 model takes DIN at
each SCLK fall while SYNC is low and updates after the 16th. The test checks,
over random samples: every ADC sample reaches the core's word (12 MSBs, two's
complement), every DAC word reaches the DAC (straight binary, PD = 00), and
the engine's stated latencies are the measured ones.

usage: python test_pmod_converters.py   (exit status 0 when every check passed)
"""

import random
import sys

from migen import Record, passive, run_simulation

from pmod_converters import CONVERTER_BITS, PmodAD1DA2

SAMPLES = 40
ACCESS_CLOCKS = 2


@passive
def adc_model(pads, values, sampled):
    """Two AD7476A sharing CS and SCLK: values[i] = (ch1, ch2) of frame i."""
    prev_cs, prev_sclk, frame, t = 1, 1, -1, 0
    bits, pending = [0, 0], []
    while True:
        cs, sclk = (yield pads.cs_n), (yield pads.sclk)
        if prev_cs and not cs:
            frame += 1
            sampled.append(t)
            words = values[frame % len(values)]
            bits, index = [w for w in words], 0
            pending = [(t + ACCESS_CLOCKS, 0)]
        elif not cs and prev_sclk and not sclk:
            index += 1
            pending.append((t + ACCESS_CLOCKS, index))
        for due, i in [p for p in pending if p[0] <= t]:
            yield pads.d0.eq(bits[0] >> (15 - i) & 1 if i < 16 else 0)
            yield pads.d1.eq(bits[1] >> (15 - i) & 1 if i < 16 else 0)
        pending = [p for p in pending if p[0] > t]
        prev_cs, prev_sclk, t = cs, sclk, t + 1
        yield


@passive
def dac_model(pads, updates):
    """Two DAC121S101 sharing SYNC and SCLK: updates gets (clock, frame1, frame2)."""
    prev_sync, prev_sclk, t, shifted, n = 1, 1, 0, [0, 0], 0
    while True:
        sync, sclk = (yield pads.sync_n), (yield pads.sclk)
        if prev_sync and not sync:
            shifted, n = [0, 0], 0
        if not sync and prev_sclk and not sclk:
            shifted = [(shifted[0] << 1) | (yield pads.dina), (shifted[1] << 1) | (yield pads.dinb)]
            n += 1
            if n == 16:
                updates.append((t, shifted[0], shifted[1]))
        prev_sync, prev_sclk, t = sync, sclk, t + 1
        yield


def core(dut, dac_words, adc_seen, dac_set, clocks):
    """The core's side: a new DAC word every clock, every ADC word recorded.
    Clock t here and in the models is the same simulation step: the models
    see the pads after edge t, the core's word of step t is taken at edge t + 1."""
    for t in range(clocks):
        word = dac_words[t % len(dac_words)]
        yield dut.dac1.eq(word[0])
        yield dut.dac2.eq(word[1])
        dac_set.append(word)
        adc_seen.append(((yield dut.adc1), (yield dut.adc2)))
        yield


def signed16(v):
    return v - (1 << 16) if v & 0x8000 else v


def main():
    rng = random.Random(7)
    adc_pads = Record([("cs_n", 1), ("sck", 1), ("d0", 1), ("d1", 1)])
    dac_pads = Record([("sync_n", 1), ("sclk", 1), ("dina", 1), ("dinb", 1)])
    # the model reads SCLK as "sclk" on both
    adc_pads.sclk = adc_pads.sck
    dut = PmodAD1DA2(adc_pads, dac_pads)
    lat = dut.latencies()
    clocks = SAMPLES * dut.clocks_per_sample
    values = [(rng.randrange(1 << CONVERTER_BITS), rng.randrange(1 << CONVERTER_BITS)) for _ in range(SAMPLES)]
    dac_words = [(rng.randrange(-32768, 32768), rng.randrange(-32768, 32768)) for _ in range(clocks)]
    sampled, updates, adc_seen, dac_set = [], [], [], []
    run_simulation(dut, [
        adc_model(adc_pads, values, sampled),
        dac_model(dac_pads, updates),
        core(dut, dac_words, adc_seen, dac_set, clocks),
    ])
    failures = []
    # ADC: frame i's sample is the core's word from sampled[i] + adc_clocks on, for hold_clocks.
    for i, t0 in enumerate(sampled[:-2]):
        t = t0 + lat.adc_clocks
        want = tuple(signed16(((v ^ 0x800) << 4) & 0xFFFF) for v in values[i])
        if adc_seen[t] != want or adc_seen[t - 1] == want and i > 0:
            failures.append(f"ADC frame {i}: core read {adc_seen[t - 1:t + 1]} around clock {t}, want {want} from it")
        if adc_seen[t + lat.hold_clocks - 1] != want:
            failures.append(f"ADC frame {i}: not held for {lat.hold_clocks} clocks")
    # DAC: update k carries the core's word of clock (update clock - dac_clocks).
    for k, (t, f1, f2) in enumerate(updates):
        word = dac_set[t - lat.dac_clocks] if t >= lat.dac_clocks else (0, 0)  # power-up: mid-scale
        want = tuple(((w & 0xFFFF) >> 4) ^ 0x800 for w in word)
        if (f1, f2) != want:
            failures.append(f"DAC update {k} at clock {t}: frames {f1:04x} {f2:04x}, want {want[0]:04x} {want[1]:04x}")
    if len(updates) < SAMPLES - 1 or len(sampled) < SAMPLES - 1:
        failures.append(f"only {len(updates)} DAC updates and {len(sampled)} ADC samples in {clocks} clocks")
    for f in failures[:10]:
        print(f)
    print(f"pmod converters: {len(sampled)} ADC frames, {len(updates)} DAC updates, "
          f"latencies {lat}, {len(failures)} failed")
    sys.exit(1 if failures else 0)


if __name__ == "__main__":
    main()
