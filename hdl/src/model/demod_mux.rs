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
}
