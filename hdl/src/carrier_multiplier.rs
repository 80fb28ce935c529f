//! The fine core's carrier product: a Q1.15 envelope times an 18-bit
//! quarter-LSB carrier, rounded once to the DAC's 16 bits, its rounding
//! error shaped away from the carrier.
//!
//! ```text
//!  a[16] ─┐
//!         ×─► [p: 34] ──────────────┐
//!  b[18] ─┘                         ▼
//!                       p + 8 m + h ─► [rounded[33:17]: 17] ─► sat ─► [y: 16]
//!  k[9] ──┐                ▲        ▲  │
//!         ×─► [m: 18] ─────┘        │  └─► r = rounded[16:0] - 2^16 ─► [r1] ─► [r2] ─► [r3] ─┐
//!  r1[16:8] ┘   (LUTs)              └── [h = 2^16 - r[n-4]: 19] ◄─────────────────────────────┘
//! ```
//!
//! `y = round(u / 2^17)`, rounded half up, where u is the product a b plus
//! the feedback of the earlier residues r = u - 2^17 y (the low 17 bits of
//! u, two's complement, -2^16 <= r < 2^16): `u[n]` = a b + K `r[n-2]` -
//! `r[n-4]`, K = k / 32. Then 2^17 y = a b - (`r[n]` - K `r[n-2]` + `r[n-4]`): the
//! rounding error leaves through 1 - K z^-2 + z^-4, which at frequency
//! theta is z^-2 (2 cos(2 theta) - K). With K = 2 cos(2 w) from the
//! carriers (`crate::notch_coefficient`, within 1/64), it has zeros at the
//! carrier +- w (and at pi -+ w), so at most 1/64 of the rounding error
//! stays at the carrier, where a fold of the clock of any period would
//! turn it into a slow error of drive and reference (docs/field.md,
//! "Rounding shaped away from the carrier"). Away from the carrier the
//! error is larger: |1 - K z^-2 + z^-4| <= 4, 6 times the white rounding's
//! power in all, at most 2 LSB on a word.
//!
//! The feedback K r is formed from r's top 9 bits, m = k (r >> 8), and
//! scaled by 2^(8 - 5) = 8: a 9 x 9 product in LUTs
//! (`crate::small_multiplier`), since multiplier blocks here cost the
//! ECP5-25F core its 100 MHz (`crate::notch_coefficient`). The 8 bits
//! dropped leave K (r - 2^8 (r >> 8)), at most 2 x 2^8 of 2^17, 1/256 LSB,
//! unshaped: 1/70 of a rounding's error at most.
//!
//! The rounding stage adds three registered terms, rounded = u + 2^16 =
//! p + 8 m + h, where h = 2^16 - `r[n-4]` is formed a clock ahead from
//! `r[n-3]` (and held with its bit 16 inverted, so that the register's
//! power-up 0 means h = 2^16, r = 0); r is rounded's low 17 bits less
//! 2^16, i.e. with bit 16 inverted, and the word is rounded's bits 33:17.
//! Saturation to +-32767 has a register of its own, out of the loop.
//!
//! `a` is F A (Q1.15, |a| <= 32767 from the envelope multiplier, -32768
//! allowed at the port) and `b` a carrier of `crate::sine_pair` with two
//! fraction bits (peak 4 x 32767): |a b| / 2^17 <= 32768 x 131068 / 2^17 =
//! 32767. The feedback adds at most 0.5 + |k| / 32 x 0.5 LSB: 4.5 for any
//! 9-bit k (|8 m| <= 8 x 256 x 256 = 2^19), 2.5 for any k of
//! `crate::notch_coefficient` (|k| <= 128), 1.5 for true carriers (|k| <=
//! 64). So |rounded| <= 2^32 plus 2^19 plus 2^17 fits 34 bits and the word
//! before saturation 17 bits; y saturates to [-32767, 32767] (reached only
//! within 2 LSB of full scale; r is taken before it, so the loop stays
//! bounded). 0 < h <= 2^17 (19 bits).
//!
//! Latency: 3 clocks (multiplier register, rounding register, saturation
//! register), as `crate::q15_multiplier::LATENCY`; the feedback loop is two
//! clocks long (r1 through the feedback product's register), so both
//! products keep their output registers. Resources: one 18 x 18 multiplier
//! (ECP5 `MULT18X18D`), a 9 x 9 one in LUTs, 3 x 17 + 19 + 17 flip-flops
//! besides the products.

use crate::fine_sine_table::{OUTPUT_BITS, OUTPUT_FRACTION_BITS};
use crate::notch_coefficient::{K_BITS, K_FRACTION_BITS};
use crate::primitives::RegisteredMultiplier;
use crate::primitives::convert::signed_bit_cast_exact;
use crate::small_multiplier::{FACTOR_BITS, PRODUCT_BITS as FEEDBACK_BITS, SmallMultiplier};
use rust_hdl::prelude::*;

