//! Bit-true model of `crate::reference_alignment::ReferenceAlignment`.

const TAPS: usize = 1 << crate::reference_alignment::DELAY_BITS;

/// Cycle-true model of the two 64-word delay lines.
#[derive(Clone, Debug)]
pub struct ReferenceAlignment {
    /// Ring buffer of (ref1, ref2); `words[newest]` entered at the last edge.
    words: [(i16, i16); TAPS],
    newest: usize,
    /// The registered output.
    aligned: (i16, i16),
}

impl Default for ReferenceAlignment {
    fn default() -> Self {
        Self {
            words: [(0, 0); TAPS],
            newest: 0,
            aligned: (0, 0),
        }
    }
}

impl ReferenceAlignment {
    /// `(aligned1, aligned2)` during the current cycle.
    #[inline(always)]
    pub fn output(&self) -> (i16, i16) {
        self.aligned
    }

    /// One clock: read the word `delay` edges old (or the input itself for
    /// a delay of 0), then write the references.
    #[inline(always)]
    pub fn step(&mut self, ref1: i16, ref2: i16, delay: u8) {
        let delay = delay as usize & (TAPS - 1);
        self.aligned = if delay == 0 {
            (ref1, ref2)
        } else {
            self.words[(self.newest + TAPS + 1 - delay) % TAPS]
        };
        self.newest = (self.newest + 1) % TAPS;
        self.words[self.newest] = (ref1, ref2);
    }
}
