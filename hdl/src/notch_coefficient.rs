//! The fine core's notch coefficient: k = 2 cos(2 w) in Q3.5 (k / 32 is
//! 2 cos(2 w)), w the carrier's phase step, from the drive carriers
//! themselves, by a bit-serial multiply-accumulate (no multiplier block).
//!
//! ```text
//!  cos[18] ──┬──────────────────────────► [hold_c] ─┐
//!            └─► [cos_1] ─► [cos_2] ─────► [bits_c] ─┼─► acc = 2 acc ± hold_c ± hold_s ─► [acc: 37]
//!  sin[18] ──┬──────────────────────────► [hold_s] ─┤      (per bit of bits_c, bits_s, MSB first)
//!            └─► [sin_1] ─► [sin_2] ─────► [bits_s] ─┘                └─► [k = (acc + 2^27)[36:28]: 9]
//!  [count: 5] 0: snapshot and clear; 1..=18: one bit each; 19: k
//! ```
//!
//! With the carriers A cos(wn + p) and A sin(wn + p) (A = 4 x 32767, the
//! quarter-LSB words of `crate::sine_pair`), `cos[n]` `cos[n-2]` + `sin[n]`
//! `sin[n-2]` = A^2 cos(2w), whatever the phase: a constant while the step
//! is. So the sum need not be formed every clock: a free-running 5-bit
//! count takes a snapshot of `cos[n]`, `sin[n]` (the multiplicands) and
//! `cos[n-2]`, `sin[n-2]` (the multipliers) at count 0, forms the two
//! products' sum exactly over the next 18 clocks by Horner's rule, MSB
//! first (acc = 2 acc + b_j x, the sign bit's term subtracted), and at
//! count 19 sets k = sum / 2^28, rounded half up. A new step reaches k
//! within 32 + 20 clocks.
//!
//! k / 32 = 2 cos(2w) A^2 / 2^34 within 1/64 (the rounding; A^2 / 2^34 =
//! 0.99994 and the words' error, 5e-6 of A, add less than 0.01 of k's
//! LSB). `crate::carrier_multiplier` feeds its rounding error back through
//! 1 - (k / 32) z^-2 + z^-4 = z^-2 (2 cos(2 theta) - k / 32) at frequency
//! theta, so at the carrier that error is at most 1/64 of itself, 36 dB
//! down, instead of folding whole into the band (docs/field.md, "Rounding
//! shaped away from the carrier"); what a fold brings back of it is far
//! below the noise. Five fraction bits are enough for that and keep the
//! feedback's product small enough for LUTs (`crate::small_multiplier`).
//! Serial, and the feedback in LUTs, because multiplier blocks for them
//! cost the ECP5-25F core its 100 MHz: with two 18 x 18 for a parallel k
//! and four for the feedback it reached 89.9, 99.6 and 95.1 MHz at seeds
//! 1 to 3, and 93.1 at seed 1 with the serial k (`gyrocal synth`), where
//! the core with 12 had reached 112.7: the tables' paths to their
//! multipliers lengthen as the multiplier sites fill.
//!
//! Widths: carriers 18-bit (|x| <= 4 x 32767), the accumulator 37-bit
//! (every partial sum is x times a prefix of an 18-bit word, |.| <= 2^34,
//! and the two together < 2^35), k 9-bit (|k| <= 128 for any words, 2^35 /
//! 2^28; 64 |cos(2w)| for true carriers). Power-up: all registers 0, so k = 0
//! until the carriers leave 0. Resources: no multiplier; 9 x 18 + 37 + 5
//! flip-flops and a 37-bit three-input sum.

use crate::fine_sine_table::OUTPUT_BITS;
use crate::primitives::convert::signed_bit_cast_exact;
use rust_hdl::prelude::*;

/// Width of k: Q3.5 with room for any pair of 18-bit words.
pub const K_BITS: usize = 9;
/// Fraction bits of k.
pub const K_FRACTION_BITS: u32 = 5;
/// The sum's shift to k: A^2 = 2^34 (nearly) is 2 x 2^5 k's LSB, so 34 - 6.
pub const SHIFT: u32 = 28;
/// Clocks between snapshots: the count's period.
pub const PERIOD: u32 = 1 << COUNT_BITS;
/// The count at which k takes the finished sum: after the snapshot and
/// one clock per multiplier bit.
pub const K_COUNT: u32 = 1 + OUTPUT_BITS as u32;
/// Width of the schedule's count.
const COUNT_BITS: usize = 5;
/// Width of the accumulator.
const ACC_BITS: usize = 2 * OUTPUT_BITS + 1;
const _: () = assert!(ACC_BITS - SHIFT as usize == K_BITS && K_FRACTION_BITS + 1 + SHIFT == 34);
const _: () = assert!(K_COUNT < PERIOD && OUTPUT_BITS == 18);

