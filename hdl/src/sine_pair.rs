//! Cosine and sine of one phase from the fine table: three phase bits
//! interpolated, one multiplier per output, one rounding at the end, to a
//! quarter LSB. The ECP5 carrier profile (`crate::fine_sine_table` says
//! why).
//!
//! ```text
//!  clock:   1 address          2 ROM read      3 words, slope     4 products, bases       5 output
//!  phase[29:17] ─► [i, ~i] ─► FineSineRom ─► [a, b] ─┬─► b x k ─► [p_s] ─┐
//!                                                   ├─► a x k ─► [p_c] ─┼─► base ± (p >> 22) ─► [>> 8] ─► sin, cos
//!  phase[16:14] ─► [s] ──────► [s] ─► FineSlope [k]       bases ─► [base] ┘
//!  phase[31:30] ─► [q] ──────► [q] ──────────► [q] ─► (which word, sign) ─► [pick, add]
//!  live ─────────► [live] ───► [live] ───────► [live] ─────────────────► [live] ─► (else 0)
//! ```
//!
//! The arithmetic is `crate::model::sine_pair`'s, which its header derives:
//! each output is `s`, `c`, `-s` or `-c` of the phase within its quadrant,
//! `(base ± t) >> 8`, with `base = 256 w + 128` or `127 - 256 w` (`w` the
//! output's own word) and `t` the other word times the slope, floored to
//! 2^-8 quarter LSB. The sine output takes the quadrant `q`, the cosine
//! `q + 1`.
//!
//! Widths: words 17 bits unsigned (18 signed at the multipliers), slopes
//! 18 signed, products 36, `t` 14 signed (|t| <= 2815), sums 27 signed
//! (|sum| < 256 x 131068 + 128 + 2815 < 2^25), outputs 18-bit two's
//! complement in [-131068, 131068] (`sum` bits 25:8, quarter LSB). Gain:
//! peak 4 x 32767. Error against `32767 sin(2 pi phase / 2^32)`: at most
//! 0.65 LSB (the model's tests). Pipeline: 5 registers, as `crate::table_sine`, so the
//! carriers keep their latency. Resources: one `FineSineRom` (eight ECP5
//! `DP16KD`), two 18 x 18 multipliers (`MULT18X18D`), about 290 flip-flops
//! of which the products' 72 sit in the multipliers' output registers.

use crate::fine_sine_table::{OUTPUT_BITS, TABLE_BITS};
use crate::fine_slope::FineSlope;
use crate::primitives::convert::signed_bit_cast_exact;
use crate::primitives::{FineSineRom, RegisteredMultiplier};
use rust_hdl::prelude::*;

/// Clock cycles from `phase` to `cos`, `sin`.
pub const LATENCY: usize = 5;

/// Cosine and sine of a 32-bit phase, interpolated.
#[derive(LogicBlock)]
pub struct SinePair {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Phase as a fraction of a turn: 2^32 is 360 degrees.
    pub phase: Signal<In, Bits<32>>,
    /// The lookup started now reaches the outputs (else they give 0 for it).
    pub live: Signal<In, Bit>,
    /// 4 x 32767 cos(phase) (quarter LSB), `LATENCY` clocks after `phase`.
    pub cos: Signal<Out, Signed<OUTPUT_BITS>>,
    /// 4 x 32767 sin(phase) (quarter LSB), `LATENCY` clocks after `phase`.
    pub sin: Signal<Out, Signed<OUTPUT_BITS>>,
    rom: FineSineRom,
    quadrant_1: DFF<Bits<2>>,
    sub_1: DFF<Bits<3>>,
    live_1: DFF<Bit>,
    quadrant_2: DFF<Bits<2>>,
    sub_2: DFF<Bits<3>>,
    live_2: DFF<Bit>,
    index_1: DFF<Bits<TABLE_BITS>>,
    mirror_1: DFF<Bits<TABLE_BITS>>,
    sine_word_3: DFF<Signed<18>>,
    cosine_word_3: DFF<Signed<18>>,
    quadrant_3: DFF<Bits<2>>,
    live_3: DFF<Bit>,
    slope_stage: FineSlope,
    sine_cross: RegisteredMultiplier<18, 18, 36>,
    cosine_cross: RegisteredMultiplier<18, 18, 36>,
    sin_part: OutputPart,
    cos_part: OutputPart,
    cos_quadrant: Signal<Local, Bits<2>>,
    quarter_turn: Constant<Bits<2>>,
    live_4: DFF<Bit>,
}

