//! The integrator half of one CIC channel: four cascaded accumulators at
//! the clock rate.
//!
//! ```text
//!  x[32] ─► ∫ ─► ∫ ─► ∫ ─► ∫ ──► integral[80]
//!           80-bit registers, wrap-around
//! ```
//!
//! Hogenauer's integrators for `crate::cic_decimator` (N = 4 stages,
//! `REGISTER_BITS` = 80 bits, the width derived there). Each stage adds its
//! predecessor's value before the edge, so during cycle n
//! `integral` = the fourth running sum of x up to cycle n - 4 (gain 1 per
//! stage, wrap-around modulo 2^80, which the combs undo exactly). These are
//! the only per-channel registers of the CIC: they must run every clock;
//! everything after the decimation strobe is shared
//! (`crate::cic_decimator`). Latency: x during cycle n first reaches
//! `integral` during cycle n + 4. Power-up: all stages 0.
//!
//! Resources: four 80-bit adders and 320 flip-flops.

use crate::cic_decimator::{INPUT_BITS, REGISTER_BITS};
use crate::primitives::convert::signed_bit_cast_exact;
use rust_hdl::prelude::*;

/// Four cascaded 80-bit integrators of one channel.
#[derive(LogicBlock)]
pub struct CicIntegrators {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Input sample, one per clock.
    pub x: Signal<In, Signed<INPUT_BITS>>,
    /// The fourth integrator (wraps modulo 2^80).
    pub integral: Signal<Out, Signed<REGISTER_BITS>>,
    x_wide: Signal<Local, Signed<REGISTER_BITS>>,
    integrator1: DFF<Signed<REGISTER_BITS>>,
    integrator2: DFF<Signed<REGISTER_BITS>>,
    integrator3: DFF<Signed<REGISTER_BITS>>,
    integrator4: DFF<Signed<REGISTER_BITS>>,
}

impl CicIntegrators {
    /// Four integrators at zero.
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            x: Default::default(),
            integral: Default::default(),
            x_wide: Default::default(),
            integrator1: Default::default(),
            integrator2: Default::default(),
            integrator3: Default::default(),
            integrator4: Default::default(),
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
        dff_setup!(
            self,
            clock,
            integrator1,
            integrator2,
            integrator3,
            integrator4
        );
        self.x_wide.next = signed_bit_cast_exact::<REGISTER_BITS, INPUT_BITS>(self.x.val());
        self.integrator1.d.next = self.integrator1.q.val() + self.x_wide.val();
        self.integrator2.d.next = self.integrator2.q.val() + self.integrator1.q.val();
        self.integrator3.d.next = self.integrator3.q.val() + self.integrator2.q.val();
        self.integrator4.d.next = self.integrator4.q.val() + self.integrator3.q.val();
        self.integral.next = self.integrator4.q.val();
    }
}