/// Clock cycles from the factors to `y`.
pub const LATENCY: usize = 3;
/// Width of the product: 16 + 18 bits.
const PRODUCT_BITS: usize = 16 + OUTPUT_BITS;
/// The product's shift to the DAC's LSB: 15 + the carrier's fraction bits.
pub const SHIFT: u32 = 15 + OUTPUT_FRACTION_BITS;
/// Width of a residue r = u - 2^17 y: the low `SHIFT` bits of u.
const RESIDUE_BITS: usize = SHIFT as usize;
/// Width of h = 2^16 - r, in (0, 2^17].
const OFFSET_BITS: usize = RESIDUE_BITS + 2;
/// The residue's low bits left out of the feedback: r >> 8 is 9 bits.
pub const RESIDUE_DROP: u32 = 8;
/// The feedback product's shift to u's scale: r lost 8 bits, k has 5
/// fraction bits.
pub const FEEDBACK_SCALE: u32 = RESIDUE_DROP - K_FRACTION_BITS;
/// Width of the rounding sum, p's: |p| <= 32768 x 131068 < 2^32, and the
/// feedback's 2.5 LSB bring it past 2^32, within 34 bits.
const SUM_BITS: usize = PRODUCT_BITS;
/// Width of the word before saturation.
const WORD_BITS: usize = SUM_BITS - SHIFT as usize;
/// The DAC words saturate to +-WORD_LIMIT.
pub const WORD_LIMIT: i64 = 32767;
const _: () = assert!(SHIFT == 17 && PRODUCT_BITS == 34 && FEEDBACK_SCALE == 3);
const _: () = assert!(RESIDUE_BITS - RESIDUE_DROP as usize == FACTOR_BITS && K_BITS == FACTOR_BITS);
const _: () = assert!(WORD_BITS == 17 && OFFSET_BITS == 19 && FEEDBACK_BITS == 18);

/// `y = round(a * b / 2^17)` with its rounding error fed back through
/// `1 - k z^-2 + z^-4`, three registers deep.
#[derive(LogicBlock)]
pub struct CarrierMultiplier {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// The envelope F A, Q1.15 (a register's output: it enters the
    /// multiplier directly).
    pub a: Signal<In, Signed<16>>,
    /// The carrier in quarter LSB, |b| <= 4 x 32767 (a register's output).
    pub b: Signal<In, Signed<OUTPUT_BITS>>,
    /// The notch coefficient 2 cos(2 w), Q3.5 (`crate::notch_coefficient`).
    pub k: Signal<In, Signed<K_BITS>>,
    /// Rounded product, Q1.15, three clocks after the factors.
    pub y: Signal<Out, Signed<16>>,
    product: RegisteredMultiplier<16, OUTPUT_BITS, PRODUCT_BITS>,
    feedback: SmallMultiplier,
    residue_top: Signal<Local, Signed<FACTOR_BITS>>,
    residue_1: DFF<Signed<RESIDUE_BITS>>,
    residue_2: DFF<Signed<RESIDUE_BITS>>,
    residue_3: DFF<Signed<RESIDUE_BITS>>,
    /// h with bit 16 inverted, so that its power-up 0 is h = 2^16 (r = 0).
    offset: DFF<Bits<OFFSET_BITS>>,
    residue_3_wide: Signal<Local, Signed<OFFSET_BITS>>,
    offset_next: Signal<Local, Signed<OFFSET_BITS>>,
    offset_value: Signal<Local, Signed<OFFSET_BITS>>,
    feedback_wide: Signal<Local, Signed<SUM_BITS>>,
    feedback_scaled: Signal<Local, Signed<SUM_BITS>>,
    offset_wide: Signal<Local, Signed<SUM_BITS>>,
    rounded: Signal<Local, Signed<SUM_BITS>>,
    low_bits: Signal<Local, Bits<RESIDUE_BITS>>,
    word: DFF<Signed<WORD_BITS>>,
    y_out: DFF<Signed<16>>,
    half_lsb: Constant<Signed<OFFSET_BITS>>,
    sign_of_residue: Constant<Bits<RESIDUE_BITS>>,
    offset_flip: Constant<Bits<OFFSET_BITS>>,
    word_max: Constant<Signed<WORD_BITS>>,
    word_min: Constant<Signed<WORD_BITS>>,
    y_max: Constant<Signed<16>>,
    y_min: Constant<Signed<16>>,
}

