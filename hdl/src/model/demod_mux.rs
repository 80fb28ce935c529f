//! Bit-true model of `crate::demod_mux::DemodMux`.

/// Cycle-true model of the SELECT mux and the two mixers.
#[derive(Clone, Copy, Debug, Default)]
pub struct DemodMux {
    adc: (i16, i16),
    reference: (i16, i16),
    w: (i32, i32),
}

impl DemodMux {
    /// `(w1, w2)` during the current cycle.
    #[inline(always)]
    pub fn output(&self) -> (i32, i32) {
        self.w
    }

    /// One clock; returns `(w1, w2)` after the edge.
    #[inline(always)]
    pub fn step(&mut self, adc: (i16, i16), aligned: (i16, i16), select: bool) -> (i32, i32) {
        self.w = (
            self.adc.0 as i32 * self.reference.0 as i32,
            self.adc.1 as i32 * self.reference.1 as i32,
        );
        self.adc = adc;
        self.reference = if select {
            (aligned.1, aligned.0)
        } else {
            aligned
        };
        self.w
    }

    /// `(w1, w2)` during the next `out.len()` cycles, then as many edges
    /// with `adc[i]` and `aligned[i]` the inputs during cycle i: `output`
    /// and `step` clock by clock. From cycle 2 on, w is the product of the
    /// inputs of two cycles before.
    #[inline(always)]
    pub fn block(
        &mut self,
        adc: &[(i16, i16)],
        aligned: &[(i16, i16)],
        select: bool,
        out: &mut [(i32, i32)],
    ) {
        let n = out.len();
        if n == 0 {
            return;
        }
        let reference = |a: (i16, i16)| if select { (a.1, a.0) } else { a };
        let product =
            |x: (i16, i16), r: (i16, i16)| (x.0 as i32 * r.0 as i32, x.1 as i32 * r.1 as i32);
        let held = product(self.adc, self.reference);
        out[0] = self.w;
        if n > 1 {
            out[1] = held;
        }
        // The mux's choice outside the loop: two plain loops of products.
        let pairs = out.iter_mut().skip(2).zip(adc).zip(aligned);
        if select {
            for ((o, &x), &a) in pairs {
                *o = product(x, (a.1, a.0));
            }
        } else {
            for ((o, &x), &a) in pairs {
                *o = product(x, a);
            }
        }
        self.w = if n == 1 {
            held
        } else {
            product(adc[n - 2], reference(aligned[n - 2]))
        };
        self.adc = adc[n - 1];
        self.reference = reference(aligned[n - 1]);
    }
}
