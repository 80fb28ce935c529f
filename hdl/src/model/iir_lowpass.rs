//! Bit-true model of `crate::iir_lowpass::IirLowpass`.
//!
//! The schedule is mirrored register by register (step counter, operand and
//! coefficient registers, the multiplier's output register, accumulator), so
//! the model matches the hardware on every cycle, including inputs dropped
//! while a schedule runs.

/// Sign-extend the low `bits` bits of `x`.
#[inline(always)]
fn wrap(x: i128, bits: u32) -> i128 {
    (x << (128 - bits)) >> (128 - bits)
}

/// The four filter coefficients, Q2.30.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct Coefficients {
    /// Biquad numerator gain g.
    pub k0: i32,
    /// Biquad feedback -a1 - 2.
    pub k1: i32,
    /// Biquad feedback 1 - a2.
    pub k2: i32,
    /// RC section coefficient.
    pub alpha: i32,
}

/// Cycle-true model of one filter channel.
#[derive(Clone, Debug, Default)]
pub struct IirLowpass {
    step: u8,
    x: [i64; 3],
    v: i128,
    operand: i128,
    coefficient: i32,
    product: i128,
    accumulator: i128,
    y1: i128,
    y2: i128,
    u: i128,
    z: i64,
    z_valid: bool,
}

impl IirLowpass {
    /// `(z, z_valid)` during the current cycle.
    #[inline(always)]
    pub fn output(&self) -> (i64, bool) {
        (self.z, self.z_valid)
    }

    /// True while a schedule runs (inputs are dropped).
    #[inline(always)]
    pub fn busy(&self) -> bool {
        self.step != 0
    }

    /// One clock; returns `(z, z_valid)` after the edge.
    #[inline(always)]
    pub fn step(&mut self, x: i64, x_valid: bool, k: &Coefficients) -> (i64, bool) {
        if self.step == 0 && !x_valid {
            // Idle: only the pulse ends. (The multiplier register keeps
            // multiplying the idle operands, but it is read only in steps
            // 4, 5, 6 and 10, after it has been reloaded.)
            self.z_valid = false;
            return (self.z, false);
        }
        let product = self.product;
        // The product register during the next cycle: read in steps 4, 5, 6
        // and 10, so it is loaded in steps 3, 4, 5 and 9.
        if matches!(self.step, 3 | 4 | 5 | 9) {
            self.product = self.operand * self.coefficient as i128;
        }
        self.z_valid = false;
        match self.step {
            0 => {
                if x_valid {
                    self.x = [x, self.x[0], self.x[1]];
                    self.step = 1;
                }
            }
            1 => {
                let sum = self.x[0] as i128 + 2 * self.x[1] as i128 + self.x[2] as i128;
                self.v = wrap(sum << 16, 60);
                self.step = 2;
            }
            2 => {
                self.operand = self.v;
                self.coefficient = k.k0;
                self.step = 3;
            }
            3 => {
                self.operand = self.y1;
                self.coefficient = k.k1;
                self.step = 4;
            }
            4 => {
                self.operand = self.y2;
                self.coefficient = k.k2;
                self.accumulator = product;
                self.step = 5;
            }
            5 | 6 => {
                self.accumulator = wrap(self.accumulator + product, 96);
                self.step += 1;
            }
            7 => {
                let scaled = wrap(wrap(self.accumulator + (1 << 29), 96) >> 30, 60);
                let y_new = wrap(2 * self.y1 - self.y2 + scaled, 60);
                self.y2 = self.y1;
                self.y1 = wrap(y_new, 58);
                self.step = 8;
            }
            8 => {
                self.operand = wrap(self.y1 - self.u, 60);
                self.coefficient = k.alpha;
                self.step = 9;
            }
            9 => self.step = 10,
            10 => {
                let scaled = wrap(wrap(product + (1 << 29), 92) >> 30, 60);
                self.u = wrap(self.u + scaled, 58);
                self.step = 11;
            }
            _ => {
                self.z = wrap(wrap(self.u + (1 << 15), 58) >> 16, 40) as i64;
                self.z_valid = true;
                self.step = 0;
            }
        }
        (self.z, self.z_valid)
    }
}