impl CarrierMultiplier {
    /// The carrier product with round-half-up and error feedback.
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            a: Default::default(),
            b: Default::default(),
            k: Default::default(),
            y: Default::default(),
            product: RegisteredMultiplier::new(),
            feedback: SmallMultiplier::new(),
            residue_top: Default::default(),
            residue_1: Default::default(),
            residue_2: Default::default(),
            residue_3: Default::default(),
            offset: Default::default(),
            residue_3_wide: Default::default(),
            offset_next: Default::default(),
            offset_value: Default::default(),
            feedback_wide: Default::default(),
            feedback_scaled: Default::default(),
            offset_wide: Default::default(),
            rounded: Default::default(),
            low_bits: Default::default(),
            word: Default::default(),
            y_out: Default::default(),
            half_lsb: Constant::new((1i64 << (SHIFT - 1)).into()),
            sign_of_residue: Constant::new((1u64 << (SHIFT - 1)).into()),
            offset_flip: Constant::new((1u64 << (SHIFT - 1)).into()),
            word_max: Constant::new(WORD_LIMIT.into()),
            word_min: Constant::new((-WORD_LIMIT).into()),
            y_max: Constant::new(WORD_LIMIT.into()),
            y_min: Constant::new((-WORD_LIMIT).into()),
        }
    }
}

impl Default for CarrierMultiplier {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for CarrierMultiplier {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self, clock, residue_1, residue_2, residue_3, offset, word, y_out
        );
        self.product.clock.next = self.clock.val();
        self.product.a.next = self.a.val();
        self.product.b.next = self.b.val();
        // The feedback product takes r[n-1] and gives k (r[n-2] >> 8)
        // during n: bits 16:8 of the residue.
        self.feedback.clock.next = self.clock.val();
        self.residue_top.next = self.residue_1.q.val().get_bits::<FACTOR_BITS>(8);
        self.feedback.a.next = self.k.val();
        self.feedback.b.next = self.residue_top.val();
        // h = 2^16 - r[n-4], from r[n-3] a clock ahead, held with bit 16
        // inverted (power-up: h = 2^16).
        self.residue_3_wide.next =
            signed_bit_cast_exact::<OFFSET_BITS, RESIDUE_BITS>(self.residue_3.q.val());
        self.offset_next.next = self.half_lsb.val() - self.residue_3_wide.val();
        self.offset.d.next = unsigned_cast(self.offset_next.val()) ^ self.offset_flip.val();
        self.offset_value.next = signed_cast(self.offset.q.val() ^ self.offset_flip.val());
        // rounded = u + 2^16 = p + 8 k (r[n-2] >> 8) + h, the last two
        // sign-extended to p's width (8 m is exact: |m| <= 2^16).
        self.feedback_wide.next =
            signed_bit_cast_exact::<SUM_BITS, FEEDBACK_BITS>(self.feedback.p.val());
        self.feedback_scaled.next = signed_cast(unsigned_cast(self.feedback_wide.val()) << 3);
        self.offset_wide.next =
            signed_bit_cast_exact::<SUM_BITS, OFFSET_BITS>(self.offset_value.val());
        self.rounded.next =
            (self.product.p.val() + self.feedback_scaled.val()) + self.offset_wide.val();
        // r = u - 2^17 y: rounded's low 17 bits less 2^16 (bit 16 inverted).
        self.low_bits.next = unsigned_cast(self.rounded.val().get_bits::<RESIDUE_BITS>(0));
        self.residue_1.d.next = signed_cast(self.low_bits.val() ^ self.sign_of_residue.val());
        self.residue_2.d.next = self.residue_1.q.val();
        self.residue_3.d.next = self.residue_2.q.val();
        // Bits 33:17 (`SHIFT`), then saturated to +-32767.
        self.word.d.next = self.rounded.val().get_bits::<WORD_BITS>(17);
        self.y_out.d.next = self.word.q.val().get_bits::<16>(0);
        if self.word.q.val() > self.word_max.val() {
            self.y_out.d.next = self.y_max.val();
        }
        if self.word.q.val() < self.word_min.val() {
            self.y_out.d.next = self.y_min.val();
        }
        self.y.next = self.y_out.q.val();
    }
}

