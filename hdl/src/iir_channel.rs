//! One channel of the output filter: its states and adders, driven by the
//! schedule of `crate::iir_lowpass::IirLowpass`, which owns the shared
//! multiplier.
//!
//! ```text
//!  start:      x0 <= x, p01 <= 2 x + x0, v <= (x + p01) 2^16, fb <= 2 y1 - y2
//!              (p01 holds 2 x0 + x1 of the next start, so v is one adder)
//!  preload:    acc_y <= fb 2^30 + 2^29,  acc_d <= (fb - u) 2^30 + 2^29
//!  accumulate: acc_y += p,  acc_d += p                     (p = k1 y1, k2 y2)
//!  finish:     y1 <= (acc_y + p) / 2^30,  y2 <= y1         (p = k0 v)
//!              difference = (acc_d + p) / 2^30 = y - u      (to the multiplier, x alpha)
//!  update_u:   u <= (u 2^30 + 2^29 + p) / 2^30              (p = alpha (y - u))
//!  publish:    z <= (u + 2^15) / 2^16
//! ```
//!
//! Every `/` is a floor (an arithmetic shift, a slice of the sum). Adding
//! 2^29 before the floor rounds half up, as before; folding the feedback
//! 2 y1 - y2 and the state u into the accumulator as multiples of 2^30 is
//! exact (floor(m 2^30 + s) / 2^30 = m + floor(s / 2^30) for integer m), so
//! the filter is the one `crate::iir_lowpass` documents, with one carry
//! chain per register stage.
//!
//! Widths (derived in `crate::iir_lowpass`): x 40, states y1 y2 u 58, the
//! multiplier operands v, y1, y2, difference 60, product p 92, accumulators
//! 94, z 40.

use crate::iir_lowpass::{ACCUMULATOR_BITS, OPERAND_BITS, PRODUCT_BITS, STATE_BITS};
use crate::primitives::convert::signed_bit_cast_exact;
use rust_hdl::prelude::*;

/// Width of the input and output samples.
pub const SAMPLE_BITS: usize = crate::cic_decimator::OUTPUT_BITS;
/// Width of the running partial sum 2 x0 + x1: |.| <= 3 2^39 < 2^41, 42 bits.
pub const PARTIAL_BITS: usize = SAMPLE_BITS + 2;

/// States and adders of one filter channel.
#[derive(LogicBlock)]
pub struct IirChannel {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Input sample (the CIC output).
    pub x: Signal<In, Signed<SAMPLE_BITS>>,
    /// The shared multiplier's output.
    pub product: Signal<In, Signed<PRODUCT_BITS>>,
    /// Take `x`: shift the history, form v and the feedback 2 y1 - y2.
    pub start: Signal<In, Bit>,
    /// Load the accumulators with the feedback and the rounding constant.
    pub preload: Signal<In, Bit>,
    /// Add `product` to both accumulators.
    pub accumulate: Signal<In, Bit>,
    /// Add the last biquad product and update y1, y2.
    pub finish: Signal<In, Bit>,
    /// Update u from `product` = alpha (y - u).
    pub update_u: Signal<In, Bit>,
    /// Round u into `z`.
    pub publish: Signal<In, Bit>,
    /// State y1 as a multiplier operand.
    pub y1: Signal<Out, Signed<OPERAND_BITS>>,
    /// State y2 as a multiplier operand.
    pub y2: Signal<Out, Signed<OPERAND_BITS>>,
    /// Numerator input x0 + 2 x1 + x2, times 2^16, as a multiplier operand.
    pub v: Signal<Out, Signed<OPERAND_BITS>>,
    /// y - u with this cycle's product (valid while `finish` is high).
    pub difference: Signal<Out, Signed<OPERAND_BITS>>,
    /// Filtered output, 8 fractional bits.
    pub z: Signal<Out, Signed<SAMPLE_BITS>>,
    x0: DFF<Signed<SAMPLE_BITS>>,
    partial: DFF<Signed<PARTIAL_BITS>>,
    v_reg: DFF<Signed<OPERAND_BITS>>,
    feedback: DFF<Signed<OPERAND_BITS>>,
    acc_y: DFF<Signed<ACCUMULATOR_BITS>>,
    acc_d: DFF<Signed<ACCUMULATOR_BITS>>,
    y1_reg: DFF<Signed<STATE_BITS>>,
    y2_reg: DFF<Signed<STATE_BITS>>,
    u: DFF<Signed<STATE_BITS>>,
    z_out: DFF<Signed<SAMPLE_BITS>>,
    x_wide: Signal<Local, Signed<OPERAND_BITS>>,
    x_partial: Signal<Local, Signed<PARTIAL_BITS>>,
    x0_partial: Signal<Local, Signed<PARTIAL_BITS>>,
    partial_wide: Signal<Local, Signed<OPERAND_BITS>>,
    x_doubled: Signal<Local, Bits<PARTIAL_BITS>>,
    y1_doubled: Signal<Local, Bits<OPERAND_BITS>>,
    v_sum: Signal<Local, Signed<OPERAND_BITS>>,
    v_shifted: Signal<Local, Bits<OPERAND_BITS>>,
    y1_wide: Signal<Local, Signed<OPERAND_BITS>>,
    y2_wide: Signal<Local, Signed<OPERAND_BITS>>,
    u_wide: Signal<Local, Signed<OPERAND_BITS>>,
    feedback_minus_u: Signal<Local, Signed<OPERAND_BITS>>,
    feedback_long: Signal<Local, Signed<ACCUMULATOR_BITS>>,
    difference_long: Signal<Local, Signed<ACCUMULATOR_BITS>>,
    u_long: Signal<Local, Signed<ACCUMULATOR_BITS>>,
    product_long: Signal<Local, Signed<ACCUMULATOR_BITS>>,
    preload_y: Signal<Local, Bits<ACCUMULATOR_BITS>>,
    preload_d: Signal<Local, Bits<ACCUMULATOR_BITS>>,
    u_scaled: Signal<Local, Bits<ACCUMULATOR_BITS>>,
    sum_y: Signal<Local, Signed<ACCUMULATOR_BITS>>,
    sum_d: Signal<Local, Signed<ACCUMULATOR_BITS>>,
    sum_u: Signal<Local, Signed<ACCUMULATOR_BITS>>,
    y_new: Signal<Local, Signed<STATE_BITS>>,
    u_new: Signal<Local, Signed<STATE_BITS>>,
    u_rounded: Signal<Local, Signed<STATE_BITS>>,
    half_coefficient_lsb: Constant<Bits<ACCUMULATOR_BITS>>,
    half_output_lsb: Constant<Signed<STATE_BITS>>,
}

