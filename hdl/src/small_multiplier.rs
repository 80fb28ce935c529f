//! A registered 9 x 9 signed multiplier from shifts and adds, so that it
//! takes no multiplier block: the fine core's error feedback
//! (`crate::carrier_multiplier`), whose part has its multipliers placed
//! near the tables (`crate::notch_coefficient` says why that matters).
//!
//! ```text
//!  a[9] ─► sign-extend ─┬─ (b[0] ? a : 0) ─┐
//!                       ├─ (b[1] ? a << 1 : 0)├─ + ─┐
//!                       │   ...                │     + ─ ... ─► - (b[8] ? a << 8 : 0) ─► [p: 18]
//!                       └─ (b[7] ? a << 7 : 0)─┘
//! ```
//!
//! p = a b exactly: b's two's complement bits weigh 2^i, bit 8 -2^8, so
//! the eight lower partial products are added in a tree of depth three
//! and the top one subtracted. Widths: factors 9-bit signed, every partial
//! product within |a| 2^8 <= 2^16, the product |a b| <= 2^16: 18-bit
//! signed, the shifts exact. Latency: 1 clock (the product register).
//! Resources: about 150 LUT4 and 18 flip-flops on the ECP5; no `*`, so
//! Yosys maps no DSP.

use crate::primitives::convert::signed_bit_cast_exact;
use rust_hdl::prelude::*;

/// Width of each factor.
pub const FACTOR_BITS: usize = 9;
/// Width of the product.
pub const PRODUCT_BITS: usize = 2 * FACTOR_BITS;

/// `p <= a * b`, 9 x 9 bits signed, from shifts and adds.
#[derive(LogicBlock)]
pub struct SmallMultiplier {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// First factor.
    pub a: Signal<In, Signed<FACTOR_BITS>>,
    /// Second factor.
    pub b: Signal<In, Signed<FACTOR_BITS>>,
    /// The product of the factors of the previous clock.
    pub p: Signal<Out, Signed<PRODUCT_BITS>>,
    wide: Signal<Local, Signed<PRODUCT_BITS>>,
    bits: Signal<Local, Bits<FACTOR_BITS>>,
    pp0: Signal<Local, Signed<PRODUCT_BITS>>,
    pp1: Signal<Local, Signed<PRODUCT_BITS>>,
    pp2: Signal<Local, Signed<PRODUCT_BITS>>,
    pp3: Signal<Local, Signed<PRODUCT_BITS>>,
    pp4: Signal<Local, Signed<PRODUCT_BITS>>,
    pp5: Signal<Local, Signed<PRODUCT_BITS>>,
    pp6: Signal<Local, Signed<PRODUCT_BITS>>,
    pp7: Signal<Local, Signed<PRODUCT_BITS>>,
    pp8: Signal<Local, Signed<PRODUCT_BITS>>,
    low: Signal<Local, Signed<PRODUCT_BITS>>,
    high: Signal<Local, Signed<PRODUCT_BITS>>,
    product: DFF<Signed<PRODUCT_BITS>>,
    zero: Constant<Signed<PRODUCT_BITS>>,
}

impl SmallMultiplier {
    /// The multiplier, its product 0 at power-up.
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            a: Default::default(),
            b: Default::default(),
            p: Default::default(),
            wide: Default::default(),
            bits: Default::default(),
            pp0: Default::default(),
            pp1: Default::default(),
            pp2: Default::default(),
            pp3: Default::default(),
            pp4: Default::default(),
            pp5: Default::default(),
            pp6: Default::default(),
            pp7: Default::default(),
            pp8: Default::default(),
            low: Default::default(),
            high: Default::default(),
            product: Default::default(),
            zero: Constant::new(0i64.into()),
        }
    }
}

impl Default for SmallMultiplier {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for SmallMultiplier {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, product);
        self.wide.next = signed_bit_cast_exact::<PRODUCT_BITS, FACTOR_BITS>(self.a.val());
        self.bits.next = unsigned_cast(self.b.val());
        // Partial product i: a 2^i where b's bit i is set (the shifts are
        // exact: |a| 2^8 < 2^17).
        self.pp0.next = self.zero.val();
        if self.bits.val().get_bit(0) {
            self.pp0.next = self.wide.val();
        }
        self.pp1.next = self.zero.val();
        if self.bits.val().get_bit(1) {
            self.pp1.next = signed_cast(unsigned_cast(self.wide.val()) << 1);
        }
        self.pp2.next = self.zero.val();
        if self.bits.val().get_bit(2) {
            self.pp2.next = signed_cast(unsigned_cast(self.wide.val()) << 2);
        }
        self.pp3.next = self.zero.val();
        if self.bits.val().get_bit(3) {
            self.pp3.next = signed_cast(unsigned_cast(self.wide.val()) << 3);
        }
        self.pp4.next = self.zero.val();
        if self.bits.val().get_bit(4) {
            self.pp4.next = signed_cast(unsigned_cast(self.wide.val()) << 4);
        }
        self.pp5.next = self.zero.val();
        if self.bits.val().get_bit(5) {
            self.pp5.next = signed_cast(unsigned_cast(self.wide.val()) << 5);
        }
        self.pp6.next = self.zero.val();
        if self.bits.val().get_bit(6) {
            self.pp6.next = signed_cast(unsigned_cast(self.wide.val()) << 6);
        }
        self.pp7.next = self.zero.val();
        if self.bits.val().get_bit(7) {
            self.pp7.next = signed_cast(unsigned_cast(self.wide.val()) << 7);
        }
        // Bit 8 is the sign: its partial product is subtracted.
        self.pp8.next = self.zero.val();
        if self.bits.val().get_bit(8) {
            self.pp8.next = signed_cast(unsigned_cast(self.wide.val()) << 8);
        }
        self.low.next = (self.pp0.val() + self.pp1.val()) + (self.pp2.val() + self.pp3.val());
        self.high.next = (self.pp4.val() + self.pp5.val()) + (self.pp6.val() + self.pp7.val());
        self.product.d.next = (self.low.val() + self.high.val()) - self.pp8.val();
        self.p.next = self.product.q.val();
    }
}

crate::impl_clocked!(SmallMultiplier);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{prepare, tick};
    use crate::primitives::convert::{i128_to_signed, signed_to_i128};

    #[test]
    fn every_factor_against_the_extremes_and_random_pairs() {
        // Every a against the extreme and small b (and the same with the
        // factors swapped), then random pairs: the product one clock on.
        let mut uut = SmallMultiplier::new();
        prepare(&mut uut);
        let mut pairs = Vec::new();
        for a in -256i64..256 {
            for b in [-256i64, -255, -1, 0, 1, 2, 127, 255] {
                pairs.push((a, b));
                pairs.push((b, a));
            }
        }
        let mut rng = crate::test_util::Rng::new(9);
        pairs.extend((0..4000).map(|_| (rng.range(-256, 255), rng.range(-256, 255))));
        for (a, b) in pairs {
            uut.a.next = i128_to_signed(a.into());
            uut.b.next = i128_to_signed(b.into());
            tick(&mut uut);
            assert_eq!(signed_to_i128(uut.p.val()) as i64, a * b, "{a} x {b}");
        }
    }
}
