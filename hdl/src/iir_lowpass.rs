//! IIR low-pass at the decimated rate: a 2nd-order Butterworth section and a
//! first-order RC section, the paper's output filter, on one shared
//! multiplier.
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
//! Formats (LSB of the CIC output = 2^-8 of a mixer LSB):
//! - x: CIC output, 40 bits, 8 fractional bits;
//! - coefficients k0, k1, k2, alpha: 32-bit two's complement, Q2.30;
//! - states y1, y2, u: 58 bits with 24 fractional bits (16 guard bits below
//!   the output LSB, which keep the dead band and any zero-input limit cycle
//!   of the recursion below half an output LSB, so z returns exactly to 0);
//! - products: 60-bit operand x 32-bit coefficient = 92 bits, accumulated in
//!   96 bits, exact; each section rounds once (half up) when dropping 30
//!   bits; z is u rounded half up to 8 fractional bits, 40 bits.
//!
//! Overflow: the accumulator and 60-bit intermediates cannot overflow; the
//! 58-bit states hold +-2^33 mixer LSBs, twice the largest mixer output,
//! which covers the 4.3% step overshoot of the Butterworth section (tests
//! drive full-scale worst-case sequences).
//!
//! Schedule, one multiply per clock: on `x_valid` the history shifts
//! (step 0), v is formed (1), k0 v, k1 y1, k2 y2 are issued (2-4) and
//! accumulated (4-6), y is updated (7), alpha (y - u) is issued (8) and u
//! updated (10), z is rounded and `z_valid` pulses (11): z appears 12 clocks
//! after `x_valid`. Inputs arriving while a schedule runs are dropped, so
//! the decimation must be at least 12 (the driver requires 16).

use crate::primitives::RegisteredMultiplier;
use crate::primitives::convert::signed_bit_cast_exact;
use rust_hdl::prelude::*;

/// Fractional bits of the coefficients (Q2.30).
pub const COEFFICIENT_FRACTION_BITS: u32 = 30;
/// Guard bits of the states below the output LSB.
pub const GUARD_BITS: u32 = 16;
/// Clock cycles from `x_valid` to `z_valid`.
pub const LATENCY: usize = 12;

/// Butterworth biquad plus RC section, one shared 60 x 32 multiplier.
#[derive(LogicBlock)]
pub struct IirLowpass {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Input sample (the CIC output).
    pub x: Signal<In, Signed<40>>,
    /// Pulse marking a new input sample.
    pub x_valid: Signal<In, Bit>,
    /// Biquad numerator gain g (Q2.30).
    pub k0: Signal<In, Signed<32>>,
    /// Biquad feedback k1 = -a1 - 2 (Q2.30).
    pub k1: Signal<In, Signed<32>>,
    /// Biquad feedback k2 = 1 - a2 (Q2.30).
    pub k2: Signal<In, Signed<32>>,
    /// RC section coefficient alpha = 1 - exp(-2 pi f_rc / f_s) (Q2.30).
    pub alpha: Signal<In, Signed<32>>,
    /// Filtered output, 8 fractional bits, updated when `z_valid` is high.
    pub z: Signal<Out, Signed<40>>,
    /// One-clock pulse marking a new `z`.
    pub z_valid: Signal<Out, Bit>,
    step: DFF<Bits<4>>,
    x0: DFF<Signed<40>>,
    x1: DFF<Signed<40>>,
    x2: DFF<Signed<40>>,
    v: DFF<Signed<60>>,
    operand: DFF<Signed<60>>,
    coefficient: DFF<Signed<32>>,
    mac: RegisteredMultiplier<60, 32, 92>,
    accumulator: DFF<Signed<96>>,
    y1: DFF<Signed<58>>,
    y2: DFF<Signed<58>>,
    u: DFF<Signed<58>>,
    z_out: DFF<Signed<40>>,
    z_valid_out: DFF<Bit>,
    x0_wide: Signal<Local, Signed<60>>,
    x1_wide: Signal<Local, Signed<60>>,
    x2_wide: Signal<Local, Signed<60>>,
    v_sum: Signal<Local, Signed<60>>,
    v_shifted: Signal<Local, Bits<60>>,
    y1_wide: Signal<Local, Signed<60>>,
    y2_wide: Signal<Local, Signed<60>>,
    u_wide: Signal<Local, Signed<60>>,
    product_wide: Signal<Local, Signed<96>>,
    accumulator_rounded: Signal<Local, Signed<96>>,
    accumulator_scaled: Signal<Local, Signed<60>>,
    y_new: Signal<Local, Signed<60>>,
    product_rounded: Signal<Local, Signed<92>>,
    product_scaled: Signal<Local, Signed<60>>,
    u_new: Signal<Local, Signed<60>>,
    u_rounded: Signal<Local, Signed<58>>,
    half_coefficient_lsb_96: Constant<Signed<96>>,
    half_coefficient_lsb_92: Constant<Signed<92>>,
    half_output_lsb: Constant<Signed<58>>,
}

