//! The modulation NCO's quarter-wave sine table (`crate::sine`), from
//! which the carriers' 8192-word tables are also interpolated at power-up
//! (`crate::carrier_table_fill`).
//!
//! 4096 entries cover the first quadrant, sampled at the centre of each
//! interval (the "half-LSB offset" table):
//!
//! ```text
//!   value[i] = round(32767 * sin((i + 1/2) * D))          D = (pi/2) / 4096
//! ```
//!
//! Centred samples make the quadrant mirror exact: cos at entry i is the
//! sine at entry 4095 - i, which is `!i` in 12 bits, with no special case
//! at the quadrant edges. Every value lies in [0, 32767], a 16-bit signed
//! word; 4096 x 16 bits is 16 iCE40 `SB_RAM40_4K` or 4 ECP5 `DP16KD`.

/// Address bits of the quarter-wave table (4096 entries); defined in the
/// leaf crate, whose host code computes the calibration envelope's
/// fundamental from the same words.
pub const ADDRESS_BITS: usize = gyrocal_regs::datapath::MODULATION_TABLE_BITS;
/// Number of entries in the quarter-wave table.
pub const ENTRIES: usize = 1 << ADDRESS_BITS;
/// Peak amplitude of every sine/cosine in the datapath: full scale of a
/// 16-bit signed word, kept symmetric (never -32768).
pub use gyrocal_regs::datapath::PEAK;

/// The table step D = (pi/2) / 4096 in radians.
pub fn step_radians() -> f64 {
    std::f64::consts::FRAC_PI_2 / ENTRIES as f64
}

/// `value[i]`, the sine at the centre of interval i of the first quadrant
/// (`gyrocal_regs::datapath::modulation_word`).
pub fn value(i: usize) -> i32 {
    gyrocal_regs::datapath::modulation_word(i)
}

/// The whole table, `value[0..4096]`.
pub fn table() -> Vec<i32> {
    (0..ENTRIES).map(value).collect()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_fit_in_signed_16_bit_words() {
        let v = table();
        assert!(v.iter().all(|&x| (0..=PEAK).contains(&x)));
        assert_eq!(*v.last().unwrap(), PEAK);
    }

    #[test]
    fn mirror_gives_the_cosine() {
        // cos((i+1/2)D) = sin((4095-i+1/2)D) exactly, so the mirrored entry
        // is the cosine sample up to the rounding of one table value.
        let d = step_radians();
        for i in 0..ENTRIES {
            let c = PEAK as f64 * ((i as f64 + 0.5) * d).cos();
            assert!((value(ENTRIES - 1 - i) as f64 - c).abs() <= 0.5);
        }
    }
}