crate::impl_clocked!(CarrierMultiplier);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{prepare, tick};
    use crate::fine_sine_table::OUTPUT_PEAK;
    use crate::model::am_mixer::CarrierMultiplier as Model;
    use crate::model::notch_coefficient::NotchCoefficient;
    use crate::model::sine_pair::sine_pair;
    use crate::primitives::convert::{i128_to_signed, signed_to_i128};
    use crate::test_util::word16;
    use proptest::prelude::*;

    #[test]
    fn extreme_factors_stay_within_the_dac_range() {
        // From power-up (no residue yet) the first word is the exact
        // floor((a c + 2^16) / 2^17), for the extreme envelopes and
        // carriers, three edges to the output. After that, held with the
        // extreme coefficients of true carriers (|k| <= 64, the notch
        // coefficient's header), the feedback moves the words by at most
        // 0.5 + 2 x 0.5 + 0.5 = 2 LSB and never out of +-32767.
        let envelopes = [i16::MIN, -32767, -1, 0, 1, i16::MAX];
        let carriers = [-OUTPUT_PEAK, -OUTPUT_PEAK + 1, -1, 0, 1, OUTPUT_PEAK];
        for a in envelopes {
            for c in carriers {
                let exact = (i64::from(a) * i64::from(c) + (1 << 16)).div_euclid(1 << 17);
                assert!((-32767..=32767).contains(&exact), "{a} x {c}");
                for k in [-64, -1, 0, 1, 64] {
                    let mut model = Model::new(OUTPUT_FRACTION_BITS);
                    let y = (0..3).map(|_| model.step(a, c, k)).last().unwrap();
                    assert_eq!(i64::from(y), exact, "{a} x {c}");
                    for _ in 0..64 {
                        let y = i64::from(model.step(a, c, k));
                        assert!((y - exact).abs() <= 2, "{a} x {c}, k {k}: {y}");
                    }
                }
            }
        }
    }

    #[test]
    fn no_rounding_error_stays_at_the_carrier() {
        // The pair's carrier at a step near 0.19 of the clock, the notch
        // coefficient from the same words, a constant envelope: the error
        // of the words against the exact a c / 2^17, projected on the
        // carrier over 2^20 clocks. Plain rounding leaves about 0.29 /
        // sqrt(N) = 2.8e-4 LSB there or more (a fold's slow error); the
        // feedback leaves |2 cos(2w) - k / 32| (at most 1/64, the notch
        // coefficient's header) times the residues' content there (at most
        // 1e-3 LSB, 1.3 times the plain rounding's here), and the dropped
        // residue bits' unshaped error (1/70 of a rounding's at most, so
        // 1.4e-5): below 3e-5. The control, k = 0 (zeros at 1/8 and 3/8 of
        // the clock instead), leaves more than
        // 1e-4. The words are counted once the coefficient holds its
        // second snapshot (the first, at power-up, sees empty delays).
        use crate::notch_coefficient::PERIOD;
        let step = 0x3169_5b9au32;
        let a = 29490i16;
        let at_carrier = |notched: bool| {
            let mut product = Model::new(OUTPUT_FRACTION_BITS);
            let mut notch = NotchCoefficient::default();
            let (mut phase, mut exact) = (0u32, std::collections::VecDeque::new());
            let w = f64::from(step) / 2f64.powi(32) * std::f64::consts::TAU;
            let (mut re, mut im) = (0.0, 0.0);
            let (n, start) = (1 << 20, 2 * PERIOD as usize + 2);
            for i in 0..n + start {
                let (c, s) = sine_pair(phase);
                phase = phase.wrapping_add(step);
                let k = if notched { notch.output() } else { 0 };
                notch.step(c, s);
                exact.push_back(f64::from(a) * f64::from(c) / 131072.0);
                let y = product.step(a, c, k);
                // The word after edge i is the product of the factors of
                // edge i - 2 (three registers, the first edge being 0).
                if i >= 2 {
                    let e = f64::from(y) - exact.pop_front().unwrap();
                    if i < start {
                        continue;
                    }
                    let t = w * (i - 2) as f64;
                    re += e * t.cos();
                    im += e * t.sin();
                }
            }
            re.hypot(im) / n as f64
        };
        let (shaped, plain) = (at_carrier(true), at_carrier(false));
        println!("at the carrier: {shaped:.2e} LSB with the notch, {plain:.2e} without");
        assert!(shaped < 3e-5, "shaped: {shaped:.3e} LSB at the carrier");
        assert!(plain > 1e-4, "control: {plain:.3e} LSB at the carrier");
    }

    fn carrier() -> impl Strategy<Value = i32> {
        prop_oneof![
            Just(OUTPUT_PEAK),
            Just(-OUTPUT_PEAK),
            Just(0),
            -OUTPUT_PEAK..=OUTPUT_PEAK
        ]
    }

    fn coefficient() -> impl Strategy<Value = i32> {
        prop_oneof![Just(-256), Just(255), Just(0), -256..=255]
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(8))]
        #[test]
        fn rtl_matches_model_on_extremes_and_random_words(
            words in prop::collection::vec((word16(), carrier(), coefficient()), 400),
        ) {
            let mut uut = CarrierMultiplier::new();
            prepare(&mut uut);
            let mut model = Model::new(OUTPUT_FRACTION_BITS);
            for (n, &(a, c, k)) in words.iter().enumerate() {
                uut.a.next = i128_to_signed(a as i128);
                uut.b.next = i128_to_signed(c as i128);
                uut.k.next = i128_to_signed(k as i128);
                tick(&mut uut);
                prop_assert_eq!(signed_to_i128(uut.y.val()) as i16, model.step(a, c, k), "cycle {}", n);
            }
        }
    }
}
