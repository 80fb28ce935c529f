//! CIC decimator: 4 integrators at the clock rate, 4 combs at f_clk / R.
//!
//! ```text
//!  x[32] ─► ∫ ─► ∫ ─► ∫ ─► ∫ ──► ↓R ──► Δ ─► Δ ─► Δ ─► Δ ──► round(· 2^8 / 2^shift) ──► y[40]
//!           80-bit registers, wrap-around   (one comb per clock after the strobe)   valid
//! ```
//!
//! Hogenauer's CIC with N = 4 stages and differential delay M = 1. Gain
//! R^N, so the registers need B_in + N log2(R_max) = 32 + 4 * 12 = 80 bits
//! for decimation R up to R_max = 4096; the integrators wrap around (two's
//! complement), which the combs undo exactly as long as the true output
//! fits 80 bits, which the width guarantees. All stages keep the full 80
//! bits (no pruning), so the only rounding is at the output.
//!
//! Output scaling: y = round(comb / 2^shift), rounded half up, low 40 bits.
//! With shift = ceil(N log2 R) - 8 the output is the input's average times
//! 2^8 times the residual gain G = R^N / 2^ceil(N log2 R), which lies in
//! (1/2, 1] and is exactly 1 when R is a power of two. The 8 extra bits
//! keep the resolution gained by averaging; the IIR filter after the CIC
//! folds 1/G into its numerator (`crate::filter_design`), so z has unity
//! gain. |x| < 2^31 gives |y| < 2^39: 40 bits, no overflow.
//!
//! The output stage is pipelined over `OUTPUT_STAGES` = 3 registers so
//! that no clock carries more than one carry chain or three mux levels:
//! 1. bias: b = comb4 + 2^(shift-1) (80-bit add; `shift` is sampled here and
//!    travels with the value, so a shift change never splits a sample);
//! 2. coarse: ((b ^ s) >> (shift & 0b111000)), low `COARSE_BITS` = 40 + 7
//!    bits, with s the sign mask of b (the fine step moves at most 7 bits
//!    and 40 are kept, so the bits above 47 are never read);
//! 3. fine: (coarse >> (shift & 0b000111)) ^ s, low 40 bits.
//!
//! Logical shifts compose, so this equals ((b ^ s) >> shift) ^ s exactly.
//!
//! Run-time settings: `decimation` R in 1..=4096 (a 13-bit word; the down
//! counter reloads R - 1 at each output, so a new R acts from the next
//! output on), `shift` in 0..=40. Timing: the integrators take x during
//! cycle n at the next edge; when the counter reaches 0 the fourth
//! integrator is sampled, the four combs follow on the next four clocks,
//! the three output steps on the next three, and `y` and a one-clock
//! `valid` pulse appear 8 clocks after the sampling cycle. Power-up: all
//! registers 0, the first output after R clocks.

use crate::primitives::convert::signed_bit_cast_exact;
use rust_hdl::prelude::*;

/// Number of integrator and comb stages.
pub const STAGES: u32 = 4;
/// Width of the input word.
pub const INPUT_BITS: usize = 32;
/// log2 of the largest decimation.
pub const MAX_DECIMATION_LOG2: u32 = 12;
/// Largest decimation: 2^12.
pub const MAX_DECIMATION: u32 = 1 << MAX_DECIMATION_LOG2;
/// Hogenauer register width: B_in + N log2(R_max) = 32 + 4 * 12 = 80.
pub const REGISTER_BITS: usize = INPUT_BITS + (STAGES * MAX_DECIMATION_LOG2) as usize;
/// Width of the output word.
pub const OUTPUT_BITS: usize = 40;
/// Width of the decimation word: R up to 2^12 needs 13 bits.
pub const DECIMATION_BITS: usize = MAX_DECIMATION_LOG2 as usize + 1;
/// Width of the output shift word: shifts 0..=40 need 6 bits.
pub const SHIFT_BITS: usize = 6;
/// Fractional bits kept at the output (y = average * 2^8 * G).
pub const OUTPUT_FRACTION_BITS: u32 = 8;
/// Low bits of the shift applied by the last (fine) output step: 0..=7.
pub const FINE_SHIFT_BITS: usize = 3;
/// The shift bits of the fine step: `shift & 0b000111`.
pub const FINE_SHIFT_MASK: u64 = (1 << FINE_SHIFT_BITS) - 1;
/// The shift bits of the coarse step (multiples of 8): `shift & 0b111000`.
pub const COARSE_SHIFT_MASK: u64 = ((1 << SHIFT_BITS) - 1) & !FINE_SHIFT_MASK;
/// Width kept after the coarse step: the fine step shifts by at most
/// 2^3 - 1 = 7 and the output keeps 40 bits, so bits 0..40 + 7 suffice.
pub const COARSE_BITS: usize = OUTPUT_BITS + (1 << FINE_SHIFT_BITS) - 1;
/// Clocks from the fourth comb's result to `y`: bias, coarse, fine.
pub const OUTPUT_STAGES: usize = 3;
/// Clocks from the sampling cycle to `y`: the sample register, the combs,
/// the output steps.
pub const SAMPLE_TO_OUTPUT: usize = 1 + STAGES as usize + OUTPUT_STAGES;

