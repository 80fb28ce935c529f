//! Sine and cosine of a 32-bit phase: two `crate::sine::Sine` generators,
//! the second a quarter turn ahead.
//!
//! ```text
//!  phase ──┬─► Sine (advance 0) ──► sin = 32767 sin(phase)
//!          └─► Sine (advance 1) ──► cos = 32767 sin(phase + 90 deg)
//! ```
//!
//! Each output is one table port and one multiplier (`crate::sine` for the
//! arithmetic, widths and error). The cosine's sine generator reads the
//! mirrored table entry where the sine's reads the direct one, so the pair
//! is word for word what a dual-output generator with one shared table
//! index gives (checked exhaustively over all 2^25 phase codes in the
//! model's tests). Outputs 16-bit, peak 32767, never -32768.
//!
//! Pipeline: `crate::sine::LATENCY` = 5 registers. `sin`/`cos` during cycle
//! n belong to the `phase` presented during cycle n - 5. Resources: 2 table
//! ROM ports, 2 16x16 multipliers.

use crate::sine::Sine;
use rust_hdl::prelude::*;

/// Clock cycles from `phase` to `sin`/`cos`.
pub const LATENCY: usize = crate::sine::LATENCY;

/// Sine and cosine of a 32-bit phase, 16-bit outputs, 5-clock pipeline.
#[derive(LogicBlock)]
pub struct SinCos {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Phase as a fraction of a turn: 2^32 is 360 degrees.
    pub phase: Signal<In, Bits<32>>,
    /// 32767 sin(phase), 16-bit two's complement, `LATENCY` clocks after `phase`.
    pub sin: Signal<Out, Signed<16>>,
    /// 32767 cos(phase), 16-bit two's complement, `LATENCY` clocks after `phase`.
    pub cos: Signal<Out, Signed<16>>,
    sine: Sine,
    cosine: Sine,
    no_turn: Constant<Bits<2>>,
    quarter_turn: Constant<Bits<2>>,
}

impl SinCos {
    /// A sine/cosine generator with the table of `crate::sine_table`.
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            phase: Default::default(),
            sin: Default::default(),
            cos: Default::default(),
            sine: Sine::new(),
            cosine: Sine::new(),
            no_turn: Constant::new(0.into()),
            quarter_turn: Constant::new(1.into()),
        }
    }
}

impl Default for SinCos {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for SinCos {
    #[hdl_gen]
    fn update(&mut self) {
        self.sine.clock.next = self.clock.val();
        self.cosine.clock.next = self.clock.val();
        self.sine.phase.next = self.phase.val();
        self.cosine.phase.next = self.phase.val();
        self.sine.advance.next = self.no_turn.val();
        self.cosine.advance.next = self.quarter_turn.val();
        self.sin.next = self.sine.sin.val();
        self.cos.next = self.cosine.sin.val();
    }
}

crate::impl_clocked!(SinCos);

/// Mutation hooks for the negative control in `crate::rtl` (tests only).
#[cfg(test)]
impl SinCos {
    #[doc(hidden)]
    pub fn mutate_rounding(&mut self) {
        self.sine.mutate_rounding();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{prepare, tick};
    use crate::model::sincos as model;
    use crate::primitives::convert::{signed_to_i128, u128_to_bits};
    use proptest::prelude::*;

    /// Drive the rust-hdl block and the model with the same phases.
    fn compare(phases: &[u32]) {
        let mut uut = SinCos::new();
        prepare(&mut uut);
        let mut golden = model::SinCos::default();
        let mut peak = 0i16;
        for (n, &p) in phases.iter().enumerate() {
            uut.phase.next = u128_to_bits(p as u128);
            tick(&mut uut);
            let hw = (
                signed_to_i128(uut.sin.val()) as i16,
                signed_to_i128(uut.cos.val()) as i16,
            );
            assert_eq!(hw, golden.step(p), "cycle {n}, phase {p:#010x}");
            peak = peak.max(hw.0.abs()).max(hw.1.abs());
        }
        // Guard against a vacuous comparison of two idle pipelines.
        assert!(peak > 20000, "outputs never left zero (peak {peak})");
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(16))]
        #[test]
        fn rtl_matches_model_on_random_phases(phases in prop::collection::vec(any::<u32>(), 300)) {
            compare(&phases);
        }
    }

    #[test]
    fn rtl_matches_model_at_quadrant_edges_and_a_ramp() {
        let mut phases = vec![0, 1, 0x3fff_ffff, 0x4000_0000, 0x7fff_ffff, 0x8000_0000];
        phases.extend([0xbfff_ffff, 0xc000_0000, u32::MAX, 0x003f_ff80, 0x0040_0000]);
        phases.extend((0..400u32).map(|k| k.wrapping_mul(0x3171_5a3b)));
        compare(&phases);
    }
}