impl IirLowpass {
    /// An idle filter with zero state.
    pub fn new() -> Self {
        let half_coefficient_lsb = 1i64 << (COEFFICIENT_FRACTION_BITS - 1);
        Self {
            clock: Default::default(),
            x: Default::default(),
            x_valid: Default::default(),
            k0: Default::default(),
            k1: Default::default(),
            k2: Default::default(),
            alpha: Default::default(),
            z: Default::default(),
            z_valid: Default::default(),
            step: Default::default(),
            x0: Default::default(),
            x1: Default::default(),
            x2: Default::default(),
            v: Default::default(),
            operand: Default::default(),
            coefficient: Default::default(),
            mac: RegisteredMultiplier::new(),
            accumulator: Default::default(),
            y1: Default::default(),
            y2: Default::default(),
            u: Default::default(),
            z_out: Default::default(),
            z_valid_out: Default::default(),
            x0_wide: Default::default(),
            x1_wide: Default::default(),
            x2_wide: Default::default(),
            v_sum: Default::default(),
            v_shifted: Default::default(),
            y1_wide: Default::default(),
            y2_wide: Default::default(),
            u_wide: Default::default(),
            product_wide: Default::default(),
            accumulator_rounded: Default::default(),
            accumulator_scaled: Default::default(),
            y_new: Default::default(),
            product_rounded: Default::default(),
            product_scaled: Default::default(),
            u_new: Default::default(),
            u_rounded: Default::default(),
            half_coefficient_lsb_96: Constant::new(half_coefficient_lsb.into()),
            half_coefficient_lsb_92: Constant::new(half_coefficient_lsb.into()),
            half_output_lsb: Constant::new((1i64 << (GUARD_BITS - 1)).into()),
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
        dff_setup!(
            self,
            clock,
            step,
            x0,
            x1,
            x2,
            v,
            operand,
            coefficient,
            accumulator,
            y1,
            y2,
            u,
            z_out,
            z_valid_out
        );
        self.mac.clock.next = self.clock.val();
        self.mac.a.next = self.operand.q.val();
        self.mac.b.next = self.coefficient.q.val();
        // Datapath helpers.
        self.x0_wide.next = signed_bit_cast_exact::<60, 40>(self.x0.q.val());
        self.x1_wide.next = signed_bit_cast_exact::<60, 40>(self.x1.q.val());
        self.x2_wide.next = signed_bit_cast_exact::<60, 40>(self.x2.q.val());
        self.v_sum.next =
            self.x0_wide.val() + self.x1_wide.val() + self.x1_wide.val() + self.x2_wide.val();
        self.v_shifted.next = unsigned_cast(self.v_sum.val()) << 16;
        self.y1_wide.next = signed_bit_cast_exact::<60, 58>(self.y1.q.val());
        self.y2_wide.next = signed_bit_cast_exact::<60, 58>(self.y2.q.val());
        self.u_wide.next = signed_bit_cast_exact::<60, 58>(self.u.q.val());
        self.product_wide.next = signed_bit_cast_exact::<96, 92>(self.mac.p.val());
        self.accumulator_rounded.next =
            self.accumulator.q.val() + self.half_coefficient_lsb_96.val();
        self.accumulator_scaled.next = self.accumulator_rounded.val().get_bits::<60>(30);
        self.y_new.next = self.y1_wide.val() + self.y1_wide.val() - self.y2_wide.val()
            + self.accumulator_scaled.val();
        self.product_rounded.next = self.mac.p.val() + self.half_coefficient_lsb_92.val();
        self.product_scaled.next = self.product_rounded.val().get_bits::<60>(30);
        self.u_new.next = self.u_wide.val() + self.product_scaled.val();
        self.u_rounded.next = self.u.q.val() + self.half_output_lsb.val();
        // Schedule.
        self.z_valid_out.d.next = false;
        if (self.step.q.val() == 0) && self.x_valid.val() {
            self.x0.d.next = self.x.val();
            self.x1.d.next = self.x0.q.val();
            self.x2.d.next = self.x1.q.val();
            self.step.d.next = 1.into();
        }
        if self.step.q.val() == 1 {
            self.v.d.next = signed_cast(self.v_shifted.val());
            self.step.d.next = 2.into();
        }
        if self.step.q.val() == 2 {
            self.operand.d.next = self.v.q.val();
            self.coefficient.d.next = self.k0.val();
            self.step.d.next = 3.into();
        }
        if self.step.q.val() == 3 {
            self.operand.d.next = self.y1_wide.val();
            self.coefficient.d.next = self.k1.val();
            self.step.d.next = 4.into();
        }
        if self.step.q.val() == 4 {
            self.operand.d.next = self.y2_wide.val();
            self.coefficient.d.next = self.k2.val();
            self.accumulator.d.next = self.product_wide.val();
            self.step.d.next = 5.into();
        }
        if self.step.q.val() == 5 {
            self.accumulator.d.next = self.accumulator.q.val() + self.product_wide.val();
            self.step.d.next = 6.into();
        }
        if self.step.q.val() == 6 {
            self.accumulator.d.next = self.accumulator.q.val() + self.product_wide.val();
            self.step.d.next = 7.into();
        }
        if self.step.q.val() == 7 {
            self.y1.d.next = self.y_new.val().get_bits::<58>(0);
            self.y2.d.next = self.y1.q.val();
            self.step.d.next = 8.into();
        }
        if self.step.q.val() == 8 {
            self.operand.d.next = self.y1_wide.val() - self.u_wide.val();
            self.coefficient.d.next = self.alpha.val();
            self.step.d.next = 9.into();
        }
        if self.step.q.val() == 9 {
            self.step.d.next = 10.into();
        }
        if self.step.q.val() == 10 {
            self.u.d.next = self.u_new.val().get_bits::<58>(0);
            self.step.d.next = 11.into();
        }
        if self.step.q.val() == 11 {
            self.z_out.d.next = self.u_rounded.val().get_bits::<40>(16);
            self.z_valid_out.d.next = true;
            self.step.d.next = 0.into();
        }
        self.z.next = self.z_out.q.val();
        self.z_valid.next = self.z_valid_out.q.val();
    }
}

crate::impl_clocked!(IirLowpass);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{prepare, tick};
    use crate::filter_design::{self, FilterDesign};
    use crate::model::iir_lowpass::{Coefficients, IirLowpass as Model};
    use crate::primitives::convert::{i128_to_signed, signed_to_i128};
    use crate::test_util::{Rng, segments};
    use proptest::prelude::*;

