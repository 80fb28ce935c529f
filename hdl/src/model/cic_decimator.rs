//! Bit-true model of `crate::cic_decimator::CicDecimator`.
//!
//! Registers mirror the hardware one for one. The hardware's 80-bit
//! wrap-around is modelled by wrapping i128 arithmetic: reduction modulo
//! 2^80 commutes with addition and subtraction, so the low 80 bits of every
//! model register equal the hardware register, and the output stage wraps
//! to 80 bits before it shifts, where the upper bits would start to matter.

use crate::cic_decimator::{OUTPUT_BITS, OUTPUT_STAGES, REGISTER_BITS};

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
///
/// The integrators are brought up to date lazily: inputs wait in `pending`
/// and are integrated in one tight loop when the counter samples the fourth
/// integrator, the only place their values are read. The result is the
/// same register values the hardware has at that cycle.
#[derive(Clone, Debug, Default)]
pub struct CicDecimator {
    integrator: [i128; 4],
    pending: Vec<i32>,
    count: u32,
    sample: i128,
    sample_valid: bool,
    comb: [i128; 4],
    comb_delay: [i128; 4],
    comb_valid: [bool; 4],
    /// The output pipeline: scaled value and strobe after each of the
    /// first `OUTPUT_STAGES - 1` steps (bias, coarse); the last is `y`.
    /// The hardware's intermediate words differ, but the scaled value is
    /// fixed at the bias step (it samples `shift` there) and only moves on.
    output_pipe: [(i64, bool); OUTPUT_STAGES - 1],
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
        // Output stages, last first (each reads the previous cycle's
        // values; the first reads comb 4 before it updates).
        let (last, last_valid) = self.output_pipe[OUTPUT_STAGES - 2];
        self.valid = last_valid;
        if last_valid {
            self.y = last;
        }
        for k in (1..OUTPUT_STAGES - 1).rev() {
            if self.output_pipe[k - 1].1 {
                self.output_pipe[k].0 = self.output_pipe[k - 1].0;
            }
            self.output_pipe[k].1 = self.output_pipe[k - 1].1;
        }
        if self.comb_valid[3] {
            self.output_pipe[0].0 = scale_output(wrap(self.comb[3]), shift);
        }
        self.output_pipe[0].1 = self.comb_valid[3];
        // Combs, last stage first so each reads the previous cycle's values
        // (nothing moves between outputs: skip them then).
        if self.sample_valid || self.comb_valid != [false; 4] {
            for k in (1..4).rev() {
                if self.comb_valid[k - 1] {
                    self.comb[k] = self.comb[k - 1].wrapping_sub(self.comb_delay[k]);
                    self.comb_delay[k] = self.comb[k - 1];
                }
                self.comb_valid[k] = self.comb_valid[k - 1];
            }
            if self.sample_valid {
                self.comb[0] = self.sample.wrapping_sub(self.comb_delay[0]);
                self.comb_delay[0] = self.sample;
            }
            self.comb_valid[0] = self.sample_valid;
        }
        // Counter and decimation.
        self.sample_valid = self.count == 0;
        if self.count == 0 {
            self.integrate_pending();
            self.sample = self.integrator[3];
            self.count = decimation.wrapping_sub(1) & 0x1fff;
        } else {
            self.count -= 1;
        }
        // Integrators: x enters at this edge (see `integrate_pending`).
        self.pending.push(x);
        (self.y, self.valid)
    }

    /// Play the integrators' edges for the inputs still pending.
    #[inline(never)]
    fn integrate_pending(&mut self) {
        let [mut i1, mut i2, mut i3, mut i4] = self.integrator;
        for &x in &self.pending {
            // Every stage takes its predecessor's value before the edge.
            i4 = i4.wrapping_add(i3);
            i3 = i3.wrapping_add(i2);
            i2 = i2.wrapping_add(i1);
            i1 = i1.wrapping_add(x as i128);
        }
        self.integrator = [i1, i2, i3, i4];
        self.pending.clear();
    }
}
