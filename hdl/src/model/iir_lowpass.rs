//! Bit-true model of `crate::iir_lowpass::IirLowpass` (both channels).
//!
//! The schedule is mirrored state by state. The shared multiplier is
//! modelled by when its products are read: an operand loaded at the edge
//! that ends state s is in the operand register during s + 1, so its
//! product is on the multiplier's output during state s + 1 + 4 (every read
//! falls inside the same schedule, so the products of idle cycles never
//! matter). Every register wraps at its hardware width.

use crate::iir_channel::SAMPLE_BITS;
use crate::iir_lowpass::{
    ACCUMULATOR_BITS, COEFFICIENT_FRACTION_BITS, GUARD_BITS, OPERAND_BITS, SCHEDULE_CLOCKS,
    STATE_BITS,
};
use crate::primitives::pipelined_multiplier::LATENCY as MULTIPLIER_LATENCY;

/// Sign-extend the low `bits` bits of `x`.
#[inline(always)]
fn wrap(x: i128, bits: usize) -> i128 {
    (x << (128 - bits)) >> (128 - bits)
}

/// Half an LSB of the product's 30 dropped bits.
const HALF_COEFFICIENT_LSB: i128 = 1 << (COEFFICIENT_FRACTION_BITS - 1);

/// `m 2^30 + 2^29`, the accumulator preload for an integer m.
#[inline(always)]
fn preload(m: i128) -> i128 {
    wrap(
        (m << COEFFICIENT_FRACTION_BITS) | HALF_COEFFICIENT_LSB,
        ACCUMULATOR_BITS,
    )
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

/// The registers of one channel (`crate::iir_channel::IirChannel`).
#[derive(Clone, Copy, Debug, Default)]
struct Channel {
    x0: i64,
    x1: i64,
    v: i128,
    feedback: i128,
    acc_y: i128,
    acc_d: i128,
    y1: i128,
    y2: i128,
    u: i128,
    z: i64,
}

impl Channel {
    fn start(&mut self, x: i64) {
        let sum = x as i128 + 2 * self.x0 as i128 + self.x1 as i128;
        self.v = wrap(sum << GUARD_BITS, OPERAND_BITS);
        self.feedback = wrap(2 * self.y1 - self.y2, OPERAND_BITS);
        self.x1 = self.x0;
        self.x0 = x;
    }

    fn preload(&mut self) {
        self.acc_y = preload(self.feedback);
        self.acc_d = preload(wrap(self.feedback - self.u, OPERAND_BITS));
    }

    fn accumulate(&mut self, p: i128) {
        self.acc_y = wrap(self.acc_y + p, ACCUMULATOR_BITS);
        self.acc_d = wrap(self.acc_d + p, ACCUMULATOR_BITS);
    }

    /// Finish the biquad; returns y - u, the RC section's operand.
    fn finish(&mut self, p: i128) -> i128 {
        let shift = COEFFICIENT_FRACTION_BITS;
        let y = wrap(wrap(self.acc_y + p, ACCUMULATOR_BITS) >> shift, STATE_BITS);
        let difference = wrap(
            wrap(self.acc_d + p, ACCUMULATOR_BITS) >> shift,
            OPERAND_BITS,
        );
        self.y2 = self.y1;
        self.y1 = y;
        difference
    }

    fn update_u(&mut self, p: i128) {
        let sum = wrap(preload(self.u) + p, ACCUMULATOR_BITS);
        self.u = wrap(sum >> COEFFICIENT_FRACTION_BITS, STATE_BITS);
    }

    fn publish(&mut self) {
        let rounded = wrap(self.u + (1 << (GUARD_BITS - 1)), STATE_BITS);
        self.z = wrap(rounded >> GUARD_BITS, SAMPLE_BITS) as i64;
    }
}

/// Cycle-true model of the two-channel filter.
#[derive(Clone, Debug, Default)]
pub struct IirLowpass {
    /// The schedule state, 0 = Idle, as `IirStep` counts.
    step: usize,
    /// Product on the multiplier output during each state of the schedule.
    product_at: [i128; SCHEDULE_CLOCKS],
    channels: [Channel; 2],
    publishing: bool,
    z_valid: bool,
}

impl IirLowpass {
    /// `(z1, z2, z_valid)` during the current cycle.
    #[inline(always)]
    pub fn output(&self) -> (i64, i64, bool) {
        (self.channels[0].z, self.channels[1].z, self.z_valid)
    }

    /// True while a schedule runs (strobes are dropped).
    #[inline(always)]
    pub fn busy(&self) -> bool {
        self.step != 0
    }

    /// Issue `operand * coefficient` at the edge that ends the current state.
    #[inline(always)]
    fn issue(&mut self, operand: i128, coefficient: i32) {
        self.product_at[self.step + 1 + MULTIPLIER_LATENCY] = operand * coefficient as i128;
    }

    /// One clock with inputs `x` and strobe `x_valid`; returns
    /// `(z1, z2, z_valid)` after the edge.
    #[inline(always)]
    pub fn step(&mut self, x: (i64, i64), x_valid: bool, k: &Coefficients) -> (i64, i64, bool) {
        self.z_valid = self.publishing;
        if self.publishing {
            self.channels[0].publish();
            self.channels[1].publish();
        }
        self.publishing = false;
        if self.step == 0 && !x_valid {
            return self.output();
        }
        let p = self.product_at[self.step];
        let [first, second] = &mut self.channels;
        let mut next = self.step + 1;
        let issue = match self.step {
            0 => {
                let operand = first.y1;
                first.start(x.0);
                second.start(x.1);
                Some((operand, k.k1))
            }
            1 => {
                first.preload();
                second.preload();
                Some((first.y2, k.k2))
            }
            2 => Some((first.v, k.k0)),
            3 => Some((second.y1, k.k1)),
            4 => Some((second.y2, k.k2)),
            5 => {
                first.accumulate(p);
                Some((second.v, k.k0))
            }
            6 => {
                first.accumulate(p);
                None
            }
            7 => Some((first.finish(p), k.alpha)),
            8 | 9 => {
                second.accumulate(p);
                None
            }
            10 => Some((second.finish(p), k.alpha)),
            12 => {
                first.update_u(p);
                None
            }
            15 => {
                second.update_u(p);
                self.publishing = true;
                next = 0;
                None
            }
            _ => None,
        };
        if let Some((operand, coefficient)) = issue {
            self.issue(operand, coefficient);
        }
        self.step = next;
        self.output()
    }
}
