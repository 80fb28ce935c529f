//! Bit-true model of `crate::notch_coefficient::NotchCoefficient`.

use crate::notch_coefficient::{K_COUNT, PERIOD, SHIFT};

/// Cycle-true model: the schedule's count, the carriers' two-clock delay,
/// the sum of the last snapshot (the serial accumulator's result, formed
/// at once) and the coefficient register.
#[derive(Clone, Copy, Debug, Default)]
pub struct NotchCoefficient {
    count: u32,
    /// cos and sin of the last two cycles, newest first.
    cos: [i32; 2],
    sin: [i32; 2],
    sum: i64,
    k: i32,
}

impl NotchCoefficient {
    /// `k` during the current cycle.
    #[inline(always)]
    pub fn output(&self) -> i32 {
        self.k
    }

    /// One clock with the drive carriers `cos`, `sin`; returns `k` after
    /// the edge.
    #[inline(always)]
    pub fn step(&mut self, cos: i32, sin: i32) -> i32 {
        if self.count == 0 {
            self.sum =
                i64::from(cos) * i64::from(self.cos[1]) + i64::from(sin) * i64::from(self.sin[1]);
        } else if self.count == K_COUNT {
            self.k = ((self.sum + (1 << (SHIFT - 1))) >> SHIFT) as i32;
        }
        self.count = (self.count + 1) % PERIOD;
        self.cos = [cos, self.cos[0]];
        self.sin = [sin, self.sin[0]];
        self.k
    }
}