    /// Largest CIC output magnitude for valid settings: the mixer output is
    /// below 2^30 and the CIC gain at most 1, times 2^8.
    const FULL_SCALE: i64 = 1 << 38;

    fn designs() -> Vec<FilterDesign> {
        [
            (1000, 500.0, 2000.0),
            (16, 6e5, 3e5),
            (4096, 12.3, 100.0),
            (333, 30e3, 1e3),
        ]
        .into_iter()
        .map(|(r, b, c)| filter_design::design(50e6, r, b, c).unwrap())
        .collect()
    }

    /// Feed one sample per schedule; return z after each.
    fn run(model: &mut Model, k: &Coefficients, x: &[i64]) -> Vec<i64> {
        x.iter()
            .map(|&v| {
                model.step(v, true, k);
                loop {
                    let (z, valid) = model.step(0, false, k);
                    if valid {
                        break z;
                    }
                }
            })
            .collect()
    }

    /// The same recursion in f64 with the quantized coefficients: the
    /// fixed-point model may differ from it only by its roundings.
    fn run_float(k: &Coefficients, x: &[i64]) -> Vec<f64> {
        let s = 2f64.powi(30);
        let (k0, k1, k2, a) = (
            k.k0 as f64 / s,
            k.k1 as f64 / s,
            k.k2 as f64 / s,
            k.alpha as f64 / s,
        );
        let (mut x1, mut x2, mut y1, mut y2, mut u) = (0.0, 0.0, 0.0, 0.0, 0.0);
        x.iter()
            .map(|&x0| {
                let x0 = x0 as f64;
                let y = 2.0 * y1 - y2 + k0 * (x0 + 2.0 * x1 + x2) + k1 * y1 + k2 * y2;
                (x2, x1, y2, y1) = (x1, x0, y1, y);
                u += a * (y - u);
                u
            })
            .collect()
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(6))]
        #[test]
        fn rtl_matches_model_with_random_inputs_and_dropped_strobes(
            design in segments(0usize..4, 3..5, 500..700),
            // Strobes one clock in 12 on average: some land while a
            // schedule runs and must be dropped by both.
            inputs in prop::collection::vec((prop::bool::weighted(1.0 / 12.0), -FULL_SCALE..=FULL_SCALE), 1500),
        ) {
            let designs = designs();
            let mut uut = IirLowpass::new();
            prepare(&mut uut);
            let mut model = Model::default();
            let mut outputs = 0;
            for (n, (&d, &(valid, x))) in design.iter().zip(&inputs).enumerate() {
                let k = designs[d].coefficients;
                let s = |v: i32| i128_to_signed::<32>(v as i128);
                uut.x.next = i128_to_signed(x as i128);
                uut.x_valid.next = valid;
                uut.k0.next = s(k.k0);
                uut.k1.next = s(k.k1);
                uut.k2.next = s(k.k2);
                uut.alpha.next = s(k.alpha);
                tick(&mut uut);
                let hw = (signed_to_i128(uut.z.val()) as i64, uut.z_valid.val());
                prop_assert_eq!(hw, model.step(x, valid, &k), "cycle {}", n);
                outputs += hw.1 as u32;
            }
            prop_assert!(outputs > 40, "only {} outputs", outputs);
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
    fn worst_case_full_scale_input_does_not_overflow() {
        // The input that maximizes the output at sample N is the sign
        // pattern of the impulse response read backwards; its peak is
        // FULL_SCALE times the l1 norm of h (about 1.1 for these filters).
        // Any wrap-around would show as a huge error against the float run.
        for f in designs() {
            let k = f.coefficients;
            let n = 3000;
            let mut impulse = vec![0i64; n];
            impulse[0] = 1 << 30;
            let h = run_float(&k, &impulse);
            for sign in [1i64, -1] {
                let x: Vec<i64> = (0..n)
                    .map(|i| sign * FULL_SCALE * h[n - 1 - i].signum() as i64)
                    .collect();
                let z = run(&mut Model::default(), &k, &x);
                let reference = run_float(&k, &x);
                let peak = reference.iter().fold(0.0f64, |m, v| m.max(v.abs()));
                assert!(
                    peak > FULL_SCALE as f64,
                    "worst case did not exceed full scale"
                );
                for (i, (&zi, &ri)) in z.iter().zip(&reference).enumerate() {
                    assert!(
                        (zi as f64 - ri).abs() < 1.0,
                        "R {} sample {i}",
                        f.decimation
                    );
                }
            }
        }
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
