//! Bit-true model of `crate::q15_multiplier::Q15Multiplier`.

/// `round(a * b / 2^15)`, rounded half up, wrapped to 16 bits.
pub use gyrocal_regs::datapath::q15_product;

/// Cycle-true model: the factor, product and rounding registers.
#[derive(Clone, Copy, Debug, Default)]
pub struct Q15Multiplier {
    factors: (i16, i16),
    product: i32,
    y: i16,
}

impl Q15Multiplier {
    /// `y` during the current cycle.
    #[inline(always)]
    pub fn output(&self) -> i16 {
        self.y
    }

    /// One clock; returns `y` after the edge.
    #[inline(always)]
    pub fn step(&mut self, a: i16, b: i16) -> i16 {
        self.y = ((self.product.wrapping_add(1 << 14)) >> 15) as i16;
        self.product = self.factors.0 as i32 * self.factors.1 as i32;
        self.factors = (a, b);
        self.y
    }
}
