//! AM mixers: the two drive signals and their reference copies.
//!
//! ```text
//!  amp1 (F1) ─┐                   ┌─► x drive_cos ──► dac1  = F1 A1 cos(wt)
//!  am1  (A1) ─┴─ x ──► fa1 ───────┤
//!                                 └─► x ref_cos   ──► ref1  = F1 A1 cos(wt + offset)
//!  amp2 (F2) ─┐                   ┌─► x drive_sin ──► dac2  = F2 A2 sin(wt)
//!  am2  (A2) ─┴─ x ──► fa2 ───────┤
//!                                 └─► x ref_sin   ──► ref2  = F2 A2 sin(wt + offset)
//! ```
//!
//! Every product is a `Q15Multiplier`: Q1.15 factors, rounded half up to
//! 16 bits. F1 and F2 are run-time amplitudes (any 16-bit value, -32768
//! included); A1, A2 come from the modulation NCO and the carriers from the
//! carrier NCO, all with peak 32767, so no product can overflow (see
//! `q15_multiplier`) and the DAC words stay within [-32767, 32767]:
//! dac1 = round(round(F1 A1 / 2^15) cos / 2^15), a full-scale drive being
//! F1 = 32767 with A1 = 32767.
//!
//! The reference words are the drive words computed from the reference
//! carrier: in readout they equal the drives up to the phase offset, in
//! calibration they carry the same modulation. Latency: carriers to outputs
//! 2 clocks, amplitudes to outputs 4 clocks, the same for drives and
//! references.

use crate::q15_multiplier::Q15Multiplier;
use rust_hdl::prelude::*;

/// Clock cycles from the carrier inputs to the drive and reference outputs.
pub const CARRIER_LATENCY: usize = 2;

/// Two AM drive channels with reference copies.
#[derive(LogicBlock)]
pub struct AmMixer {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Drive amplitude F1 of mode 1, Q1.15.
    pub amp1: Signal<In, Signed<16>>,
    /// Drive amplitude F2 of mode 2, Q1.15.
    pub amp2: Signal<In, Signed<16>>,
    /// Amplitude factor A1 from the modulation NCO.
    pub am1: Signal<In, Signed<16>>,
    /// Amplitude factor A2 from the modulation NCO.
    pub am2: Signal<In, Signed<16>>,
    /// In-phase drive carrier.
    pub drive_cos: Signal<In, Signed<16>>,
    /// Quadrature drive carrier.
    pub drive_sin: Signal<In, Signed<16>>,
    /// In-phase reference carrier.
    pub ref_cos: Signal<In, Signed<16>>,
    /// Quadrature reference carrier.
    pub ref_sin: Signal<In, Signed<16>>,
    /// DAC word of drive 1: F1 A1 cos.
    pub dac1: Signal<Out, Signed<16>>,
    /// DAC word of drive 2: F2 A2 sin.
    pub dac2: Signal<Out, Signed<16>>,
    /// Reference copy of drive 1, from the reference carrier.
    pub ref1: Signal<Out, Signed<16>>,
    /// Reference copy of drive 2, from the reference carrier.
    pub ref2: Signal<Out, Signed<16>>,
    envelope1: Q15Multiplier,
    envelope2: Q15Multiplier,
    drive1: Q15Multiplier,
    drive2: Q15Multiplier,
    reference1: Q15Multiplier,
    reference2: Q15Multiplier,
}

impl AmMixer {
    /// The two AM channels.
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            amp1: Default::default(),
            amp2: Default::default(),
            am1: Default::default(),
            am2: Default::default(),
            drive_cos: Default::default(),
            drive_sin: Default::default(),
            ref_cos: Default::default(),
            ref_sin: Default::default(),
            dac1: Default::default(),
            dac2: Default::default(),
            ref1: Default::default(),
            ref2: Default::default(),
            envelope1: Q15Multiplier::new(),
            envelope2: Q15Multiplier::new(),
            drive1: Q15Multiplier::new(),
            drive2: Q15Multiplier::new(),
            reference1: Q15Multiplier::new(),
            reference2: Q15Multiplier::new(),
        }
    }
}

impl Default for AmMixer {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for AmMixer {
    #[hdl_gen]
    fn update(&mut self) {
        self.envelope1.clock.next = self.clock.val();
        self.envelope2.clock.next = self.clock.val();
        self.drive1.clock.next = self.clock.val();
        self.drive2.clock.next = self.clock.val();
        self.reference1.clock.next = self.clock.val();
        self.reference2.clock.next = self.clock.val();
        self.envelope1.a.next = self.amp1.val();
        self.envelope1.b.next = self.am1.val();
        self.envelope2.a.next = self.amp2.val();
        self.envelope2.b.next = self.am2.val();
        self.drive1.a.next = self.envelope1.y.val();
        self.drive1.b.next = self.drive_cos.val();
        self.drive2.a.next = self.envelope2.y.val();
        self.drive2.b.next = self.drive_sin.val();
        self.reference1.a.next = self.envelope1.y.val();
        self.reference1.b.next = self.ref_cos.val();
        self.reference2.a.next = self.envelope2.y.val();
        self.reference2.b.next = self.ref_sin.val();
        self.dac1.next = self.drive1.y.val();
        self.dac2.next = self.drive2.y.val();
        self.ref1.next = self.reference1.y.val();
        self.ref2.next = self.reference2.y.val();
    }
}

crate::impl_clocked!(AmMixer);