impl IirChannel {
    /// A channel with zero state.
    pub fn new() -> Self {
        use crate::iir_lowpass::{COEFFICIENT_FRACTION_BITS, GUARD_BITS};
        Self {
            clock: Default::default(),
            x: Default::default(),
            product: Default::default(),
            start: Default::default(),
            preload: Default::default(),
            accumulate: Default::default(),
            finish: Default::default(),
            update_u: Default::default(),
            publish: Default::default(),
            y1: Default::default(),
            y2: Default::default(),
            v: Default::default(),
            difference: Default::default(),
            z: Default::default(),
            x0: Default::default(),
            partial: Default::default(),
            v_reg: Default::default(),
            feedback: Default::default(),
            acc_y: Default::default(),
            acc_d: Default::default(),
            y1_reg: Default::default(),
            y2_reg: Default::default(),
            u: Default::default(),
            z_out: Default::default(),
            x_wide: Default::default(),
            x_partial: Default::default(),
            x0_partial: Default::default(),
            partial_wide: Default::default(),
            x_doubled: Default::default(),
            y1_doubled: Default::default(),
            v_sum: Default::default(),
            v_shifted: Default::default(),
            y1_wide: Default::default(),
            y2_wide: Default::default(),
            u_wide: Default::default(),
            feedback_minus_u: Default::default(),
            feedback_long: Default::default(),
            difference_long: Default::default(),
            u_long: Default::default(),
            product_long: Default::default(),
            preload_y: Default::default(),
            preload_d: Default::default(),
            u_scaled: Default::default(),
            sum_y: Default::default(),
            sum_d: Default::default(),
            sum_u: Default::default(),
            y_new: Default::default(),
            u_new: Default::default(),
            u_rounded: Default::default(),
            half_coefficient_lsb: Constant::new((1u64 << (COEFFICIENT_FRACTION_BITS - 1)).into()),
            half_output_lsb: Constant::new((1i64 << (GUARD_BITS - 1)).into()),
        }
    }
}