/// Stages 4 and 5 of one output: which of `s`, `c`, `-s`, `-c` it is, the
/// base from its own word, then the cross term added or subtracted.
#[derive(LogicBlock)]
pub struct OutputPart {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// The output's quadrant (stage 3).
    pub quadrant: Signal<In, Bits<2>>,
    /// The interval's sine word `a` (stage 3).
    pub sine_word: Signal<In, Signed<18>>,
    /// The interval's cosine word `b` (stage 3).
    pub cosine_word: Signal<In, Signed<18>>,
    /// `b x slope` (stage 4, registered).
    pub sine_cross: Signal<In, Signed<36>>,
    /// `a x slope` (stage 4, registered).
    pub cosine_cross: Signal<In, Signed<36>>,
    /// The lookup is live (stage 4).
    pub live: Signal<In, Bit>,
    /// The output in quarter LSB (stage 5, registered).
    pub value: Signal<Out, Signed<OUTPUT_BITS>>,
    base_4: DFF<Signed<27>>,
    sine_type_4: DFF<Bit>,
    add_4: DFF<Bit>,
    value_5: DFF<Signed<OUTPUT_BITS>>,
    own: Signal<Local, Bits<27>>,
    scaled: Signal<Local, Signed<27>>,
    cross_bits: Signal<Local, Signed<14>>,
    cross_term: Signal<Local, Signed<27>>,
    sum: Signal<Local, Signed<27>>,
    half: Constant<Signed<27>>,
    half_less_one: Constant<Signed<27>>,
    guard: Constant<Bits<27>>,
    zero: Constant<Signed<OUTPUT_BITS>>,
}

impl OutputPart {
    fn new() -> Self {
        use crate::fine_sine_table::{OUTPUT_SHIFT, SUM_GUARD_BITS};
        let half = 1i64 << (OUTPUT_SHIFT - 1);
        Self {
            clock: Default::default(),
            quadrant: Default::default(),
            sine_word: Default::default(),
            cosine_word: Default::default(),
            sine_cross: Default::default(),
            cosine_cross: Default::default(),
            live: Default::default(),
            value: Default::default(),
            base_4: Default::default(),
            sine_type_4: Default::default(),
            add_4: Default::default(),
            value_5: Default::default(),
            own: Default::default(),
            scaled: Default::default(),
            cross_bits: Default::default(),
            cross_term: Default::default(),
            sum: Default::default(),
            half: Constant::new(half.into()),
            half_less_one: Constant::new((half - 1).into()),
            guard: Constant::new(u64::from(SUM_GUARD_BITS).into()),
            zero: Constant::new(0.into()),
        }
    }
}

impl Logic for OutputPart {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, base_4, sine_type_4, add_4, value_5);
        // Stage 4: the output's own word, scaled to the sum (x 256), and
        // the base: 256 w + 128, or its one's complement plus 128.
        // (The words are never negative: their low 17 bits zero-extended.)
        self.own.next = bit_cast::<27, 17>(unsigned_cast(self.cosine_word.val().get_bits::<17>(0)));
        if !self.quadrant.val().get_bit(0) {
            self.own.next =
                bit_cast::<27, 17>(unsigned_cast(self.sine_word.val().get_bits::<17>(0)));
        }
        self.scaled.next = signed_cast(self.own.val() << self.guard.val());
        self.base_4.d.next = self.scaled.val() + self.half.val();
        if self.quadrant.val().get_bit(1) {
            self.base_4.d.next = self.half_less_one.val() - self.scaled.val();
        }
        self.sine_type_4.d.next = !self.quadrant.val().get_bit(0);
        self.add_4.d.next = (!self.quadrant.val().get_bit(0)) ^ self.quadrant.val().get_bit(1);
        // Stage 5: the cross term (the product floored to 2^-8 quarter
        // LSB, bits 35:22) added or subtracted, the sum's bits 25:8 out
        // (`fine_sine_table::OUTPUT_SHIFT`).
        self.cross_bits.next = self.cosine_cross.val().get_bits::<14>(22);
        if self.sine_type_4.q.val() {
            self.cross_bits.next = self.sine_cross.val().get_bits::<14>(22);
        }
        self.cross_term.next = signed_bit_cast_exact::<27, 14>(self.cross_bits.val());
        self.sum.next = self.base_4.q.val() - self.cross_term.val();
        if self.add_4.q.val() {
            self.sum.next = self.base_4.q.val() + self.cross_term.val();
        }
        self.value_5.d.next = self.zero.val();
        if self.live.val() {
            self.value_5.d.next = self.sum.val().get_bits::<OUTPUT_BITS>(8);
        }
        self.value.next = self.value_5.q.val();
    }
}

