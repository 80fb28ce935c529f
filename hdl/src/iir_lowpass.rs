//! IIR low-pass at the decimated rate, both channels: a 2nd-order
//! Butterworth section and a first-order RC section (the paper's output
//! filter) on ONE 16 x 16 multiplier, digit-serial.
//!
//! ```text
//!  x[40] ─► v = x0 + 2 x1 + x2 ─► y = 2 y1 - y2 + round((k0 v + k1 y1 + k2 y2) / 2^30)   (biquad)
//!                                 u = u1 + round(alpha (y - u1) / 2^30)                  (RC)
//!                                 z = round(u / 2^16) ──► z[40], z_valid
//! ```
//!
//! The biquad is the direct form I of b = g[1, 2, 1], a = [1, a1, a2],
//! written around the double pole at z = 1 that low cut-offs approach:
//! k1 = -a1 - 2 and k2 = 1 - a2 are small, so their 30 fractional bits are
//! spent on the pole's distance from 1, not on the leading 2 and 1
//! (`crate::filter_design` computes k0 = g, k1, k2, alpha from cut-offs in
//! Hz and quantizes them; its DC gain is 4 k0 / -(k1 + k2)).
//!
//! Arithmetic of record (unchanged; the micro-program computes exactly it,
//! `model::iir_lowpass` proves it against an i128 reference). Formats and
//! widths (LSB of the CIC output = 2^-8 of a mixer LSB):
//! - x: CIC output, 40 bits, 8 fractional bits;
//! - coefficients k0, k1, k2, alpha: 32-bit two's complement, Q2.30;
//! - states y1, y2, u: `STATE_BITS` = 40 + 16 + 2 = 58 bits with 24
//!   fractional bits (`GUARD_BITS` = 16 guard bits below the output LSB,
//!   which keep the dead band and any zero-input limit cycle of the
//!   recursion below half an output LSB, so z returns exactly to 0; 2 bits
//!   of headroom: they hold +-2^33 mixer LSBs, twice the largest mixer
//!   output, which covers the 4.3% step overshoot of the Butterworth
//!   section);
//! - multiplier operands: `OPERAND_BITS` = 58 + 2 = 60, which holds
//!   2 y1 - y2 and y - u exactly (|.| < 3 2^57 and < 2^58), and v 2^16
//!   (v < 2^41, 58 bits);
//! - products: 60 x 32 = `PRODUCT_BITS` = 92 bits (|p| <= 2^90), exact;
//! - accumulators: a feedback term m 2^30 with |m| < 2^59 plus three
//!   products, each below 2^91 in magnitude: the sum of four such terms
//!   stays below 2^93, so `ACCUMULATOR_BITS` = 92 + 2 = 94 never overflows.
//!   Each section rounds once (half up) when dropping 30 bits; z is u
//!   rounded half up to 8 fractional bits, 40 bits. The 60-bit difference
//!   y - u is taken from the 94-bit sum before y is cut to 58 bits.
//!
//! Overflow bound for the filters `crate::filter_design` makes (its whole
//! range): the input x is the CIC output for mixer words of at most 2^30
//! (a product of two 16-bit words), so |x| <= x_max = 2^38 G (+1/2), G the
//! CIC gain, and the filter's DC gain is 1/G. Each linear register is at
//! most x_max times the l1 norm of its impulse response, which the sign
//! sequence of that response read backwards reaches; l1 x G depends on the
//! cut-off ratios only. Largest l1 x G over the range (corners R = 166, 182,
//! 4096 with each cut-off at f_z / 1000 or f_z / 5, and a 40 x 8 sweep):
//! 1.168 for y, 1.091 for u, 1.864 for 2 y1 - y2, 2.127 for y - u, 2.810
//! for 2 y1 - y2 - u. Peaks of the worst-case sequences against the range
//! of each register (the accumulators peak with their section's worst
//! case; v is at most 4 x_max 2^16 for any input):
//!
//! | register | bits | peak | margin |
//! |---|---|---|---|
//! | v = (x + 2 x0 + x1) 2^16 | 60 | 2^56.00 | 3.00 bits |
//! | 2 y1 - y2 | 60 | 2^54.90 | 4.10 bits |
//! | biquad accumulator | 94 | 2^84.22 | 8.78 bits |
//! | 2 y1 - y2 - u | 60 | 2^55.49 | 3.51 bits |
//! | difference accumulator | 94 | 2^85.09 | 7.91 bits |
//! | y (y1, y2) | 58 | 2^54.22 | 2.78 bits |
//! | y - u | 60 | 2^55.09 | 3.91 bits |
//! | RC accumulator | 94 | 2^84.12 | 8.88 bits |
//! | u, u + 2^15 | 58 | 2^54.12 | 2.88 bits |
//! | z | 40 | 2^38.12 | 0.88 bits |
//!
//! `model::iir_lowpass`'s `worst_case_sequences_fit_every_register` drives
//! each worst case through the i128 arithmetic of record at the corners
//! (no register wraps, each reaches its bound) and z's through the bit-true
//! model; `worst_case_of_z_through_the_rust_hdl_design` drives z's through
//! this design. A 40-bit x beyond 2^38 G (from a CIC shift smaller than
//! the designed one) can overflow z: outside the supported settings.
//!
//! Datapath (the widths of `crate::iir_program`):
//!
//! ```text
//!  ROM[pc] ─► [word] ─┬─ read ─► digit RAM (128 x 16) ─► [a] ─┐
//!                     ├─ factor ─► coefficient digit mux ─► [b] ─┴─ 16 x 16 ─► [p] ─► acc[36] ─┬─► RAM (digits)
//!                     └─ op, emit, publish                              (acc >> 15) + p ─┘   └─► stage[90] ─► z1, z2
//! ```
//!
//! Every product of the header is cut into 15-bit digits and summed column
//! by column (`crate::iir_program`): one 16 x 16 signed product per clock
//! (one iCE40 `SB_MAC16`, one ECP5 `MULT18X18D`), a 36-bit accumulator
//! that shifts 15 bits right between columns, and finished digits written
//! back to the RAM. The states x0, x1, y1, y2, u and the difference live in
//! one block RAM as digits; the flip-flops are the two captured inputs, the
//! operand, product and accumulator registers, the 90-bit output staging
//! register and the outputs.
//!
//! Blocks, in the order a word runs through them:
//! - `crate::iir_sequencer`: the program counter, the micro-program ROM
//!   (one block RAM) and the word register after it, the sample counter
//!   and the slot rotation of the RAM addresses;
//! - this block: operand a (the RAM digit, a state's top digit
//!   sign-extended), the multiplier and the column accumulator;
//! - `crate::iir_coefficient_digit`: operand b, a digit of a scaled
//!   coefficient or a constant;
//! - `crate::iir_digits`: the digit RAM, what is written into it (a column
//!   digit, a result's top digit, an input digit), the captured inputs and
//!   the output staging and publication.
//!
//! Schedule: a program counter and a micro-program ROM, not a state enum:
//! the schedule is `SCHEDULE_CLOCKS` words, and each word drives four
//! pipeline stages at once (a read, an operand, an accumulation, a write),
//! so one enum state per clock would be a flat list of ~170 states with no
//! structure to read. The structure lives in `crate::iir_program`, written
//! with typed Rust (`Location`, `Factor`, `AccumulatorOp`, `Emit`) and
//! encoded into the ROM; the model runs the same words, so the two cannot
//! drift apart.
//!
//! Timing: `x_valid` in idle (pc = 0) captures x1, x2 and starts the
//! program; `publish`, its last word, copies the staged z1, z2 to the
//! outputs and `z_valid` pulses during the next cycle: z appears `LATENCY`
//! clocks after `x_valid`. The program is back in idle `SCHEDULE_CLOCKS`
//! clocks after the strobe, so the decimation must be at least that
//! (`crate::filter_design::MIN_DECIMATION`); a strobe that arrives while it
//! runs is dropped. z1 and z2 change only at `publish`.
//!
//! Gain: the filter's DC gain, 4 k0 / -(k1 + k2). Resources (Yosys 0.23,
//! `synth_ice40 -dsp -top gyro_interface__iir` on the exported Verilog): 1
//! `SB_MAC16`, 4 `SB_RAM40_4K` (the digit RAM's two halves, and the 256 x
//! 30-bit program in two), 329 flip-flops, 381 `SB_LUT4` (380 in one block,
//! before the sequencer, the coefficient digit and the digit store became
//! blocks of their own); with the digit RAM
//! in one piece and Yosys's collision logic it was 3 block RAMs, 369
//! flip-flops and 385 LUT4. The 60 x 32 design before it took 8 `SB_MAC16`,
//! 1870 flip-flops and 3379 `SB_LUT4` (`-noflatten`).

