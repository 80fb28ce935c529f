//! Sine of a 32-bit phase: quarter-wave table plus first-order Taylor
//! interpolation, one table port and one multiplier.
//!
//! ```text
//!  clock:        1 index        2 ROM read      3 words     4 product            5 output
//!  phase[31:30] + advance = q ─► [q] ─────────► [q] ───────► [q] ─────────────────► [q] ┐
//!  phase[29:22] i ─► q odd ? ~i : i ─► ROM: value, slope ─► [v, s] ─► ±v (q >= 2: -) ─┐ │
//!  phase[21:7]  f ─► fs = f - 2^14 ─► [fs] ─► [fs] ─────────► fs * s ─► round(/2^22) ─┤ │
//!                                                                                    ▼ ▼
//!                          sin = ±v + correction (q = 0, 3)   or   ±v - correction (q = 1, 2)
//! ```
//!
//! The phase is a binary fraction of a turn (2^32 = 360 degrees); `advance`
//! adds whole quarter turns to it (1: the output is the cosine). Bits 29:22
//! pick one of the 256 intervals of the quadrant, whose centre is sampled in
//! `crate::sine_table`; the next 15 bits, re-centred to fs in [-2^14, 2^14),
//! are the offset from that centre in units of 2^-15 table step. In an even
//! quadrant the sample of interval i is moved to the exact phase by the
//! first-order Taylor term `sin(t + d) = sin t + d cos t`, with the
//! derivative read from the slope column (scaled by 2^7), so
//! `fs * slope / 2^(15 + 7)` is the correction in output LSBs, rounded half
//! up (add 2^21, then floor). An odd quadrant runs the same interval
//! backwards: its first-quadrant value is the cosine of the remainder, the
//! mirrored entry ~i moved by the same offset the other way. Quadrants 2
//! and 3 negate: the sample is negated beside the product, and the
//! correction's sign is the product of the two rules (added in quadrants 0
//! and 3, subtracted in 1 and 2), so sign and correction take one adder.
//! Phase bits 6:0 are ignored (truncated).
//!
//! The mirrored index is registered before the table, so the ROM's address
//! comes from flip-flops: where a tool builds the ROM from LUTs (Yosys
//! `synth_xilinx`), a mirror in front of it would be folded into the ROM,
//! doubling it to a function of nine inputs. On block RAM the index
//! register is an ordinary 8-bit register in front of the RAM's own.
//!
//! Widths: the output is 16-bit two's complement with peak 32767, symmetric,
//! never -32768: the correction is at most 101 LSB and the first-quadrant
//! values stay within [0, 32767] (checked exhaustively over all 2^23
//! interval and offset codes in the model's tests), so neither the negated
//! sample nor the negated sum can overflow. Error against
//! `32767 sin(2 pi phase / 2^32)`: at most 1.2 LSB; spur-free dynamic range
//! above 100 dBc (measured by FFT in `crate::carrier_nco`'s tests).
//!
//! Pipeline: 5 registers (index, ROM read, table words, product and signed
//! sample, output). `sin` during cycle n belongs to the `phase` and
//! `advance` presented during cycle n - 5. Power-up: every register is 0,
//! so the index register reads table entry 0 once: the output is 0 during
//! cycles 0..=3 and `sine_table::value(0)` (the sample of the first interval,
//! with a zero offset) during cycle 4, then the sine of the phase of cycle 0
//! on. Resources: one table ROM port (256 x 32 bits), one 16x16 multiplier.

use crate::primitives::{QuarterSineRom, RegisteredMultiplier};
use rust_hdl::prelude::*;

/// Clock cycles from `phase` to `sin`.
pub const LATENCY: usize = 5;

