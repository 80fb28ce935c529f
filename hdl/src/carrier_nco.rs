//! Carrier NCO: one 32-bit phase accumulator, two quadrature outputs.
//!
//! ```text
//!            ┌──────────────┐  phase
//!  step ────►│ acc += step  ├──────┬──────────────► SinCos ──► drive_cos, drive_sin
//!            └──────────────┘      │
//!  ref_offset ───────────────────► + ────────────► SinCos ──► ref_cos,   ref_sin
//! ```
//!
//! The drive pair excites the gyroscope (I to mode 1, Q to mode 2); the
//! reference pair is the same carrier advanced by `ref_offset` (a fraction
//! of a turn, 2^32 = 360 degrees) and feeds the reference copies of the
//! drives used by the demodulators. Setting `ref_offset` to half a carrier
//! step cancels the half-sample delay of the DACs' zero-order hold (see
//! `crate::alignment`).
//!
//! Frequency: f = step * f_clk / 2^32, resolution f_clk / 2^32 (0.0116 Hz at
//! 50 MHz). Phase during cycle n: the sum of the steps presented during
//! cycles 0..n-1 (power-up phase 0), wrapping at 2^32. Outputs during cycle n
//! belong to the phase of cycle n - 4 (`sincos::LATENCY`); 16-bit, peak
//! 32767, spurs below -100 dBc.

use crate::sincos::SinCos;
use rust_hdl::prelude::*;

/// Clock cycles from a phase to the carrier outputs.
pub const LATENCY: usize = crate::sincos::LATENCY;

/// 32-bit carrier NCO with a drive and a phase-shifted reference output.
#[derive(LogicBlock)]
pub struct CarrierNco {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Phase increment per clock: f_carrier = step * f_clk / 2^32.
    pub step: Signal<In, Bits<32>>,
    /// Phase advance of the reference pair over the drive pair (2^32 = 1 turn).
    pub ref_offset: Signal<In, Bits<32>>,
    /// 32767 cos(phase): in-phase drive carrier (mode 1).
    pub drive_cos: Signal<Out, Signed<16>>,
    /// 32767 sin(phase): quadrature drive carrier (mode 2).
    pub drive_sin: Signal<Out, Signed<16>>,
    /// 32767 cos(phase + ref_offset).
    pub ref_cos: Signal<Out, Signed<16>>,
    /// 32767 sin(phase + ref_offset).
    pub ref_sin: Signal<Out, Signed<16>>,
    phase: DFF<Bits<32>>,
    drive: SinCos,
    reference: SinCos,
}

impl CarrierNco {
    /// A carrier NCO at phase zero.
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            step: Default::default(),
            ref_offset: Default::default(),
            drive_cos: Default::default(),
            drive_sin: Default::default(),
            ref_cos: Default::default(),
            ref_sin: Default::default(),
            phase: Default::default(),
            drive: SinCos::new(),
            reference: SinCos::new(),
        }
    }
}

impl Default for CarrierNco {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for CarrierNco {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, phase);
        self.drive.clock.next = self.clock.val();
        self.reference.clock.next = self.clock.val();
        self.phase.d.next = self.phase.q.val() + self.step.val();
        self.drive.phase.next = self.phase.q.val();
        self.reference.phase.next = self.phase.q.val() + self.ref_offset.val();
        self.drive_cos.next = self.drive.cos.val();
        self.drive_sin.next = self.drive.sin.val();
        self.ref_cos.next = self.reference.cos.val();
        self.ref_sin.next = self.reference.sin.val();
    }
}

crate::impl_clocked!(CarrierNco);
