//! Bit-true model of `crate::sine_pair::SinePair`: the cosine and sine of
//! one phase from the fine table (`crate::fine_sine_table`), three phase
//! bits interpolated, one rounding, to a quarter LSB.
//!
//! For a phase with quadrant `q` (bits 31:30), interval `i` (29:17) and
//! sub-interval `s` (16:14), let `a = word[i]` and `b = word[8191 - i]`
//! (the first-quadrant sine and cosine at the interval's centre, quarter
//! LSB) and `k = slope[s]`. To first order the first-quadrant sine and
//! cosine of the phase within its quadrant are `a + b k` and `b - a k`;
//! the quadrant rotates them, (sin, cos) = (s, c), (c, -s), (-s, -c),
//! (-c, s). Each output is one of `s`, `c`, `-s`, `-c`, made as
//!
//! ```text
//!   t_s = floor(b k / 2^22), t_c = floor(a k / 2^22)       (2^-8 quarter LSB)
//!    s: (256 a + 128 + t_s) >> 8        -s: (127 - 256 a - t_s) >> 8
//!    c: (256 b + 128 - t_c) >> 8        -c: (127 - 256 b + t_c) >> 8
//! ```
//!
//! in quarter LSB: an output is `4 x 32767` at the peak (18 signed bits),
//! and the AM mixer rounds its product with it once, to the DAC's LSB.
//!
//! The negative forms are the positive ones' one's complement plus the
//! same rounding constant, so `-s` is exactly the negation of `s` (the
//! output is odd: sin(x + pi) = -sin(x) word for word), and the cosine
//! output is the sine output a quarter turn on.

use crate::fine_sine_table::{
    OUTPUT_SHIFT, PRODUCT_SHIFT, SUBINTERVALS, SUM_GUARD_BITS, TABLE_ENTRIES, slope, words,
};
use std::sync::OnceLock;

/// The fine table and its slopes, built once per process.
struct Tables {
    words: Vec<u32>,
    slopes: [i32; SUBINTERVALS],
}

fn tables() -> &'static Tables {
    static TABLES: OnceLock<Tables> = OnceLock::new();
    TABLES.get_or_init(|| Tables {
        words: words(),
        slopes: std::array::from_fn(slope),
    })
}

/// `(4 x 32767 cos, 4 x 32767 sin)` of a 32-bit phase (2^32 = one turn),
/// in quarter LSB, as `SinePair` computes them.
#[inline(always)]
pub fn sine_pair(phase: u32) -> (i32, i32) {
    let t = tables();
    let quadrant = phase >> 30;
    let i = (phase >> 17) as usize & (TABLE_ENTRIES - 1);
    let s = (phase >> 14) as usize & (SUBINTERVALS - 1);
    let (a, b) = (
        i64::from(t.words[i]),
        i64::from(t.words[TABLE_ENTRIES - 1 - i]),
    );
    let k = i64::from(t.slopes[s]);
    let (t_s, t_c) = ((b * k) >> PRODUCT_SHIFT, (a * k) >> PRODUCT_SHIFT);
    let half = 1i64 << (OUTPUT_SHIFT - 1);
    let output = |q: u32| {
        let sine_type = q & 1 == 0;
        let negative = q & 2 != 0;
        let (word, cross) = if sine_type { (a, t_s) } else { (b, t_c) };
        let scaled = word << SUM_GUARD_BITS;
        let base = if negative {
            half - 1 - scaled
        } else {
            scaled + half
        };
        let sum = if sine_type != negative {
            base + cross
        } else {
            base - cross
        };
        (sum >> OUTPUT_SHIFT) as i32
    };
    (output((quadrant + 1) & 3), output(quadrant))
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::TAU;

    fn exact(phase: u32) -> (f64, f64) {
        let angle = f64::from(phase) / 2f64.powi(32) * TAU;
        (32767.0 * angle.cos(), 32767.0 * angle.sin())
    }

    /// An output word in LSB of 32767.
    fn lsb(word: i32) -> f64 {
        f64::from(word) / 4.0
    }

    #[test]
    fn error_against_the_exact_sine_is_at_most_0_65_lsb() {
        // The final rounding, half a quarter LSB: 0.125 LSB; the phase bits below the
        // interpolated ones, at most half a sub-interval (D / 16 rad) from
        // its centre: 32767 pi / 2^18 = 0.393 LSB; the word's rounding,
        // half a quarter LSB: 0.125 LSB; the products' floor, 2^-8 quarter
        // LSB: 0.001; the cross word's rounding times the slope (at most
        // 7 D / 16 = 8.4e-5 rad) and the curvature (7 D / 16)^2 / 2 x 32767:
        // 1.2e-4 together. Sum 0.644 LSB (the built carriers: 4.2; this
        // pair rounded to whole LSB: 1.02).
        let mut worst = 0.0f64;
        for k in 0u32..(1 << 22) {
            let phase = k.wrapping_mul(0x9e37_79b9);
            let (c, s) = sine_pair(phase);
            let (ec, es) = exact(phase);
            worst = worst.max((lsb(c) - ec).abs().max((lsb(s) - es).abs()));
        }
        eprintln!("worst error {worst:.4} LSB");
        assert!(worst <= 0.65, "worst error {worst} LSB");
    }

    #[test]
    fn every_sub_interval_centre_is_within_0_26_lsb_of_the_exact_sine() {
        // At a sub-interval's centre the phase truncation is gone: the
        // final rounding (0.125), the word's (0.125) and the products'
        // (0.001) and the curvature (1.2e-4) remain: 0.251. Every interval and
        // sub-interval of all four quadrants.
        for i in 0..TABLE_ENTRIES as u32 {
            for s in 0..SUBINTERVALS as u32 {
                for q in 0..4u32 {
                    let phase = (q << 30) | (i << 17) | (s << 14) | (1 << 13);
                    let (c, sn) = sine_pair(phase);
                    let (ec, es) = exact(phase);
                    assert!(
                        (lsb(c) - ec).abs() <= 0.26 && (lsb(sn) - es).abs() <= 0.26,
                        "phase {phase:#x}: ({c}, {sn}) against ({ec:.3}, {es:.3})"
                    );
                }
            }
        }
    }

    #[test]
    fn the_outputs_are_odd_and_in_quadrature_word_for_word() {
        for k in 0u32..(1 << 18) {
            let phase = k.wrapping_mul(0x9e37_79b9);
            let (c, s) = sine_pair(phase);
            assert_eq!(sine_pair(phase.wrapping_add(1 << 31)), (-c, -s));
            assert_eq!(sine_pair(phase.wrapping_add(1 << 30)).1, c);
            let peak = crate::fine_sine_table::OUTPUT_PEAK;
            assert!((-peak..=peak).contains(&c) && (-peak..=peak).contains(&s));
        }
    }
}
