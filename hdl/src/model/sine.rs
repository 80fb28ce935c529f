//! Bit-true model of `crate::sine::Sine`.
//!
//! `sine` is the lookup the pipeline stages make, collapsed into one
//! function; `Sine` delays it by the block's latency, starting from what
//! the power-up registers give (`crate::quarter_wave`): 0 during cycles
//! 0..=4.

use super::delay_ring::DelayRing;
use crate::quarter_wave::LATENCY;
use crate::sine_table;
use std::sync::OnceLock;

/// The ROM's words.
pub type Table = [i16; sine_table::ENTRIES];

/// The table, built once per process.
pub fn table() -> &'static Table {
    static TABLE: OnceLock<Table> = OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|i| sine_table::value(i) as i16))
}

/// `32767 sin` of a 32-bit phase plus `advance` quarter turns, as
/// `crate::sine::Sine` computes it.
#[inline(always)]
pub fn sine(phase: u32, advance: u8) -> i16 {
    sine_with(table(), phase, advance)
}

/// The ROM ignores the index's lowest bit: one word per pair of intervals.
#[inline(always)]
fn sine_with(table: &Table, phase: u32, advance: u8) -> i16 {
    super::quarter_wave::lookup(phase, advance, |index| table[index >> 1])
}

/// Cycle-true model of one `crate::sine::Sine`.
#[derive(Clone, Debug)]
pub struct Sine {
    /// Values in flight.
    pipe: DelayRing<i16, LATENCY>,
    table: &'static Table,
}

impl Default for Sine {
    fn default() -> Self {
        Self {
            pipe: DelayRing::default(),
            table: table(),
        }
    }
}

impl Sine {
    /// The output during the current cycle.
    #[inline(always)]
    pub fn output(&self) -> i16 {
        self.pipe.output()
    }

    /// Present `phase` and `advance` for one clock; returns the output
    /// after the edge.
    #[inline(always)]
    pub fn step(&mut self, phase: u32, advance: u8) -> i16 {
        self.pipe.step(sine_with(self.table, phase, advance))
    }

    /// The outputs during the next `out.len()` cycles, then as many edges
    /// with `input(k)` (phase, advance) presented at edge k: `output` and
    /// `step` clock by clock (`DelayRing::block`).
    #[inline(always)]
    pub fn block(&mut self, out: &mut [i16], input: impl Fn(usize) -> (u32, u8)) {
        let words = Self::words(self.table, input);
        self.block_words(out, words);
    }

    /// `block` where the caller knows the words: `word(k)` is the word
    /// of the phase and advance presented at edge k.
    #[inline(always)]
    pub fn block_words(&mut self, out: &mut [i16], word: impl Fn(usize) -> i16) {
        self.pipe.block(out, word);
    }

    /// `n` edges with `input(k)` presented at edge k, as `block` plays
    /// them, without the outputs (`DelayRing::skip`).
    #[inline(always)]
    pub fn skip(&mut self, n: usize, input: impl Fn(usize) -> (u32, u8)) {
        let words = Self::words(self.table, input);
        self.pipe.skip(n, words);
    }

    /// The word of each edge's phase and advance, `input(k)`.
    #[inline(always)]
    fn words(table: &'static Table, input: impl Fn(usize) -> (u32, u8)) -> impl Fn(usize) -> i16 {
        move |k| {
            let (phase, advance) = input(k);
            sine_with(table, phase, advance)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    #[test]
    fn every_phase_gives_the_rounded_sine_of_its_interval_centre() {
        // Exhaustive over the 2^14 intervals of a turn and the 4 advances:
        // the quadrant mirror and negation reproduce, word for word, the
        // rounded sine at the centre of the phase's interval (f64 rounds
        // half away from zero, symmetric like the negated table).
        for code in 0u32..(1 << 14) {
            let phase = code << 18;
            let centre = phase + (1 << 17);
            for advance in 0u8..4 {
                let angle = (centre as f64 / 2f64.powi(32) + f64::from(advance) / 4.0) * TAU;
                let want = (32767.0 * angle.sin()).round() as i16;
                assert_eq!(
                    sine(phase, advance),
                    want,
                    "interval {code}, advance {advance}"
                );
                assert_eq!(
                    sine(phase | 0x3ffff, advance),
                    want,
                    "end of interval {code}"
                );
            }
        }
    }

    #[test]
    fn error_against_the_exact_sine_is_at_most_6_8_lsb() {
        // Half an interval of phase, 32767 pi / 2^14 = 6.28 LSB, plus the
        // table's rounding, 0.5.
        let mut worst = 0.0f64;
        for k in 0u32..(1 << 20) {
            let phase = k.wrapping_mul(0x9e37_79b9);
            let angle = phase as f64 / 2f64.powi(32) * TAU;
            worst = worst.max((sine(phase, 0) as f64 - 32767.0 * angle.sin()).abs());
            worst = worst.max((sine(phase, 1) as f64 - 32767.0 * angle.cos()).abs());
        }
        assert!(worst <= 6.79, "worst error {worst} LSB");
    }
}
