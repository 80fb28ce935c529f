//! One CIC integrator split in two 40-bit halves, the high half one clock
//! behind the low one, so no clock carries an 80-bit carry chain.
//!
//! ```text
//!  in_low[40]  ─► low  += in_low   ─► [low]  ──► low
//!                          └ carry ─► [carry] ┐
//!  in_high[40] ─► high += in_high + carry ◄───┘ ─► [high] ─► high  (one clock behind)
//! ```
//!
//! The 80-bit integrator S(n) = S(n-1) + X(n-1) of `crate::cic_integrators`
//! (modulo 2^80), with S = H 2^40 + L: the low half is L(n) = L(n-1) +
//! X_low(n-1) modulo 2^40, whose carry out is registered; the high register
//! holds H one clock late, H'(n) = H(n-1) = H'(n-1) + X_high(n-2) + carry,
//! one 41-bit addition (2 H' + 1) + (2 X_high + carry), halved, so the
//! carry enters as a carry-in. The caller gives `in_high` one clock later
//! than `in_low` (the previous stage's `high`, or the input's sign delayed a
//! clock). Then `low` during cycle n is L(n) and `high` is H(n-1). An
//! 80-bit add took 34 ns on an iCE40 UP5K (29 MHz); a 41-bit one half that.
//! Power-up: 0. Resources: 81 flip-flops, two 41-bit adders.

use crate::cic_widths::REGISTER_HALF_BITS as HALF_BITS;
use rust_hdl::prelude::*;

/// A half with its carry.
const CARRY_BITS: usize = HALF_BITS + 1;

/// One integrator in two halves, the high half a clock behind.
#[derive(LogicBlock)]
pub struct CicIntegratorStage {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Low half of the input X(n), this clock.
    pub in_low: Signal<In, Bits<HALF_BITS>>,
    /// High half of the input, one clock late: X_high(n - 1).
    pub in_high: Signal<In, Bits<HALF_BITS>>,
    /// L(n), the low half of the integral.
    pub low: Signal<Out, Bits<HALF_BITS>>,
    /// H(n - 1), the high half of the integral one clock late.
    pub high: Signal<Out, Bits<HALF_BITS>>,
    low_sum: DFF<Bits<HALF_BITS>>,
    carry: DFF<Bits<1>>,
    high_sum: DFF<Bits<HALF_BITS>>,
    low_total: Signal<Local, Bits<CARRY_BITS>>,
    high_total: Signal<Local, Bits<CARRY_BITS>>,
    one: Constant<Bits<CARRY_BITS>>,
}

impl CicIntegratorStage {
    /// An integrator at zero.
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            in_low: Default::default(),
            in_high: Default::default(),
            low: Default::default(),
            high: Default::default(),
            low_sum: Default::default(),
            carry: Default::default(),
            high_sum: Default::default(),
            low_total: Default::default(),
            high_total: Default::default(),
            one: Constant::new(1.into()),
        }
    }
}

impl Default for CicIntegratorStage {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for CicIntegratorStage {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, low_sum, carry, high_sum);
        self.low_total.next = bit_cast::<CARRY_BITS, HALF_BITS>(self.low_sum.q.val())
            + bit_cast::<CARRY_BITS, HALF_BITS>(self.in_low.val());
        self.low_sum.d.next = self.low_total.val().get_bits::<HALF_BITS>(0);
        self.carry.d.next = self.low_total.val().get_bits::<1>(40);
        self.high_total.next = ((bit_cast::<CARRY_BITS, HALF_BITS>(self.high_sum.q.val()) << 1)
            | self.one.val())
            + ((bit_cast::<CARRY_BITS, HALF_BITS>(self.in_high.val()) << 1)
                | bit_cast::<CARRY_BITS, 1>(self.carry.q.val()));
        self.high_sum.d.next = self.high_total.val().get_bits::<HALF_BITS>(1);
        self.low.next = self.low_sum.q.val();
        self.high.next = self.high_sum.q.val();
    }
}

crate::impl_clocked!(CicIntegratorStage);