/// Four-stage CIC decimator with run-time rate and output shift.
#[derive(LogicBlock)]
pub struct CicDecimator {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Input sample, one per clock.
    pub x: Signal<In, Signed<INPUT_BITS>>,
    /// Decimation R, 1..=4096.
    pub decimation: Signal<In, Bits<DECIMATION_BITS>>,
    /// Output shift: y = round(comb / 2^shift); use ceil(4 log2 R) - 8.
    pub shift: Signal<In, Bits<SHIFT_BITS>>,
    /// Decimated output, updated when `valid` is high.
    pub y: Signal<Out, Signed<OUTPUT_BITS>>,
    /// One-clock pulse marking a new `y`.
    pub valid: Signal<Out, Bit>,
    x_wide: Signal<Local, Signed<REGISTER_BITS>>,
    integrator1: DFF<Signed<REGISTER_BITS>>,
    integrator2: DFF<Signed<REGISTER_BITS>>,
    integrator3: DFF<Signed<REGISTER_BITS>>,
    integrator4: DFF<Signed<REGISTER_BITS>>,
    count: DFF<Bits<DECIMATION_BITS>>,
    sample: DFF<Signed<REGISTER_BITS>>,
    sample_valid: DFF<Bit>,
    comb1: DFF<Signed<REGISTER_BITS>>,
    comb2: DFF<Signed<REGISTER_BITS>>,
    comb3: DFF<Signed<REGISTER_BITS>>,
    comb4: DFF<Signed<REGISTER_BITS>>,
    comb_delay1: DFF<Signed<REGISTER_BITS>>,
    comb_delay2: DFF<Signed<REGISTER_BITS>>,
    comb_delay3: DFF<Signed<REGISTER_BITS>>,
    comb_delay4: DFF<Signed<REGISTER_BITS>>,
    comb_valid1: DFF<Bit>,
    comb_valid2: DFF<Bit>,
    comb_valid3: DFF<Bit>,
    comb_valid4: DFF<Bit>,
    rounding: Signal<Local, Bits<REGISTER_BITS>>,
    biased: Signal<Local, Signed<REGISTER_BITS>>,
    biased_out: DFF<Bits<REGISTER_BITS>>,
    biased_shift: DFF<Bits<SHIFT_BITS>>,
    biased_valid: DFF<Bit>,
    sign_mask: Signal<Local, Bits<REGISTER_BITS>>,
    coarse_shift: Signal<Local, Bits<SHIFT_BITS>>,
    coarse_shifted: Signal<Local, Bits<REGISTER_BITS>>,
    coarse: DFF<Bits<COARSE_BITS>>,
    coarse_negative: DFF<Bit>,
    fine_shift: DFF<Bits<SHIFT_BITS>>,
    coarse_valid: DFF<Bit>,
    fine_mask: Signal<Local, Bits<COARSE_BITS>>,
    shifted: Signal<Local, Bits<COARSE_BITS>>,
    y_out: DFF<Signed<OUTPUT_BITS>>,
    valid_out: DFF<Bit>,
    one: Constant<Bits<REGISTER_BITS>>,
    all_ones: Constant<Bits<REGISTER_BITS>>,
    coarse_all_ones: Constant<Bits<COARSE_BITS>>,
    coarse_shift_mask: Constant<Bits<SHIFT_BITS>>,
    fine_shift_mask: Constant<Bits<SHIFT_BITS>>,
}