use crate::iir_coefficient_digit::IirCoefficientDigit;
use crate::iir_digits::IirDigits;
use crate::iir_program::{
    ACCUMULATOR_BITS as COLUMN_BITS, OPERAND_BITS as DIGIT_OPERAND_BITS,
    PRODUCT_BITS as DIGIT_PRODUCT_BITS, STATE_TOP_BITS,
};
use crate::iir_sequencer::IirSequencer;
use crate::primitives::RegisteredMultiplier;
use crate::primitives::convert::signed_bit_cast_exact;
use rust_hdl::prelude::*;

pub use crate::iir_widths::{
    ACCUMULATOR_BITS, COEFFICIENT_BITS, COEFFICIENT_FRACTION_BITS, GUARD_BITS, OPERAND_BITS,
    PRODUCT_BITS, SAMPLE_BITS, STATE_BITS,
};
/// Clock cycles from `x_valid` to `z_valid` (`Program::latency`, checked by a test).
pub const LATENCY: usize = 168;
/// Clock cycles from a strobe to the next one accepted: the least decimation
/// (`Program::schedule_clocks`, checked by a test).
pub const SCHEDULE_CLOCKS: usize = gyrocal_regs::datapath::MIN_DECIMATION as usize;
/// Width of the accumulator after dropping a finished 15-bit column digit.
const CARRY_BITS: usize = COLUMN_BITS - crate::iir_program::DIGIT_BITS;