/// Sine of a 32-bit phase plus whole quarter turns, 16-bit output, 5-clock
/// pipeline.
#[derive(LogicBlock)]
pub struct Sine {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Phase as a fraction of a turn: 2^32 is 360 degrees.
    pub phase: Signal<In, Bits<32>>,
    /// Quarter turns added to `phase` (0: sine, 1: cosine, 2: -sine, 3: -cosine).
    pub advance: Signal<In, Bits<2>>,
    /// 32767 sin(phase + advance quarter turns), 16-bit two's complement,
    /// `LATENCY` clocks after `phase`.
    pub sin: Signal<Out, Signed<16>>,
    rom: QuarterSineRom,
    slope_product: RegisteredMultiplier<16, 16, 32>,
    // Stage 1: the table index, mirrored in odd quadrants.
    index_1: DFF<Bits<8>>,
    quadrant_1: DFF<Bits<2>>,
    offset_1: DFF<Signed<16>>,
    // Stage 2 (beside the ROM read).
    quadrant_2: DFF<Bits<2>>,
    offset_2: DFF<Signed<16>>,
    // Stage 3: the table words registered (the block RAM's read port has
    // no output register, and its clock-to-out plus a multiplier does not
    // fit one clock at 100 MHz on an ECP5).
    quadrant_read: DFF<Bits<2>>,
    offset_read: DFF<Signed<16>>,
    value_read: DFF<Signed<16>>,
    slope_read: DFF<Signed<16>>,
    // Stage 4 (beside the slope product): the sample, negated in the
    // negative half of the turn.
    quadrant_4: DFF<Bits<2>>,
    signed_sample_4: DFF<Signed<16>>,
    // Stage 5: output register.
    sin_out: DFF<Signed<16>>,
    // Combinational helpers.
    quadrant: Signal<Local, Bits<2>>,
    fraction: Signal<Local, Bits<16>>,
    rounded: Signal<Local, Signed<32>>,
    correction_10: Signal<Local, Signed<10>>,
    correction: Signal<Local, Signed<16>>,
    half_step: Constant<Bits<16>>,
    rounding: Constant<Signed<32>>,
}

impl Sine {
    /// A sine generator with the table of `crate::sine_table`.
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            phase: Default::default(),
            advance: Default::default(),
            sin: Default::default(),
            rom: QuarterSineRom::new(),
            slope_product: RegisteredMultiplier::new(),
            index_1: Default::default(),
            quadrant_1: Default::default(),
            offset_1: Default::default(),
            quadrant_2: Default::default(),
            offset_2: Default::default(),
            quadrant_read: Default::default(),
            offset_read: Default::default(),
            value_read: Default::default(),
            slope_read: Default::default(),
            quadrant_4: Default::default(),
            signed_sample_4: Default::default(),
            sin_out: Default::default(),
            quadrant: Default::default(),
            fraction: Default::default(),
            rounded: Default::default(),
            correction_10: Default::default(),
            correction: Default::default(),
            half_step: Constant::new(0x4000.into()),
            rounding: Constant::new((1i64 << 21).into()),
        }
    }
}

