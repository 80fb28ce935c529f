//! Fractional (Q1.15) multiplier with rounding: y = round(a * b / 2^15).
//!
//! ```text
//!  a[16] ──► [a] ──┐
//!                   ×──► [p: 32 bit] ──► (p + 2^14)[30:15] ──► [y: 16 bit]
//!  b[16] ──► [b] ──┘
//! ```
//!
//! Both factors are 16-bit two's complement read as fractions of 2^15
//! (32767 is just below 1.0). The product is rounded half up: add 2^14,
//! then drop 15 bits (floor). The result fits 16 bits for every pair except
//! a = b = -32768 (which would be +1.0): with |b| <= 32767, which holds for
//! every use in this design (b is always a sine, cosine or modulation factor,
//! peak 32767), |a b + 2^14| / 2^15 <= 32767.5 and y lies in [-32767, 32767].
//!
//! Latency: 3 clocks (factor registers, multiplier register, rounding
//! register). The factor registers serve this multiplier alone, so the
//! placer can put them beside the DSP: the factors come from registers that
//! feed several multipliers, and on an ECP5 the route from such a shared
//! register to a far DSP plus the DSP itself was the critical path at
//! 100 MHz.

use crate::primitives::RegisteredMultiplier;
use rust_hdl::prelude::*;

/// Clock cycles from the factors to `y`.
pub const LATENCY: usize = 3;

/// `y = round(a * b / 2^15)`, three registers deep.
#[derive(LogicBlock)]
pub struct Q15Multiplier {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// First factor, Q1.15.
    pub a: Signal<In, Signed<16>>,
    /// Second factor, Q1.15; keep it above -32768 (see the header).
    pub b: Signal<In, Signed<16>>,
    /// Rounded product, Q1.15, three clocks after the factors.
    pub y: Signal<Out, Signed<16>>,
    a_in: DFF<Signed<16>>,
    b_in: DFF<Signed<16>>,
    product: RegisteredMultiplier<16, 16, 32>,
    rounded: Signal<Local, Signed<32>>,
    y_out: DFF<Signed<16>>,
    half_lsb: Constant<Signed<32>>,
}

impl Q15Multiplier {
    /// A Q1.15 multiplier with round-half-up.
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
            half_lsb: Constant::new((1i64 << 14).into()),
        }
    }
}

impl Default for Q15Multiplier {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for Q15Multiplier {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, a_in, b_in, y_out);
        self.a_in.d.next = self.a.val();
        self.b_in.d.next = self.b.val();
        self.product.clock.next = self.clock.val();
        self.product.a.next = self.a_in.q.val();
        self.product.b.next = self.b_in.q.val();
        self.rounded.next = self.product.p.val() + self.half_lsb.val();
        self.y_out.d.next = self.rounded.val().get_bits::<16>(15);
        self.y.next = self.y_out.q.val();
    }
}

crate::impl_clocked!(Q15Multiplier);

/// Mutation hooks for the negative control in `crate::rtl` (tests only).
#[cfg(test)]
impl Q15Multiplier {
    #[doc(hidden)]
    pub fn mutate_rounding(&mut self) {
        self.half_lsb = Constant::new((1i64 << 13).into());
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{prepare, tick};
    use crate::model::q15_multiplier::{Q15Multiplier as Model, q15_product};
    use crate::primitives::convert::{i128_to_signed, signed_to_i128};
    use crate::test_util::{sample16, word16};
    use proptest::prelude::*;

    #[test]
    fn extreme_factors_never_overflow() {
        // Exact reference: floor((a b + 2^14) / 2^15) in i64. For every b
        // above -32768 the result must equal it and lie in [-32767, 32767].
        let extremes = [i16::MIN, -32767, -16384, -1, 0, 1, 16384, 32766, i16::MAX];
        for a in extremes {
            for b in extremes.iter().copied().filter(|&b| b != i16::MIN) {
                let exact = (a as i64 * b as i64 + (1 << 14)).div_euclid(1 << 15);
                assert!((-32767..=32767).contains(&exact));
                assert_eq!(q15_product(a, b) as i64, exact, "{a} x {b}");
            }
        }
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(8))]
        #[test]
        fn rtl_matches_model_on_extremes_and_random_words(
            words in prop::collection::vec((word16(), sample16()), 400),
        ) {
            let mut uut = Q15Multiplier::new();
            prepare(&mut uut);
            let mut model = Model::default();
            for (n, &(a, b)) in words.iter().enumerate() {
                uut.a.next = i128_to_signed(a as i128);
                uut.b.next = i128_to_signed(b as i128);
                tick(&mut uut);
                prop_assert_eq!(signed_to_i128(uut.y.val()) as i16, model.step(a, b), "cycle {}", n);
            }
        }
    }
}
