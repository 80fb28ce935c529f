//! Sine of a 32-bit phase from a 4096-entry quarter-wave ROM, one table
//! port, no multiplier: the modulation NCO's sine generator, which also
//! computes the carriers' tables at power-up.
//!
//! ```text
//!  phase, advance ──► QuarterWave ──► sin
//!      (live: 1)        │ index ▲ value
//!                       ▼       │
//!                  QuarterSineRom (4096 x 16, index >> 1)
//! ```
//!
//! The phase is a binary fraction of a turn (2^32 = 360 degrees); `advance`
//! adds whole quarter turns to it (1: the output is the cosine). Bits 29:18
//! pick one of the 4096 intervals of the quadrant, whose centre is sampled
//! in `crate::sine_table`: the output is the sine of the phase rounded to
//! the nearest of 2^14 interval centres per turn (`crate::quarter_wave`
//! indexes 8192 intervals; the ROM ignores the lowest index bit). Phase
//! bits 17:0 are ignored.
//!
//! Widths: the output is 16-bit two's complement with peak 32767, never
//! -32768. Error against `32767 sin(2 pi phase / 2^32)`: at most
//! 32767 pi / 2^14 + 0.5 = 6.8 LSB (half an interval of phase, and the
//! table's rounding). Spurs: the phase rounding's largest spur is near
//! -6.02 x 14 + 3.9 = -80 dBc at worst (Nicholas and Samueli's bound for
//! 14 phase bits); measured by FFT in `crate::modulation_nco`. The
//! modulation it makes is a few hertz to a few kilohertz: its spurs are
//! sidebands of the carrier that far from it, at -80 dBc of the
//! modulation's own sideband.
//!
//! Pipeline: 5 registers (`QuarterWave`). `sin` during cycle n belongs to
//! the `phase` and `advance` presented during cycle n - 5; it is 0 during
//! cycles 0..=4 after power-up. Resources: one table ROM port (4096 x 16),
//! no multiplier.

use crate::primitives::QuarterSineRom;
use crate::quarter_wave::QuarterWave;
use rust_hdl::prelude::*;

/// Clock cycles from `phase` to `sin`.
pub const LATENCY: usize = crate::quarter_wave::LATENCY;

/// Sine of a 32-bit phase plus whole quarter turns, 16-bit output, 5-clock
/// pipeline.
#[derive(LogicBlock)]
pub struct Sine {
    /// The clock.
    pub clock: Signal<In, Clock>,
    /// Phase as a fraction of a turn: 2^32 is 360 degrees.
    pub phase: Signal<In, Bits<32>>,
    /// Quarter turns added to `phase` (0: sine, 1: cosine, 2: -sine, 3: -cosine).
    pub advance: Signal<In, Bits<2>>,
    /// 32767 sin(phase + advance quarter turns), 16-bit two's complement,
    /// `LATENCY` clocks after `phase`.
    pub sin: Signal<Out, Signed<16>>,
    lookup: QuarterWave,
    rom: QuarterSineRom,
    rom_ready: Constant<Bit>,
}

impl Sine {
    /// A sine generator with the table of `crate::sine_table`.
    pub fn new() -> Self {
        Self {
            clock: Default::default(),
            phase: Default::default(),
            advance: Default::default(),
            sin: Default::default(),
            lookup: QuarterWave::new(),
            rom: QuarterSineRom::new(),
            rom_ready: Constant::new(true),
        }
    }
}

impl Default for Sine {
    fn default() -> Self {
        Self::new()
    }
}

impl Logic for Sine {
    #[hdl_gen]
    fn update(&mut self) {
        self.lookup.clock.next = self.clock.val();
        self.rom.clock.next = self.clock.val();
        self.lookup.phase.next = self.phase.val();
        self.lookup.advance.next = self.advance.val();
        self.lookup.live.next = self.rom_ready.val();
        self.rom.addr.next = self.lookup.index.val();
        self.lookup.word.next = self.rom.value.val();
        self.sin.next = self.lookup.sin.val();
    }
}

crate::impl_clocked!(Sine);

#[cfg(test)]
mod tests {
    use super::*;
    use crate::drive::{prepare, tick};
    use crate::model::sine::{Sine as Model, sine};
    use crate::primitives::convert::{signed_to_i128, u128_to_bits};
    use proptest::prelude::*;

    /// Drive the rust-hdl block and the model with the same phases and
    /// quarter-turn advances.
    fn compare(inputs: &[(u32, u8)]) {
        let mut uut = Sine::new();
        prepare(&mut uut);
        let mut golden = Model::default();
        let mut peak = 0i16;
        for (n, &(p, advance)) in inputs.iter().enumerate() {
            uut.phase.next = u128_to_bits(p as u128);
            uut.advance.next = u128_to_bits(advance as u128);
            tick(&mut uut);
            let hw = signed_to_i128(uut.sin.val()) as i16;
            assert_eq!(hw, golden.step(p, advance), "cycle {n}, phase {p:#010x}");
            peak = peak.max(hw.abs());
        }
        // Guard against a vacuous comparison of two idle pipelines.
        assert!(peak > 20000, "output never left zero (peak {peak})");
    }

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(16))]
        #[test]
        fn rtl_matches_model_on_random_phases_and_advances(
            inputs in prop::collection::vec((any::<u32>(), 0u8..4), 300),
        ) {
            compare(&inputs);
        }
    }

    #[test]
    fn rtl_matches_model_at_quadrant_edges_and_a_ramp() {
        let mut phases = vec![0, 1, 0x3fff_ffff, 0x4000_0000, 0x7fff_ffff, 0x8000_0000];
        phases.extend([0xbfff_ffff, 0xc000_0000, u32::MAX, 0x0003_ffff, 0x0004_0000]);
        phases.extend((0..400u32).map(|k| k.wrapping_mul(0x3171_5a3b)));
        let inputs: Vec<(u32, u8)> = phases
            .iter()
            .enumerate()
            .map(|(k, &p)| (p, (k % 4) as u8))
            .collect();
        compare(&inputs);
    }

    #[test]
    fn spur_free_dynamic_range_above_80_dbc() {
        // The required 80 dBc against the phase-rounding bound for 14 phase
        // bits, -80.4 dBc at worst (header). Phase ramps at a few frequency
        // words, the golden-ratio one among them, whose rounding pattern
        // never repeats within the record.
        for step in [0x0123_4567u32, 0x9e37_79b9, 0x0008_0001, 0x3141_5927] {
            let samples: Vec<f64> = (0..1u32 << 17)
                .map(|n| f64::from(sine(n.wrapping_mul(step), 0)))
                .collect();
            let sfdr = crate::test_util::sfdr_dbc(&samples);
            eprintln!("step {step:#010x}: SFDR {sfdr:.1} dBc");
            assert!(sfdr > 80.0, "step {step:#010x}: SFDR {sfdr:.1} dBc");
        }
    }

    #[test]
    fn an_advance_is_a_quarter_turn_of_phase() {
        for k in 0u32..4096 {
            let p = k.wrapping_mul(0x9e37_79b9);
            for a in 0u8..4 {
                let turned = p.wrapping_add(u32::from(a) << 30);
                assert_eq!(sine(p, a), sine(turned, 0), "phase {p:#x}, advance {a}");
            }
        }
    }
}
