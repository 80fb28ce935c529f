"""Frame engine for one pair of Digilent PMODs: a Pmod AD1 and a Pmod DA2.

Pmod AD1: two AD7476A (12-bit SAR ADC, samples at the fall of CS), sharing
CS and SCLK; pins 1 CS, 2 D0 (ADC 1), 3 D1 (ADC 2), 4 SCK.
Pmod DA2: two DAC121S101 (12-bit DAC), sharing SYNC and SCLK; pins 1 SYNC,
2 DINA (DAC 1), 3 DINB (DAC 2), 4 SCLK. Both speak 16-bit frames, MSB first:

    ADC out: 0 0 0 0 D11..D0        (straight binary; next bit after each SCLK fall)
    DAC in:  0 0 PD1 PD0 D11..D0    (straight binary; PD = 00 normal; taken at SCLK falls)

Timing (system clocks, DIV = sclk_div, even, >= 4): a sample period is
CLOCKS = DIV * 18: CS/SYNC low for 16 SCLK periods, high for 2. SCLK is high
in the first half of each period and low in the second: 16 falls, the first
half a period after CS/SYNC fall. DIN changes at each period's start (SCLK
rise) and holds across the fall; each ADC bit is taken just before the next
fall (DIV/2 + 1 clocks after the previous one: 60 ns at DIV = 4, 50 MHz,
above the AD7476A's 40 ns access time). Every pad is registered; the ADC pins
pass one register. DIV = 4 at 50 MHz: SCLK 12.5 MHz (AD7476A <= 20 MHz,
DAC121S101 <= 30 MHz), 694.4 kS/s.

Towards gyro_interface_axi (one clock, the system clock), which reads an ADC
word and writes a DAC word every clock: the engine holds each ADC sample for
a whole period and sends the DAC word of the period's first clock. The 12
bits sit at the MSBs of the core's 16-bit two's complement words (README:
a narrower converter sits at the MSBs). Latencies in `Latencies`.
"""

from dataclasses import dataclass

from migen import Cat, If, Replicate, Signal

from litex.gen import LiteXModule

FRAME_SCLKS = 16
IDLE_SCLKS = 2
CONVERTER_BITS = 12
WORD_BITS = 16


@dataclass(frozen=True)
class Latencies:
    """System clocks from the ADC's sampling instant (CS fall at the pin) to
    the first clock the core reads that sample, from the clock the core
    presents a DAC word to the DAC's update (16th SCLK fall at the pin), and
    how many clocks one sample lasts. test_pmod_converters.py measures them."""

    adc_clocks: int
    dac_clocks: int
    hold_clocks: int


class PmodAD1DA2(LiteXModule):
    """adc1/adc2: to the core; dac1/dac2: from the core (16-bit, signed)."""

    def __init__(self, adc_pads, dac_pads, sclk_div=4):
        assert sclk_div >= 4 and sclk_div % 2 == 0, "sclk_div: an even number >= 4"
        self.sclk_div = sclk_div
        self.clocks_per_sample = sclk_div * (FRAME_SCLKS + IDLE_SCLKS)
        self.adc1 = Signal((WORD_BITS, True))
        self.adc2 = Signal((WORD_BITS, True))
        self.dac1 = Signal((WORD_BITS, True))
        self.dac2 = Signal((WORD_BITS, True))

        # # #

        half = sclk_div // 2
        periods = FRAME_SCLKS + IDLE_SCLKS
        period = Signal(max=periods)  # SCLK period in the sample period
        phase = Signal(max=sclk_div)  # clock within the SCLK period
        self.sync += If(
            phase == sclk_div - 1,
            phase.eq(0),
            If(period == periods - 1, period.eq(0)).Else(period.eq(period + 1)),
        ).Else(phase.eq(phase + 1))
        active = Signal()
        start = Signal()  # the first clock of a sample period
        frame_end = Signal()  # the first clock after the 16th SCLK period
        self.comb += [
            active.eq(period < FRAME_SCLKS),
            start.eq((period == 0) & (phase == 0)),
            frame_end.eq((period == FRAME_SCLKS) & (phase == 0)),
        ]

        # The pads, registered: a function of the count one clock earlier.
        sclk, cs_n = Signal(reset=1), Signal(reset=1)
        self.sync += [sclk.eq(~active | (phase < half)), cs_n.eq(~active)]

        # DAC: the word of the period's first clock, shifted out MSB first, a bit
        # at each SCLK period's start.
        dins = [Signal(), Signal()]
        for din, dac in zip(dins, [self.dac1, self.dac2]):
            frame = Signal(WORD_BITS)
            self.sync += If(
                start,
                din.eq(offset_binary(dac)[-1]),
                frame.eq(offset_binary(dac) << 1),
            ).Elif(
                active & (phase == 0),
                din.eq(frame[-1]),
                frame.eq(frame << 1),
            ).Elif(~active, din.eq(0))
        self.comb += [dac_pads.sync_n.eq(cs_n), dac_pads.sclk.eq(sclk),
                      dac_pads.dina.eq(dins[0]), dac_pads.dinb.eq(dins[1])]

        # ADC: one register at the pins; take a bit just before each fall 1..15
        # (the pad shows the counters' state one clock late, the pin register one more).
        take = Signal()
        self.comb += take.eq((phase == half + 1) & (period >= 1) & active)
        for pin, adc in [(adc_pads.d0, self.adc1), (adc_pads.d1, self.adc2)]:
            pin_q, shift = Signal(), Signal(CONVERTER_BITS)
            self.sync += [
                pin_q.eq(pin),
                If(take, shift.eq(Cat(pin_q, shift[:-1]))),
                If(frame_end, adc.eq(twos_complement(shift))),
            ]
        self.comb += [adc_pads.cs_n.eq(cs_n), adc_pads.sck.eq(sclk)]

    def latencies(self):
        """The converter latencies of this engine (see `Latencies`)."""
        frame_end = FRAME_SCLKS * self.sclk_div
        last_fall = (FRAME_SCLKS - 1) * self.sclk_div + self.sclk_div // 2
        return Latencies(
            adc_clocks=frame_end,
            dac_clocks=last_fall + 2,
            hold_clocks=self.clocks_per_sample,
        )


def offset_binary(word):
    """The DAC frame of a 16-bit two's complement word: its 12 MSBs, straight binary, PD = 00."""
    top = WORD_BITS - CONVERTER_BITS
    return Cat(word[top:WORD_BITS - 1], ~word[WORD_BITS - 1], Replicate(0, WORD_BITS - CONVERTER_BITS))


def twos_complement(sample):
    """The core's 16-bit word of a 12-bit straight-binary ADC sample (at the MSBs)."""
    return Cat(Replicate(0, WORD_BITS - CONVERTER_BITS), sample[:-1], ~sample[-1])
