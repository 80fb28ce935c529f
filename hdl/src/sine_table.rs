//! The quarter-wave sine table of the modulation NCO's sine generator
//! (`crate::sine`), which also computes the carriers' 8192-word tables at
//! power-up (`crate::carrier_table_fill`).
//!
//! 256 entries cover the first quadrant, sampled at the centre of each
//! interval (the "half-LSB offset" table):
//!
//! ```text
//!   value[i] = round(32767 * sin((i + 1/2) * D))          D = (pi/2) / 256
//!   slope[i] = round(32767 * cos((i + 1/2) * D) * D * 2^7)
//! ```
//!
//! Centred samples make the quadrant mirror exact: cos at entry i is the sine
//! at entry 255 - i, which is `!i` in 8 bits, with no special case at the
//! quadrant edges. `slope` is the derivative of `value` per table step, scaled
//! by 2^7 so it keeps 7 more bits than the 16-bit samples; the first-order
//! Taylor correction in `crate::sine` uses it to interpolate between entries, which
//! takes the spur level from about -72 dBc (plain 256-entry table) to below
//! -100 dBc. Both columns are positive and below 2^15 (value <= 32767,
//! slope <= 25735), so they are stored as 16-bit signed words.

/// Address bits of the quarter-wave table (256 entries).
pub const ADDRESS_BITS: usize = 8;
/// Number of entries in the quarter-wave table.
pub const ENTRIES: usize = 1 << ADDRESS_BITS;
/// Peak amplitude of every sine/cosine in the datapath: full scale of a
/// 16-bit signed word, kept symmetric (never -32768).
pub const PEAK: i32 = 32767;
/// Extra fractional bits of the `slope` column.
pub const SLOPE_EXTRA_BITS: u32 = 7;

/// The table step D = (pi/2) / 256 in radians.
pub fn step_radians() -> f64 {
    std::f64::consts::FRAC_PI_2 / ENTRIES as f64
}

/// `value[i]`, the sine at the centre of interval i of the first quadrant.
pub fn value(i: usize) -> i32 {
    let d = step_radians();
    (PEAK as f64 * ((i as f64 + 0.5) * d).sin()).round() as i32
}

/// `slope[i]`, the derivative of the sine per table step, times 2^7.
pub fn slope(i: usize) -> i32 {
    let d = step_radians();
    (PEAK as f64 * ((i as f64 + 0.5) * d).cos() * d * f64::from(1u32 << SLOPE_EXTRA_BITS)).round()
        as i32
}

/// Both columns, built once: `(value, slope)`.
pub fn table() -> (Vec<i32>, Vec<i32>) {
    (
        (0..ENTRIES).map(value).collect(),
        (0..ENTRIES).map(slope).collect(),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn columns_fit_in_signed_16_bit_words() {
        let (v, s) = table();
        assert!(v.iter().all(|&x| (0..=PEAK).contains(&x)));
        assert!(s.iter().all(|&x| (0..=PEAK).contains(&x)));
        assert_eq!(*v.last().unwrap(), PEAK);
        assert_eq!(s[0], 25735);
    }

    #[test]
    fn mirror_gives_the_cosine() {
        // cos((i+1/2)D) = sin((255-i+1/2)D) exactly, so the mirrored entry is
        // the cosine sample up to the shared rounding of one table value.
        let d = step_radians();
        for i in 0..ENTRIES {
            let c = PEAK as f64 * ((i as f64 + 0.5) * d).cos();
            assert!((value(ENTRIES - 1 - i) as f64 - c).abs() <= 0.5);
        }
    }
}
