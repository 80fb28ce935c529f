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
        self.y = round(self.product);
        self.product = multiply(self.factors);
        self.factors = (a, b);
        self.y
    }

    /// `y` during the next `out.len()` cycles, then as many edges with
    /// `input(k)` presented at edge k: `output` and `step` clock by clock.
    #[inline(always)]
    pub fn block(&mut self, out: &mut [i16], input: impl Fn(usize) -> (i16, i16)) {
        let registers = (&mut self.factors, &mut self.product, &mut self.y);
        product_block(registers, out, input, multiply, round);
    }
}

/// The product register's word.
#[inline(always)]
fn multiply((a, b): (i16, i16)) -> i32 {
    a as i32 * b as i32
}

/// The rounding register's word: `round(p / 2^15)` half up, wrapped.
#[inline(always)]
fn round(p: i32) -> i16 {
    ((p.wrapping_add(1 << 14)) >> 15) as i16
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
    let held = (*factors, *product, *y);
    for (k, o) in out.iter_mut().enumerate().take(3) {
        *o = product_in_flight(held, k, &multiply, &round);
    }
    for (k, o) in out.iter_mut().enumerate().skip(3) {
        *o = round(multiply(input(k - 3)));
    }
    product_skip((factors, product, y), out.len(), input, multiply, round);
}

/// The word of a product pipeline during cycle `k` < 3 from its registers
/// (factors, product, word): the word, the rounded product, the rounded
/// factors' product.
#[inline(always)]
pub fn product_in_flight<F: Copy, P: Copy>(
    (factors, product, y): (F, P, i16),
    k: usize,
    multiply: impl Fn(F) -> P,
    round: impl Fn(P) -> i16,
) -> i16 {
    match k {
        0 => y,
        1 => round(product),
        _ => round(multiply(factors)),
    }
}

/// A product pipeline's registers after `m` edges with `input(k)` at edge
/// k, as `product_block` leaves them: the word `m` cycles on, the product
/// of the input before the last, the last input.
#[inline(always)]
pub fn product_skip<F: Copy, P: Copy>(
    (factors, product, y): (&mut F, &mut P, &mut i16),
    m: usize,
    input: impl Fn(usize) -> F,
    multiply: impl Fn(F) -> P,
    round: impl Fn(P) -> i16,
) {
    if m == 0 {
        return;
    }
    let word = match m {
        1 | 2 => product_in_flight((*factors, *product, *y), m, &multiply, &round),
        _ => round(multiply(input(m - 3))),
    };
    *product = match m {
        1 => multiply(*factors),
        _ => multiply(input(m - 2)),
    };
    *factors = input(m - 1);
    *y = word;
}
