//! The interpolated carrier profile's constants: a quarter-wave table of
//! words with two fractional bits and the slopes that interpolate three
//! more phase bits. Imported by the block (`crate::sine_pair`), its ROM
//! (`crate::primitives::FineSineRom`) and its model (`crate::model::sine_pair`).
//!
//! ```text
//!   word[i]  = round(4 * 32767 * sin((i + 1/2) * D))      D = (pi/2) / 8192, i < 8192
//!   slope[s] = round((2 s - 7) * (D / 16) * 2^30)          s < 8
//! ```
//!
//! Why it exists: the built carriers (`crate::table_sine`) round each table
//! word to an integer. A carrier near a short fold of the clock visits few
//! table phases, drifting slowly, and the words' rounding comes back as a
//! slow error of the carrier's amplitude and phase: the rate ripple of
//! docs/field.md. Words a quarter LSB fine, three phase bits interpolated
//! and one rounding at the end, to a quarter LSB, make the output a
//! function of 18 phase bits rounded once, and that error averages away
//! (`examples/carrier_profiles.rs` measures it). The AM mixer multiplies
//! the quarter-LSB output, so the DAC word is rounded only once.
//!
//! Widths: `word[i]` lies in [0, 131068] (17 unsigned bits; 4 x 32767 =
//! 131068 < 2^17); `slope[s]` lies in [-90076, 90076] (18 signed bits). A
//! product `word * slope` lies within 131068 x 90076 < 2^34 (35 signed
//! bits). The slope is the phase offset of sub-interval `s` from the centre
//! of its interval, (2 s - 7) / 16 intervals, in radians at 2^30: the first
//! order term of sin(x + d) = sin x + d cos x, with the cosine the
//! mirrored word. Its rounding is at most 0.5 / 2^30 rad a unit of the
//! cross word: 6e-5 quarter LSB.

/// Index bits of the quarter-wave table: 2^13 intervals per quadrant.
pub const TABLE_BITS: usize = crate::quarter_wave::TABLE_BITS;
/// Intervals per quadrant.
pub const TABLE_ENTRIES: usize = 1 << TABLE_BITS;
/// Fractional bits of a table word (quarter LSB).
pub const WORD_FRACTION_BITS: u32 = 2;
/// Word width (unsigned).
pub const WORD_BITS: usize = 17;
/// Phase bits interpolated below the table index.
pub const INTERPOLATED_BITS: usize = 3;
/// Sub-intervals of an interval (`slope` entries).
pub const SUBINTERVALS: usize = 1 << INTERPOLATED_BITS;
/// Slope width (signed).
pub const SLOPE_BITS: usize = 18;
/// Fraction bits of a slope (radians at 2^30).
pub const SLOPE_FRACTION_BITS: u32 = 30;
/// Fraction bits kept of a product below the word's quarter LSB: a
/// product is shifted right by `SLOPE_FRACTION_BITS - SUM_GUARD_BITS`.
pub const SUM_GUARD_BITS: u32 = 8;
/// The product's arithmetic right shift (floor) to the sum's scale.
pub const PRODUCT_SHIFT: u32 = SLOPE_FRACTION_BITS - SUM_GUARD_BITS;
/// Fraction bits of the sum below the word's unit (32767 at the peak).
pub const SUM_FRACTION_BITS: u32 = WORD_FRACTION_BITS + SUM_GUARD_BITS;
/// Fraction bits of an output word: the pair's outputs are four times the
/// sine, 32767 x 4 at the peak, like the table words. The AM mixer
/// (`crate::am_mixer::FineAmMixer`) rounds its product once, to the DAC's
/// 16 bits; a carrier rounded to an integer first would add a second
/// rounding, whose pattern a fold turns into a slow error (docs/field.md).
pub const OUTPUT_FRACTION_BITS: u32 = 2;
/// Output width (signed): |output| <= 4 x 32767 < 2^17.
pub const OUTPUT_BITS: usize = 18;
/// The final rounding's shift: `SUM_FRACTION_BITS - OUTPUT_FRACTION_BITS`.
pub const OUTPUT_SHIFT: u32 = SUM_FRACTION_BITS - OUTPUT_FRACTION_BITS;
/// An output word's peak, 4 x 32767.
pub const OUTPUT_PEAK: i32 = crate::sine_table::PEAK << OUTPUT_FRACTION_BITS;

const _: () = assert!(4 * 32767 < 1 << WORD_BITS);

/// The table interval in radians, D = (pi/2) / 8192.
pub fn interval_radians() -> f64 {
    std::f64::consts::FRAC_PI_2 / TABLE_ENTRIES as f64
}

/// `word[i]`: four times the sine at the centre of interval `i`.
pub fn word(i: usize) -> u32 {
    let peak = f64::from(4 * crate::sine_table::PEAK);
    (peak * ((i as f64 + 0.5) * interval_radians()).sin()).round() as u32
}

/// The whole table, `word[0..8192]`.
pub fn words() -> Vec<u32> {
    (0..TABLE_ENTRIES).map(word).collect()
}

/// `slope[s]`: the phase offset of sub-interval `s` from its interval's
/// centre, in radians at 2^30.
pub fn slope(s: usize) -> i32 {
    let offset = (2.0 * s as f64 - 7.0) / 16.0 * interval_radians();
    (offset * 2f64.powi(SLOPE_FRACTION_BITS as i32)).round() as i32
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn words_fit_17_unsigned_bits_and_end_at_four_times_the_peak() {
        let w = words();
        assert!(w.iter().all(|&x| x < 1 << WORD_BITS));
        assert_eq!(w[TABLE_ENTRIES - 1], 4 * 32767);
    }

    #[test]
    fn slopes_fit_18_signed_bits_and_are_odd_about_the_centre() {
        for s in 0..SUBINTERVALS {
            assert!(slope(s).abs() < 1 << (SLOPE_BITS - 1), "slope {s}");
            assert_eq!(slope(s), -slope(SUBINTERVALS - 1 - s));
        }
        assert_eq!(slope(7), 90076);
    }

    #[test]
    fn a_product_fits_35_signed_bits() {
        let most = i64::from(4 * 32767) * i64::from(slope(7));
        assert!(most < 1 << 34);
    }
}
