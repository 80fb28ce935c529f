//! The readout/calibration mux and the demodulation multipliers.
//!
//! ```text
//!  adc1 ──► [reg] ─────────────────────────┐
//!                                          × ──► [w1: 32 bit]
//!  aligned1 ──┬──► select ? aligned2 : aligned1 ──► [reg] ┘
//!  aligned2 ──┼──► select ? aligned1 : aligned2 ──► [reg] ┐
//!  adc2 ──► [reg] ─────────────────────────× ──► [w2: 32 bit]
//! ```
//!
//! Paper Fig. 1: in readout (`select` = 0) each gyroscope output is mixed
//! with its own drive (w1 = x1 * drive1, w2 = x2 * drive2); in calibration
//! (`select` = 1) with the other channel's drive (w1 = x1 * drive2,
//! w2 = x2 * drive1). The ADC words are registered on entry (the input
//! register of the FPGA); the products are exact 32-bit values, never
//! rounded: |w| <= 32768 * 32767 < 2^30.
//!
//! Timing: during cycle n, w = adc(n - 2) * aligned(n - 2).

use crate::primitives::RegisteredMultiplier;
use rust_hdl::prelude::*;

/// Clock cycles from the ADC inputs (and aligned references) to `w`.
pub const LATENCY: usize = 2;

/// SELECT mux plus the two demodulation multipliers.
#[derive(LogicBlock)]
pub struct DemodMux {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// ADC word of output 1 (16-bit two's complement).
    pub adc1: Signal<In, Signed<16>>,
    /// ADC word of output 2 (16-bit two's complement).
    pub adc2: Signal<In, Signed<16>>,
    /// Aligned reference of drive 1.
    pub aligned1: Signal<In, Signed<16>>,
    /// Aligned reference of drive 2.
    pub aligned2: Signal<In, Signed<16>>,
    /// 0: readout (own drive), 1: calibration (the other channel's drive).
    pub select: Signal<In, Bit>,
    /// Mixer output 1: adc1 times its reference, exact.
    pub w1: Signal<Out, Signed<32>>,
    /// Mixer output 2: adc2 times its reference, exact.
    pub w2: Signal<Out, Signed<32>>,
    adc1_in: DFF<Signed<16>>,
    adc2_in: DFF<Signed<16>>,
    reference1: DFF<Signed<16>>,
    reference2: DFF<Signed<16>>,
    mixer1: RegisteredMultiplier<16, 16, 32>,
    mixer2: RegisteredMultiplier<16, 16, 32>,
}

impl DemodMux {
    /// The mux and the two mixers.
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            adc1: Default::default(),
            adc2: Default::default(),
            aligned1: Default::default(),
            aligned2: Default::default(),
            select: Default::default(),
            w1: Default::default(),
            w2: Default::default(),
            adc1_in: Default::default(),
            adc2_in: Default::default(),
            reference1: Default::default(),
            reference2: Default::default(),
            mixer1: RegisteredMultiplier::new(),
            mixer2: RegisteredMultiplier::new(),
        }
    }
}

impl Default for DemodMux {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for DemodMux {
    #[hdl_gen]
    fn update(&mut self) {
        dff_setup!(self, clock, adc1_in, adc2_in, reference1, reference2);
        self.mixer1.clock.next = self.clock.val();
        self.mixer2.clock.next = self.clock.val();
        self.adc1_in.d.next = self.adc1.val();
        self.adc2_in.d.next = self.adc2.val();
        if self.select.val() {
            self.reference1.d.next = self.aligned2.val();
            self.reference2.d.next = self.aligned1.val();
        } else {
            self.reference1.d.next = self.aligned1.val();
            self.reference2.d.next = self.aligned2.val();
        }
        self.mixer1.a.next = self.adc1_in.q.val();
        self.mixer1.b.next = self.reference1.q.val();
        self.mixer2.a.next = self.adc2_in.q.val();
        self.mixer2.b.next = self.reference2.q.val();
        self.w1.next = self.mixer1.p.val();
        self.w2.next = self.mixer2.p.val();
    }
}

crate::impl_clocked!(DemodMux);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{prepare, tick};
    use crate::model::demod_mux::DemodMux as Model;
    use crate::primitives::convert::{i128_to_signed, signed_to_i128};
    use crate::test_util::{segments, word16};
    use proptest::prelude::*;

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(8))]
        #[test]
        fn rtl_matches_model_in_both_modes_with_extreme_words(
            selects in segments(any::<bool>(), 8..12, 50..80),
            words in prop::collection::vec(((word16(), word16()), (word16(), word16())), 640),
        ) {
            let mut uut = DemodMux::new();
            prepare(&mut uut);
            let mut model = Model::default();
            for (n, (&select, &(adc, aligned))) in selects.iter().zip(&words).enumerate() {
                let s = |x: i16| i128_to_signed(x as i128);
                uut.adc1.next = s(adc.0);
                uut.adc2.next = s(adc.1);
                uut.aligned1.next = s(aligned.0);
                uut.aligned2.next = s(aligned.1);
                uut.select.next = select;
                tick(&mut uut);
                let v = |x: Signed<32>| signed_to_i128(x) as i32;
                let hw = (v(uut.w1.val()), v(uut.w2.val()));
                prop_assert_eq!(hw, model.step(adc, aligned, select), "cycle {}", n);
            }
        }
    }

    #[test]
    fn select_crosses_the_references() {
        let mut m = Model::default();
        for _ in 0..3 {
            m.step((2, 3), (5, 7), false);
        }
        assert_eq!(m.output(), (10, 21));
        for _ in 0..3 {
            m.step((2, 3), (5, 7), true);
        }
        assert_eq!(m.output(), (14, 15));
        for _ in 0..3 {
            m.step((-32768, -32768), (-32768, 32767), false);
        }
        assert_eq!(m.output(), (1 << 30, -32768 * 32767));
    }
}
