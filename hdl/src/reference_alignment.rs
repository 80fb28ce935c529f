//! Reference alignment: the run-time delay that lines the demodulation
//! references up with the loop latency.
//!
//! ```text
//!  ref1 ──► [64-word RAM delay line] ── word(delay) ──► aligned1
//!  ref2 ──► [64-word RAM delay line] ── word(delay) ──► aligned2
//! ```
//!
//! The samples the demodulators see left the DACs some clocks earlier: the
//! DAC and ADC pipelines plus the half-sample delay of the DAC's zero-order
//! hold. The integer part is taken out here (`delay` = 0..63), the half
//! sample by the carrier NCO's `ref_offset`; `crate::alignment` computes
//! both from the converter latencies. The modulation envelope is delayed
//! with the carrier, so calibration references stay aligned too.
//!
//! Timing: during cycle n, `aligned = ref(n - 1 - delay)` for a delay held
//! constant, delay 0..63 as before; the read is registered in the RAM
//! (`crate::primitives::TappedDelayLine`, with a bypass for delay 0), so a
//! new `delay` acts one clock later than the combinational tap of the
//! earlier shift register did. The alignment arithmetic
//! (`crate::settings`) is unchanged.

use crate::primitives::TappedDelayLine;
use rust_hdl::prelude::*;

/// Address bits of the delay: 64 taps.
pub const DELAY_BITS: usize = gyrocal_regs::datapath::DELAY_BITS as usize;

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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{prepare, tick};
    use crate::model::reference_alignment::ReferenceAlignment as Model;
    use crate::primitives::convert::{i128_to_signed, signed_to_i128, u128_to_bits};
    use crate::test_util::{segments, word16};
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(8))]
        #[test]
        fn rtl_matches_model_with_changing_delay(
            delays in segments(0u8..64, 10..20, 30..60),
            refs in prop::collection::vec((word16(), word16()), 600),
        ) {
            let mut uut = ReferenceAlignment::new();
            prepare(&mut uut);
            let mut model = Model::default();
            for (n, (&delay, &(r1, r2))) in delays.iter().zip(&refs).enumerate() {
                uut.ref1.next = i128_to_signed(r1 as i128);
                uut.ref2.next = i128_to_signed(r2 as i128);
                uut.delay.next = u128_to_bits(delay as u128);
                tick(&mut uut);
                model.step(r1, r2, delay);
                // The read is registered: it used the delay of the last cycle.
                let v = |x: Signed<16>| signed_to_i128(x) as i16;
                prop_assert_eq!((v(uut.aligned1.val()), v(uut.aligned2.val())), model.output(), "cycle {}", n);
            }
        }
    }

    #[test]
    fn a_delay_of_d_delays_by_d_plus_one_clocks() {
        let mut model = Model::default();
        for k in 0..100i16 {
            model.step(k, -k, 9);
            if k >= 10 {
                assert_eq!(model.output(), (k - 9, 9 - k));
            }
        }
        // Delay 0 (the bypass): one clock.
        model.step(7, -7, 0);
        assert_eq!(model.output(), (7, -7));
    }
}