impl SinePair {
    /// The pair at power-up: every register 0.
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            phase: Default::default(),
            live: Default::default(),
            cos: Default::default(),
            sin: Default::default(),
            rom: FineSineRom::new(),
            quadrant_1: Default::default(),
            sub_1: Default::default(),
            live_1: Default::default(),
            quadrant_2: Default::default(),
            sub_2: Default::default(),
            live_2: Default::default(),
            index_1: Default::default(),
            mirror_1: Default::default(),
            sine_word_3: Default::default(),
            cosine_word_3: Default::default(),
            quadrant_3: Default::default(),
            live_3: Default::default(),
            slope_stage: FineSlope::new(),
            sine_cross: RegisteredMultiplier::new(),
            cosine_cross: RegisteredMultiplier::new(),
            sin_part: OutputPart::new(),
            cos_part: OutputPart::new(),
            cos_quadrant: Default::default(),
            quarter_turn: Constant::new(1.into()),
            live_4: Default::default(),
        }
    }
}

impl Default for SinePair {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for SinePair {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            quadrant_1,
            sub_1,
            live_1,
            quadrant_2,
            sub_2,
            live_2,
            index_1,
            mirror_1,
            sine_word_3,
            cosine_word_3,
            quadrant_3,
            live_3,
            live_4
        );
        self.rom.clock.next = self.clock.val();
        self.slope_stage.clock.next = self.clock.val();
        self.sine_cross.clock.next = self.clock.val();
        self.cosine_cross.clock.next = self.clock.val();
        self.sin_part.clock.next = self.clock.val();
        self.cos_part.clock.next = self.clock.val();
        // Stage 1: the interval and its mirror, the sub-interval, the quadrant.
        self.index_1.d.next = self.phase.val().get_bits::<TABLE_BITS>(17);
        self.mirror_1.d.next = !(self.phase.val().get_bits::<TABLE_BITS>(17));
        self.sub_1.d.next = self.phase.val().get_bits::<3>(14);
        self.quadrant_1.d.next = self.phase.val().get_bits::<2>(30);
        self.live_1.d.next = self.live.val();
        // Stage 2: the ROM reads both words.
        self.rom.addr_a.next = self.index_1.q.val();
        self.rom.addr_b.next = self.mirror_1.q.val();
        self.sub_2.d.next = self.sub_1.q.val();
        self.quadrant_2.d.next = self.quadrant_1.q.val();
        self.live_2.d.next = self.live_1.q.val();
        // Stage 3: the words registered (a block RAM's clock-to-out), the
        // slope (`FineSlope`, its register inside).
        self.sine_word_3.d.next = self.rom.word_a.val();
        self.cosine_word_3.d.next = self.rom.word_b.val();
        self.slope_stage.sub.next = self.sub_2.q.val();
        self.quadrant_3.d.next = self.quadrant_2.q.val();
        self.live_3.d.next = self.live_2.q.val();
        // Stage 4: the cross products; each output's base (OutputPart).
        self.sine_cross.a.next = self.cosine_word_3.q.val();
        self.sine_cross.b.next = self.slope_stage.slope.val();
        self.cosine_cross.a.next = self.sine_word_3.q.val();
        self.cosine_cross.b.next = self.slope_stage.slope.val();
        self.live_4.d.next = self.live_3.q.val();
        self.cos_quadrant.next = self.quadrant_3.q.val() + self.quarter_turn.val();
        self.sin_part.quadrant.next = self.quadrant_3.q.val();
        self.cos_part.quadrant.next = self.cos_quadrant.val();
        self.sin_part.sine_word.next = self.sine_word_3.q.val();
        self.sin_part.cosine_word.next = self.cosine_word_3.q.val();
        self.cos_part.sine_word.next = self.sine_word_3.q.val();
        self.cos_part.cosine_word.next = self.cosine_word_3.q.val();
        // Stage 5: each output from its base and a cross product.
        self.sin_part.sine_cross.next = self.sine_cross.p.val();
        self.sin_part.cosine_cross.next = self.cosine_cross.p.val();
        self.cos_part.sine_cross.next = self.sine_cross.p.val();
        self.cos_part.cosine_cross.next = self.cosine_cross.p.val();
        self.sin_part.live.next = self.live_4.q.val();
        self.cos_part.live.next = self.live_4.q.val();
        self.sin.next = self.sin_part.value.val();
        self.cos.next = self.cos_part.value.val();
    }
}

