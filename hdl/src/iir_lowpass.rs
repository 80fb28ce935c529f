//! IIR low-pass at the decimated rate, both channels: a 2nd-order
//! Butterworth section and a first-order RC section (the paper's output
//! filter) on one shared, pipelined multiplier.
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
//! Formats and widths (LSB of the CIC output = 2^-8 of a mixer LSB):
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
//!   rounded half up to 8 fractional bits, 40 bits.
//!
//! Schedule (`IirStep`, one state per clock; `crate::iir_channel` holds
//! each channel's registers): the multiplier (`PipelinedMultiplier`, 4
//! clocks) takes one product per clock, channel 1 first. During the cycle
//! with `x_valid` (Idle) k1 y1 of channel 1 is issued, then k2 y2 and k0 v
//! (v is formed at the Idle edge), then the same three for channel 2.
//! Their products come back in states 5..7 (channel 1) and 8..10
//! (channel 2), where they are accumulated; at the last one y is updated
//! and alpha (y - u) issued at once; its product comes back 5 clocks later
//! and updates u (states 12 and 15). The edge after state 15 rounds both
//! u into z, and `z_valid` pulses during the next cycle: z appears
//! `LATENCY` = 17 clocks after `x_valid`. The schedule is back in Idle 16
//! clocks after it left it, so the decimation must be at least 16; a strobe
//! that arrives while it runs is dropped.

use crate::iir_channel::{IirChannel, SAMPLE_BITS};
use crate::primitives::PipelinedMultiplier;
use rust_hdl::prelude::*;

/// Fractional bits of the coefficients (Q2.30).
pub const COEFFICIENT_FRACTION_BITS: u32 = 30;
/// Width of the coefficients.
pub const COEFFICIENT_BITS: usize = 32;
/// Guard bits of the states below the output LSB.
pub const GUARD_BITS: u32 = 16;
/// Width of the states y1, y2, u: 40-bit samples, guard bits, 2 bits of headroom.
pub const STATE_BITS: usize = SAMPLE_BITS + GUARD_BITS as usize + 2;
/// Width of the multiplier's first operand: 2 y1 - y2 and y - u fit exactly.
pub const OPERAND_BITS: usize = STATE_BITS + 2;
/// Width of the exact product.
pub const PRODUCT_BITS: usize = OPERAND_BITS + COEFFICIENT_BITS;
/// Width of the accumulators: four terms below 2^(PRODUCT_BITS - 1) each.
pub const ACCUMULATOR_BITS: usize = PRODUCT_BITS + 2;
/// Clock cycles from `x_valid` to `z_valid`.
pub const LATENCY: usize = 17;
/// Clock cycles from leaving Idle to being back in it: the least decimation.
pub const SCHEDULE_CLOCKS: usize = 16;

/// The filter schedule, one state per clock (see the module header).
#[derive(Copy, Clone, Debug, PartialEq, LogicState)]
pub enum IirStep {
    /// Waiting for `x_valid`; on it: history, v, feedback; issue k1 y1 (1).
    Idle,
    /// Preload the accumulators; issue k2 y2 (channel 1).
    IssueY2First,
    /// Issue k0 v (channel 1).
    IssueVFirst,
    /// Issue k1 y1 (channel 2).
    IssueY1Second,
    /// Issue k2 y2 (channel 2).
    IssueY2Second,
    /// Issue k0 v (channel 2); accumulate k1 y1 (channel 1).
    IssueVSecond,
    /// Accumulate k2 y2 (channel 1).
    AccumulateFirst,
    /// Add k0 v, update y (channel 1); issue alpha (y - u) (channel 1).
    FinishFirst,
    /// Accumulate k1 y1 (channel 2).
    AccumulateSecondY1,
    /// Accumulate k2 y2 (channel 2).
    AccumulateSecondY2,
    /// Add k0 v, update y (channel 2); issue alpha (y - u) (channel 2).
    FinishSecond,
    /// Wait for alpha (y - u) (channel 1).
    WaitFirstRc,
    /// Update u (channel 1).
    UpdateFirstRc,
    /// Wait for alpha (y - u) (channel 2).
    WaitSecondRc1,
    /// Wait for alpha (y - u) (channel 2).
    WaitSecondRc2,
    /// Update u (channel 2); publish z at the next edge.
    UpdateSecondRc,
}

/// Butterworth biquad plus RC section for two channels, one shared
/// pipelined 60 x 32 multiplier.
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
    step: DFF<IirStep>,
    operand: DFF<Signed<OPERAND_BITS>>,
    coefficient: DFF<Signed<COEFFICIENT_BITS>>,
    mac: PipelinedMultiplier<OPERAND_BITS, COEFFICIENT_BITS, PRODUCT_BITS>,
    channel1: IirChannel,
    channel2: IirChannel,
    publishing: DFF<Bit>,
    z_valid_out: DFF<Bit>,
}