/// `k = (cos[n] cos[n-2] + sin[n] sin[n-2]) / 2^28` of the drive carriers, rounded,
/// one snapshot every `PERIOD` clocks.
#[derive(LogicBlock)]
pub struct NotchCoefficient {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// In-phase drive carrier, quarter LSB.
    pub cos: Signal<In, Signed<OUTPUT_BITS>>,
    /// Quadrature drive carrier, quarter LSB.
    pub sin: Signal<In, Signed<OUTPUT_BITS>>,
    /// 2 cos(2 w) in Q3.5 (within 1/64; see the header).
    pub k: Signal<Out, Signed<K_BITS>>,
    count: DFF<Bits<COUNT_BITS>>,
    cos_1: DFF<Signed<OUTPUT_BITS>>,
    cos_2: DFF<Signed<OUTPUT_BITS>>,
    sin_1: DFF<Signed<OUTPUT_BITS>>,
    sin_2: DFF<Signed<OUTPUT_BITS>>,
    hold_c: DFF<Signed<OUTPUT_BITS>>,
    hold_s: DFF<Signed<OUTPUT_BITS>>,
    bits_c: DFF<Bits<OUTPUT_BITS>>,
    bits_s: DFF<Bits<OUTPUT_BITS>>,
    acc: DFF<Signed<ACC_BITS>>,
    k_out: DFF<Signed<K_BITS>>,
    rounded: Signal<Local, Signed<ACC_BITS>>,
    doubled: Signal<Local, Signed<ACC_BITS>>,
    cos_wide: Signal<Local, Signed<ACC_BITS>>,
    sin_wide: Signal<Local, Signed<ACC_BITS>>,
    cos_term: Signal<Local, Signed<ACC_BITS>>,
    sin_term: Signal<Local, Signed<ACC_BITS>>,
    zero: Constant<Signed<ACC_BITS>>,
    half: Constant<Signed<ACC_BITS>>,
    snapshot: Constant<Bits<COUNT_BITS>>,
    sign_step: Constant<Bits<COUNT_BITS>>,
    k_step: Constant<Bits<COUNT_BITS>>,
}

impl NotchCoefficient {
    /// The coefficient at power-up (0).
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            cos: Default::default(),
            sin: Default::default(),
            k: Default::default(),
            count: Default::default(),
            cos_1: Default::default(),
            cos_2: Default::default(),
            sin_1: Default::default(),
            sin_2: Default::default(),
            hold_c: Default::default(),
            hold_s: Default::default(),
            bits_c: Default::default(),
            bits_s: Default::default(),
            acc: Default::default(),
            k_out: Default::default(),
            rounded: Default::default(),
            doubled: Default::default(),
            cos_wide: Default::default(),
            sin_wide: Default::default(),
            cos_term: Default::default(),
            sin_term: Default::default(),
            zero: Constant::new(0i64.into()),
            half: Constant::new((1i64 << (SHIFT - 1)).into()),
            snapshot: Constant::new(0u64.into()),
            sign_step: Constant::new(1u64.into()),
            k_step: Constant::new(u64::from(K_COUNT).into()),
        }
    }
}

