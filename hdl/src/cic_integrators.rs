//! The integrator half of one CIC channel: four cascaded accumulators at
//! the clock rate.
//!
//! ```text
//!  x[32] ─► ∫ ─► ∫ ─► ∫ ─► ∫ ──► integral[80]
//!           80-bit registers, wrap-around, each in two 40-bit halves
//! ```
//!
//! Hogenauer's integrators for `crate::cic_decimator` (N = 4 stages,
//! `REGISTER_BITS` = 80 bits, the width derived there). Each stage adds its
//! predecessor's value before the edge, so during cycle n
//! `integral` = the fourth running sum of x up to cycle n - 4 (gain 1 per
//! stage, wrap-around modulo 2^80, which the combs undo exactly). These are
//! the only per-channel registers of the CIC: they must run every clock;
//! everything after the decimation strobe is shared
//! (`crate::cic_decimator`).
//!
//! Each stage is a `CicIntegratorStage`: two 40-bit halves, the high half
//! one clock behind the low one (an 80-bit carry chain every clock held an
//! iCE40 UP5K to 29 MHz). The high halves form a cascade of their own, one
//! clock late throughout: the input's high half (its sign) enters one clock
//! after its low half, and `integral` joins the fourth stage's high half
//! with its low half delayed a clock. So `integral` during cycle n is the
//! fourth running sum of x up to cycle n - 5, word for word the unsplit
//! integrators' value of one clock earlier. Latency: x during cycle n first
//! reaches `integral` during cycle n + 5. Power-up: all stages 0.
//!
//! Resources: eight 41-bit adders and 4 x 81 + 41 flip-flops.

use crate::cic_integrator_stage::CicIntegratorStage;
use crate::cic_widths::{INPUT_BITS, REGISTER_BITS, REGISTER_HALF_BITS as HALF_BITS};
use crate::primitives::convert::signed_bit_cast_exact;
use rust_hdl::prelude::*;

/// Clocks from x to `integral`: four stages and the halves' skew.
pub const LATENCY: usize = 5;

/// Four cascaded 80-bit integrators of one channel.
#[derive(LogicBlock)]
pub struct CicIntegrators {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Input sample, one per clock.
    pub x: Signal<In, Signed<INPUT_BITS>>,
    /// The fourth integrator (wraps modulo 2^80), one clock behind the
    /// unsplit cascade.
    pub integral: Signal<Out, Signed<REGISTER_BITS>>,
    x_wide: Signal<Local, Signed<REGISTER_BITS>>,
    x_bits: Signal<Local, Bits<REGISTER_BITS>>,
    x_high: DFF<Bits<HALF_BITS>>,
    stage1: CicIntegratorStage,
    stage2: CicIntegratorStage,
    stage3: CicIntegratorStage,
    stage4: CicIntegratorStage,
    low4: DFF<Bits<HALF_BITS>>,
    half_shift: Constant<Bits<8>>,
}

impl CicIntegrators {
    /// Four integrators at zero.
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            x: Default::default(),
            integral: Default::default(),
            x_wide: Default::default(),
            x_bits: Default::default(),
            x_high: Default::default(),
            stage1: CicIntegratorStage::new(),
            stage2: CicIntegratorStage::new(),
            stage3: CicIntegratorStage::new(),
            stage4: CicIntegratorStage::new(),
            low4: Default::default(),
            half_shift: Constant::new((HALF_BITS as u64).into()),
        }
    }
}

impl Default for CicIntegrators {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for CicIntegrators {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, x_high, low4);
        self.stage1.clock.next = self.clock.val();
        self.stage2.clock.next = self.clock.val();
        self.stage3.clock.next = self.clock.val();
        self.stage4.clock.next = self.clock.val();
        // The input sign-extended; its high half enters a clock late.
        self.x_wide.next = signed_bit_cast_exact::<REGISTER_BITS, INPUT_BITS>(self.x.val());
        self.x_bits.next = unsigned_cast(self.x_wide.val());
        self.x_high.d.next = self.x_bits.val().get_bits::<HALF_BITS>(40);
        self.stage1.in_low.next = self.x_bits.val().get_bits::<HALF_BITS>(0);
        self.stage1.in_high.next = self.x_high.q.val();
        self.stage2.in_low.next = self.stage1.low.val();
        self.stage2.in_high.next = self.stage1.high.val();
        self.stage3.in_low.next = self.stage2.low.val();
        self.stage3.in_high.next = self.stage2.high.val();
        self.stage4.in_low.next = self.stage3.low.val();
        self.stage4.in_high.next = self.stage3.high.val();
        // The fourth stage's halves lined up: the low half a clock late.
        self.low4.d.next = self.stage4.low.val();
        self.integral.next = signed_cast(
            (bit_cast::<REGISTER_BITS, HALF_BITS>(self.stage4.high.val()) << self.half_shift.val())
                | bit_cast::<REGISTER_BITS, HALF_BITS>(self.low4.q.val()),
        );
    }
}

crate::impl_clocked!(CicIntegrators);
