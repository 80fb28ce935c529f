//! The IIR's second multiplier operand: a 15-bit digit of a scaled
//! coefficient, or a constant, registered.
//!
//! ```text
//!  k0, k1, k2, alpha [32] ─► scaled [34]: alpha | k1 + 2^31 | k2 - 2^30 | 2 k0 | 4 k0   (factor bits 4:2)
//!                            ─► digit: bits 14:0 | 29:15 (unsigned) | 33:30 (signed)    (factor bits 1:0)
//!  factor 0..3 ─► 0 | 1 | -1 | 2^14                                                     (the constants)
//!                            ─► [b] [16]
//! ```
//!
//! `crate::iir_program` names the operand of each product by `Factor`
//! (`Factor::encode`: bits 4:2 the source, 1:0 the digit, source 0 the
//! constants). The scaled coefficients are the biquad's and the RC's
//! multipliers as the program's sums use them (`iir_program`'s header:
//! k1 + 2^31 and k2 - 2^30 carry the leading 2 y1 - y2 into the sum, 2 k0
//! and 4 k0 the numerator's taps); every one fits 34 bits, cut into two
//! unsigned 15-bit digits and a signed 4-bit top digit. The digit is
//! registered (`b`), one pipeline stage of the program's word. Power-up: 0.

use crate::iir_program::{OPERAND_BITS, SCALED_COEFFICIENT_BITS};
use crate::iir_widths::COEFFICIENT_BITS;
use crate::primitives::convert::signed_bit_cast_exact;
use rust_hdl::prelude::*;

/// A digit of a scaled coefficient or a constant, as `factor` names it.
#[derive(LogicBlock)]
pub struct IirCoefficientDigit {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// The word's factor field (`Factor::encode`).
    pub factor: Signal<In, Bits<5>>,
    /// Biquad numerator gain g (Q2.30).
    pub k0: Signal<In, Signed<COEFFICIENT_BITS>>,
    /// Biquad feedback k1 (Q2.30).
    pub k1: Signal<In, Signed<COEFFICIENT_BITS>>,
    /// Biquad feedback k2 (Q2.30).
    pub k2: Signal<In, Signed<COEFFICIENT_BITS>>,
    /// RC coefficient alpha (Q2.30).
    pub alpha: Signal<In, Signed<COEFFICIENT_BITS>>,
    /// The digit of the factor of the clock before: the multiplier's b.
    pub digit: Signal<Out, Signed<OPERAND_BITS>>,
    b: DFF<Signed<OPERAND_BITS>>,
    k0_wide: Signal<Local, Signed<SCALED_COEFFICIENT_BITS>>,
    k1_wide: Signal<Local, Signed<SCALED_COEFFICIENT_BITS>>,
    k2_wide: Signal<Local, Signed<SCALED_COEFFICIENT_BITS>>,
    alpha_wide: Signal<Local, Signed<SCALED_COEFFICIENT_BITS>>,
    scaled: Signal<Local, Signed<SCALED_COEFFICIENT_BITS>>,
    scaled_low: Signal<Local, Signed<30>>,
    scaled_bits: Signal<Local, Bits<30>>,
    top_bits: Signal<Local, Signed<4>>,
    top_digit: Signal<Local, Signed<OPERAND_BITS>>,
    pow30: Constant<Signed<SCALED_COEFFICIENT_BITS>>,
    pow31: Constant<Signed<SCALED_COEFFICIENT_BITS>>,
    one: Constant<Signed<OPERAND_BITS>>,
    minus_one: Constant<Signed<OPERAND_BITS>>,
    pow14: Constant<Signed<OPERAND_BITS>>,
}

impl IirCoefficientDigit {
    /// The operand register at 0.
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            factor: Default::default(),
            k0: Default::default(),
            k1: Default::default(),
            k2: Default::default(),
            alpha: Default::default(),
            digit: Default::default(),
            b: Default::default(),
            k0_wide: Default::default(),
            k1_wide: Default::default(),
            k2_wide: Default::default(),
            alpha_wide: Default::default(),
            scaled: Default::default(),
            scaled_low: Default::default(),
            scaled_bits: Default::default(),
            top_bits: Default::default(),
            top_digit: Default::default(),
            pow30: Constant::new((1i64 << 30).into()),
            pow31: Constant::new((1i64 << 31).into()),
            one: Constant::new((1i64).into()),
            minus_one: Constant::new((-1i64).into()),
            pow14: Constant::new((1i64 << 14).into()),
        }
    }
}

impl Default for IirCoefficientDigit {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for IirCoefficientDigit {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, b);
        self.k0_wide.next =
            signed_bit_cast_exact::<SCALED_COEFFICIENT_BITS, COEFFICIENT_BITS>(self.k0.val());
        self.k1_wide.next =
            signed_bit_cast_exact::<SCALED_COEFFICIENT_BITS, COEFFICIENT_BITS>(self.k1.val());
        self.k2_wide.next =
            signed_bit_cast_exact::<SCALED_COEFFICIENT_BITS, COEFFICIENT_BITS>(self.k2.val());
        self.alpha_wide.next =
            signed_bit_cast_exact::<SCALED_COEFFICIENT_BITS, COEFFICIENT_BITS>(self.alpha.val());
        self.scaled.next = self.alpha_wide.val();
        if self.factor.val().get_bits::<3>(2) == 1 {
            self.scaled.next = self.k1_wide.val() + self.pow31.val();
        }
        if self.factor.val().get_bits::<3>(2) == 2 {
            self.scaled.next = self.k2_wide.val() - self.pow30.val();
        }
        if self.factor.val().get_bits::<3>(2) == 3 {
            self.scaled.next = signed_cast(unsigned_cast(self.k0_wide.val()) << 1);
        }
        if self.factor.val().get_bits::<3>(2) == 4 {
            self.scaled.next = signed_cast(unsigned_cast(self.k0_wide.val()) << 2);
        }
        self.scaled_low.next = self.scaled.val().get_bits::<30>(0);
        self.scaled_bits.next = unsigned_cast(self.scaled_low.val());
        self.top_bits.next = self.scaled.val().get_bits::<4>(30);
        self.top_digit.next = signed_bit_cast_exact::<OPERAND_BITS, 4>(self.top_bits.val());
        self.b.d.next = self.top_digit.val();
        if self.factor.val().get_bits::<2>(0) == 0 {
            self.b.d.next = signed_cast(bit_cast::<OPERAND_BITS, 15>(
                self.scaled_bits.val().get_bits::<15>(0),
            ));
        }
        if self.factor.val().get_bits::<2>(0) == 1 {
            self.b.d.next = signed_cast(bit_cast::<OPERAND_BITS, 15>(
                self.scaled_bits.val().get_bits::<15>(15),
            ));
        }
        if self.factor.val().get_bits::<3>(2) == 0 {
            self.b.d.next = 0.into();
            if self.factor.val().get_bits::<2>(0) == 1 {
                self.b.d.next = self.one.val();
            }
            if self.factor.val().get_bits::<2>(0) == 2 {
                self.b.d.next = self.minus_one.val();
            }
            if self.factor.val().get_bits::<2>(0) == 3 {
                self.b.d.next = self.pow14.val();
            }
        }
        self.digit.next = self.b.q.val();
    }
}

crate::impl_clocked!(IirCoefficientDigit);