impl CicDecimator {
    /// A CIC decimator with all registers at zero.
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            x: Default::default(),
            decimation: Default::default(),
            shift: Default::default(),
            y: Default::default(),
            valid: Default::default(),
            x_wide: Default::default(),
            integrator1: Default::default(),
            integrator2: Default::default(),
            integrator3: Default::default(),
            integrator4: Default::default(),
            count: Default::default(),
            sample: Default::default(),
            sample_valid: Default::default(),
            comb1: Default::default(),
            comb2: Default::default(),
            comb3: Default::default(),
            comb4: Default::default(),
            comb_delay1: Default::default(),
            comb_delay2: Default::default(),
            comb_delay3: Default::default(),
            comb_delay4: Default::default(),
            comb_valid1: Default::default(),
            comb_valid2: Default::default(),
            comb_valid3: Default::default(),
            comb_valid4: Default::default(),
            rounding: Default::default(),
            biased: Default::default(),
            biased_out: Default::default(),
            biased_shift: Default::default(),
            biased_valid: Default::default(),
            sign_mask: Default::default(),
            coarse_shift: Default::default(),
            coarse_shifted: Default::default(),
            coarse: Default::default(),
            coarse_negative: Default::default(),
            fine_shift: Default::default(),
            coarse_valid: Default::default(),
            fine_mask: Default::default(),
            shifted: Default::default(),
            y_out: Default::default(),
            valid_out: Default::default(),
            one: Constant::new(1.into()),
            all_ones: Constant::new(Bits::<REGISTER_BITS>::mask()),
            coarse_all_ones: Constant::new(Bits::<COARSE_BITS>::mask()),
            coarse_shift_mask: Constant::new(COARSE_SHIFT_MASK.into()),
            fine_shift_mask: Constant::new(FINE_SHIFT_MASK.into()),
        }
    }
}

impl Default for CicDecimator {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for CicDecimator {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self,
            clock,
            integrator1,
            integrator2,
            integrator3,
            integrator4,
            count,
            sample,
            sample_valid,
            comb1,
            comb2,
            comb3,
            comb4,
            comb_delay1,
            comb_delay2,
            comb_delay3,
            comb_delay4,
            comb_valid1,
            comb_valid2,
            comb_valid3,
            comb_valid4,
            biased_out,
            biased_shift,
            biased_valid,
            coarse,
            coarse_negative,
            fine_shift,
            coarse_valid,
            y_out,
            valid_out
        );
        // Integrators, wrap-around.
        self.x_wide.next = signed_bit_cast_exact::<REGISTER_BITS, INPUT_BITS>(self.x.val());
        self.integrator1.d.next = self.integrator1.q.val() + self.x_wide.val();
        self.integrator2.d.next = self.integrator2.q.val() + self.integrator1.q.val();
        self.integrator3.d.next = self.integrator3.q.val() + self.integrator2.q.val();
        self.integrator4.d.next = self.integrator4.q.val() + self.integrator3.q.val();
        // Rate counter and decimation.
        self.sample_valid.d.next = false;
        if self.count.q.val() == 0 {
            self.count.d.next = self.decimation.val() - 1;
            self.sample.d.next = self.integrator4.q.val();
            self.sample_valid.d.next = true;
        } else {
            self.count.d.next = self.count.q.val() - 1;
        }
        // Combs, one per clock after the strobe.
        self.comb_valid1.d.next = self.sample_valid.q.val();
        self.comb_valid2.d.next = self.comb_valid1.q.val();
        self.comb_valid3.d.next = self.comb_valid2.q.val();
        self.comb_valid4.d.next = self.comb_valid3.q.val();
        if self.sample_valid.q.val() {
            self.comb1.d.next = self.sample.q.val() - self.comb_delay1.q.val();
            self.comb_delay1.d.next = self.sample.q.val();
        }
        if self.comb_valid1.q.val() {
            self.comb2.d.next = self.comb1.q.val() - self.comb_delay2.q.val();
            self.comb_delay2.d.next = self.comb1.q.val();
        }
        if self.comb_valid2.q.val() {
            self.comb3.d.next = self.comb2.q.val() - self.comb_delay3.q.val();
            self.comb_delay3.d.next = self.comb2.q.val();
        }
        if self.comb_valid3.q.val() {
            self.comb4.d.next = self.comb3.q.val() - self.comb_delay4.q.val();
            self.comb_delay4.d.next = self.comb3.q.val();
        }
        // Output: arithmetic shift right with round-half-up, as
        // ((b ^ s) >> shift) ^ s with s the sign mask of the biased value
        // b, in three registered steps (module header): bias, coarse, fine.
        self.rounding.next = (self.one.val() << self.shift.val()) >> 1;
        self.biased.next = self.comb4.q.val() + signed_cast(self.rounding.val());
        self.biased_valid.d.next = self.comb_valid4.q.val();
        if self.comb_valid4.q.val() {
            self.biased_out.d.next = unsigned_cast(self.biased.val());
            self.biased_shift.d.next = self.shift.val();
        }
        self.sign_mask.next = 0.into();
        // Sign bit, REGISTER_BITS - 1 (rust-hdl needs a literal index; a
        // signed compare with 0 costs a comparator in Yosys).
        if self.biased_out.q.val().get_bit(79) {
            self.sign_mask.next = self.all_ones.val();
        }
        self.coarse_shift.next = self.biased_shift.q.val() & self.coarse_shift_mask.val();
        self.coarse_shifted.next =
            (self.biased_out.q.val() ^ self.sign_mask.val()) >> self.coarse_shift.val();
        self.coarse_valid.d.next = self.biased_valid.q.val();
        if self.biased_valid.q.val() {
            self.coarse.d.next = self.coarse_shifted.val().get_bits::<COARSE_BITS>(0);
            self.coarse_negative.d.next = self.biased_out.q.val().get_bit(79);
            self.fine_shift.d.next = self.biased_shift.q.val() & self.fine_shift_mask.val();
        }
        self.fine_mask.next = 0.into();
        if self.coarse_negative.q.val() {
            self.fine_mask.next = self.coarse_all_ones.val();
        }
        self.shifted.next = (self.coarse.q.val() >> self.fine_shift.q.val()) ^ self.fine_mask.val();
        self.valid_out.d.next = self.coarse_valid.q.val();
        if self.coarse_valid.q.val() {
            self.y_out.d.next = signed_cast(self.shifted.val().get_bits::<OUTPUT_BITS>(0));
        }
        self.y.next = self.y_out.q.val();
        self.valid.next = self.valid_out.q.val();
    }
}

