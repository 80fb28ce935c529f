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

    /// `y` during the next `out.len()` cycles, then as many edges with
    /// `input(k)` presented at edge k: `output` and `step` clock by clock.
    #[inline(always)]
    pub fn block(&mut self, out: &mut [i16], input: impl Fn(usize) -> (i16, i16)) {
        let registers = (&mut self.factors, &mut self.product, &mut self.y);
        product_block(
            registers,
            out,
            input,
            |(a, b)| a as i32 * b as i32,
            |p| ((p.wrapping_add(1 << 14)) >> 15) as i16,
        );
    }
}

/// A product pipeline's three registers (factors, product, rounded word)
/// over a block: the rounded words during the next `out.len()` cycles,
/// then as many edges with `input(k)` entering the factor register at edge
/// k. At each edge the word takes `round(product)`, the product
/// `multiply(factors)` and the factors the input, so from cycle 3 on the
/// word is `round(multiply(input(k - 3)))`, without a carried dependence.
#[inline(always)]
pub fn product_block<F: Copy, P: Copy>(
    (factors, product, y): (&mut F, &mut P, &mut i16),
    out: &mut [i16],
    input: impl Fn(usize) -> F,
    multiply: impl Fn(F) -> P,
    round: impl Fn(P) -> i16,
) {
    let n = out.len();
    if n == 0 {
        return;
    }
    let (f0, p0) = (*factors, *product);
    // The product register during cycle k.
    let product_at = |k: usize| match k {
        0 => p0,
        1 => multiply(f0),
        _ => multiply(input(k - 2)),
    };
    out[0] = *y;
    for (k, o) in out.iter_mut().enumerate().skip(1).take(2) {
        *o = round(product_at(k - 1));
    }
    for (k, o) in out.iter_mut().enumerate().skip(3) {
        *o = round(multiply(input(k - 3)));
    }
    *y = round(product_at(n - 1));
    *product = product_at(n);
    *factors = input(n - 1);
}