impl Default for IirChannel {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for IirChannel {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(
            self, clock, x0, partial, v_reg, feedback, acc_y, acc_d, y1_reg, y2_reg, u, z_out
        );
        // Operands, sign-extended (trap: cast into a local first).
        self.x_wide.next = signed_bit_cast_exact::<OPERAND_BITS, SAMPLE_BITS>(self.x.val());
        self.x_partial.next = signed_bit_cast_exact::<PARTIAL_BITS, SAMPLE_BITS>(self.x.val());
        self.x0_partial.next = signed_bit_cast_exact::<PARTIAL_BITS, SAMPLE_BITS>(self.x0.q.val());
        self.partial_wide.next =
            signed_bit_cast_exact::<OPERAND_BITS, PARTIAL_BITS>(self.partial.q.val());
        self.y1_wide.next = signed_bit_cast_exact::<OPERAND_BITS, STATE_BITS>(self.y1_reg.q.val());
        self.y2_wide.next = signed_bit_cast_exact::<OPERAND_BITS, STATE_BITS>(self.y2_reg.q.val());
        self.u_wide.next = signed_bit_cast_exact::<OPERAND_BITS, STATE_BITS>(self.u.q.val());
        // Numerator sum x + (2 x0 + x1), one adder (the new x0 is x).
        self.v_sum.next = self.x_wide.val() + self.partial_wide.val();
        // Doublings as shifts, so each sum below is a single adder.
        self.x_doubled.next = unsigned_cast(self.x_partial.val()) << 1;
        self.y1_doubled.next = unsigned_cast(self.y1_wide.val()) << 1;
        // 16 = GUARD_BITS: the states carry 16 bits below the input LSB.
        self.v_shifted.next = unsigned_cast(self.v_sum.val()) << 16;
        self.feedback_minus_u.next = self.feedback.q.val() - self.u_wide.val();
        // Accumulator words: m 2^30 + 2^29 (30 = COEFFICIENT_FRACTION_BITS).
        self.feedback_long.next =
            signed_bit_cast_exact::<ACCUMULATOR_BITS, OPERAND_BITS>(self.feedback.q.val());
        self.difference_long.next =
            signed_bit_cast_exact::<ACCUMULATOR_BITS, OPERAND_BITS>(self.feedback_minus_u.val());
        self.u_long.next = signed_bit_cast_exact::<ACCUMULATOR_BITS, STATE_BITS>(self.u.q.val());
        self.product_long.next =
            signed_bit_cast_exact::<ACCUMULATOR_BITS, PRODUCT_BITS>(self.product.val());
        self.preload_y.next =
            (unsigned_cast(self.feedback_long.val()) << 30) | self.half_coefficient_lsb.val();
        self.preload_d.next =
            (unsigned_cast(self.difference_long.val()) << 30) | self.half_coefficient_lsb.val();
        self.u_scaled.next =
            (unsigned_cast(self.u_long.val()) << 30) | self.half_coefficient_lsb.val();
        self.sum_y.next = self.acc_y.q.val() + self.product_long.val();
        self.sum_d.next = self.acc_d.q.val() + self.product_long.val();
        self.sum_u.next = signed_cast(self.u_scaled.val()) + self.product_long.val();
        self.y_new.next = self.sum_y.val().get_bits::<STATE_BITS>(30);
        self.u_new.next = self.sum_u.val().get_bits::<STATE_BITS>(30);
        self.difference.next = self.sum_d.val().get_bits::<OPERAND_BITS>(30);
        self.u_rounded.next = self.u.q.val() + self.half_output_lsb.val();
        // Register stages, one per control.
        if self.start.val() {
            self.x0.d.next = self.x.val();
            // The next start's 2 x0 + x1: x becomes x0 and x0 becomes x1.
            self.partial.d.next = signed_cast(self.x_doubled.val()) + self.x0_partial.val();
            self.v_reg.d.next = signed_cast(self.v_shifted.val());
            self.feedback.d.next = signed_cast(self.y1_doubled.val()) - self.y2_wide.val();
        }
        if self.preload.val() {
            self.acc_y.d.next = signed_cast(self.preload_y.val());
            self.acc_d.d.next = signed_cast(self.preload_d.val());
        }
        if self.accumulate.val() {
            self.acc_y.d.next = self.sum_y.val();
            self.acc_d.d.next = self.sum_d.val();
        }
        if self.finish.val() {
            self.y1_reg.d.next = self.y_new.val();
            self.y2_reg.d.next = self.y1_reg.q.val();
        }
        if self.update_u.val() {
            self.u.d.next = self.u_new.val();
        }
        if self.publish.val() {
            // 16 = GUARD_BITS, dropped with rounding half up.
            self.z_out.d.next = self.u_rounded.val().get_bits::<SAMPLE_BITS>(16);
        }
        self.y1.next = self.y1_wide.val();
        self.y2.next = self.y2_wide.val();
        self.v.next = self.v_reg.q.val();
        self.z.next = self.z_out.q.val();
    }
}

crate::impl_clocked!(IirChannel);