crate::impl_clocked!(SinePair);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{prepare, tick};
    use crate::model::sine_pair::sine_pair;
    use crate::primitives::convert::signed_to_i128;
    use crate::test_util::Rng;

    /// Random phases, with runs of one step (a carrier) and liveness
    /// switched on and off; every quadrant, interval and sub-interval is
    /// reachable.
    fn stimulus(seed: u64, cycles: usize) -> Vec<(u32, bool)> {
        let mut rng = Rng::new(seed);
        let mut phase = 0u32;
        let mut step = 0u32;
        (0..cycles)
            .map(|n| {
                if n % 37 == 0 {
                    step = rng.next_u64() as u32;
                }
                phase = if n % 5 == 0 {
                    rng.next_u64() as u32
                } else {
                    phase.wrapping_add(step)
                };
                (phase, n % 97 > 7)
            })
            .collect()
    }

    /// The model's outputs after each edge: the lookup of 5 edges before,
    /// or 0 for one that was not live.
    fn expected(stimulus: &[(u32, bool)]) -> Vec<(i32, i32)> {
        (0..stimulus.len())
            .map(|n| match n.checked_sub(LATENCY - 1) {
                Some(k) if stimulus[k].1 => sine_pair(stimulus[k].0),
                _ => (0, 0),
            })
            .collect()
    }

    #[test]
    fn rtl_matches_the_model_on_every_cycle() {
        let stimulus = stimulus(11, 3000);
        let want = expected(&stimulus);
        let mut uut = SinePair::new();
        prepare(&mut uut);
        for (n, &(phase, live)) in stimulus.iter().enumerate() {
            uut.phase.next = u64::from(phase).into();
            uut.live.next = live;
            tick(&mut uut);
            let v = |x: Signed<OUTPUT_BITS>| signed_to_i128(x) as i32;
            assert_eq!((v(uut.cos.val()), v(uut.sin.val())), want[n], "edge {n}");
        }
    }

    /// The exported Verilog (the ROM's and the multipliers' hand-written
    /// leaves included) in Icarus against the model, both outputs.
    #[test]
    fn the_verilog_matches_the_model() {
        let stimulus = stimulus(12, 1500);
        let want = expected(&stimulus);
        let mut uut = SinePair::new();
        prepare(&mut uut);
        let verilog = generate_verilog(&uut);
        let steps: Vec<String> = stimulus
            .iter()
            .map(|&(phase, live)| format!("phase = 32'd{phase}; live = {};", u8::from(live)))
            .collect();
        let inputs = [("phase", 32, false), ("live", 1, false)];
        for (output, pick) in [("cos", 0usize), ("sin", 1)] {
            let got =
                crate::test_util::icarus_clocked(&verilog, &inputs, (output, OUTPUT_BITS), &steps);
            assert_eq!(got.len(), want.len());
            for (n, (g, w)) in got.iter().zip(&want).enumerate() {
                let w = if pick == 0 { w.0 } else { w.1 };
                assert_eq!(g, &w.to_string(), "{output}, edge {n}");
            }
        }
    }
}