impl Default for NotchCoefficient {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for NotchCoefficient {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self, clock, count, cos_1, cos_2, sin_1, sin_2, hold_c, hold_s, bits_c, bits_s, acc,
            k_out
        );
        self.count.d.next = self.count.q.val() + 1;
        self.cos_1.d.next = self.cos.val();
        self.cos_2.d.next = self.cos_1.q.val();
        self.sin_1.d.next = self.sin.val();
        self.sin_2.d.next = self.sin_1.q.val();
        // One Horner step: 2 acc plus each multiplicand whose multiplier
        // bit (MSB first: bit 17, `OUTPUT_BITS - 1`, written out because
        // the export does not evaluate a constant expression) is set, the
        // sign bit's (count 1) subtracted.
        self.doubled.next = signed_cast(unsigned_cast(self.acc.q.val()) << 1);
        self.cos_wide.next = signed_bit_cast_exact::<ACC_BITS, OUTPUT_BITS>(self.hold_c.q.val());
        self.sin_wide.next = signed_bit_cast_exact::<ACC_BITS, OUTPUT_BITS>(self.hold_s.q.val());
        self.cos_term.next = self.zero.val();
        if self.bits_c.q.val().get_bit(17) {
            self.cos_term.next = self.cos_wide.val();
            if self.count.q.val() == self.sign_step.val() {
                self.cos_term.next = self.zero.val() - self.cos_wide.val();
            }
        }
        self.sin_term.next = self.zero.val();
        if self.bits_s.q.val().get_bit(17) {
            self.sin_term.next = self.sin_wide.val();
            if self.count.q.val() == self.sign_step.val() {
                self.sin_term.next = self.zero.val() - self.sin_wide.val();
            }
        }
        if self.count.q.val() < self.k_step.val() {
            self.acc.d.next = (self.doubled.val() + self.cos_term.val()) + self.sin_term.val();
            self.bits_c.d.next = self.bits_c.q.val() << 1;
            self.bits_s.d.next = self.bits_s.q.val() << 1;
        }
        // Count 0: a snapshot, the accumulator cleared.
        if self.count.q.val() == self.snapshot.val() {
            self.hold_c.d.next = self.cos.val();
            self.hold_s.d.next = self.sin.val();
            self.bits_c.d.next = unsigned_cast(self.cos_2.q.val());
            self.bits_s.d.next = unsigned_cast(self.sin_2.q.val());
            self.acc.d.next = self.zero.val();
        }
        // Count 19: the sum is complete; k is bits 36:28 (`SHIFT`) of it
        // plus a half, |k| <= 128.
        self.rounded.next = self.acc.q.val() + self.half.val();
        if self.count.q.val() == self.k_step.val() {
            self.k_out.d.next = self.rounded.val().get_bits::<K_BITS>(28);
        }
        self.k.next = self.k_out.q.val();
    }
}

crate::impl_clocked!(NotchCoefficient);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{prepare, tick};
    use crate::fine_sine_table::OUTPUT_PEAK;
    use crate::model::notch_coefficient::NotchCoefficient as Model;
    use crate::primitives::convert::{i128_to_signed, signed_to_i128};
    use proptest::prelude::*;

    fn carrier() -> impl Strategy<Value = i32> {
        prop_oneof![
            Just(OUTPUT_PEAK),
            Just(-OUTPUT_PEAK),
            Just(0),
            -OUTPUT_PEAK..=OUTPUT_PEAK
        ]
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(8))]
        #[test]
        fn rtl_matches_model_on_extremes_and_random_words(
            words in prop::collection::vec((carrier(), carrier()), 300),
        ) {
            let mut uut = NotchCoefficient::new();
            prepare(&mut uut);
            let mut model = Model::default();
            for (n, &(c, s)) in words.iter().enumerate() {
                uut.cos.next = i128_to_signed(c as i128);
                uut.sin.next = i128_to_signed(s as i128);
                tick(&mut uut);
                prop_assert_eq!(signed_to_i128(uut.k.val()) as i32, model.step(c, s), "cycle {}", n);
            }
        }
    }

    #[test]
    fn the_coefficient_is_twice_the_cosine_of_twice_the_step() {
        // The pair's own carriers at steps across the turn: k within 0.51
        // of 64 cos(2 w) (the rounding's half, and 6e-5 x 64 from the
        // amplitude, 1e-5 x 64 from the words) on every clock from the
        // first snapshot whose delays hold words on (the second: the
        // first, at power-up, pairs cos[0] with a 0), over three snapshots
        // at different phases.
        use crate::model::sine_pair::sine_pair;
        for step in [
            0x0000_1000u32,
            0x3169_5b9a,
            0x4000_0000,
            0x7fff_0000,
            0xc123_4567,
        ] {
            let mut model = Model::default();
            let w = f64::from(step) / 2f64.powi(32) * std::f64::consts::TAU;
            let want = 2.0 * (2.0 * w).cos() * 32.0;
            let mut phase = 0x0123_4567u32;
            let mut seen = Vec::new();
            for n in 0..4 * PERIOD {
                let (cos, sin) = sine_pair(phase);
                let k = model.step(cos, sin);
                phase = phase.wrapping_add(step);
                if n >= PERIOD + K_COUNT {
                    seen.push(k);
                }
            }
            for k in seen {
                assert!(
                    (f64::from(k) - want).abs() <= 0.51,
                    "step {step:#x}: {k} against {want}"
                );
            }
        }
    }
}
