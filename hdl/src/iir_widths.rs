//! The output filter's widths of record (`crate::iir_lowpass`'s header
//! derives them), in a leaf that the filter's blocks, its micro-program
//! (`crate::iir_program`) and its model import downward.

/// Width of the input and output samples.
pub const SAMPLE_BITS: usize = crate::cic_widths::OUTPUT_BITS;
/// Fractional bits of the coefficients (Q2.30).
pub use gyrocal_regs::datapath::COEFFICIENT_FRACTION_BITS;
/// Width of the coefficients.
pub const COEFFICIENT_BITS: usize = 32;
/// Guard bits of the states below the output LSB.
pub use gyrocal_regs::datapath::GUARD_BITS;
/// Width of the states y1, y2, u: 40-bit samples, guard bits, 2 bits of headroom.
pub const STATE_BITS: usize = SAMPLE_BITS + GUARD_BITS as usize + 2;
/// Width of the recorded multiplier operand: 2 y1 - y2 and y - u fit exactly.
pub const OPERAND_BITS: usize = STATE_BITS + 2;
/// Width of the recorded exact product.
pub const PRODUCT_BITS: usize = OPERAND_BITS + COEFFICIENT_BITS;
/// Width of the recorded accumulators: four terms below 2^(PRODUCT_BITS - 1) each.
pub const ACCUMULATOR_BITS: usize = PRODUCT_BITS + 2;