crate::impl_clocked!(CicDecimator);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{prepare, tick};
    use crate::filter_design::cic_bit_growth;
    use crate::model::cic_decimator::CicDecimator as Model;
    use crate::primitives::convert::{i128_to_signed, signed_to_i128, u128_to_bits};
    use crate::test_util::segments;
    use proptest::prelude::*;

    /// Run the model over `x`, returning the outputs in order.
    fn outputs(x: &[i32], r: u32, shift: u32) -> Vec<i64> {
        let mut m = Model::default();
        x.iter()
            .filter_map(|&v| Some(m.step(v, r, shift)).filter(|o| o.1).map(|o| o.0))
            .collect()
    }

    /// (R, shift) with the shift anywhere in 0..=ceil(4 log2 R).
    fn rate_and_shift() -> impl Strategy<Value = (u32, u32)> {
        prop::sample::select(vec![1u32, 2, 3, 5, 16, 17, 31])
            .prop_flat_map(|r| (Just(r), 0..=cic_bit_growth(r)))
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(6))]
        #[test]
        fn rtl_matches_model_with_rate_changes_and_extreme_inputs(
            settings in segments(rate_and_shift(), 4..6, 250..300),
            inputs in prop::collection::vec(prop_oneof![1 => Just(i32::MIN), 1 => Just(i32::MAX), 6 => any::<i32>()], 1800),
        ) {
            let mut uut = CicDecimator::new();
            prepare(&mut uut);
            let mut model = Model::default();
            let mut strobes = 0;
            for (n, (&(r, shift), &x)) in settings.iter().zip(&inputs).enumerate() {
                uut.x.next = i128_to_signed(x as i128);
                uut.decimation.next = u128_to_bits(r as u128);
                uut.shift.next = u128_to_bits(shift as u128);
                tick(&mut uut);
                let hw = (signed_to_i128(uut.y.val()) as i64, uut.valid.val());
                prop_assert_eq!(hw, model.step(x, r, shift), "cycle {}", n);
                strobes += hw.1 as u32;
            }
            prop_assert!(strobes > 10, "only {} outputs", strobes);
        }
    }

    #[test]
    fn impulse_response_is_four_boxcars() {
        // Independent reference: the convolution of four length-R boxcars,
        // sum R^4. With shift 0 the outputs are exact integer taps, read at
        // every R-th position from some phase.
        let r = 5;
        let mut h = vec![1i64];
        for _ in 0..4 {
            let mut g = vec![0i64; h.len() + r - 1];
            for (i, &v) in h.iter().enumerate() {
                for t in &mut g[i..i + r] {
                    *t += v;
                }
            }
            h = g;
        }
        assert_eq!(h.iter().sum::<i64>(), 5i64.pow(4));
        let mut x = vec![0i32; 200];
        x[50] = 1;
        let y = outputs(&x, r as u32, 0);
        let taps: Vec<i64> = y.into_iter().filter(|&v| v != 0).collect();
        let phase = (0..r).find(|&p| h[p] == taps[0]).unwrap();
        let expected: Vec<i64> = h[phase..]
            .iter()
            .step_by(r)
            .copied()
            .filter(|&v| v != 0)
            .collect();
        assert_eq!(taps, expected);
    }

    #[test]
    fn dc_gain_is_r_to_the_fourth_over_two_to_the_shift() {
        for (r, c) in [(16u32, 12345i32), (1000, -777), (4096, 1), (17, i32::MAX)] {
            let shift = cic_bit_growth(r) - OUTPUT_FRACTION_BITS;
            let y = outputs(&vec![c; 12 * r as usize], r, shift);
            let exact = c as i128 * (r as i128).pow(4);
            let want = (exact + (1i128 << (shift - 1))).div_euclid(1i128 << shift) as i64;
            assert_eq!(*y.last().unwrap(), want, "R {r}");
            assert_eq!(y[y.len() - 2], want, "R {r} not settled");
        }
    }

    #[test]
    fn full_scale_inputs_wrap_the_integrators_and_come_out_exact() {
        // R = 4096: the 80-bit integrators wrap thousands of times; the
        // output is still the exact average times 2^8 (G = 1 for R = 2^12).
        let shift = cic_bit_growth(4096) - OUTPUT_FRACTION_BITS;
        for c in [i32::MIN, i32::MAX] {
            let y = outputs(&vec![c; 6 * 4096], 4096, shift);
            assert_eq!(*y.last().unwrap(), c as i64 * 256);
        }
    }

    /// Four cascaded running sums of length R at full rate, exact.
    fn cascade(x: &[i32], r: usize) -> Vec<i128> {
        let mut s: Vec<i128> = x.iter().map(|&v| v as i128).collect();
        for _ in 0..4 {
            let prev = s.clone();
            let mut acc = 0i128;
            for n in 0..s.len() {
                acc += prev[n] - if n >= r { prev[n - r] } else { 0 };
                s[n] = acc;
            }
        }
        s
    }

    #[test]
    fn ramp_and_sine_match_a_direct_sum() {
        // Direct reference: each output is the boxcar cascade at one input
        // index, every R-th, rounded by the shift. The alignment (which
        // index feeds output q) is read off an impulse, then held fixed.
        let r = 16usize;
        let shift = cic_bit_growth(r as u32) - OUTPUT_FRACTION_BITS;
        let mut impulse = vec![0i32; 400];
        impulse[0] = 1;
        let probe = outputs(&impulse, r as u32, 0);
        let h = cascade(&impulse, r);
        let q = probe.iter().position(|&v| v != 0).unwrap();
        let j = (0..r)
            .find(|&j| h[j] == probe[q] as i128 && h[j + r] == probe[q + 1] as i128)
            .unwrap();
        let ramp: Vec<i32> = (0..3000).map(|n| n * 1000 - 1_500_000).collect();
        let sine: Vec<i32> = (0..3000)
            .map(|n| (1e9 * (n as f64 * 0.013).sin()) as i32)
            .collect();
        for x in [ramp, sine] {
            let s = cascade(&x, r);
            let y = outputs(&x, r as u32, shift);
            for k in q..q + 150 {
                let want = (s[j + (k - q) * r] + (1i128 << (shift - 1))).div_euclid(1i128 << shift);
                assert_eq!(y[k] as i128, want, "output {k}");
            }
        }
    }
}
