//! Bit-true model of `crate::sincos::SinCos`.
//!
//! `evaluate` is the arithmetic of the four pipeline stages collapsed into
//! one function; `SinCos` delays it by the block's latency with zero
//! power-up values, which is exactly what the registers do: an all-zero
//! pipeline produces zero outputs (offset 0 times slope 0, sample 0,
//! quadrant 0), so the first `LATENCY` outputs are 0.

use crate::sincos::LATENCY;
use crate::sine_table;
use std::sync::OnceLock;

/// The table columns interleaved as `[value, slope]`.
pub type Table = [[i32; 2]; sine_table::ENTRIES];

/// The table, built once per process.
pub fn table() -> &'static Table {
    static TABLE: OnceLock<Table> = OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|i| [sine_table::value(i), sine_table::slope(i)]))
}

/// First-quadrant sine and cosine of the interval and offset encoded in
/// phase bits 29:7, before the quadrant mirror.
#[inline(always)]
pub fn first_quadrant(phase: u32) -> (i32, i32) {
    first_quadrant_with(table(), phase)
}

#[inline(always)]
fn first_quadrant_with(table: &Table, phase: u32) -> (i32, i32) {
    let i = ((phase >> 22) & 0xff) as usize;
    let [sin_sample, sin_slope] = table[i];
    let [cos_sample, cos_slope] = table[0xff - i];
    let offset = ((phase >> 7) & 0x7fff) as i32 - 0x4000;
    let round = |p: i32| (p + (1 << 21)) >> 22;
    (
        sin_sample + round(offset * sin_slope),
        cos_sample - round(offset * cos_slope),
    )
}

/// `(sin, cos)` of a 32-bit phase, as the hardware computes it.
#[inline(always)]
pub fn evaluate(phase: u32) -> (i16, i16) {
    evaluate_with(table(), phase)
}

#[inline(always)]
fn evaluate_with(table: &Table, phase: u32) -> (i16, i16) {
    let (s, c) = first_quadrant_with(table, phase);
    // Quadrant mirror without branches: odd quadrants swap sine and
    // cosine; the sine is negated in quadrants 2 and 3, the cosine in 1 and 2.
    let q = phase >> 30;
    let (a, b) = if q & 1 == 0 { (s, c) } else { (c, s) };
    let sin = if q >= 2 { -a } else { a };
    let cos = if q == 1 || q == 2 { -b } else { b };
    (sin as i16, cos as i16)
}

/// Cycle-true model of the pipeline.
#[derive(Clone, Debug)]
pub struct SinCos {
    /// Values in flight; `pipe[head]` is the current output.
    pipe: [(i16, i16); LATENCY],
    head: usize,
    table: &'static Table,
}

impl Default for SinCos {
    fn default() -> Self {
        Self {
            pipe: Default::default(),
            head: 0,
            table: table(),
        }
    }
}

impl SinCos {
    /// `(sin, cos)` during the current cycle.
    #[inline(always)]
    pub fn output(&self) -> (i16, i16) {
        self.pipe[self.head]
    }

    /// Present `phase` for one clock; returns `(sin, cos)` after the edge.
    #[inline(always)]
    pub fn step(&mut self, phase: u32) -> (i16, i16) {
        // The slot of the current output is reused for the newest value,
        // which comes out LATENCY edges later.
        self.pipe[self.head] = evaluate_with(self.table, phase);
        self.head = (self.head + 1) % LATENCY;
        self.pipe[self.head]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn first_quadrant_stays_within_the_peak_for_every_phase() {
        // Exhaustive over the 2^23 interval/offset codes that matter (bits
        // 29:7): the Taylor correction never pushes a first-quadrant value
        // outside [0, 32767], so the quadrant mirror's negation is safe and
        // -32768 never occurs.
        for code in 0u32..(1 << 23) {
            let (s, c) = first_quadrant(code << 7);
            assert!((0..=sine_table::PEAK).contains(&s), "sin {s} at {code:#x}");
            assert!((0..=sine_table::PEAK).contains(&c), "cos {c} at {code:#x}");
        }
    }

    #[test]
    fn error_against_the_exact_sine_is_at_most_1_2_lsb() {
        // Table rounding (0.5), correction rounding (0.5), the neglected
        // second-order term (D^2/8 * 32767 = 0.15 LSB) and the 7 ignored
        // phase bits (2 pi 2^-25 * 32767 = 0.006 LSB) add to at most 1.16.
        let mut worst = 0.0f64;
        for k in 0u32..(1 << 20) {
            let phase = k.wrapping_mul(0x9e37_79b9);
            let (s, c) = evaluate(phase);
            let angle = phase as f64 / 2f64.powi(32) * std::f64::consts::TAU;
            worst = worst.max((s as f64 - 32767.0 * angle.sin()).abs());
            worst = worst.max((c as f64 - 32767.0 * angle.cos()).abs());
        }
        assert!(worst <= 1.16, "worst error {worst} LSB");
    }
}
