//! Reference alignment: the run-time delay that lines the demodulation
//! references up with the loop latency.
//!
//! ```text
//!  ref1 ──► [64-tap shift register] ── tap(delay) ──► aligned1
//!  ref2 ──► [64-tap shift register] ── tap(delay) ──► aligned2
//! ```
//!
//! The samples the demodulators see left the DACs some clocks earlier: the
//! DAC and ADC pipelines plus the half-sample delay of the DAC's zero-order
//! hold. The integer part is taken out here (`delay` = 0..63), the half
//! sample by the carrier NCO's `ref_offset`; `crate::alignment` computes
//! both from the converter latencies. The modulation envelope is delayed
//! with the carrier, so calibration references stay aligned too.
//!
//! Timing: during cycle n, `aligned = ref(n - 1 - delay)` (combinational tap
//! read; the demodulator registers it).

use crate::primitives::TappedDelayLine;
use rust_hdl::prelude::*;

/// Address bits of the delay: 64 taps.
pub const DELAY_BITS: usize = 6;

/// Two reference delay lines sharing one run-time delay.
#[derive(LogicBlock)]
pub struct ReferenceAlignment {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Reference copy of drive 1.
    pub ref1: Signal<In, Signed<16>>,
    /// Reference copy of drive 2.
    pub ref2: Signal<In, Signed<16>>,
    /// Delay in clocks beyond the first: aligned = ref delayed by delay + 1.
    pub delay: Signal<In, Bits<DELAY_BITS>>,
    /// `ref1` delayed by `delay + 1` clocks.
    pub aligned1: Signal<Out, Signed<16>>,
    /// `ref2` delayed by `delay + 1` clocks.
    pub aligned2: Signal<Out, Signed<16>>,
    line1: TappedDelayLine<16, DELAY_BITS>,
    line2: TappedDelayLine<16, DELAY_BITS>,
}

impl ReferenceAlignment {
    /// Two 64-tap reference delay lines.
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            ref1: Default::default(),
            ref2: Default::default(),
            delay: Default::default(),
            aligned1: Default::default(),
            aligned2: Default::default(),
            line1: TappedDelayLine::new(),
            line2: TappedDelayLine::new(),
        }
    }
}

impl Default for ReferenceAlignment {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for ReferenceAlignment {
    #[hdl_gen]
    fn update(&mut self) {
        self.line1.clock.next = self.clock.val();
        self.line2.clock.next = self.clock.val();
        self.line1.d.next = self.ref1.val();
        self.line2.d.next = self.ref2.val();
        self.line1.delay.next = self.delay.val();
        self.line2.delay.next = self.delay.val();
        self.aligned1.next = self.line1.q.val();
        self.aligned2.next = self.line2.q.val();
    }
}

crate::impl_clocked!(ReferenceAlignment);