impl Default for Sine {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for Sine {
    #[hdl_gen]
    fn update(&mut self) {
        self.rom.clock.next = self.clock.val();
        self.slope_product.clock.next = self.clock.val();
        dff_setup!(
            self,
            clock,
            index_1,
            quadrant_1,
            offset_1,
            quadrant_2,
            offset_2,
            quadrant_read,
            offset_read,
            value_read,
            slope_read,
            quadrant_4,
            signed_sample_4,
            sin_out
        );
        // Stage 1: table index (the mirrored entry in odd quadrants);
        // offset from the interval centre.
        self.quadrant.next = self.phase.val().get_bits::<2>(30) + self.advance.val();
        self.index_1.d.next = self.phase.val().get_bits::<8>(22);
        if self.quadrant.val().get_bit(0) {
            self.index_1.d.next = !(self.phase.val().get_bits::<8>(22));
        }
        self.quadrant_1.d.next = self.quadrant.val();
        self.fraction.next = bit_cast::<16, 15>(self.phase.val().get_bits::<15>(7));
        self.offset_1.d.next = signed_cast(self.fraction.val() - self.half_step.val());
        // Stage 2: table read.
        self.rom.addr.next = self.index_1.q.val();
        self.quadrant_2.d.next = self.quadrant_1.q.val();
        self.offset_2.d.next = self.offset_1.q.val();
        // Stage 3: table words registered.
        self.quadrant_read.d.next = self.quadrant_2.q.val();
        self.offset_read.d.next = self.offset_2.q.val();
        self.value_read.d.next = self.rom.value.val();
        self.slope_read.d.next = self.rom.slope.val();
        // Stage 4: derivative times offset; the sample's sign.
        self.slope_product.a.next = self.offset_read.q.val();
        self.slope_product.b.next = self.slope_read.q.val();
        self.quadrant_4.d.next = self.quadrant_read.q.val();
        self.signed_sample_4.d.next = self.value_read.q.val();
        if self.quadrant_read.q.val().get_bit(1) {
            self.signed_sample_4.d.next = -self.value_read.q.val();
        }
        // Stage 5: correction rounded half up, added in quadrants 0 and 3,
        // subtracted in 1 and 2.
        self.rounded.next = self.slope_product.p.val() + self.rounding.val();
        self.correction_10.next = self.rounded.val().get_bits::<10>(22);
        self.correction.next = signed_bit_cast::<16, 10>(self.correction_10.val());
        self.sin_out.d.next = self.signed_sample_4.q.val() + self.correction.val();
        if self.quadrant_4.q.val().get_bit(0) ^ self.quadrant_4.q.val().get_bit(1) {
            self.sin_out.d.next = self.signed_sample_4.q.val() - self.correction.val();
        }
        self.sin.next = self.sin_out.q.val();
    }
}

crate::impl_clocked!(Sine);

/// Mutation hooks for the negative control in `crate::rtl` (tests only).
#[cfg(test)]
impl Sine {
    #[doc(hidden)]
    pub fn mutate_rounding(&mut self) {
        self.rounding = Constant::new(((1i64 << 21) + (1 << 20)).into());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{prepare, tick};
    use crate::model::sine::{Sine as Model, sine};
    use crate::primitives::convert::{signed_to_i128, u128_to_bits};
    use proptest::prelude::*;

    /// Drive the rust-hdl block and the model with the same phases and
    /// quarter-turn advances.
    fn compare(inputs: &[(u32, u8)]) {
        let mut uut = Sine::new();
        prepare(&mut uut);
        let mut golden = Model::default();
        let mut peak = 0i16;
        for (n, &(p, advance)) in inputs.iter().enumerate() {
            uut.phase.next = u128_to_bits(p as u128);
            uut.advance.next = u128_to_bits(advance as u128);
            tick(&mut uut);
            let hw = signed_to_i128(uut.sin.val()) as i16;
            assert_eq!(hw, golden.step(p, advance), "cycle {n}, phase {p:#010x}");
            peak = peak.max(hw.abs());
        }
        // Guard against a vacuous comparison of two idle pipelines.
        assert!(peak > 20000, "output never left zero (peak {peak})");
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(16))]
        #[test]
        fn rtl_matches_model_on_random_phases_and_advances(
            inputs in prop::collection::vec((any::<u32>(), 0u8..4), 300),
        ) {
            compare(&inputs);
        }
    }

    #[test]
    fn rtl_matches_model_at_quadrant_edges_and_a_ramp() {
        let mut phases = vec![0, 1, 0x3fff_ffff, 0x4000_0000, 0x7fff_ffff, 0x8000_0000];
        phases.extend([0xbfff_ffff, 0xc000_0000, u32::MAX, 0x003f_ff80, 0x0040_0000]);
        phases.extend((0..400u32).map(|k| k.wrapping_mul(0x3171_5a3b)));
        let inputs: Vec<(u32, u8)> = phases
            .iter()
            .enumerate()
            .map(|(k, &p)| (p, (k % 4) as u8))
            .collect();
        compare(&inputs);
    }

    #[test]
    fn an_advance_is_a_quarter_turn_of_phase() {
        for k in 0u32..4096 {
            let p = k.wrapping_mul(0x9e37_79b9);
            for a in 0u8..4 {
                let turned = p.wrapping_add(u32::from(a) << 30);
                assert_eq!(sine(p, a), sine(turned, 0), "phase {p:#x}, advance {a}");
            }
        }
    }
}