/// Butterworth biquad plus RC section for two channels on one 16 x 16
/// multiplier, run by a micro-program.
#[derive(LogicBlock)]
pub struct IirLowpass {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Input sample of channel 1 (the CIC output).
    pub x1: Signal<In, Signed<SAMPLE_BITS>>,
    /// Input sample of channel 2.
    pub x2: Signal<In, Signed<SAMPLE_BITS>>,
    /// Pulse marking new input samples on both channels.
    pub x_valid: Signal<In, Bit>,
    /// Biquad numerator gain g (Q2.30).
    pub k0: Signal<In, Signed<COEFFICIENT_BITS>>,
    /// Biquad feedback k1 = -a1 - 2 (Q2.30).
    pub k1: Signal<In, Signed<COEFFICIENT_BITS>>,
    /// Biquad feedback k2 = 1 - a2 (Q2.30).
    pub k2: Signal<In, Signed<COEFFICIENT_BITS>>,
    /// RC section coefficient alpha = 1 - exp(-2 pi f_rc / f_s) (Q2.30).
    pub alpha: Signal<In, Signed<COEFFICIENT_BITS>>,
    /// Filtered output of channel 1, 8 fractional bits, updated with `z_valid`.
    pub z1: Signal<Out, Signed<SAMPLE_BITS>>,
    /// Filtered output of channel 2, 8 fractional bits, updated with `z_valid`.
    pub z2: Signal<Out, Signed<SAMPLE_BITS>>,
    /// One-clock pulse marking new `z1`, `z2`.
    pub z_valid: Signal<Out, Bit>,
    sequencer: IirSequencer,
    coefficient: IirCoefficientDigit,
    digits: IirDigits,
    mul: RegisteredMultiplier<DIGIT_OPERAND_BITS, DIGIT_OPERAND_BITS, DIGIT_PRODUCT_BITS>,
    a: DFF<Signed<DIGIT_OPERAND_BITS>>,
    acc: DFF<Signed<COLUMN_BITS>>,
    // The running word's fields (`crate::iir_sequencer`).
    op: Signal<Local, Bits<2>>,
    // Operand a.
    ram_low: Signal<Local, Signed<STATE_TOP_BITS>>,
    ram_wrapped: Signal<Local, Signed<DIGIT_OPERAND_BITS>>,
    // Accumulator.
    product: Signal<Local, Signed<COLUMN_BITS>>,
    carry: Signal<Local, Signed<CARRY_BITS>>,
    carry_wide: Signal<Local, Signed<COLUMN_BITS>>,
    addend: Signal<Local, Signed<COLUMN_BITS>>,
    pow29: Constant<Signed<COLUMN_BITS>>,
}

