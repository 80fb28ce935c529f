//! Bit-true model of `crate::sine::Sine`.
//!
//! `sine` is the arithmetic of the pipeline stages collapsed into one
//! function; `Sine` delays it by the block's latency, starting
//! from what the power-up registers give (`crate::sine`'s header): 0 during
//! cycles 0..=3, then `power_up_word()`, table entry 0 read through the
//! all-zero index register with a zero offset, during cycle 4.

use crate::sine::LATENCY;
use crate::sine_table;
use std::sync::OnceLock;

/// The table columns interleaved as `[value, slope]`.
pub type Table = [[i32; 2]; sine_table::ENTRIES];

/// The table, built once per process.
pub fn table() -> &'static Table {
    static TABLE: OnceLock<Table> = OnceLock::new();
    TABLE.get_or_init(|| std::array::from_fn(|i| [sine_table::value(i), sine_table::slope(i)]))
}

/// `32767 sin` of a 32-bit phase plus `advance` quarter turns, as
/// `crate::sine::Sine` computes it.
#[inline(always)]
pub fn sine(phase: u32, advance: u8) -> i16 {
    sine_with(table(), phase, advance)
}

#[inline(always)]
fn sine_with(table: &Table, phase: u32, advance: u8) -> i16 {
    let q = ((phase >> 30) + u32::from(advance)) & 3;
    let i = ((phase >> 22) & 0xff) as usize;
    let [sample, slope] = table[if q & 1 == 0 { i } else { 0xff - i }];
    let offset = ((phase >> 7) & 0x7fff) as i32 - 0x4000;
    let correction = (offset * slope + (1 << 21)) >> 22;
    let first = if q & 1 == 0 {
        sample + correction
    } else {
        sample - correction
    };
    (if q >= 2 { -first } else { first }) as i16
}

/// The output during cycle `LATENCY - 1` after power-up: the entry the
/// all-zero index register reads, with a zero correction, quadrant 0.
pub fn power_up_word() -> i16 {
    sine_table::value(0) as i16
}

/// Cycle-true model of one `crate::sine::Sine`.
#[derive(Clone, Debug)]
pub struct Sine {
    /// Values in flight; `pipe[head]` is the current output.
    pipe: [i16; LATENCY],
    head: usize,
    table: &'static Table,
}

impl Default for Sine {
    fn default() -> Self {
        // Zero in every slot but the one that comes out during cycle
        // LATENCY - 1.
        let mut pipe = [0; LATENCY];
        pipe[LATENCY - 1] = power_up_word();
        Self {
            pipe,
            head: 0,
            table: table(),
        }
    }
}

impl Sine {
    /// The output during the current cycle.
    #[inline(always)]
    pub fn output(&self) -> i16 {
        self.pipe[self.head]
    }

    /// Present `phase` and `advance` for one clock; returns the output
    /// after the edge.
    #[inline(always)]
    pub fn step(&mut self, phase: u32, advance: u8) -> i16 {
        self.pipe[self.head] = sine_with(self.table, phase, advance);
        self.head = (self.head + 1) % LATENCY;
        self.pipe[self.head]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// `(sin, cos)` of a 32-bit phase: the sine with no advance and with a
    /// quarter turn (the modulation NCO's A2 and A1).
    fn evaluate(phase: u32) -> (i16, i16) {
        (sine(phase, 0), sine(phase, 1))
    }

    /// First-quadrant sine and cosine of the interval and offset encoded in
    /// phase bits 29:7, before the quadrant mirror: the arithmetic of the
    /// former dual-output generator, one table index for both.
    fn first_quadrant(phase: u32) -> (i32, i32) {
        let i = ((phase >> 22) & 0xff) as usize;
        let [sin_sample, sin_slope] = table()[i];
        let [cos_sample, cos_slope] = table()[0xff - i];
        let offset = ((phase >> 7) & 0x7fff) as i32 - 0x4000;
        let round = |p: i32| (p + (1 << 21)) >> 22;
        (
            sin_sample + round(offset * sin_slope),
            cos_sample - round(offset * cos_slope),
        )
    }

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

    /// The former dual-output arithmetic: one table index for both, the
    /// quadrant mirror swapping and negating the pair.
    fn dual_output_reference(phase: u32) -> (i16, i16) {
        let (s, c) = first_quadrant(phase);
        let q = phase >> 30;
        let (a, b) = if q & 1 == 0 { (s, c) } else { (c, s) };
        let sin = if q >= 2 { -a } else { a };
        let cos = if q == 1 || q == 2 { -b } else { b };
        (sin as i16, cos as i16)
    }

    #[test]
    fn two_sines_equal_the_dual_output_generator_for_every_phase() {
        // Exhaustive over phase bits 31:7 (bits 6:0 are ignored): the
        // quadrant-advanced sine reproduces the pair the earlier SinCos
        // computed from one table index, word for word.
        for code in 0u32..(1 << 25) {
            let phase = code << 7;
            assert_eq!(
                evaluate(phase),
                dual_output_reference(phase),
                "phase {phase:#x}"
            );
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