impl IirLowpass {
    /// An idle filter with zero state.
    pub fn new() -> Self {
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
            step: Default::default(),
            operand: Default::default(),
            coefficient: Default::default(),
            mac: PipelinedMultiplier::new(),
            channel1: IirChannel::new(),
            channel2: IirChannel::new(),
            publishing: Default::default(),
            z_valid_out: Default::default(),
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
            operand,
            coefficient,
            publishing,
            z_valid_out
        );
        self.mac.clock.next = self.clock.val();
        self.channel1.clock.next = self.clock.val();
        self.channel2.clock.next = self.clock.val();
        self.mac.a.next = self.operand.q.val();
        self.mac.b.next = self.coefficient.q.val();
        self.channel1.x.next = self.x1.val();
        self.channel2.x.next = self.x2.val();
        self.channel1.product.next = self.mac.p.val();
        self.channel2.product.next = self.mac.p.val();
        // Controls default to idle.
        self.channel1.start.next = false;
        self.channel2.start.next = false;
        self.channel1.preload.next = false;
        self.channel2.preload.next = false;
        self.channel1.accumulate.next = false;
        self.channel2.accumulate.next = false;
        self.channel1.finish.next = false;
        self.channel2.finish.next = false;
        self.channel1.update_u.next = false;
        self.channel2.update_u.next = false;
        self.channel1.publish.next = self.publishing.q.val();
        self.channel2.publish.next = self.publishing.q.val();
        self.z_valid_out.d.next = self.publishing.q.val();
        self.publishing.d.next = false;
        match self.step.q.val() {
            IirStep::Idle => {
                if self.x_valid.val() {
                    self.channel1.start.next = true;
                    self.channel2.start.next = true;
                    self.operand.d.next = self.channel1.y1.val();
                    self.coefficient.d.next = self.k1.val();
                    self.step.d.next = IirStep::IssueY2First;
                }
            }
            IirStep::IssueY2First => {
                self.channel1.preload.next = true;
                self.channel2.preload.next = true;
                self.operand.d.next = self.channel1.y2.val();
                self.coefficient.d.next = self.k2.val();
                self.step.d.next = IirStep::IssueVFirst;
            }
            IirStep::IssueVFirst => {
                self.operand.d.next = self.channel1.v.val();
                self.coefficient.d.next = self.k0.val();
                self.step.d.next = IirStep::IssueY1Second;
            }
            IirStep::IssueY1Second => {
                self.operand.d.next = self.channel2.y1.val();
                self.coefficient.d.next = self.k1.val();
                self.step.d.next = IirStep::IssueY2Second;
            }
            IirStep::IssueY2Second => {
                self.operand.d.next = self.channel2.y2.val();
                self.coefficient.d.next = self.k2.val();
                self.step.d.next = IirStep::IssueVSecond;
            }
            IirStep::IssueVSecond => {
                self.operand.d.next = self.channel2.v.val();
                self.coefficient.d.next = self.k0.val();
                self.channel1.accumulate.next = true;
                self.step.d.next = IirStep::AccumulateFirst;
            }
            IirStep::AccumulateFirst => {
                self.channel1.accumulate.next = true;
                self.step.d.next = IirStep::FinishFirst;
            }
            IirStep::FinishFirst => {
                self.channel1.finish.next = true;
                self.operand.d.next = self.channel1.difference.val();
                self.coefficient.d.next = self.alpha.val();
                self.step.d.next = IirStep::AccumulateSecondY1;
            }
            IirStep::AccumulateSecondY1 => {
                self.channel2.accumulate.next = true;
                self.step.d.next = IirStep::AccumulateSecondY2;
            }
            IirStep::AccumulateSecondY2 => {
                self.channel2.accumulate.next = true;
                self.step.d.next = IirStep::FinishSecond;
            }
            IirStep::FinishSecond => {
                self.channel2.finish.next = true;
                self.operand.d.next = self.channel2.difference.val();
                self.coefficient.d.next = self.alpha.val();
                self.step.d.next = IirStep::WaitFirstRc;
            }
            IirStep::WaitFirstRc => {
                self.step.d.next = IirStep::UpdateFirstRc;
            }
            IirStep::UpdateFirstRc => {
                self.channel1.update_u.next = true;
                self.step.d.next = IirStep::WaitSecondRc1;
            }
            IirStep::WaitSecondRc1 => {
                self.step.d.next = IirStep::WaitSecondRc2;
            }
            IirStep::WaitSecondRc2 => {
                self.step.d.next = IirStep::UpdateSecondRc;
            }
            IirStep::UpdateSecondRc => {
                self.channel2.update_u.next = true;
                self.publishing.d.next = true;
                self.step.d.next = IirStep::Idle;
            }
        }
        self.z1.next = self.channel1.z.val();
        self.z2.next = self.channel2.z.val();
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

    /// Feed one sample per schedule, `x` on channel 1 and `-x` on channel
    /// 2; return channel 1's z after each, having checked that channel 2
    /// stays within the rounding of its mirror image.
    fn run(model: &mut Model, k: &Coefficients, x: &[i64]) -> Vec<i64> {
        x.iter()
            .map(|&v| {
                model.step((v, -v), true, k);
                loop {
                    let (z1, z2, valid) = model.step((0, 0), false, k);
                    if valid {
                        // Each channel is within 1 LSB of the float
                        // recursion (below), so the integers z1 and -z2
                        // differ by at most 1.
                        assert!((z1 + z2).abs() <= 1, "{z1} vs {z2}");
                        break z1;
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
            inputs in prop::collection::vec((prop::bool::weighted(1.0 / 12.0), -FULL_SCALE..=FULL_SCALE, -FULL_SCALE..=FULL_SCALE), 1500),
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
            prop_assert!(outputs > 40, "only {} outputs", outputs);
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
