//! The fine core's carrier product: a Q1.15 envelope times an 18-bit
//! quarter-LSB carrier, rounded once to the DAC's 16 bits.
//!
//! ```text
//!  a[16] ──► [a] ──┐
//!                   ×──► [p: 34 bit] ──► (p + 2^16)[32:17] ──► [y: 16 bit]
//!  b[18] ──► [b] ──┘
//! ```
//!
//! `y = round(a b / 2^17)`, rounded half up: `a` is F A (Q1.15, peak
//! 32767, -32768 allowed) and `b` a carrier of `crate::sine_pair` with two
//! fraction bits (peak 4 x 32767). |a b + 2^16| / 2^17 <= 32768 x 131068 /
//! 131072 + 0.5 = 32767.5, so `y` lies in [-32767, 32767] and needs no
//! saturation. This is `crate::q15_multiplier` with the carrier's two
//! fraction bits kept to the product: the table core rounds the carrier to
//! an integer and then the product, and a fold of the clock turns that
//! second rounding's pattern into a slow error of the drive
//! (docs/field.md).
//!
//! Latency: 3 clocks (factor registers, multiplier register, rounding
//! register), as `crate::q15_multiplier::LATENCY`. Resources: one 18 x 18
//! multiplier (ECP5 `MULT18X18D`).

use crate::fine_sine_table::{OUTPUT_BITS, OUTPUT_FRACTION_BITS};
use crate::primitives::RegisteredMultiplier;
use rust_hdl::prelude::*;

/// Clock cycles from the factors to `y`.
pub const LATENCY: usize = 3;
/// Width of the product: 16 + 18 bits.
const PRODUCT_BITS: usize = 16 + OUTPUT_BITS;
/// The product's shift to the DAC's LSB: 15 + the carrier's fraction bits.
pub const SHIFT: u32 = 15 + OUTPUT_FRACTION_BITS;
const _: () = assert!(SHIFT == 17 && PRODUCT_BITS == 34);

/// `y = round(a * b / 2^17)`, three registers deep.
#[derive(LogicBlock)]
pub struct CarrierMultiplier {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// The envelope F A, Q1.15.
    pub a: Signal<In, Signed<16>>,
    /// The carrier in quarter LSB, |b| <= 4 x 32767.
    pub b: Signal<In, Signed<OUTPUT_BITS>>,
    /// Rounded product, Q1.15, three clocks after the factors.
    pub y: Signal<Out, Signed<16>>,
    a_in: DFF<Signed<16>>,
    b_in: DFF<Signed<OUTPUT_BITS>>,
    product: RegisteredMultiplier<16, OUTPUT_BITS, PRODUCT_BITS>,
    rounded: Signal<Local, Signed<PRODUCT_BITS>>,
    y_out: DFF<Signed<16>>,
    half_lsb: Constant<Signed<PRODUCT_BITS>>,
}

impl CarrierMultiplier {
    /// The carrier product with round-half-up.
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            a: Default::default(),
            b: Default::default(),
            y: Default::default(),
            a_in: Default::default(),
            b_in: Default::default(),
            product: RegisteredMultiplier::new(),
            rounded: Default::default(),
            y_out: Default::default(),
            half_lsb: Constant::new((1i64 << (SHIFT - 1)).into()),
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
        dff_setup!(self, clock, a_in, b_in, y_out);
        self.a_in.d.next = self.a.val();
        self.b_in.d.next = self.b.val();
        self.product.clock.next = self.clock.val();
        self.product.a.next = self.a_in.q.val();
        self.product.b.next = self.b_in.q.val();
        self.rounded.next = self.product.p.val() + self.half_lsb.val();
        // Bits 32:17 (`SHIFT`).
        self.y_out.d.next = self.rounded.val().get_bits::<16>(17);
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
    use crate::primitives::convert::{i128_to_signed, signed_to_i128};
    use crate::test_util::word16;
    use proptest::prelude::*;

    #[test]
    fn extreme_factors_stay_within_the_dac_range() {
        // Exact reference floor((a c + 2^16) / 2^17) in i64, for the
        // extreme envelopes and carriers; three edges to the output.
        let envelopes = [i16::MIN, -32767, -1, 0, 1, i16::MAX];
        let carriers = [-OUTPUT_PEAK, -OUTPUT_PEAK + 1, -1, 0, 1, OUTPUT_PEAK];
        for a in envelopes {
            for c in carriers {
                let exact = (i64::from(a) * i64::from(c) + (1 << 16)).div_euclid(1 << 17);
                assert!((-32767..=32767).contains(&exact), "{a} x {c}");
                let mut model = Model::new(OUTPUT_FRACTION_BITS);
                let y = (0..3).map(|_| model.step(a, c)).last().unwrap();
                assert_eq!(i64::from(y), exact, "{a} x {c}");
            }
        }
    }

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
            words in prop::collection::vec((word16(), carrier()), 400),
        ) {
            let mut uut = CarrierMultiplier::new();
            prepare(&mut uut);
            let mut model = Model::new(OUTPUT_FRACTION_BITS);
            for (n, &(a, c)) in words.iter().enumerate() {
                uut.a.next = i128_to_signed(a as i128);
                uut.b.next = i128_to_signed(c as i128);
                tick(&mut uut);
                prop_assert_eq!(signed_to_i128(uut.y.val()) as i16, model.step(a, c), "cycle {}", n);
            }
        }
    }
}
