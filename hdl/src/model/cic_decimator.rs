//! Bit-true model of `crate::cic_decimator::CicDecimator`.
//!
//! Registers mirror the hardware one for one; 80-bit wrap-around is done by
//! keeping i128 values sign-extended from bit 79 after every operation.

use crate::cic_decimator::{OUTPUT_BITS, REGISTER_BITS};

/// Wrap to an 80-bit two's complement value.
#[inline(always)]
fn wrap(x: i128) -> i128 {
    const SHIFT: u32 = 128 - REGISTER_BITS as u32;
    (x << SHIFT) >> SHIFT
}

/// `round(x / 2^shift)` (half up) on an 80-bit value, wrapped to 40 bits.
#[inline(always)]
pub fn scale_output(x: i128, shift: u32) -> i64 {
    let rounding = if shift == 0 { 0 } else { 1i128 << (shift - 1) };
    let shifted = wrap(x + rounding) >> shift;
    const OUT_SHIFT: u32 = 128 - OUTPUT_BITS as u32;
    ((shifted << OUT_SHIFT) >> OUT_SHIFT) as i64
}

/// Cycle-true model of one CIC channel.
#[derive(Clone, Debug, Default)]
pub struct CicDecimator {
    integrator: [i128; 4],
    count: u32,
    sample: i128,
    sample_valid: bool,
    comb: [i128; 4],
    comb_delay: [i128; 4],
    comb_valid: [bool; 4],
    y: i64,
    valid: bool,
}

impl CicDecimator {
    /// `(y, valid)` during the current cycle.
    #[inline(always)]
    pub fn output(&self) -> (i64, bool) {
        (self.y, self.valid)
    }

    /// One clock with input `x`, decimation R (13-bit word) and output shift.
    #[inline(always)]
    pub fn step(&mut self, x: i32, decimation: u32, shift: u32) -> (i64, bool) {
        // Output stage (reads comb 4 before it updates).
        self.valid = self.comb_valid[3];
        if self.comb_valid[3] {
            self.y = scale_output(self.comb[3], shift);
        }
        // Combs, last stage first so each reads the previous cycle's values.
        for k in (1..4).rev() {
            if self.comb_valid[k - 1] {
                self.comb[k] = wrap(self.comb[k - 1] - self.comb_delay[k]);
                self.comb_delay[k] = self.comb[k - 1];
            }
            self.comb_valid[k] = self.comb_valid[k - 1];
        }
        if self.sample_valid {
            self.comb[0] = wrap(self.sample - self.comb_delay[0]);
            self.comb_delay[0] = self.sample;
        }
        self.comb_valid[0] = self.sample_valid;
        // Counter and decimation.
        self.sample_valid = self.count == 0;
        if self.count == 0 {
            self.sample = self.integrator[3];
            self.count = decimation.wrapping_sub(1) & 0x1fff;
        } else {
            self.count -= 1;
        }
        // Integrators, last stage first.
        for k in (1..4).rev() {
            self.integrator[k] = wrap(self.integrator[k] + self.integrator[k - 1]);
        }
        self.integrator[0] = wrap(self.integrator[0] + x as i128);
        (self.y, self.valid)
    }
}