impl IirLowpass {
    /// An idle filter with zero state, holding the program of `crate::iir_program`.
    pub fn new() -> Self {
        assert_eq!(STATE_TOP_BITS, 13);
        assert_eq!(SAMPLE_BITS - 2 * 15, 10);
        Self {
            clock: Default::default(),
            x1: Default::default(),
            x2: Default::default(),
            x_valid: Default::default(),
            k0: Default::default(),
            k1: Default::default(),
            k2: Default::default(),
            alpha: Default::default(),
            z1: Default::default(),
            z2: Default::default(),
            z_valid: Default::default(),
            sequencer: IirSequencer::new(),
            coefficient: IirCoefficientDigit::new(),
            digits: IirDigits::new(),
            mul: RegisteredMultiplier::new(),
            a: Default::default(),
            acc: Default::default(),
            op: Default::default(),
            ram_low: Default::default(),
            ram_wrapped: Default::default(),
            product: Default::default(),
            carry: Default::default(),
            carry_wide: Default::default(),
            addend: Default::default(),
            pow29: Constant::new((1i64 << 29).into()),
        }
    }
}

impl Default for IirLowpass {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for IirLowpass {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, a, acc);
        self.sequencer.clock.next = self.clock.val();
        self.coefficient.clock.next = self.clock.val();
        self.digits.clock.next = self.clock.val();
        self.mul.clock.next = self.clock.val();
        // A strobe in idle captures x1, x2 and starts the program.
        self.sequencer.x_valid.next = self.x_valid.val();
        self.digits.x1.next = self.x1.val();
        self.digits.x2.next = self.x2.val();
        self.digits.capture.next = self.sequencer.idle.val() & self.x_valid.val();
        // The word's RAM addresses, emission and publication.
        self.digits.read_address.next = self.sequencer.read_address.val();
        self.digits.write_address.next = self.sequencer.write_address.val();
        self.digits.emit.next = self.sequencer.emit.val();
        self.digits.x_select.next = self.sequencer.x_select.val();
        self.digits.publish.next = self.sequencer.publish.val();
        self.op.next = self.sequencer.op.val();
        // Operand a: the RAM digit, a state's top digit sign-extended from bit 12.
        self.ram_low.next = self.digits.q.val().get_bits::<STATE_TOP_BITS>(0);
        self.ram_wrapped.next =
            signed_bit_cast_exact::<DIGIT_OPERAND_BITS, STATE_TOP_BITS>(self.ram_low.val());
        self.a.d.next = self.digits.q.val();
        if self.sequencer.wrap_top.val() {
            self.a.d.next = self.ram_wrapped.val();
        }
        // Operand b: a digit of a scaled coefficient, or a constant.
        self.coefficient.factor.next = self.sequencer.factor.val();
        self.coefficient.k0.next = self.k0.val();
        self.coefficient.k1.next = self.k1.val();
        self.coefficient.k2.next = self.k2.val();
        self.coefficient.alpha.next = self.alpha.val();
        self.mul.a.next = self.a.q.val();
        self.mul.b.next = self.coefficient.digit.val();
        // Accumulator: hold, start (+ 2^29), add, or shift a column and add.
        self.product.next =
            signed_bit_cast_exact::<COLUMN_BITS, DIGIT_PRODUCT_BITS>(self.mul.p.val());
        self.carry.next = self.acc.q.val().get_bits::<CARRY_BITS>(15);
        self.carry_wide.next = signed_bit_cast_exact::<COLUMN_BITS, CARRY_BITS>(self.carry.val());
        self.addend.next = self.acc.q.val();
        if self.op.val() == 1 {
            self.addend.next = 0.into();
            if self.sequencer.round_start.val() {
                self.addend.next = self.pow29.val();
            }
        }
        if self.op.val() == 3 {
            self.addend.next = self.carry_wide.val();
        }
        if self.op.val() != 0 {
            self.acc.d.next = self.addend.val() + self.product.val();
        }
        self.digits.column.next = self.acc.q.val().get_bits::<15>(0);
        self.z1.next = self.digits.z1.val();
        self.z2.next = self.digits.z2.val();
        self.z_valid.next = self.digits.z_valid.val();
    }
}

crate::impl_clocked!(IirLowpass);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{prepare, tick};
    use crate::filter_design::{self, FilterDesign};
    use crate::model::iir_lowpass::{Coefficients, IirLowpass as Model, reference};
    use crate::primitives::convert::{i128_to_signed, signed_to_i128};
    use crate::test_util::{Rng, segments};
    use proptest::prelude::*;

    /// Largest CIC output magnitude for valid settings: the mixer output is
    /// below 2^30 and the CIC gain at most 1, times 2^8.
    const FULL_SCALE: i64 = 1 << 38;

    fn designs() -> Vec<FilterDesign> {
        [
            (1000, 500.0, 2000.0),
            (200, 4.8e4, 2.4e4),
            (4096, 12.3, 100.0),
            (333, 30e3, 1e3),
        ]
        .into_iter()
        .map(|(r, b, c)| filter_design::design(50e6, r, b, c).unwrap())
        .collect()
    }

    /// Feed one sample per schedule, `x` on channel 1 and `-x` on channel
    /// 2; return channel 1's z after each, having checked that channel 2
    /// stays within the rounding of its mirror image. z comes `LATENCY`
    /// clocks after its strobe (`z_valid_follows_x_valid_by_the_latency_...`),
    /// so a model that never publishes fails here instead of hanging.
    fn run(model: &mut Model, k: &Coefficients, x: &[i64]) -> Vec<i64> {
        x.iter()
            .enumerate()
            .map(|(n, &v)| {
                model.step((v, -v), true, k);
                let z = (0..LATENCY).find_map(|_| {
                    let (z1, z2, valid) = model.step((0, 0), false, k);
                    valid.then_some((z1, z2))
                });
                let (z1, z2) =
                    z.unwrap_or_else(|| panic!("sample {n}: no z within {LATENCY} clocks"));
                // Each channel is within 1 LSB of the float recursion
                // (below), so the integers z1 and -z2 differ by at most 1.
                assert!((z1 + z2).abs() <= 1, "{z1} vs {z2}");
                z1
            })
            .collect()
    }

    /// u of the f64 recursion (`reference::float_run`): the fixed-point
    /// model may differ from it only by its roundings.
    fn run_float(k: &Coefficients, x: &[i64]) -> Vec<f64> {
        reference::float_run(k, x).iter().map(|s| s.u).collect()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(6))]
        #[test]
        fn rtl_matches_model_with_random_inputs_and_dropped_strobes(
            design in segments(0usize..4, 3..5, 1500..2000),
            // Strobes one clock in 120 on average, against a schedule of
            // SCHEDULE_CLOCKS: many land while a schedule runs and must be
            // dropped by both.
            inputs in prop::collection::vec((prop::bool::weighted(1.0 / 120.0), -FULL_SCALE..=FULL_SCALE, -FULL_SCALE..=FULL_SCALE), 4500),
        ) {
            let designs = designs();
            let mut uut = IirLowpass::new();
            prepare(&mut uut);
            let mut model = Model::default();
            let mut outputs = 0;
            for (n, (&d, &(valid, x1, x2))) in design.iter().zip(&inputs).enumerate() {
                let k = designs[d].coefficients;
                let s = |v: i32| i128_to_signed::<32>(v as i128);
                uut.x1.next = i128_to_signed(x1 as i128);
                uut.x2.next = i128_to_signed(x2 as i128);
                uut.x_valid.next = valid;
                uut.k0.next = s(k.k0);
                uut.k1.next = s(k.k1);
                uut.k2.next = s(k.k2);
                uut.alpha.next = s(k.alpha);
                tick(&mut uut);
                let z = |v: Signed<SAMPLE_BITS>| signed_to_i128(v) as i64;
                let hw = (z(uut.z1.val()), z(uut.z2.val()), uut.z_valid.val());
                prop_assert_eq!(hw, model.step((x1, x2), valid, &k), "cycle {}", n);
                outputs += hw.2 as u32;
            }
            // About 4500 / (SCHEDULE_CLOCKS + 120) = 16 expected.
            prop_assert!(outputs > 8, "only {} outputs", outputs);
        }
    }

    #[test]
    fn z_valid_follows_x_valid_by_the_latency_and_the_schedule_takes_its_length() {
        // One strobe, then a second one as early as the schedule accepts:
        // both give a z_valid exactly LATENCY clocks after their strobe; a
        // strobe one clock earlier is dropped.
        for gap in [SCHEDULE_CLOCKS, SCHEDULE_CLOCKS - 1] {
            let mut uut = IirLowpass::new();
            prepare(&mut uut);
            let mut valid_at = vec![];
            for n in 0..gap + 2 * LATENCY {
                uut.x_valid.next = n == 0 || n == gap;
                tick(&mut uut);
                if uut.z_valid.val() {
                    // After the tick that ends cycle n we are in cycle n + 1.
                    valid_at.push(n + 1);
                }
            }
            let expected = if gap == SCHEDULE_CLOCKS {
                vec![LATENCY, gap + LATENCY]
            } else {
                vec![LATENCY]
            };
            assert_eq!(valid_at, expected, "second strobe {gap} clocks later");
        }
    }

    #[test]
    fn step_and_impulse_track_the_float_recursion() {
        // Each section rounds once per sample (half a state LSB, 2^-16
        // output LSB); the recursion amplifies a constant rounding error by
        // at most its dead band (< 0.25 output LSB, `filter_design`), and
        // the output rounding adds 0.5. So |z - float| < 1 output LSB.
        for f in designs() {
            let k = f.coefficients;
            let n = 4000;
            let step: Vec<i64> = vec![FULL_SCALE / 3; n];
            let mut impulse = vec![0i64; n];
            impulse[0] = FULL_SCALE;
            for x in [step, impulse] {
                let z = run(&mut Model::default(), &k, &x);
                let reference = run_float(&k, &x);
                for (i, (&zi, &ri)) in z.iter().zip(&reference).enumerate() {
                    assert!(
                        (zi as f64 - ri).abs() < 1.0,
                        "R {} sample {i}: {zi} vs {ri}",
                        f.decimation
                    );
                }
            }
        }
    }

    #[test]
    fn dc_gain_of_the_chain_is_the_designed_one() {
        // CIC output c G (G = CIC gain) comes out as c G * 4 k0 / -(k1 + k2)
        // = c * dc_gain, to within the dead band and output rounding.
        for f in designs() {
            let c = 123_456_789_i64;
            let x = vec![(c as f64 * f.cic_gain).round() as i64; 6000];
            let z = run(&mut Model::default(), &f.coefficients, &x);
            let want = x[0] as f64 / f.cic_gain * f.dc_gain;
            assert!(
                (*z.last().unwrap() as f64 - want).abs() < 1.0,
                "R {}",
                f.decimation
            );
        }
    }

    #[test]
    fn worst_case_of_z_through_the_rust_hdl_design() {
        // The overflow bound's worst case (header; all registers and the
        // corners of the supported range: `model::iir_lowpass`, test
        // `worst_case_sequences_fit_every_register`) through the design
        // itself: x = +-x_max times the signs of u's impulse response read
        // backwards, x_max = 2^38 G, on a design whose response fades within
        // a hundred samples (both cut-offs at f_z / 5, R = 166), so that the
        // rust-hdl simulation stays short. z must equal the exact i128
        // recursion with no register wrapped, and exceed x_max (the l1
        // norm of u's response is above 1: the stimulus is the worst case).
        let fz = 50e6 / 166.0;
        let f = filter_design::design(50e6, 166, 0.2 * fz, 0.2 * fz).unwrap();
        let k = f.coefficients;
        let x_max = ((1u64 << 38) as f64 * f.cic_gain).ceil() as i64;
        let mut impulse = vec![0i64; 400];
        impulse[0] = 1;
        let h = run_float(&k, &impulse);
        let n = (0..h.len())
            .find(|&n| h[n..].iter().map(|v| v.abs()).sum::<f64>() < 1e-9)
            .unwrap();
        assert!(n < 120, "the response fades in {n} samples");
        let x = reference::worst_case_input(&h, n, x_max, 1);
        let (mut c1, mut c2) = (reference::Channel::default(), reference::Channel::default());
        let want: Vec<(i64, i64)> = x
            .iter()
            .map(|&v| (c1.sample(v, &k), c2.sample(-v, &k)))
            .collect();
        assert!(!c1.peaks.wrapped && !c2.peaks.wrapped);
        assert!(want[n - 1].0 > x_max, "{} against {x_max}", want[n - 1].0);
        let mut uut = IirLowpass::new();
        prepare(&mut uut);
        let s = |v: i32| i128_to_signed::<32>(v as i128);
        (uut.k0.next, uut.k1.next, uut.k2.next, uut.alpha.next) =
            (s(k.k0), s(k.k1), s(k.k2), s(k.alpha));
        let mut got = Vec::new();
        for &v in &x {
            for t in 0..SCHEDULE_CLOCKS {
                uut.x1.next = i128_to_signed(if t == 0 { v } else { 0 } as i128);
                uut.x2.next = i128_to_signed(if t == 0 { -v } else { 0 } as i128);
                uut.x_valid.next = t == 0;
                tick(&mut uut);
                if uut.z_valid.val() {
                    let z = |v: Signed<SAMPLE_BITS>| signed_to_i128(v) as i64;
                    got.push((z(uut.z1.val()), z(uut.z2.val())));
                }
            }
        }
        // z comes LATENCY > SCHEDULE_CLOCKS after its strobe: the last one
        // is still on its way.
        assert_eq!(got[..], want[..got.len()]);
        assert_eq!(got.len(), n - 1);
    }

    #[test]
    fn zero_input_after_full_scale_returns_exactly_to_zero() {
        // No limit cycle and no dead band visible at the output: after
        // random full-scale samples, zeros bring z to exactly 0 and keep it
        // there. The decay to below half an LSB from 2^38 takes about
        // ln(2^39) / (1 - r) samples; 20000 covers the slowest design.
        let mut rng = Rng::new(29);
        for f in designs() {
            let k = f.coefficients;
            let mut x: Vec<i64> = (0..200)
                .map(|_| rng.range(-FULL_SCALE, FULL_SCALE))
                .collect();
            x.extend(std::iter::repeat_n(0, 20000));
            let z = run(&mut Model::default(), &k, &x);
            assert!(z[..200].iter().any(|&v| v != 0));
            let tail = &z[z.len() - 5000..];
            assert!(
                tail.iter().all(|&v| v == 0),
                "R {}: {:?}",
                f.decimation,
                &tail[..5]
            );
        }
    }
}
